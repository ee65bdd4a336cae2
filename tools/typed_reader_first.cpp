#include "typed_reader_impl.hpp"

namespace horus::tools {

namespace {
detail::Opened open_any(std::string_view type_name, const std::string& name, const std::optional<Backend>& backend,
                        detail::Want want, std::string& error) {
  detail::Opened out;
  error.clear();
  detail::open_first_half(type_name, name, backend, want, out, error);
  if (!out.known) detail::open_second_half(type_name, name, backend, want, out, error);
  return out;
}
}  // namespace

std::string standard_type(std::string_view type_name) {
  std::string error;
  return open_any(type_name, {}, std::nullopt, detail::Want::Name, error).qualified;
}

std::unique_ptr<TypedReader> open_reader(std::string_view type_name, const std::string& name, const Backend& backend,
                                         std::string& error) {
  return open_any(type_name, name, backend, detail::Want::Reader, error).reader;
}

std::unique_ptr<TypedWriter> open_writer(std::string_view type_name, const std::string& name,
                                         const std::optional<Backend>& backend, std::string& error) {
  return open_any(type_name, name, backend, detail::Want::Writer, error).writer;
}

namespace detail {
void open_first_half(std::string_view type_name, const std::string& name, const std::optional<Backend>& backend,
                     Want want, Opened& out, std::string& error) {
  using First = msg::detail::Concat<msg::GeometryMessages, msg::SensorMessages, msg::ControlMessages,
                                    msg::VisionMessages, msg::DetectionMessages, msg::PerceptionMessages>::type;
  open_as(First{}, type_name, name, backend, want, out, error);
}
}  // namespace detail

}  // namespace horus::tools

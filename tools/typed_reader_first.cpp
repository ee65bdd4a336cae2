#include "typed_reader_impl.hpp"

namespace horus::tools {

std::unique_ptr<TypedReader> open_reader(std::string_view type_name, const std::string& name, const Backend& backend,
                                         std::string& error) {
  bool known = false;
  error.clear();
  auto r = detail::open_reader_first_half(type_name, name, backend, error, known);
  if (!known) r = detail::open_reader_second_half(type_name, name, backend, error, known);
  return r;
}

namespace detail {
std::unique_ptr<TypedReader> open_reader_first_half(std::string_view type_name, const std::string& name,
                                                    const Backend& backend, std::string& error, bool& known) {
  using First = msg::detail::Concat<msg::GeometryMessages, msg::SensorMessages, msg::ControlMessages,
                                    msg::VisionMessages, msg::DetectionMessages, msg::PerceptionMessages>::type;
  return open_as(First{}, type_name, name, backend, error, known);
}
}  // namespace detail

}  // namespace horus::tools

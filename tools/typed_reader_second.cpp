#include "typed_reader_impl.hpp"

namespace horus::tools::detail {

std::unique_ptr<TypedReader> open_reader_second_half(std::string_view type_name, const std::string& name,
                                                     const Backend& backend, std::string& error, bool& known) {
  using Second = msg::detail::Concat<msg::NavigationMessages, msg::DiagnosticsMessages, msg::ForceMessages,
                                     msg::InputMessages, msg::TrackingMessages, msg::TimeMessages,
                                     msg::AudioMessages, msg::GenericMessages>::type;
  return open_as(Second{}, type_name, name, backend, error, known);
}

}  // namespace horus::tools::detail

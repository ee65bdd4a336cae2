#include "typed_reader_impl.hpp"

namespace horus::tools::detail {

void open_second_half(std::string_view qualified, Want want, Opened& out, std::string& error) {
  using Second = msg::detail::Concat<msg::NavigationMessages, msg::DiagnosticsMessages, msg::ForceMessages,
                                     msg::InputMessages, msg::TrackingMessages, msg::TimeMessages,
                                     msg::AudioMessages, msg::GenericMessages>::type;
  open_as(Second{}, qualified, want, out, error);
}

}  // namespace horus::tools::detail

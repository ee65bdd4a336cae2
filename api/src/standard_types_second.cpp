// The standard types' tables of the navigation, diagnostics, force, input, tracking, time, audio
// and generic messages (horus/standard_types.hpp).
#include "standard_types_impl.hpp"

namespace horus::detail::standard {

std::span<const StandardType* const> second_half() noexcept {
  static const std::vector<const StandardType*> types =
      types_of(msg::detail::Concat<msg::NavigationMessages, msg::DiagnosticsMessages, msg::ForceMessages,
                                   msg::InputMessages, msg::TrackingMessages, msg::TimeMessages, msg::AudioMessages,
                                   msg::GenericMessages>::type{});
  return types;
}

}  // namespace horus::detail::standard

// The network tables of the navigation, diagnostics, force, input, tracking, time, audio and
// generic messages.
#include "standard_wire_ops.hpp"

namespace horus::detail::standard {

using Second = msg::detail::Concat<msg::NavigationMessages, msg::DiagnosticsMessages, msg::ForceMessages,
                                   msg::InputMessages, msg::TrackingMessages, msg::TimeMessages, msg::AudioMessages,
                                   msg::GenericMessages>::type;

const WireOps* find_second(std::uint64_t hash) noexcept { return Domains<Second>::find(hash); }

}  // namespace horus::detail::standard

// The network tables of the geometry, sensor, control, vision, detection and perception messages.
#include "standard_wire_ops.hpp"

namespace horus::detail::standard {

using First = msg::detail::Concat<msg::GeometryMessages, msg::SensorMessages, msg::ControlMessages,
                                  msg::VisionMessages, msg::DetectionMessages, msg::PerceptionMessages>::type;

const WireOps* find_first(std::uint64_t hash) noexcept { return Domains<First>::find(hash); }

}  // namespace horus::detail::standard

// The standard types' tables of the geometry, sensor, control, vision, detection and perception
// messages (horus/standard_types.hpp).
#include "standard_types_impl.hpp"

namespace horus::detail::standard {

std::span<const StandardType* const> first_half() noexcept {
  static const std::vector<const StandardType*> types =
      types_of(msg::detail::Concat<msg::GeometryMessages, msg::SensorMessages, msg::ControlMessages,
                                   msg::VisionMessages, msg::DetectionMessages, msg::PerceptionMessages>::type{});
  return types;
}

}  // namespace horus::detail::standard

// The recorder sources and player sinks of the geometry, sensor, control, vision, detection and
// perception messages (standard.hpp).
#include "standard_impl.hpp"

namespace horus::record_detail {

void open_standard_first(std::string_view type_name, std::string_view name, const TopicOptions& options,
                         StandardOpen& out) {
  open_standard(msg::detail::Concat<msg::GeometryMessages, msg::SensorMessages, msg::ControlMessages,
                                    msg::VisionMessages, msg::DetectionMessages, msg::PerceptionMessages>::type{},
                type_name, name, options, out);
}

}  // namespace horus::record_detail

// The functions of horus/msg/tracking.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/tracking.hpp"

#include <fmt/format.h>

#include <string>
#include <string_view>

namespace horus::msg {

std::string SegmentationMask::log_summary() const {
  const auto t = mask_type_enum();
  std::string out = fmt::format("SegmentationMask({} {}x{} px",
                                t ? (*t == SegmentationType::Semantic   ? "semantic"
                                     : *t == SegmentationType::Instance ? "instance"
                                                                        : "panoptic")
                                  : "unknown type",
                                width, height);
  if (!is_instance()) out += fmt::format(", {} classes", num_classes);
  if (!frame_id_str().empty()) out += fmt::format(", frame {}", frame_id_str());
  out += fmt::format(", seq {})", seq);
  return out;
}

std::string LandmarkArray::log_summary() const {
  return fmt::format("LandmarkArray({} landmarks, {}D, {} visible >= 0.5, conf {:.2f}, instance {})", count(),
                     dimension, visible_count(0.5f), confidence, instance_id);
}

std::string TrackedObject::log_summary() const {
  const auto s = state_enum();
  const std::string_view state_name = !s                             ? std::string_view("unknown state")
                                      : *s == TrackState::Tentative  ? std::string_view("tentative")
                                      : *s == TrackState::Confirmed  ? std::string_view("confirmed")
                                                                     : std::string_view("deleted");
  const std::string cls =
      class_name_str().empty() ? fmt::format("class {}", class_id) : std::string(class_name_str());
  return fmt::format("TrackedObject(id {}, {}, {}, conf {:.2f}, age {} frames, {} missed, speed {:.1f})",
                     track_id, cls, state_name, confidence, age, time_since_update, speed());
}

std::string TrackingHeader::log_summary() const {
  return fmt::format("TrackingHeader(frame {}, {} tracks, {} active, {} created)", frame_id, num_tracks,
                     active_tracks, total_tracks);
}

}  // namespace horus::msg

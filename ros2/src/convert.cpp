// The table of conversions (convert.hpp): each domain's file adds its own.
#include <algorithm>
#include <string_view>
#include <vector>

#include "cdr_io.hpp"

namespace horus::ros2 {

std::span<const Conversion> conversions() noexcept {
  static const std::vector<Conversion> all = [] {
    std::vector<Conversion> v;
    for (auto part : {detail::geometry_conversions(), detail::sensor_conversions(), detail::vision_conversions(),
                      detail::navigation_conversions()})
      v.insert(v.end(), part.begin(), part.end());
    std::stable_sort(v.begin(), v.end(), [](const Conversion& a, const Conversion& b) {
      return a.horus_type != b.horus_type ? a.horus_type < b.horus_type : a.ros_type < b.ros_type;
    });
    return v;
  }();
  return all;
}

const Conversion* find_conversion(std::uint64_t horus_hash, std::string_view ros_type) noexcept {
  for (const Conversion& c : conversions())
    if (c.horus_hash == horus_hash && (ros_type.empty() ? c.preferred : c.ros_type == ros_type)) return &c;
  return nullptr;
}

std::string conversion_targets(std::uint64_t horus_hash) {
  std::vector<std::string_view> names;
  for (const Conversion& c : conversions())
    if (c.horus_hash == horus_hash) names.push_back(c.ros_type);
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ")) + std::string(names[i]);
  return out;
}

}  // namespace horus::ros2

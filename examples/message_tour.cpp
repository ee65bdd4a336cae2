// A tour of the standard messages: helpers, a variable-size map, large data, a generic
// message, and how each prints (fmt, JSON, log summary).
#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <string>

#include <horus/format.hpp>
#include <horus/horus.hpp>
#include <horus/json.hpp>
#include <horus/msg/generic_value.hpp>

int main() {
  using namespace horus::msg;

  auto battery = BatteryState::make(12.6f, 75.0f);
  battery.current = -2.5f;
  battery.charge = 3.0f;
  fmt::print("battery: {}\n", horus::log_summary(battery));
  if (auto left = battery.time_remaining()) fmt::print("  time remaining: {:.0f} s\n", *left);

  // Variable-size: an occupancy grid and the cost map inflated from it.
  auto grid = OccupancyGrid::make(200, 200, 0.05f, Pose2D::origin());  // 10 m x 10 m, all unknown
  std::fill(grid.data.begin(), grid.data.end(), OccupancyGrid::FREE);
  if (auto cell = grid.world_to_grid(1.0, 2.0)) grid.set_occupancy(cell->first, cell->second, 100);
  const auto costs = CostMap::from_occupancy_grid(grid, 0.55f);
  fmt::print("grid: {}\n  occupied at (1, 2): {}; cost at (1.2, 2): {}\n", horus::log_summary(grid),
             grid.is_occupied(1.0, 2.0), static_cast<int>(costs.cost(1.2, 2.0).value_or(255)));

  horus::Topic<OccupancyGrid> map_pub("tour.map"), map_sub("tour.map");
  map_pub.send(grid);
  if (auto m = map_sub.recv()) fmt::print("  received a map of {} cells\n", m->data.size());

  // Large data: an image through a topic.
  Image img(480, 640, ImageEncoding::Rgb8);
  img.set_pixel(100, 200, {255, 0, 0});
  horus::Topic<Image> cam_pub("tour.camera"), cam_sub("tour.camera");
  cam_pub.send(img);
  if (auto m = cam_sub.recv()) {
    const auto px = m->pixel(100, 200);
    fmt::print("image: {}; pixel (100, 200) = [{}, {}, {}]\n", horus::log_summary(*m), (*px)[0], (*px)[1], (*px)[2]);
  }

  // A generic (MessagePack) message.
  auto generic = GenericMessage::from_value(std::map<std::string, double>{{"temperature", 22.5}});
  if (!generic) {
    fmt::print("generic: {}\n", generic.error());
    return 1;
  }
  const auto back = generic->to_value<std::map<std::string, double>>();
  fmt::print("generic: {}; temperature {}\n", horus::log_summary(*generic), back ? back->at("temperature") : -1.0);

  // Every message prints with fmt and renders as JSON.
  const auto pose = Pose2D::make(1.0, 2.0, 0.5);
  fmt::print("pose: {}\n  json: {}\n", pose, horus::to_json(pose).dump());
  return 0;
}

// A node that uses one topic of one message type, as bench/compile_time.sh compiles it.
#include <horus/msg/geometry.hpp>
#include <horus/topic.hpp>

int main() {
  horus::Topic<horus::msg::Pose2D> pose("robot.pose");
  pose.send(horus::msg::Pose2D{1.0, 2.0, 0.5, 0});
  if (auto m = pose.recv()) return m->x > 0 ? 0 : 1;
  return 1;
}

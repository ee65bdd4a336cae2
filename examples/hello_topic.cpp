// The smallest horus program: one publisher, one subscriber, one message.
#include <fmt/format.h>

#include "horus/format.hpp"
#include "horus/horus.hpp"

int main() {
  horus::Topic<horus::msg::CmdVel> pub("cmd_vel");  // throws horus::Exception on a bad name or type
  horus::Topic<horus::msg::CmdVel> sub("cmd_vel");  // same name: connected

  pub.send(horus::msg::CmdVel::make(1.0f, 0.5f));  // 1 m/s forward, 0.5 rad/s
  if (auto cmd = sub.recv()) fmt::print("received {}\n", *cmd);

  // The std::expected form, for code that does not use exceptions.
  auto bad = horus::Topic<horus::msg::Pose2D>::open("cmd_vel");
  if (!bad) fmt::print("as expected: {}\n", bad.error().message());
  return 0;
}

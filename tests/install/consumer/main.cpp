// A user's program: includes the installed headers and links horus::horus.
#include <horus/horus.hpp>

#include <cstdio>

int main() {
  horus::Topic<horus::msg::CmdVel> pub("consumer.cmd_vel");
  horus::Topic<horus::msg::CmdVel> sub("consumer.cmd_vel");
  pub.send(horus::msg::CmdVel::make(1.5f, 0.25f));
  auto m = sub.recv();
  if (!m) return 1;
  std::printf("received CmdVel linear=%.1f\n", static_cast<double>(m->linear));
  return 0;
}

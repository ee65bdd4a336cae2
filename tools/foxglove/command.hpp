// horus foxglove (command.cpp): the Foxglove WebSocket server and the status page, over hub.hpp and server.hpp.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

namespace horus::tools {

struct FoxgloveArgs {
  std::string ns;  // shared-memory namespace
  std::string address = "127.0.0.1";
  int port = 8765;                  // 0: any free port (printed)
  std::vector<std::string> topics;  // patterns (empty: every topic but horus.fleet.*)
  std::string frame = "world";      // the frame of converted messages that name none
  bool no_publish = false;          // refuse clientPublish
  int max_clients = 64;
  std::string backend;    // the fleet's transport (--backend), else the configuration's
  double duration_s = 0;  // 0: until Ctrl-C
  bool ros2 = false;      // also the DDS domain's ROS 2 topics, in their ROS 2 schemas
};
int cmd_foxglove(const FoxgloveArgs& args, const std::atomic<bool>& stop);

}  // namespace horus::tools

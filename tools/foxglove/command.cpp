#include "command.hpp"

#include <chrono>
#include <cstdio>
#include <thread>

#include <fmt/format.h>

#include "../fleet_cmd.hpp"
#include "../ros2_cmd.hpp"
#include "horus/fleet.hpp"
#include "horus/names.hpp"
#include "hub.hpp"
#include "server.hpp"

namespace horus::tools {

int cmd_foxglove(const FoxgloveArgs& a, const std::atomic<bool>& stop) {
  for (const auto& p : a.topics)
    if (auto ok = check_topic_pattern(p); !ok) {
      fmt::print(stderr, "horus foxglove: --topics '{}': {}\n", p, ok.error().message());
      return 2;
    }
  if (a.port < 0 || a.port > 65535) {
    fmt::print(stderr, "horus foxglove: --port {} is not a TCP port (0 to 65535; 0: any free one)\n", a.port);
    return 2;
  }
  if (a.max_clients < 1) {
    fmt::print(stderr, "horus foxglove: --max-clients must be at least 1\n");
    return 2;
  }
  fox::HubOptions ho;
  ho.patterns = a.topics;
  ho.transport = fleet_transport(a.backend);
  ho.ns = a.ns;
  ho.frame = a.frame;
  ho.client_publish = !a.no_publish;
  ho.name = fmt::format("horus foxglove on {}", fleet::host_name());
  if (a.ros2) ho.ros2_transport = ros2_transport(a.backend);
  std::string error;
  auto hub = fox::Hub::start(ho, error);
  if (!hub) {
    fmt::print(stderr, "horus foxglove: {}\n", error);
    return 1;
  }
  fox::ServerOptions so;
  so.address = a.address;
  so.port = static_cast<std::uint16_t>(a.port);
  so.max_clients = static_cast<std::size_t>(a.max_clients);
  auto server = fox::Server::start(*hub, so, error);
  if (!server) {
    fmt::print(stderr, "horus foxglove: {}\n", error);
    return 1;
  }
  const std::string shown = a.address == "0.0.0.0" ? fleet::host_name() : a.address;
  fmt::print("horus foxglove: ws://{}:{} (Foxglove: Open connection, Foxglove WebSocket); status page http://{}:{}/\n",
             shown, server->port(), shown, server->port());
  fmt::print("serving {} channels of {}{}{}; Ctrl-C stops\n", hub->channel_count(),
             ho.transport.empty() ? std::string("this host") : "this host and the fleet (" + ho.transport + ")",
             ho.ros2_transport.empty() ? "" : " and the ROS 2 topics of the domain (" + ho.ros2_transport + ")",
             a.no_publish ? "; clients may not publish" : "");
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  while (!stop.load()) {
    if (a.duration_s > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= a.duration_s)
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  server.reset();  // its connections first: they hold the hub
  hub.reset();
  return 0;
}

}  // namespace horus::tools

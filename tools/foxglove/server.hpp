// The sockets of `horus foxglove`: one port for the Foxglove WebSocket protocol (a request that upgrades with
// subprotocol foxglove.websocket.v1) and the status page (GET / and /status.json), on Boost.Beast over one I/O thread.
// Each connection is a hub Client with a bounded queue: a client that reads slower than its topics publish loses its
// oldest data frames (counted; newest kept), never slows the hub or a publisher.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "hub.hpp"

namespace horus::tools::fox {

struct ServerOptions {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8765;                        // 0: any free port (Server::port() tells which)
  std::size_t queue_bytes = std::size_t{64} << 20;  // a client's queued data frames, at most
  std::size_t max_clients = 64;
};

class Server {
 public:
  /// Listens and serves on a thread of its own; null with `error` naming the address and why.
  static std::unique_ptr<Server> start(Hub& hub, const ServerOptions& options, std::string& error);
  virtual ~Server() = default;  // closes every connection
  virtual std::uint16_t port() const = 0;
};

}  // namespace horus::tools::fox

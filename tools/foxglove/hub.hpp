// What `horus foxglove` serves, apart from the sockets (server.cpp): the channels (every topic of this host and of the
// fleet that matches, and beside each of a type Foxglove draws its converted channel), the clients and their
// subscriptions, the one subscription per channel that feeds them, client publishing, time, the connection graph, and
// the status page's figures.
//
// Threads: the server's I/O thread calls add_client/remove_client/on_text/on_binary; the hub's scan thread looks for
// topics and hosts every 500 ms (advertise, unadvertise, graph, status), sends time at 10 Hz; its pump thread waits on
// every subscribed topic at once and hands each message to every client subscribed to it, as one shared buffer. Nothing
// here blocks on a client: a client queues what it is given, bounded (Client::send_data drops its oldest).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace horus::tools::fox {

using Payload = std::shared_ptr<const std::vector<std::byte>>;

/// What the hub needs of a connection (server.cpp's WebSocket session). Thread-safe; none of these blocks: they queue
/// and return.
class Client {
 public:
  virtual ~Client() = default;
  /// A JSON message: always delivered, in order.
  virtual void send_text(std::string text) = 0;
  /// A message data frame. When the client's queue is over its bound the oldest data frames are dropped (counted, per
  /// subscription, and the client told by a status warning).
  virtual void send_data(std::uint32_t subscription, std::uint64_t receive_ns, Payload payload) = 0;
  virtual void send_time(std::uint64_t ns) = 0;
  /// Closes the connection after what is queued (code and reason as WebSocket sends them).
  virtual void close(std::uint16_t code, std::string reason) = 0;
  struct Stats {
    std::uint64_t sent = 0;     // data frames written
    std::uint64_t dropped = 0;  // data frames dropped for a slow reader
    std::uint64_t queued_bytes = 0;
  };
  virtual Stats stats() const = 0;
};

struct HubOptions {
  std::vector<std::string> patterns;  // topic patterns served (empty: every topic but horus.fleet.*)
  std::string transport;              // the fleet's network backend (empty: this host only)
  std::string ns;                     // this host's shared-memory namespace
  std::string frame = "world";        // the frame of converted messages that name none
  bool client_publish = true;         // clients may publish (clientPublish)
  std::string name;                   // serverInfo's name
  std::string ros2_transport;         // a DDS transport: also the domain's ROS 2 topics (empty: none)
};

class Hub {
 public:
  /// Starts the scan and pump threads (and the fleet layer when a transport is given).
  static std::unique_ptr<Hub> start(HubOptions options, std::string& error);
  virtual ~Hub() = default;

  /// A new connection: it gets serverInfo and an advertise of every channel. Its id.
  virtual std::uint64_t add_client(std::shared_ptr<Client> client, std::string peer) = 0;
  virtual void remove_client(std::uint64_t id) = 0;

  /// A frame from client `id`. Bad input is answered with a status error; a frame that is not the protocol (not JSON,
  /// an unknown binary opcode) also closes the connection (1007/1003) with a reason naming what was wrong.
  virtual void on_text(std::uint64_t id, std::string_view text) = 0;
  virtual void on_binary(std::uint64_t id, std::span<const std::byte> frame) = 0;

  /// The status page's figures (GET /status.json): hosts, topics with rate and bandwidth, channels, clients. Refreshed
  /// every second.
  virtual std::string status_json() const = 0;
  /// Channels advertised now.
  virtual std::size_t channel_count() const = 0;
};

}  // namespace horus::tools::fox

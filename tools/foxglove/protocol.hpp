// The Foxglove WebSocket protocol (subprotocol "foxglove.websocket.v1"), as bytes and JSON only: what a client may
// send, parsed and checked (a bad frame gets an error naming what was wrong and what was expected), and what the server
// sends, built. No socket here: server.cpp carries the frames, hub.cpp acts on them; this file is what
// fuzz/fuzz_foxglove.cpp feeds garbage to.
//
// Client → server (JSON): subscribe, unsubscribe, advertise (clientPublish), unadvertise, subscribeConnectionGraph,
// unsubscribeConnectionGraph. Binary: 0x01 client message data (uint32 channel id, payload). Server → client (JSON):
// serverInfo, status, advertise, unadvertise, connectionGraphUpdate; binary: 0x01 message data (uint32 subscription id,
// uint64 receive time in ns, payload), 0x02 time (uint64 ns). Integers little-endian.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace horus::tools::fox {

inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";
/// The same protocol under the name Foxglove's SDK servers answer and its newer clients offer
/// (foxglove/foxglove-sdk, websocket/handshake.rs): accepted beside kSubprotocol.
inline constexpr std::string_view kSdkSubprotocol = "foxglove.sdk.v1";
/// The largest frame a client may send (a client message of an image fits); a larger one closes the connection with
/// 1009 (message too big).
inline constexpr std::size_t kMaxClientFrame = std::size_t{16} << 20;

// ---- what a client sends ------------------------------------------------------------------
struct Subscribe {
  struct Item {
    std::uint32_t id = 0;
    std::uint32_t channel = 0;
  };
  std::vector<Item> subscriptions;
};
struct Unsubscribe {
  std::vector<std::uint32_t> ids;
};
struct ClientChannel {
  std::uint32_t id = 0;
  std::string topic;
  std::string encoding;
  std::string schema_name;
  std::optional<std::string> schema;
  std::optional<std::string> schema_encoding;
};
struct ClientAdvertise {
  std::vector<ClientChannel> channels;
};
struct ClientUnadvertise {
  std::vector<std::uint32_t> ids;
};
struct SubscribeGraph {};
struct UnsubscribeGraph {};
/// An op of the protocol this server does not offer (parameters, services, assets): the client is told so in a status
/// message; the connection stays.
struct Unsupported {
  std::string op;
};
using ClientOp = std::variant<Subscribe, Unsubscribe, ClientAdvertise, ClientUnadvertise, SubscribeGraph,
                              UnsubscribeGraph, Unsupported>;

/// A text frame. Errors: not JSON, not an object, no "op", an op that names nothing of the protocol, a field missing or
/// of the wrong type (named with its path, e.g. "subscribe: subscriptions[1].channelId must be an unsigned 32-bit
/// integer").
std::expected<ClientOp, std::string> parse_client_text(std::string_view text);

/// A binary frame: client message data. `payload` views `frame`.
struct ClientData {
  std::uint32_t channel = 0;
  std::span<const std::byte> payload;
};
/// Errors: empty, an opcode other than 0x01 (0x02, a service call, is named as unsupported), shorter than its header.
std::expected<ClientData, std::string> parse_client_binary(std::span<const std::byte> frame);

// ---- what the server sends ----------------------------------------------------------------
struct ServerChannel {
  std::uint32_t id = 0;
  std::string topic;
  std::string encoding;         // "cdr" or "json"
  std::string schema_name;      // "horus::msg::Pose2D", "foxglove::RawImage"
  std::string schema;           // the OMG IDL text (or a JSON Schema for "json")
  std::string schema_encoding;  // "omgidl" or "jsonschema"
};

std::string server_info(std::string_view name, std::string_view session_id, std::span<const std::string> metadata_kv);
std::string advertise(std::span<const ServerChannel> channels);
std::string unadvertise(std::span<const std::uint32_t> ids);
enum class Level : std::uint8_t { Info = 0, Warning = 1, Error = 2 };
std::string status(Level level, std::string_view message);

/// The connection graph: who publishes and subscribes each topic ("host/process[pid]").
struct GraphTopic {
  std::string name;
  std::vector<std::string> ids;
  friend bool operator==(const GraphTopic&, const GraphTopic&) = default;
};
struct Graph {
  std::vector<GraphTopic> published;
  std::vector<GraphTopic> subscribed;
};
/// The update from `before` to `now` (the whole graph when `before` is empty); nothing when they are equal.
std::optional<std::string> graph_update(const Graph& before, const Graph& now);

/// The 13-byte header of a message data frame; the payload follows it.
std::array<std::byte, 13> message_data_header(std::uint32_t subscription, std::uint64_t receive_ns);
std::array<std::byte, 9> time_frame(std::uint64_t ns);

/// What a WebSocket close reason may hold (123 bytes): `why` cut to fit.
std::string close_reason(std::string_view why);

}  // namespace horus::tools::fox

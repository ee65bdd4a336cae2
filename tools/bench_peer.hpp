// One side of a `horus bench` round trip, for a standard message type known only at run time:
// a topic it receives on and a topic it sends on, both Topic<T> handles opened as any program
// would (the environment and the configuration file choose scope, backend and QoS). The ping
// sends messages carrying a tag (its sequence number) and reads the tag of what comes back; the
// pong sends back what it receives, unchanged. Instantiated once per standard type beside the
// CLI's other typed handles (typed_reader_*.cpp), not in a translation unit of its own.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "horus/backend.hpp"

namespace horus::tools {

/// The clock of every measured round trip (steady_clock, in ns).
inline std::int64_t bench_now_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// What both sides agree on: the type, and the payload size of a sized type (0: the type's own).
struct BenchPayload {
  std::string type;        // as the user wrote it, or qualified
  std::uint64_t size = 0;  // CompressedImage: data bytes; Image, DepthImage, PointCloud, Tensor: pool bytes
};

struct BenchEndpoints {
  std::string in;   // the topic received on (the ping's "pong" topic, the pong's "ping" topic)
  std::string out;  // the topic sent on
  std::optional<Backend> backend;  // nullopt: the environment and the configuration file choose
};

class BenchPeer {
 public:
  virtual ~BenchPeer() = default;
  /// Sends a message tagged `tag` (modulo tag_modulus()), `sent_at` (bench_now_ns()) taken
  /// just before the topic's send; false when the topic refused it (a pool whose slots are all
  /// pinned or lent, every publisher lane taken, a message larger than the slot).
  virtual bool send(std::uint64_t tag, std::int64_t& sent_at) = 0;
  /// The tag of the next received message, or nothing when none is waiting.
  virtual std::optional<std::uint64_t> recv_tag() = 0;
  /// What the pong notes of an echo when the ping asks for its clock (bench_cmd.cpp): the
  /// message's tag and the time (bench_now_ns()) between receiving it and sending it back.
  struct EchoStamp {
    std::uint64_t tag = 0;
    std::int64_t at = 0;
  };
  /// Receives one message and sends it back unchanged; false when none was waiting. Fills
  /// `stamp` when it is not null.
  virtual bool echo_one(EchoStamp* stamp) = 0;
  /// Sleeps until a message is waiting or `timeout` passes; true when one is.
  virtual bool wait(std::chrono::nanoseconds timeout) = 0;
  /// Tags are carried modulo this (the field that carries them: 2^23 for a float, 2^62 for a
  /// 64-bit integer); the ping resolves a tag to the latest sequence number it sent that has it.
  virtual std::uint64_t tag_modulus() const = 0;
  /// Bytes of one message as the network carries it (its XCDR1 encoding).
  virtual std::uint64_t message_bytes() const = 0;
  /// "horus::msg::Pose2D (fixed size, 40 bytes)", "... Image 1 x 1048576 Mono8 (pool)".
  virtual std::string describe() const = 0;
  /// Where the tag travels ("field timestamp_ns", "the first 8 bytes of the data").
  virtual std::string tag_carrier() const = 0;
  /// Messages the receiving topic lost (its dropped_count()).
  virtual std::uint64_t dropped() const = 0;
  /// Subscribers of the sending topic (remote readers included for a fleet topic).
  virtual std::uint32_t subscribers() const = 0;
  /// Slots per publisher of the sending topic.
  virtual std::uint32_t capacity() const = 0;
  /// "shm", "inproc", "cyclonedds", ...
  virtual std::string backend() const = 0;
};

/// The qualified standard type `payload.type` names, with the size checked for it: sized types
/// take --size, the others refuse it. Empty with `error` set when there is no such type or the
/// size does not fit.
std::string bench_type(const BenchPayload& payload, std::string& error);

/// Opens both topics of one side as `payload.type` (a standard message, qualified or not).
/// Nothing with `error` set when the type is unknown, the size does not fit its slot, or a
/// topic does not open (a topic that exists with another type or slot size, a bad backend).
std::unique_ptr<BenchPeer> open_bench_peer(const BenchPayload& payload, const BenchEndpoints& endpoints,
                                           std::string& error);

/// The largest payload `horus bench` sends (LCM's largest message; a pool slot that large is
/// virtual memory until written).
inline constexpr std::uint64_t kMaxBenchPayload = std::uint64_t{1} << 28;
/// Sized payloads below this go as CompressedImage (serialized, copied), from it on as Image
/// (the pool, zero-copy), when --size is given without --type.
inline constexpr std::uint64_t kPoolPayloadFrom = 64 * 1024;

}  // namespace horus::tools

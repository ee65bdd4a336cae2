// Topics of a standard message whose type is known only at run time (horus topic echo / hz /
// bw / pub, record, play): the library's AnyTopic of each standard type (horus/standard_types.hpp,
// compiled once there) behind the CLI's small interfaces (typed_reader.cpp); and horus bench's
// peers, which take each type's Topic<T> itself (the round trip they measure is the typed one),
// instantiated once per type in typed_reader_{first,second}.cpp (two files built in parallel).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "bench_peer.hpp"
#include "horus/backend.hpp"
#include "horus/record/player.hpp"
#include "horus/record/recorder.hpp"

namespace horus::tools {

class TypedReader {
 public:
  virtual ~TypedReader() = default;
  /// The next message as text (JSON or the one-line summary), or nothing.
  virtual std::optional<std::string> recv_text(bool json) = 0;
  /// Takes the next message without printing it; its size in bytes (the XCDR1 encoding, what it
  /// takes on DDS), or nothing when there was none.
  virtual std::optional<std::size_t> recv_size() = 0;
  /// Sleeps until a message is waiting or `timeout` passes (Topic::wait_for); true: one is.
  virtual bool wait(std::chrono::nanoseconds timeout) = 0;
};

class TypedWriter {
 public:
  virtual ~TypedWriter() = default;
  /// Sends the message `json` describes (from_json: strict); the error naming the field, or empty.
  virtual std::string send_json(const nlohmann::json& json) = 0;
  /// Subscribers the topic has (remote readers included for a fleet topic).
  virtual std::uint32_t sub_count() const = 0;
  virtual std::string backend() const = 0;
};

/// The standard message called `type_name` (qualified, "horus::msg::Pose2D", or not, "Pose2D"):
/// its qualified name, or empty when there is none.
std::string standard_type(std::string_view type_name);

/// Opens topic `name` (with `backend`: shared memory, or the fleet transport the segment names)
/// as the standard message called `type_name`. Nothing, with `error` empty, when it is not a
/// standard type; nothing with `error` set when opening failed.
std::unique_ptr<TypedReader> open_reader(std::string_view type_name, const std::string& name, const Backend& backend,
                                         std::string& error);
/// The same for publishing; without a backend the environment and the configuration file choose.
std::unique_ptr<TypedWriter> open_writer(std::string_view type_name, const std::string& name,
                                         const std::optional<Backend>& backend, std::string& error);

/// The standard message whose LCM type has fingerprint `fingerprint` (lcm-gen's): its qualified
/// name, or empty.
std::string standard_type_by_lcm_fingerprint(std::uint64_t fingerprint);

/// A recorder's source for topic `name` (opened with `backend`) of the standard message
/// `type_name`; nothing with `error` empty when it is not a standard type.
std::unique_ptr<RecordSource> open_record_source(std::string_view type_name, const std::string& name,
                                                 const std::optional<Backend>& backend, std::string& error);
/// A player's sink publishing into topic `name` (the environment and configuration choose its
/// scope), decoding the recorded bytes (LCM's encoding, or XCDR1 with its header); `type_hash`
/// receives the standard type's hash to compare with the recorded one.
/// A channel of a ROS 2 bag of a converted type (`conversion`) plays through it; `options`
/// (`horus play --ros2`: a ROS 2 mapping) open the topic.
std::unique_ptr<PlaySink> open_play_sink(std::string_view type_name, const std::string& name, bool lcm_encoding,
                                         const ros2::Conversion* conversion, const TopicOptions& options,
                                         std::uint64_t& type_hash, std::string& error);

namespace detail {
/// What one half of the standard types offers horus bench for a qualified type name (known: it
/// is in that half).
struct Opened {
  bool known = false;
  const BenchPayload* bench_payload = nullptr;
  const BenchEndpoints* bench_endpoints = nullptr;
  std::unique_ptr<BenchPeer> bench;
};
enum class Want { BenchCheck, Bench };
void open_first_half(std::string_view qualified, Want want, Opened& out, std::string& error);
void open_second_half(std::string_view qualified, Want want, Opened& out, std::string& error);
}  // namespace detail

}  // namespace horus::tools

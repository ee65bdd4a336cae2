// horus::Recorder: records topics into an MCAP file (or an LCM event log), from a thread of its
// own. A node records its own topics; `horus record` records any topic it can reach.
//
//   auto rec = horus::Recorder::open("run.mcap");                 // zstd chunks of 4 MiB
//   rec.value()->add<horus::msg::Imu>("imu");                      // subscribes, like Topic<Imu>
//   rec.value()->add<horus::msg::Image>("camera.front");           // an Image is its bytes in the file
//   ...
//   rec.value()->close();                                          // the summary; the file is whole
//
// MCAP (RecordFormat::Mcap): each topic is a channel with message encoding "cdr" (XCDR1 with
// its 4-byte encapsulation header: the bytes horus sends over DDS) and a schema of encoding
// "omgidl" named by the type's qualified name, holding the IDL of the type and every type it
// uses (horus-idlgen's definitions, no preprocessor line): Foxglove decodes it. The channel's
// metadata has "horus.type", "horus.type_hash" (16 hex digits), "horus.signature" (the layout
// text, horus/wire/dynamic.hpp) and "horus.scope". A message's log time is when the recorder
// took it; its publish time is the message's own timestamp_ns when it has one that is within a
// day of that, else the log time.
//
// LCM (RecordFormat::Lcm): the log lcm-logger writes: one event per message, on the topic's
// LCM channel (its name), in lcm-gen's encoding, timestamped in microseconds.
//
// Chunks are written whole when full and at least every flush_interval, so a recorder killed
// with SIGKILL leaves a file that reads (ReadOptions::recover, `horus record recover`) up to its
// last chunk. Messages a topic's ring overwrote before the recorder took them are counted per
// topic (RecordedTopic::dropped); nothing is lost silently.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <type_traits>
#include <vector>

#include "horus/error.hpp"
#include "horus/record/mcap.hpp"
#include "horus/reflect.hpp"
#include "horus/topic.hpp"
#include "horus/transport/encapsulation.hpp"
#include "horus/waitset.hpp"
#include "horus/wire/lcm.hpp"
#include "horus/wire/xcdr1.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

enum class RecordFormat : std::uint8_t { Mcap, Lcm };
std::string_view to_string(RecordFormat f) noexcept;
/// "mcap" or "lcm" (Errc::InvalidArgument naming both otherwise).
Result<RecordFormat> parse_record_format(std::string_view name);

/// What an MCAP recording holds. Horus: each topic as horus's own type (above). Ros2: a bag as
/// rosbag2 writes it (docs/ROS2.md), which `ros2 bag` and Foxglove's ROS panels read: the
/// Header's profile "ros2"; each topic under its ROS 2 name (its `ros2:` rule's, else "/" + its
/// name with '.' as '/') as its ROS 2 type (a conversion of ros2/convert.hpp, else its own type
/// of the horus_msgs package: `horus idl --ros2`), a schema of encoding "ros2msg" (the .msg text
/// and its dependencies), messages "cdr" as a ROS 2 node sends them, channel metadata
/// "offered_qos_profiles" and "topic_type_hash"; and at the end of each file a Metadata record
/// "rosbag2" holding the bag's metadata.yaml ("serialized_metadata").
enum class RecordProfile : std::uint8_t { Horus, Ros2 };
std::string_view to_string(RecordProfile p) noexcept;
/// "horus" or "ros2" (Errc::InvalidArgument naming both otherwise).
Result<RecordProfile> parse_record_profile(std::string_view name);

/// The type a recorded topic carries.
struct RecordedType {
  std::string name;       // qualified: "horus::msg::Imu"
  std::uint64_t hash = 0; // horus::type_hash
  std::string signature;  // reflect::type_signature (empty: unknown; the channel then has no schema)
  /// The OMG IDL of the type when it is not derived from the signature (Foxglove's own schemas,
  /// `horus record --foxglove`): used as given.
  std::string schema;
};

/// One topic a Recorder takes messages from. Recorder::add<T> makes one of a Topic<T>; a program
/// that knows types only at run time (the CLI) implements its own.
class RecordSource {
 public:
  virtual ~RecordSource() = default;
  virtual const std::string& topic() const = 0;
  virtual const RecordedType& type() const = 0;
  /// "process", "host" or "fleet".
  virtual std::string scope() const = 0;
  /// Why the topic cannot be recorded in `format` (LCM cannot express every type), or nothing.
  virtual std::optional<std::string> unsupported(RecordFormat format) const = 0;
  /// Takes the next message, encoded for `format` into `out` (MCAP: encapsulation header and
  /// XCDR1 body; LCM: lcm-gen's bytes); its own timestamp in ns (0: it has none), or nothing
  /// when there was no message.
  virtual std::optional<std::uint64_t> next(RecordFormat format, std::vector<std::byte>& out) = 0;
  /// Takes the next message and hands it to `fn` (a `const void*` to a message of type().hash,
  /// valid during the call); its own timestamp in ns (0: none), or nothing when there was none.
  /// The ROS 2 profile converts messages through it; a source of no horus type (Foxglove's
  /// schemas) has none and returns nothing.
  virtual std::optional<std::uint64_t> take(void (*fn)(void* ctx, const void* msg), void* ctx) {
    (void)fn;
    (void)ctx;
    return std::nullopt;
  }
  /// Attaches the topic to `ws` (false: this source cannot be waited for; it is polled).
  virtual bool attach(WaitSet& ws) = 0;
  /// Messages the subscription lost before they were taken (the ring overwrote them).
  virtual std::uint64_t dropped() const = 0;
};

namespace record_detail {
template <class T>
std::uint64_t own_stamp(const T& m) {
  if constexpr (requires { m.timestamp_ns; }) {
    if constexpr (std::is_integral_v<std::remove_cvref_t<decltype(m.timestamp_ns)>>)
      return static_cast<std::uint64_t>(m.timestamp_ns);
  }
  return 0;
}
}  // namespace record_detail

/// The source of a Topic<T>.
template <class T>
class TopicSource final : public RecordSource {
 public:
  explicit TopicSource(Topic<T> topic)
      : topic_(std::move(topic)),
        name_(topic_.name()),
        type_{std::string(horus::type_name<T>()), horus::type_hash<T>, reflect::type_signature<T>(), {}} {}
  const std::string& topic() const override { return name_; }
  const RecordedType& type() const override { return type_; }
  std::string scope() const override { return std::string(horus::to_string(topic_.scope())); }
  std::optional<std::string> unsupported(RecordFormat format) const override {
    if constexpr (!lcm::expressible<T>) {
      if (format == RecordFormat::Lcm)
        return type_.name + " has no LCM encoding (a variable-size array of variable-size arrays, or an empty array)";
    }
    (void)format;
    return std::nullopt;
  }
  std::optional<std::uint64_t> next(RecordFormat format, std::vector<std::byte>& out) override {
    auto m = topic_.recv();
    if (!m) return std::nullopt;
    const T& msg = *m;
    if (format == RecordFormat::Mcap) {
      const std::size_t body = cdr::encoded_size(msg);
      out.resize(net::encapsulation::serialized_size(body));
      cdr::encode(msg, std::span<std::byte>(out).subspan(net::encapsulation::kHeaderSize, body));
      net::encapsulation::write_header_and_padding(out, body);
    } else {
      if constexpr (lcm::expressible<T>) {
        out.resize(lcm::encoded_size(msg));
        lcm::encode(msg, std::span<std::byte>(out));
      } else {
        return std::nullopt;
      }
    }
    return record_detail::own_stamp(msg);
  }
  std::optional<std::uint64_t> take(void (*fn)(void* ctx, const void* msg), void* ctx) override {
    auto m = topic_.recv();
    if (!m) return std::nullopt;
    const T& msg = *m;
    fn(ctx, &msg);
    return record_detail::own_stamp(msg);
  }
  bool attach(WaitSet& ws) override {
    try {
      ws.attach(topic_);
      return true;
    } catch (const Exception&) {
      return false;  // the wait set is full (kMaxAttachments): polled instead
    }
  }
  std::uint64_t dropped() const override { return topic_.dropped_count(); }

 private:
  Topic<T> topic_;
  std::string name_;
  RecordedType type_;
};

struct RecorderOptions {
  RecordFormat format = RecordFormat::Mcap;
  RecordProfile profile = RecordProfile::Horus;  // Ros2: MCAP only
  mcap::Compression compression = mcap::Compression::Zstd;  // MCAP only
  std::size_t chunk_size = 4u << 20;                         // MCAP: a chunk is written when it holds this much
  std::chrono::milliseconds flush_interval{1000};            // and at least this often (what a kill loses)
  /// Starts a new file when this one reaches this many bytes (0: never): run.mcap, run_1.mcap, ...
  std::uint64_t split_size = 0;
  /// false: a file that exists already is not replaced; open() (or the split that reaches it)
  /// fails with Errc::InvalidArgument naming it. `horus record` sets it from --overwrite.
  bool overwrite = true;
};

struct RecordedTopic {
  std::string topic;
  std::string type;
  std::string scope;
  std::string ros2_topic;  // RecordProfile::Ros2: the channel's name ("/robot1/cmd_vel") and type
  std::string ros2_type;
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;    // encoded, as in the file
  std::uint64_t dropped = 0;  // lost before the recorder took them
};

struct RecorderStats {
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;           // messages' encoded bytes
  std::uint64_t file_bytes = 0;      // bytes written to the files so far
  std::vector<std::string> files;    // in order; the last one is being written
  std::vector<RecordedTopic> topics; // in the order they were added
  /// Rounds of the recording thread so far: each one follows a wake-up (a message, a topic
  /// added, the 200 ms tick, a 2 ms gather after messages). An idle recorder adds about 5 a
  /// second, one that polls a source that cannot wake it about 500.
  std::uint64_t rounds = 0;
};

class Recorder {
 public:
  /// Creates `path` (and, with split_size, the files after it) and starts the recording thread.
  static Result<std::unique_ptr<Recorder>> open(const std::string& path, RecorderOptions options = {});
  ~Recorder();  // close(), errors logged
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Records topic `name` of type T, opened as Topic<T>::open(name, options): it receives what
  /// is sent from now on. Errors: the topic's (a type mismatch...), a topic recorded already,
  /// a type the format cannot carry.
  template <class T>
  Result<void> add(std::string_view name, const TopicOptions& options = {}) {
    if (recording(name)) return already(name);
    auto topic = Topic<T>::open(name, options);
    if (!topic) return std::unexpected(topic.error());
    return add(std::make_unique<TopicSource<T>>(std::move(*topic)));
  }
  /// Records what `source` gives.
  Result<void> add(std::unique_ptr<RecordSource> source);
  /// Whether topic `name` is recorded.
  bool recording(std::string_view name) const;

  /// Counts so far (thread-safe).
  RecorderStats stats() const;
  /// The first error that stopped the recording (a full disk...), or nothing.
  std::optional<Error> error() const;
  /// Writes every complete chunk now.
  Result<void> flush();
  /// Takes what the topics still hold, stops the thread, writes the summary. Idempotent.
  Result<void> close();

 private:
  struct Impl;
  explicit Recorder(std::unique_ptr<Impl> impl);
  static Result<void> already(std::string_view name);
  std::unique_ptr<Impl> impl_;
};

}  // namespace horus

HORUS_API_END

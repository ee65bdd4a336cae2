// horus::Player: publishes a recording into horus topics with its recorded timing. Reads MCAP
// files (horus's, and any whose channels carry "cdr" messages of a horus type) and LCM event
// logs (horus's --format lcm, and lcm-logger's: each channel plays into the topic of its name).
//
//   auto player = horus::Player::open("run.mcap");
//   player.value()->bind<horus::msg::Imu>("imu");                  // recorded topic -> Topic<Imu>
//   horus::PlayOptions o;
//   o.rate = 2.0;                                                   // twice as fast
//   auto stats = player.value()->play(o);                           // blocks until the end
//
// A ROS 2 bag (rosbag2's MCAP, `horus record --profile ros2`): a channel of a ROS 2 type that a
// standard message converts from (ros2/convert.hpp; the channel's "horus.type" when horus wrote
// it, else the message whose preferred type it is) plays through the conversion, one of the
// horus_msgs package as its horus type; its ROS 2 name "/robot1/cmd_vel" plays into the horus
// topic "robot1.cmd_vel" (the channel's "horus.topic" when horus wrote it).
//
// A channel plays only once bound (bind<T>, or bind() with a sink of one's own: the CLI binds
// the standard types by name). bind<T> checks the recorded type: the MCAP channel's horus type
// hash, or the fingerprint of the first LCM message on the channel.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "horus/error.hpp"
#include "horus/record/recorder.hpp"
#include "horus/ros2/convert.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// One recorded topic.
struct PlayChannel {
  std::string topic;             // as recorded (an LCM log: the channel)
  std::string horus_topic;       // the topic it plays into unless told: `topic`, or a ROS 2 name's horus one
  std::string type;              // qualified horus type; empty when unknown (an lcm-logger log)
  std::uint64_t type_hash = 0;   // MCAP: from the channel's metadata (0: none)
  std::string signature;         // MCAP: the layout text (empty: none)
  std::string encoding;          // the messages': "cdr" or "lcm" (others are not played)
  std::string schema_encoding;   // MCAP: "omgidl" for horus's (empty: no schema)
  std::uint16_t channel_id = 0;  // MCAP
  std::uint64_t lcm_fingerprint = 0;  // LCM: the first message's fingerprint
  std::string scope;             // MCAP: as recorded
  std::string ros2_type;         // a ROS 2 bag's channel: its type ("sensor_msgs/msg/LaserScan")
  /// A ROS 2 bag's channel of a converted type: the conversion it plays through (nullptr: the
  /// bytes are the horus type's own, or the channel is no ROS 2 one).
  const ros2::Conversion* conversion = nullptr;
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;
  std::uint64_t first_ns = 0, last_ns = 0;  // log times
};

/// Where the messages of one channel go. The bytes are in the channel's encoding ("cdr": the
/// encapsulation header and the XCDR1 body; "lcm": lcm-gen's bytes).
class PlaySink {
 public:
  virtual ~PlaySink() = default;
  /// Publishes one message; an error names what did not decode.
  virtual Result<void> publish(std::span<const std::byte> data) = 0;
};

/// The sink of a Topic<T> fed a ROS 2 type's CDR through its conversion.
template <class T>
class ConvertingSink final : public PlaySink {
 public:
  ConvertingSink(Topic<T> topic, const ros2::Conversion& conversion) : topic_(std::move(topic)), conversion_(conversion) {
    topic_.publish_only();
  }
  Result<void> publish(std::span<const std::byte> data) override {
    auto sample = net::encapsulation::parse(data);
    if (const auto* why = std::get_if<std::string>(&sample)) return fail(Errc::Corrupt, *why);
    const auto& s = std::get<net::Sample>(sample);
    auto m = std::make_unique<T>();
    if (auto ok = conversion_.decode(s.body, s.little_endian, m.get(), nullptr); !ok)
      return fail(ok.error().malformed ? Errc::Corrupt : Errc::LimitReached, ok.error().what);
    if (auto ok = topic_.send_blocking(*m, std::chrono::milliseconds(100)); !ok) {
      if (ok.error().code() != Errc::Timeout) return ok;
      topic_.send(*m);
    }
    return {};
  }

 private:
  Topic<T> topic_;
  const ros2::Conversion& conversion_;
};

/// The sink of a Topic<T>.
template <class T>
class TopicSink final : public PlaySink {
 public:
  TopicSink(Topic<T> topic, bool lcm_encoding) : topic_(std::move(topic)), lcm_(lcm_encoding) { topic_.publish_only(); }
  Result<void> publish(std::span<const std::byte> data) override {
    std::expected<T, std::string> m = std::unexpected(std::string());
    if (lcm_) {
      if constexpr (lcm::expressible<T>) m = lcm::decode<T>(data);
      else return fail(Errc::TypeMismatch, std::string(type_name<T>()) + " has no LCM encoding");
    } else {
      auto sample = net::encapsulation::parse(data);
      if (const auto* why = std::get_if<std::string>(&sample)) return fail(Errc::Corrupt, *why);
      const auto& s = std::get<net::Sample>(sample);
      m = cdr::decode<T>(s.body, s.little_endian);
    }
    if (!m) return fail(Errc::Corrupt, m.error());
    // A subscriber that keeps no room for 100 ms loses its oldest message (and counts it), as
    // it would to any publisher.
    if (auto ok = topic_.send_blocking(*m, std::chrono::milliseconds(100)); !ok) {
      if (ok.error().code() != Errc::Timeout) return ok;
      topic_.send(*m);
    }
    return {};
  }
  Topic<T>& topic() { return topic_; }

 private:
  Topic<T> topic_;
  bool lcm_;
};

struct PlayOptions {
  double rate = 1.0;        // 2.0: twice as fast; 0: as fast as possible
  double start_s = 0.0;     // skip the first seconds of the recording
  bool loop = false;        // start over at the end (until stop)
  std::vector<std::string> topics;  // patterns (config's: '*' one segment, '**' any); empty: all bound
};

struct PlayStats {
  std::uint64_t published = 0;
  std::uint64_t failed = 0;        // did not decode or could not be sent (first_error says why)
  std::string first_error;
  std::uint64_t loops = 0;         // passes completed
  std::map<std::string, std::uint64_t> per_topic;  // published, by recorded topic
};

class Player {
 public:
  /// Opens an MCAP file or an LCM log (told apart by their first bytes). With `recover`, an
  /// MCAP file that ends early (a killed recorder) plays up to its last complete chunk.
  static Result<std::unique_ptr<Player>> open(const std::string& path, bool recover = false);
  ~Player();
  Player(const Player&) = delete;
  Player& operator=(const Player&) = delete;

  RecordFormat format() const noexcept;
  const std::vector<PlayChannel>& channels() const noexcept;
  const PlayChannel* channel(std::string_view topic) const noexcept;
  /// Ends of the recording (log times, ns since the Unix epoch).
  std::uint64_t start_ns() const noexcept;
  std::uint64_t end_ns() const noexcept;
  std::uint64_t file_bytes() const noexcept;
  /// The MCAP file ended early and was read up to its last complete chunk (open with recover).
  bool truncated() const noexcept;

  /// Plays recorded topic `topic` into Topic<T> named `to` (default: its horus_topic),
  /// checking the recorded type against T.
  template <class T>
  Result<void> bind(std::string_view topic, std::string_view to = {}, const TopicOptions& options = {}) {
    const auto* c = channel(topic);
    if (c == nullptr) return unknown(topic);
    if (auto ok = playable(*c); !ok) return ok;
    if (c->encoding == "lcm") {
      if constexpr (lcm::expressible<T>) {
        if (c->lcm_fingerprint != lcm::fingerprint<T>()) return mismatch(*c, type_name<T>());
      } else {
        return mismatch(*c, type_name<T>());
      }
    } else if (c->type_hash != 0 && c->type_hash != type_hash<T>) {
      return mismatch(*c, type_name<T>());
    }
    auto t = Topic<T>::open(to.empty() ? std::string_view(c->horus_topic) : to, options);
    if (!t) return std::unexpected(t.error());
    if (c->conversion != nullptr) return bind(topic, std::make_unique<ConvertingSink<T>>(std::move(*t), *c->conversion));
    return bind(topic, std::make_unique<TopicSink<T>>(std::move(*t), c->encoding == "lcm"));
  }
  Result<void> bind(std::string_view topic, std::unique_ptr<PlaySink> sink);
  /// Whether horus can play channel `c`: cdr messages with an omgidl schema (or none), of a ROS 2
  /// type horus converts from (ros2msg), or LCM;
  /// else an error naming the channel, its encodings and what horus plays.
  static Result<void> playable(const PlayChannel& c);

  /// Publishes the bound channels' messages in log-time order, spaced as recorded (divided by
  /// rate), until the end (or, with loop, until `stop`). `stop` (may be null) ends it early.
  Result<PlayStats> play(const PlayOptions& options, const std::atomic<bool>* stop = nullptr);

 private:
  struct Impl;
  explicit Player(std::unique_ptr<Impl> impl);
  static Result<void> unknown(std::string_view topic);
  static Result<void> mismatch(const PlayChannel& c, std::string_view type);
  std::unique_ptr<Impl> impl_;
};

}  // namespace horus

HORUS_API_END

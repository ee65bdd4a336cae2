// horus::Player (see player.hpp).
#include "horus/record/player.hpp"

#include <algorithm>
#include <set>
#include <thread>

#include <fmt/format.h>

#include "horus/config.hpp"
#include "horus/record/lcm_log.hpp"
#include "horus/ros2/names.hpp"
#include "horus/standard_types.hpp"

namespace horus {

namespace {

std::uint64_t parse_hex(const std::string& s) {
  std::uint64_t v = 0;
  if (s.empty() || s.size() > 16) return 0;
  for (char c : s) {
    int d = -1;
    if (c >= '0' && c <= '9') d = c - '0';
    else if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
    else if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
    if (d < 0) return 0;
    v = (v << 4) | static_cast<std::uint64_t>(d);
  }
  return v;
}

std::uint64_t lcm_fingerprint_of(std::span<const std::byte> data) {
  if (data.size() < 8) return 0;
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < 8; ++i) v = (v << 8) | static_cast<std::uint8_t>(data[i]);
  return v;
}

void note(PlayChannel& c, std::uint64_t t, std::size_t bytes) {
  if (c.messages == 0 || t < c.first_ns) c.first_ns = t;
  c.last_ns = std::max(c.last_ns, t);
  ++c.messages;
  c.bytes += bytes;
}

// A ROS 2 bag's channel (schema encoding ros2msg): the horus type it plays as, and how. The type
// horus recorded it from (its "horus.type") when that converts to the channel's type; else the
// standard message whose preferred ROS 2 type it is (else the first that converts to it); a
// message's own type (horus_msgs, or another package a rule named, with "horus.type") is that
// standard message, bytes as they are.
void resolve_ros2(PlayChannel& c, const std::string& schema_name, const std::string& recorded,
                  const std::string& horus_topic) {
  auto name = ros2::parse_type_name(schema_name);
  c.ros2_type = name ? name->full() : schema_name;
  c.horus_topic = !horus_topic.empty() ? horus_topic : ros2::horus_topic_of(c.topic);
  c.type.clear();
  c.type_hash = 0;
  const ros2::Conversion* chosen = nullptr;
  for (const auto& conv : ros2::conversions()) {
    if (conv.ros_type != c.ros2_type) continue;
    if (!recorded.empty() ? conv.horus_type == recorded : (chosen == nullptr || (conv.preferred && !chosen->preferred)))
      chosen = &conv;
  }
  if (chosen != nullptr) {
    c.conversion = chosen;
    c.type = std::string(chosen->horus_type);
    c.type_hash = chosen->horus_hash;
  } else if (const StandardType* t = !recorded.empty()                          ? find_standard_type(recorded)
                                     : name && name->package == "horus_msgs" ? find_standard_type(name->name)
                                                                             : nullptr;
             t != nullptr) {  // its own type (horus_msgs, or the package its rule named): its bytes
    c.type = std::string(t->name);
    c.type_hash = t->hash;
  }
}

}  // namespace

struct Player::Impl {
  std::string path;
  RecordFormat format = RecordFormat::Mcap;
  std::unique_ptr<mcap::Reader> mcap;
  std::unique_ptr<lcmlog::Reader> lcm;
  std::vector<PlayChannel> channels;
  std::map<std::uint16_t, std::size_t> by_channel_id;  // MCAP channel id -> index in channels
  std::map<std::string, std::size_t, std::less<>> by_topic;
  std::map<std::size_t, std::unique_ptr<PlaySink>> sinks;
  std::uint64_t start = 0, end = 0;
  bool truncated = false;

  PlayChannel& channel_of(std::string_view topic) {
    if (auto it = by_topic.find(topic); it != by_topic.end()) return channels[it->second];
    by_topic.emplace(std::string(topic), channels.size());
    PlayChannel c;
    c.topic = std::string(topic);
    c.horus_topic = c.topic;
    channels.push_back(std::move(c));
    return channels.back();
  }

  // One pass over the file: every channel with its counts and times (an MCAP summary has the
  // counts, not the bytes or each channel's times, so both formats read through).
  Result<void> index() {
    if (mcap) {
      for (const auto& [id, ch] : mcap->channels()) add_mcap_channel(id, ch);
      auto ok = mcap->read_messages([&](const mcap::Channel& ch, const mcap::Schema*, const mcap::Message& m) {
        if (!by_channel_id.contains(ch.id)) add_mcap_channel(ch.id, ch);
        note(channels[by_channel_id[ch.id]], m.log_time, m.data.size());
        return true;
      });
      if (!ok) return ok;
      truncated = mcap->truncated();
    } else {
      auto ok = lcm->read([&](const lcmlog::Event& e) {
        auto& c = channel_of(e.channel);
        if (c.messages == 0) {
          c.encoding = "lcm";
          c.lcm_fingerprint = lcm_fingerprint_of(e.data);
        }
        note(c, static_cast<std::uint64_t>(std::max<std::int64_t>(e.timestamp_us, 0)) * 1000, e.data.size());
        return true;
      });
      if (!ok) return ok;
      truncated = lcm->truncated();
    }
    bool any = false;
    for (const auto& c : channels) {
      if (c.messages == 0) continue;
      start = any ? std::min(start, c.first_ns) : c.first_ns;
      end = std::max(end, c.last_ns);
      any = true;
    }
    return {};
  }

  void add_mcap_channel(std::uint16_t id, const mcap::Channel& ch) {
    if (by_channel_id.contains(id)) return;
    auto& c = channel_of(ch.topic);
    by_channel_id.emplace(id, static_cast<std::size_t>(&c - channels.data()));
    c.encoding = ch.message_encoding;
    c.channel_id = id;
    auto meta = [&](const char* key) {
      auto it = ch.metadata.find(key);
      return it == ch.metadata.end() ? std::string() : it->second;
    };
    c.type = meta("horus.type");
    c.type_hash = parse_hex(meta("horus.type_hash"));
    c.signature = meta("horus.signature");
    c.scope = meta("horus.scope");
    if (ch.schema_id != 0)
      if (auto it = mcap->schemas().find(ch.schema_id); it != mcap->schemas().end()) {
        if (c.type.empty()) c.type = it->second.name;
        c.schema_encoding = it->second.encoding;
        if (c.schema_encoding == "ros2msg") resolve_ros2(c, it->second.name, meta("horus.type"), meta("horus.topic"));
      }
  }
};

Player::Player(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Player::~Player() = default;

Result<std::unique_ptr<Player>> Player::open(const std::string& path, bool recover) {
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  if (lcmlog::looks_like_log(path)) {
    impl->format = RecordFormat::Lcm;
    auto r = lcmlog::Reader::open(path);
    if (!r) return std::unexpected(r.error());
    impl->lcm = std::move(*r);
  } else {
    mcap::ReadOptions o;
    o.recover = recover;
    auto r = mcap::Reader::open(path, o);
    if (!r) return std::unexpected(r.error());
    impl->mcap = std::move(*r);
  }
  if (auto ok = impl->index(); !ok) return std::unexpected(ok.error());
  return std::unique_ptr<Player>(new Player(std::move(impl)));
}

RecordFormat Player::format() const noexcept { return impl_->format; }
const std::vector<PlayChannel>& Player::channels() const noexcept { return impl_->channels; }
const PlayChannel* Player::channel(std::string_view topic) const noexcept {
  auto it = impl_->by_topic.find(topic);
  return it == impl_->by_topic.end() ? nullptr : &impl_->channels[it->second];
}
std::uint64_t Player::start_ns() const noexcept { return impl_->start; }
std::uint64_t Player::end_ns() const noexcept { return impl_->end; }
std::uint64_t Player::file_bytes() const noexcept {
  return impl_->mcap ? impl_->mcap->file_size() : impl_->lcm->file_size();
}
bool Player::truncated() const noexcept { return impl_->truncated; }

Result<void> Player::unknown(std::string_view topic) {
  return fail(Errc::InvalidName, fmt::format("the recording has no topic '{}'", topic));
}

Result<void> Player::mismatch(const PlayChannel& c, std::string_view type) {
  if (c.encoding == "lcm")
    return fail(Errc::TypeMismatch, fmt::format("topic '{}' was recorded with LCM fingerprint {:016x}, which is not {}'s",
                                                c.topic, c.lcm_fingerprint, type));
  return fail(Errc::TypeMismatch, fmt::format("topic '{}' was recorded as {} (type hash {:016x}), not as {}", c.topic,
                                              c.type.empty() ? std::string("an unknown type") : c.type, c.type_hash,
                                              type));
}

Result<void> Player::bind(std::string_view topic, std::unique_ptr<PlaySink> sink) {
  auto it = impl_->by_topic.find(topic);
  if (it == impl_->by_topic.end()) return unknown(topic);
  if (auto ok = playable(impl_->channels[it->second]); !ok) return ok;
  if (!sink) return fail(Errc::InvalidArgument, "Player::bind: no sink");
  impl_->sinks[it->second] = std::move(sink);
  return {};
}

Result<void> Player::playable(const PlayChannel& c) {
  if (c.encoding == "lcm") return {};
  if (c.encoding != "cdr")
    return fail(Errc::TypeMismatch, fmt::format("topic '{}' (channel {}) has message encoding '{}'; horus plays cdr "
                                                "messages (with an omgidl schema) and LCM logs",
                                                c.topic, c.channel_id, c.encoding));
  if (c.schema_encoding == "ros2msg") {
    if (!c.type.empty()) return {};
    const std::string targets = [&] {
      std::set<std::string_view> types;
      for (const auto& conv : ros2::conversions()) types.insert(conv.ros_type);
      std::string out;
      for (auto t : types) out += (out.empty() ? "" : ", ") + std::string(t);
      return out;
    }();
    return fail(Errc::TypeMismatch, fmt::format("topic '{}' (channel {}) is of ROS 2 type {}, which no horus message "
                                                "converts from (horus plays {} and the horus_msgs types; docs/ROS2.md)",
                                                c.topic, c.channel_id, c.ros2_type, targets));
  }
  if (!c.schema_encoding.empty() && c.schema_encoding != "omgidl")
    return fail(Errc::TypeMismatch, fmt::format("topic '{}' (channel {}) has schema {} of encoding '{}'; horus plays cdr "
                                                "messages whose schema is omgidl",
                                                c.topic, c.channel_id, c.type, c.schema_encoding));
  return {};
}

Result<PlayStats> Player::play(const PlayOptions& options, const std::atomic<bool>* stop) {
  if (!(options.rate >= 0.0)) return fail(Errc::InvalidArgument, fmt::format("play rate {} is not >= 0", options.rate));
  if (!(options.start_s >= 0.0))
    return fail(Errc::InvalidArgument, fmt::format("play start {} s is not >= 0", options.start_s));
  for (const auto& p : options.topics)
    if (auto ok = check_topic_pattern(p); !ok) return std::unexpected(ok.error());
  // Which channels play: bound, and matching a pattern when there are any.
  std::vector<PlaySink*> sink_of(impl_->channels.size(), nullptr);
  for (auto& [index, sink] : impl_->sinks) {
    bool wanted = options.topics.empty();
    const auto& c = impl_->channels[index];
    for (const auto& p : options.topics)
      wanted = wanted || topic_pattern_matches(p, c.topic) || topic_pattern_matches(p, c.horus_topic);
    if (wanted) sink_of[index] = sink.get();
  }
  PlayStats stats;
  const std::uint64_t from = impl_->start + static_cast<std::uint64_t>(options.start_s * 1e9);
  if (from > impl_->end)
    return fail(Errc::InvalidArgument,
                fmt::format("play start {} s is past the end of the recording ({:.3f} s long); expected a start "
                            "within it",
                            options.start_s, static_cast<double>(impl_->end - impl_->start) / 1e9));
  const auto stopped = [&] { return stop != nullptr && stop->load(std::memory_order_relaxed); };
  for (;;) {
    const auto t0 = std::chrono::steady_clock::now();
    bool first = true;
    std::uint64_t base = from;
    auto deliver = [&](std::size_t index, std::uint64_t log_time, std::span<const std::byte> data) {
      if (stopped()) return false;
      PlaySink* sink = sink_of[index];
      if (sink == nullptr || log_time < from) return true;
      if (first) {
        base = log_time;
        first = false;
      }
      if (options.rate > 0) {
        const auto due = t0 + std::chrono::nanoseconds(static_cast<std::int64_t>(
                                  static_cast<double>(log_time - std::min(log_time, base)) / options.rate));
        // Sleeps in steps, so that `stop` is seen within 50 ms.
        while (!stopped()) {
          const auto now = std::chrono::steady_clock::now();
          if (now >= due) break;
          std::this_thread::sleep_for(std::min<std::chrono::nanoseconds>(due - now, std::chrono::milliseconds(50)));
        }
        if (stopped()) return false;
      }
      if (auto ok = sink->publish(data); ok) {
        ++stats.published;
        ++stats.per_topic[impl_->channels[index].topic];
      } else {
        ++stats.failed;
        if (stats.first_error.empty())
          stats.first_error = fmt::format("topic '{}': {}", impl_->channels[index].topic, ok.error().message());
      }
      return true;
    };
    Result<void> ok;
    if (impl_->mcap) {
      ok = impl_->mcap->read_messages([&](const mcap::Channel& ch, const mcap::Schema*, const mcap::Message& m) {
        return deliver(impl_->by_channel_id[ch.id], m.log_time, m.data);
      });
    } else {
      ok = impl_->lcm->read([&](const lcmlog::Event& e) {
        return deliver(impl_->by_topic.find(e.channel)->second,
                       static_cast<std::uint64_t>(std::max<std::int64_t>(e.timestamp_us, 0)) * 1000, e.data);
      });
    }
    if (!ok) return std::unexpected(ok.error());
    if (stopped()) break;
    ++stats.loops;
    if (!options.loop) break;
    // A pass that played nothing (no message of the chosen topics after the start) would spin.
    if (first)
      return fail(Errc::InvalidArgument,
                  fmt::format("nothing to play from {} s on with the topics chosen; looping would repeat nothing",
                              options.start_s));
  }
  return stats;
}

}  // namespace horus

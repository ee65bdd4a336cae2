// horus record, horus record info / recover, horus play: the command line over horus::Recorder
// and horus::Player (record/), with the standard types bound by name (typed_reader.hpp).
#include "record_cmd.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <map>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "horus/config.hpp"
#include "horus/discovery/registry.hpp"
#include "horus/fleet.hpp"
#include "horus/fleet_messages.hpp"
#include "horus/names.hpp"
#include "horus/record/lcm_log.hpp"
#include "horus/record/mcap.hpp"
#include "horus/record/player.hpp"
#include "horus/record/recorder.hpp"
#include "horus/ros2/names.hpp"
#include "foxglove/schemas.hpp"
#include "typed_reader.hpp"

namespace horus::tools {
namespace {

using Clock = std::chrono::steady_clock;

std::string mb(double bytes) {
  if (bytes < 1e3) return fmt::format("{:.0f} B", bytes);
  if (bytes < 1e6) return fmt::format("{:.1f} kB", bytes / 1e3);
  if (bytes < 1e9) return fmt::format("{:.1f} MB", bytes / 1e6);
  return fmt::format("{:.2f} GB", bytes / 1e9);
}

std::string utc(std::uint64_t ns) {
  const std::time_t s = static_cast<std::time_t>(ns / 1'000'000'000ULL);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", &tm);
  return fmt::format("{}.{:03d} UTC", buf, static_cast<int>(ns / 1'000'000ULL % 1000));
}

// Opens a recording; one that ends early is opened again to read up to its last complete
// chunk, with a warning (what a killed recorder leaves).
Result<std::unique_ptr<Player>> open_recording(const std::string& file, const char* cmd) {
  auto p = Player::open(file);
  if (p) return p;
  auto recovered = Player::open(file, true);
  if (!recovered || !(*recovered)->truncated()) return p;
  fmt::print(stderr,
             "horus {}: {} ends early (a recorder that was killed?): reading up to its last complete chunk; "
             "`horus record recover {}` writes a whole copy\n  ({})\n",
             cmd, file, file, p.error().message());
  return recovered;
}

// The live view of a recording: one line per second (a table of the topics on a terminal).
class Progress {
 public:
  explicit Progress(bool tty) : tty_(tty) {}
  void show(const RecorderStats& s, double elapsed_s) {
    const double dt = std::max(1e-3, elapsed_s - last_s_);
    std::string text = fmt::format("recording {} topics: {} messages, {} -> {} ({}), {:.0f} s\n", s.topics.size(),
                                   s.messages, mb(static_cast<double>(s.bytes)), s.files.empty() ? "" : s.files.back(),
                                   mb(static_cast<double>(s.file_bytes)), elapsed_s);
    std::map<std::string, std::uint64_t> now;
    if (tty_) {
      for (const auto& t : s.topics) {
        const auto before = last_.contains(t.topic) ? last_[t.topic] : 0;
        text += fmt::format("  {:<40} {:>10} msgs {:>9.1f} Hz {:>10} {}\n", t.topic, t.messages,
                            static_cast<double>(t.messages - before) / dt, mb(static_cast<double>(t.bytes)),
                            t.dropped ? fmt::format("{} dropped", t.dropped) : "");
      }
    }
    for (const auto& t : s.topics) now[t.topic] = t.messages;
    last_ = std::move(now);
    last_s_ = elapsed_s;
    if (tty_ && lines_ > 0) fmt::print("\033[{}A\033[J", lines_);
    fmt::print("{}", text);
    std::fflush(stdout);
    lines_ = tty_ ? static_cast<int>(std::count(text.begin(), text.end(), '\n')) : 0;
  }
  void forget() { lines_ = 0; }

 private:
  bool tty_;
  int lines_ = 0;
  double last_s_ = 0;
  std::map<std::string, std::uint64_t> last_;
};

// Checks the arguments and sets the recorder's options from them; false, with the error printed,
// when they are wrong.
bool record_options(const RecordArgs& a, RecorderOptions& o) {
  auto profile = parse_record_profile(a.profile);
  if (!profile) {
    fmt::print(stderr, "horus record: --profile: {}\n", profile.error().message());
    return false;
  }
  if (*profile == RecordProfile::Ros2 && (a.foxglove || a.format != "mcap")) {
    fmt::print(stderr, "horus record: --profile ros2 writes a rosbag2 MCAP bag of ROS 2 types; not with {}\n",
               a.foxglove ? "--foxglove (Foxglove's ROS panels read the ROS 2 types themselves)" : "--format " + a.format);
    return false;
  }
  o.profile = *profile;
  if (a.foxglove && a.format != "mcap") {
    fmt::print(stderr, "horus record: --foxglove records Foxglove's schemas, which only MCAP holds (not --format {})\n",
               a.format);
    return false;
  }
  if (a.topics.empty() && !a.all) {
    fmt::print(stderr, "horus record: name the topics to record with --topics PATTERN (e.g. --topics 'robot.**') "
                       "or record every topic with --all\n");
    return false;
  }
  for (const auto& p : a.topics)
    if (auto ok = check_topic_pattern(p); !ok) {
      fmt::print(stderr, "horus record: --topics '{}': {}\n", p, ok.error().message());
      return false;
    }
  auto format = parse_record_format(a.format);
  auto compression = mcap::parse_compression(a.compression);
  if (!format || !compression) {
    fmt::print(stderr, "horus record: {}\n", (!format ? format.error() : compression.error()).message());
    return false;
  }
  if (!(a.split_mb >= 0) || !(a.duration_s >= 0)) {
    fmt::print(stderr, "horus record: --split-size and --duration must be >= 0\n");
    return false;
  }
  o.format = *format;
  o.compression = *compression;
  o.split_size = static_cast<std::uint64_t>(a.split_mb * 1e6);
  o.overwrite = a.overwrite;
  return true;
}

// Fleet topics that only other hosts have: through the fleet layer, when a network backend
// is configured (this process then bridges them to this host, as any subscriber would).
std::unique_ptr<Fleet> open_record_fleet(const RecordArgs& a) {
  std::string transport = a.backend;
  if (transport.empty())
    if (auto s = fleet_settings(); s) transport = s->transport;
  std::unique_ptr<Fleet> fleet;
  if (!transport.empty()) {
    FleetOptions fo;
    fo.transport = transport;
    if (auto f = Fleet::open(fo); f) fleet = std::move(*f);
    else fmt::print(stderr, "horus record: other hosts' topics are not recorded: {}\n", f.error().message());
  }
  return fleet;
}

// The topics to record, found on this host and the fleet's hosts as they appear, added to the
// recorder (each once; one that cannot be recorded is said once and skipped).
struct RecordScan {
  const RecordArgs& a;
  Recorder& recorder;
  std::unique_ptr<Fleet> fleet;
  std::set<std::string, std::less<>> skipped;
  std::set<std::string, std::less<>> transports;  // Backend keeps a view of the name

  bool wanted(const std::string& name) const {
    if (a.topics.empty()) return !horus::fleet::is_fleet_layer_topic(name);
    return std::any_of(a.topics.begin(), a.topics.end(), [&](const auto& p) { return topic_pattern_matches(p, name); });
  }

  void consider(const std::string& name, const std::string& type, const std::string& scope, const std::string& via) {
    if (skipped.contains(name) || !wanted(name) || recorder.recording(name)) return;
    std::optional<Backend> backend = Backend::SharedMemory;
    if (scope == "fleet") backend = Backend::network(*transports.insert(via).first);
    std::string error;
    auto source = open_record_source(type, name, backend, error);
    if (!source) {
      skipped.insert(name);
      if (error.empty())
        error = type + " is not a standard horus message (a program records its own types with horus::Recorder)";
      fmt::print(stderr, "horus record: not recording '{}': {}\n", name, error);
      return;
    }
    if (auto ok = recorder.add(std::move(source)); !ok) {
      skipped.insert(name);
      fmt::print(stderr, "horus record: not recording '{}': {}\n", name, ok.error().message());
      return;
    }
    fmt::print("+ {} ({}, {})\n", name, type, scope);
    if (const auto* fs = a.foxglove ? fox::foxglove_schema_of(type) : nullptr; fs != nullptr) {
      TopicOptions to;
      to.backend = backend;
      auto converted = fox::open_foxglove_source(type, name, to, a.frame, error);
      auto ok = converted ? recorder.add(std::move(converted)) : Result<void>(fail(Errc::InvalidArgument, error));
      if (ok) fmt::print("+ {}{} ({}, {})\n", name, fox::kConvertedSuffix, fs->name, scope);
      else fmt::print(stderr, "horus record: not recording '{}{}': {}\n", name, fox::kConvertedSuffix, ok.error().message());
    }
    std::fflush(stdout);
  }

  void discover() {
    for (const auto& t : discovery::list_topics(a.ns))
      if (!t.stale) consider(t.topic, t.type_name, t.scope, t.transport);
    if (fleet)
      for (const auto& h : fleet->hosts()) {
        if (h.self || h.state == HostState::Lost) continue;
        for (const auto& t : h.topics)
          if (t.scope == "fleet") consider(t.name, t.type_name, t.scope, t.transport);
      }
  }
};

std::string record_patterns(const RecordArgs& a) {
  return a.topics.empty() ? std::string("--all") : fmt::format("--topics '{}'", fmt::join(a.topics, "' '"));
}

// Records until Ctrl-C, --duration or the recorder's error: a scan every 500 ms, a line of
// progress every second.
void record_until_stopped(const RecordArgs& a, const std::atomic<bool>& stop, RecordScan& scan, Progress& progress,
                          Clock::time_point start) {
  Recorder& recorder = scan.recorder;
  auto next_scan = start, next_show = start + std::chrono::seconds(1);
  bool said_none = false;  // "no topic matches yet", once
  while (!stop.load()) {
    const auto now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - start).count();
    if (a.duration_s > 0 && elapsed >= a.duration_s) break;
    if (recorder.error()) break;
    if (now >= next_scan) {
      scan.discover();
      next_scan = now + std::chrono::milliseconds(500);
      if (!said_none && scan.skipped.empty() && recorder.stats().topics.empty()) {
        said_none = true;
        fmt::print(stderr, "horus record: no topic matches {} yet ({} topics on this host{}); recording what appears\n",
                   record_patterns(a), discovery::list_topics(a.ns).size(), scan.fleet ? " and the fleet's" : "");
      }
    }
    if (now >= next_show) {
      progress.show(recorder.stats(), elapsed);
      next_show = now + std::chrono::seconds(1);
    }
    // Ten looks a second (Ctrl-C, --duration, the recorder's error, the next scan and line): a
    // recorder runs all shift, its idle cost is what it costs.
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

// Closes the recording and prints what it holds; the exit code.
int finish_recording(const RecordArgs& a, Recorder& recorder, double elapsed) {
  auto closed = recorder.close();
  const auto s = recorder.stats();
  fmt::print("recorded {} messages of {} topics in {:.1f} s: {} of messages, {} in {}\n", s.messages, s.topics.size(),
             elapsed, mb(static_cast<double>(s.bytes)), mb(static_cast<double>(s.file_bytes)),
             fmt::join(s.files, ", "));
  for (const auto& t : s.topics)
    fmt::print("  {:<40} {:<36} {:>10} msgs {:>9.1f} Hz {}\n", t.topic, t.type, t.messages,
               elapsed > 0 ? static_cast<double>(t.messages) / elapsed : 0.0,
               t.dropped ? fmt::format("({} lost before the recorder took them)", t.dropped) : "");
  if (!closed) {
    fmt::print(stderr, "horus record: {}\n", closed.error().message());
    return 1;
  }
  if (s.topics.empty()) {
    fmt::print(stderr, "horus record: no topic matched {} in {:.1f} s: {} holds no messages\n", record_patterns(a),
               elapsed, fmt::join(s.files, ", "));
    return 1;
  }
  return 0;
}

// recover's default output: FILE.recovered.EXT (FILE.recovered.mcap without an extension).
std::string recovered_name(const std::string& file) {
  const auto dot = file.rfind('.');
  return (dot == std::string::npos || file.find('/', dot) != std::string::npos ? file : file.substr(0, dot)) +
         ".recovered" + (dot == std::string::npos ? std::string(".mcap") : file.substr(dot));
}

// What recover copied.
struct Recovered {
  std::uint64_t copied = 0;
  std::size_t channels = 0;
  bool truncated = false;
};

// Copies an LCM log's whole events into a new log.
Result<void> recover_lcm_log(const std::string& file, const std::string& out, Recovered& got) {
  auto r = lcmlog::Reader::open(file);
  if (!r) return std::unexpected(r.error());
  auto w = lcmlog::Writer::create(out);
  if (!w) return std::unexpected(w.error());
  Result<void> ok;
  std::set<std::string, std::less<>> seen;
  ok = (*r)->read([&](const lcmlog::Event& e) {
    if (auto written = (*w)->write(e.channel, e.timestamp_us, e.data); !written) {
      ok = written;
      return false;
    }
    seen.emplace(e.channel);
    ++got.copied;
    return true;
  });
  got.truncated = (*r)->truncated();
  got.channels = seen.size();
  if (ok) ok = (*w)->close();
  return ok;
}

// Copies an MCAP file's readable messages, with their schemas and channels, into a new file.
Result<void> recover_mcap(const std::string& file, const std::string& out, Recovered& got) {
  mcap::ReadOptions ro;
  ro.recover = true;
  auto r = mcap::Reader::open(file, ro);
  if (!r) return std::unexpected(r.error());
  auto w = mcap::Writer::create(out);
  if (!w) return std::unexpected(w.error());
  std::map<std::uint16_t, std::uint16_t> schema_ids, channel_ids;  // old -> new
  Result<void> failed;
  auto read = (*r)->read_messages([&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
    if (!channel_ids.contains(ch.id)) {
      std::uint16_t sid = 0;
      if (schema != nullptr) {
        if (auto it = schema_ids.find(schema->id); it != schema_ids.end()) {
          sid = it->second;
        } else if (auto id = (*w)->add_schema(schema->name, schema->encoding, schema->data); id) {
          sid = schema_ids[schema->id] = *id;
        } else {
          failed = std::unexpected(id.error());
          return false;
        }
      }
      auto id = (*w)->add_channel(sid, ch.topic, ch.message_encoding, ch.metadata);
      if (!id) {
        failed = std::unexpected(id.error());
        return false;
      }
      channel_ids[ch.id] = *id;
    }
    mcap::Message copy = m;
    copy.channel_id = channel_ids[ch.id];
    if (auto written = (*w)->write(copy); !written) {
      failed = written;
      return false;
    }
    ++got.copied;
    return true;
  });
  Result<void> ok = !read ? read : failed;
  got.truncated = (*r)->truncated();
  got.channels = channel_ids.size();
  if (ok) ok = (*w)->close();
  return ok;
}

// play's --remap OLD=NEW pairs; false, with the error printed, when one is not two topic names.
bool parse_remap(const PlayArgs& a, std::map<std::string, std::string, std::less<>>& remap) {
  for (const auto& r : a.remap) {
    const auto eq = r.find('=');
    const std::string from = r.substr(0, eq), to = eq == std::string::npos ? "" : r.substr(eq + 1);
    if (eq == std::string::npos || !validate_topic_name(from) || !validate_topic_name(to)) {
      fmt::print(stderr, "horus play: --remap '{}': expected OLD=NEW, two topic names\n", r);
      return false;
    }
    remap[from] = to;
  }
  return true;
}

// Binds a recorded channel to a topic of its standard type (its --remap name); false, with the
// reason printed, when it is skipped.
bool bind_channel(const PlayArgs& a, Player& player, const PlayChannel& c,
                  const std::map<std::string, std::string, std::less<>>& remap) {
  if (!a.topics.empty() &&
      std::none_of(a.topics.begin(), a.topics.end(), [&](const auto& p) { return topic_pattern_matches(p, c.topic); }))
    return false;
  if (auto ok = Player::playable(c); !ok) {
    fmt::print(stderr, "horus play: skipping '{}': {}\n", c.topic, ok.error().message());
    return false;
  }
  const bool lcm = c.encoding == "lcm";
  const std::string type = lcm ? standard_type_by_lcm_fingerprint(c.lcm_fingerprint) : standard_type(c.type);
  if (type.empty()) {
    fmt::print(stderr, "horus play: skipping '{}': {} is not a standard horus message (a program plays its own types "
                       "with horus::Player::bind<T>)\n",
               c.topic, lcm ? fmt::format("LCM type {:016x}", c.lcm_fingerprint) : c.type);
    return false;
  }
  const auto it = remap.find(c.topic);
  const std::string to = it == remap.end() ? c.horus_topic : it->second;
  std::uint64_t hash = 0;
  std::string error;
  TopicOptions options;
  if (a.ros2) {
    Ros2Mapping m;
    m.name = !c.ros2_type.empty() && it == remap.end() ? c.topic : ros2::topic_name_of(to);  // a ROS 2 bag's own
    m.type = c.ros2_type;
    options.ros2 = m;
  }
  auto sink = open_play_sink(type, to, lcm, c.conversion, options, hash, error);
  if (sink && !lcm && c.type_hash != 0 && c.type_hash != hash)
    error = fmt::format("it was recorded with type hash {:016x}; this build's {} has {:016x}", c.type_hash, type, hash);
  if (!error.empty() || !sink) {
    fmt::print(stderr, "horus play: skipping '{}': {}\n", c.topic, error);
    return false;
  }
  if (auto ok = player.bind(c.topic, std::move(sink)); !ok) {
    fmt::print(stderr, "horus play: skipping '{}': {}\n", c.topic, ok.error().message());
    return false;
  }
  return true;
}

}  // namespace

int cmd_record(const RecordArgs& a, const std::atomic<bool>& stop) {
  RecorderOptions o;
  if (!record_options(a, o)) return 2;
  auto rec = Recorder::open(a.output, o);
  if (!rec) {
    fmt::print(stderr, "horus record: {}\n", rec.error().message());
    return 1;
  }
  Recorder& recorder = **rec;
  RecordScan scan{a, recorder, open_record_fleet(a), {}, {}};

  fmt::print("recording into {} ({}{}); Ctrl-C stops\n", a.output, a.format,
             o.format == RecordFormat::Mcap ? ", " + std::string(a.compression) + " chunks" : "");
  std::fflush(stdout);
  Progress progress(::isatty(STDOUT_FILENO) == 1);
  const auto start = Clock::now();
  record_until_stopped(a, stop, scan, progress, start);
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  return finish_recording(a, recorder, elapsed);
}

int cmd_record_info(const std::string& file, bool json) {
  auto p = open_recording(file, "record info");
  if (!p) {
    fmt::print(stderr, "horus record info: {}\n", p.error().message());
    return 1;
  }
  const Player& player = **p;
  const double duration = static_cast<double>(player.end_ns() - player.start_ns()) / 1e9;
  std::uint64_t messages = 0;
  for (const auto& c : player.channels()) messages += c.messages;
  if (json) {
    nlohmann::json topics = nlohmann::json::array();
    for (const auto& c : player.channels()) {
      const double span = static_cast<double>(c.last_ns - c.first_ns) / 1e9;
      topics.push_back({{"topic", c.topic},
                        {"type", c.type},
                        {"type_hash", fmt::format("{:016x}", c.type_hash)},
                        {"encoding", c.encoding},
                        {"scope", c.scope},
                        {"messages", c.messages},
                        {"bytes", c.bytes},
                        {"rate_hz", span > 0 ? static_cast<double>(c.messages - 1) / span : 0.0}});
    }
    nlohmann::json out{{"file", file},
                       {"format", std::string(to_string(player.format()))},
                       {"bytes", player.file_bytes()},
                       {"truncated", player.truncated()},
                       {"start_ns", player.start_ns()},
                       {"end_ns", player.end_ns()},
                       {"duration_s", duration},
                       {"messages", messages},
                       {"topics", topics}};
    fmt::print("{}\n", out.dump(2));
    return 0;
  }
  fmt::print("file:      {} ({}, {}{})\n", file, to_string(player.format()), mb(static_cast<double>(player.file_bytes())),
             player.truncated() ? ", ends early: read up to its last complete chunk" : "");
  if (messages > 0)
    fmt::print("duration:  {:.3f} s, {} to {}\n", duration, utc(player.start_ns()), utc(player.end_ns()));
  fmt::print("messages:  {}\ntopics:    {}\n", messages, player.channels().size());
  for (const auto& c : player.channels()) {
    const double span = static_cast<double>(c.last_ns - c.first_ns) / 1e9;
    std::string type = c.type;
    if (type.empty() && c.encoding == "lcm") {
      type = standard_type_by_lcm_fingerprint(c.lcm_fingerprint);
      if (type.empty()) type = fmt::format("LCM type {:016x}", c.lcm_fingerprint);
    }
    fmt::print("  {:<40} {:<36} {:>10} msgs {:>9.1f} Hz {:>10} {}\n", c.topic, type, c.messages,
               span > 0 ? static_cast<double>(c.messages - 1) / span : 0.0, mb(static_cast<double>(c.bytes)), c.encoding);
  }
  return 0;
}

int cmd_record_recover(const std::string& file, const std::string& output) {
  const std::string out = output.empty() ? recovered_name(file) : output;
  if (out == file) {
    fmt::print(stderr, "horus record recover: the output must not be the input file\n");
    return 2;
  }
  Recovered got;
  const Result<void> ok = lcmlog::looks_like_log(file) ? recover_lcm_log(file, out, got) : recover_mcap(file, out, got);
  if (!ok) {
    fmt::print(stderr, "horus record recover: {}\n", ok.error().message());
    return 1;
  }
  fmt::print("{} messages of {} topics from {} ({}) into {}\n", got.copied, got.channels, file,
             got.truncated ? "it ended early; read up to its last complete chunk" : "it was whole", out);
  return 0;
}

int cmd_play(const PlayArgs& a, const std::atomic<bool>& stop) {
  std::map<std::string, std::string, std::less<>> remap;
  if (!parse_remap(a, remap)) return 2;
  for (const auto& p : a.topics)
    if (auto ok = check_topic_pattern(p); !ok) {
      fmt::print(stderr, "horus play: --topics '{}': {}\n", p, ok.error().message());
      return 2;
    }
  auto opened = open_recording(a.file, "play");
  if (!opened) {
    fmt::print(stderr, "horus play: {}\n", opened.error().message());
    return 1;
  }
  Player& player = **opened;
  for (const auto& [from, to] : remap)
    if (player.channel(from) == nullptr) {
      fmt::print(stderr, "horus play: --remap {}={}: the recording has no topic '{}'\n", from, to, from);
      return 2;
    }
  std::size_t bound = 0;
  std::uint64_t messages = 0;
  for (const auto& c : player.channels()) {
    if (!bind_channel(a, player, c, remap)) continue;
    ++bound;
    messages += c.messages;
  }
  if (bound == 0) {
    fmt::print(stderr, "horus play: nothing to play from {}\n", a.file);
    return 1;
  }
  PlayOptions o;
  o.rate = a.rate;
  o.start_s = a.start_s;
  o.loop = a.loop;
  o.topics = a.topics;
  fmt::print("playing {} topics ({} messages, {:.1f} s) from {} at rate {}{}\n", bound, messages,
             static_cast<double>(player.end_ns() - player.start_ns()) / 1e9, a.file, a.rate, a.loop ? ", looping" : "");
  std::fflush(stdout);
  auto stats = player.play(o, &stop);
  if (!stats) {
    fmt::print(stderr, "horus play: {}\n", stats.error().message());
    return 1;
  }
  fmt::print("published {} messages{}\n", stats->published,
             stats->failed ? fmt::format("; {} failed, the first: {}", stats->failed, stats->first_error) : "");
  return stats->failed ? 1 : 0;
}

}  // namespace horus::tools

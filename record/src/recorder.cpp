// horus::Recorder (see recorder.hpp): one thread drains the sources into the file.
#include "horus/record/recorder.hpp"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "horus/idlgen/emit.hpp"
#include "horus/log.hpp"
#include "horus/record/lcm_log.hpp"
#include "horus/wire/dynamic.hpp"
#include "ros2_profile.hpp"

namespace horus {

std::string_view to_string(RecordFormat f) noexcept { return f == RecordFormat::Mcap ? "mcap" : "lcm"; }

Result<RecordFormat> parse_record_format(std::string_view name) {
  if (name == "mcap") return RecordFormat::Mcap;
  if (name == "lcm") return RecordFormat::Lcm;
  return fail(Errc::InvalidArgument, fmt::format("unknown recording format '{}'; expected mcap or lcm", name));
}

std::string_view to_string(RecordProfile p) noexcept { return p == RecordProfile::Ros2 ? "ros2" : "horus"; }

Result<RecordProfile> parse_record_profile(std::string_view name) {
  if (name == "horus") return RecordProfile::Horus;
  if (name == "ros2") return RecordProfile::Ros2;
  return fail(Errc::InvalidArgument, fmt::format("unknown recording profile '{}'; expected horus or ros2", name));
}

namespace {

using Clock = std::chrono::steady_clock;
constexpr std::size_t kBatch = 256;  // messages taken from one topic before the next topic's turn
// After a round that took messages, the thread lets more gather before the next round instead of
// waking for each one (10 topics at 1 kHz would wake it 10000 times a second): a recorder needs
// throughput, not latency, and the rings hold far more than this.
constexpr auto kGather = std::chrono::milliseconds(2);

std::uint64_t now_unix_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

// A message's own stamp when it is plausibly a wall-clock time near `log_time` (within a day
// before, an hour after); else the log time.
std::uint64_t publish_time(std::uint64_t stamp, std::uint64_t log_time) {
  constexpr std::uint64_t kDay = 86'400'000'000'000ULL, kHour = 3'600'000'000'000ULL;
  if (stamp != 0 && stamp + kDay > log_time && stamp < log_time + kHour) return stamp;
  return log_time;
}

// run.mcap -> run_1.mcap, run_2.mcap, ...
std::string split_path(const std::string& base, std::size_t index) {
  if (index == 0) return base;
  const std::filesystem::path p(base);
  return (p.parent_path() / (p.stem().string() + "_" + std::to_string(index) + p.extension().string())).string();
}

}  // namespace

struct Recorder::Impl {
  struct Entry {
    std::unique_ptr<RecordSource> source;
    std::uint16_t channel = 0;
    std::uint32_t sequence = 0;
    bool attached = false;
    std::optional<record_detail::Ros2Channel> ros2;  // RecordProfile::Ros2
    RecordedTopic stats;
  };

  std::string base_path;
  RecorderOptions options;
  mutable std::mutex mu;  // everything below
  std::vector<Entry> entries;
  std::unique_ptr<mcap::Writer> mcap;
  std::unique_ptr<lcmlog::Writer> lcm;
  std::map<std::string, std::uint16_t, std::less<>> schema_ids;  // of the current MCAP file
  std::vector<std::string> files;
  std::uint64_t closed_bytes = 0;
  std::uint64_t messages = 0, bytes = 0;
  std::optional<Error> error;
  bool closed = false;
  Clock::time_point last_flush = Clock::now();
  std::vector<std::byte> buffer;
  std::vector<RecordedTopic> closed_topics;
  bool backlog = false;  // the last drain left messages behind  // the topics' counts when close() let them go

  WaitSet ws;
  Trigger wake;
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> rounds{0};
  std::thread thread;

  Result<void> open_file(std::size_t index) {
    const auto path = split_path(base_path, index);
    if (!options.overwrite) {
      std::error_code ec;
      if (std::filesystem::exists(path, ec) || ec)
        return fail(Errc::InvalidArgument,
                    fmt::format("{} exists already; not replacing a recording (overwrite it on purpose: "
                                "RecorderOptions::overwrite, `horus record --overwrite`)",
                                path));
    }
    if (options.format == RecordFormat::Mcap) {
      mcap::WriterOptions w;
      w.compression = options.compression;
      w.chunk_size = options.chunk_size;
      if (options.profile == RecordProfile::Ros2) w.profile = "ros2";
      auto writer = mcap::Writer::create(path, w);
      if (!writer) return std::unexpected(writer.error());
      mcap = std::move(*writer);
      schema_ids.clear();
      for (auto& e : entries)
        if (auto ok = register_channel(e); !ok) return ok;
    } else {
      auto writer = lcmlog::Writer::create(path);
      if (!writer) return std::unexpected(writer.error());
      lcm = std::move(*writer);
    }
    files.push_back(path);
    return {};
  }

  std::uint64_t file_size() const {
    if (mcap) return mcap->file_size();
    if (lcm) return lcm->file_size();
    return 0;
  }

  Result<void> close_file() {
    Result<void> r;
    if (mcap) {
      if (options.profile == RecordProfile::Ros2) r = write_bag_metadata();
      if (auto ok = mcap->close(); r) r = ok;
      closed_bytes += mcap->file_size();
      mcap.reset();
    }
    if (lcm) {
      r = lcm->close();
      closed_bytes += lcm->file_size();
      lcm.reset();
    }
    return r;
  }

  // rosbag2's "rosbag2" Metadata record of the current file: its metadata.yaml.
  Result<void> write_bag_metadata() {
    const auto& st = mcap->statistics();
    std::vector<record_detail::BagTopic> topics;
    for (const auto& e : entries) {
      const auto n = st.channel_message_counts.find(e.channel);
      topics.push_back({&*e.ros2, n == st.channel_message_counts.end() ? 0 : n->second});
    }
    const std::string yaml = record_detail::bag_metadata(files.back(), topics, st.message_start_time,
                                                         st.message_end_time, st.message_count);
    return mcap->add_metadata("rosbag2", {{"serialized_metadata", yaml}});
  }

  // A ROS 2 topic's schema (once per type and file) and channel in the current MCAP file.
  Result<void> register_ros2_channel(Entry& e) {
    const auto& type = e.ros2->type;
    std::uint16_t schema = 0;
    if (auto it = schema_ids.find(type.type); it != schema_ids.end()) {
      schema = it->second;
    } else {
      auto id = mcap->add_schema(type.type, "ros2msg",
                                 std::as_bytes(std::span(type.definition.data(), type.definition.size())));
      if (!id) return std::unexpected(id.error());
      schema = *id;
      schema_ids.emplace(type.type, schema);
    }
    auto channel = mcap->add_channel(schema, e.ros2->topic, "cdr", e.ros2->metadata(*e.source));
    if (!channel) return std::unexpected(channel.error());
    e.channel = *channel;
    return {};
  }

  // The entry's schema (once per type and file) and channel in the current MCAP file.
  Result<void> register_channel(Entry& e) {
    if (e.ros2) return register_ros2_channel(e);
    const auto& type = e.source->type();
    std::uint16_t schema = 0;
    if (auto it = schema_ids.find(type.name); it != schema_ids.end()) {
      schema = it->second;
    } else if (!type.signature.empty() || !type.schema.empty()) {
      std::string idl = type.schema;
      if (idl.empty()) {
        if (auto dyn = wire::parse_signature(type.signature, type.hash); dyn) {
          try {
            idl = idlgen::omgidl_schema(*dyn);
          } catch (const std::exception& ex) {
            detail::log().warn("horus record: topic '{}' ({}) is recorded without a schema: {}", e.source->topic(),
                               type.name, ex.what());
          }
        } else {
          detail::log().warn(
              "horus record: topic '{}' ({}) is recorded without a schema: its signature does not parse: {}",
              e.source->topic(), type.name, dyn.error());
        }
      }
      if (!idl.empty()) {
        auto id = mcap->add_schema(type.name, "omgidl", std::as_bytes(std::span(idl.data(), idl.size())));
        if (!id) return std::unexpected(id.error());
        schema = *id;
        schema_ids.emplace(type.name, schema);
      }
    }
    std::map<std::string, std::string> meta{{"horus.type", type.name},
                                            {"horus.type_hash", fmt::format("{:016x}", type.hash)},
                                            {"horus.scope", e.source->scope()}};
    if (!type.signature.empty()) meta.emplace("horus.signature", type.signature);
    auto channel = mcap->add_channel(schema, e.source->topic(), "cdr", meta);
    if (!channel) return std::unexpected(channel.error());
    e.channel = *channel;
    return {};
  }

  // Takes up to kBatch messages of every topic into the file; how many it took. Holds mu.
  std::size_t drain(bool everything) {
    std::size_t took = 0;
    backlog = false;
    for (auto& e : entries) {
      for (std::size_t n = 0; everything || n < kBatch; ++n) {
        if (n + 1 == kBatch) backlog = true;  // a topic has more: no pause before the next round
        std::optional<std::uint64_t> stamp;
        try {
          stamp = e.ros2 ? e.ros2->next(*e.source, buffer) : e.source->next(options.format, buffer);
        } catch (const std::exception& ex) {
          ++e.stats.dropped;
          detail::log().warn("horus record: a message of topic '{}' could not be encoded and is not recorded: {}",
                             e.source->topic(), ex.what());
          continue;
        }
        if (!stamp) break;
        ++took;
        const auto log_time = now_unix_ns();
        Result<void> ok;
        if (mcap) {
          mcap::Message m;
          m.channel_id = e.channel;
          m.sequence = e.sequence++;
          m.log_time = log_time;
          m.publish_time = publish_time(*stamp, log_time);
          m.data = buffer;
          ok = mcap->write(m);
        } else if (lcm) {
          ok = lcm->write(e.source->topic(), static_cast<std::int64_t>(log_time / 1000), buffer);
        }
        if (!ok) {
          fail_with(ok.error());
          return took;
        }
        ++e.stats.messages;
        e.stats.bytes += buffer.size();
        ++messages;
        bytes += buffer.size();
      }
      e.stats.dropped = std::max(e.stats.dropped, e.source->dropped());
    }
    return took;
  }

  void fail_with(const Error& err) {
    if (error) return;
    error = err;
    detail::log().error("horus record: recording into {} stopped: {}", files.empty() ? base_path : files.back(),
                        err.message());
  }

  // Flushes every flush_interval, starts the next file at split_size. Holds mu.
  void housekeeping() {
    if (error) return;
    const auto now = Clock::now();
    if (now - last_flush >= options.flush_interval) {
      last_flush = now;
      auto ok = mcap ? mcap->flush() : (lcm ? lcm->flush() : Result<void>{});
      if (!ok) fail_with(ok.error());
    }
    if (options.split_size > 0 && file_size() >= options.split_size) {
      auto closed_ok = close_file();
      if (!closed_ok) return fail_with(closed_ok.error());
      if (auto ok = open_file(files.size()); !ok) fail_with(ok.error());
    }
  }

  void run() {
    for (;;) {
      // The trigger says "look again" (a topic added, close()): it stays fired until reset, and a
      // fired trigger ends every wait at once (the thread spun a core on an idle topic). Reset
      // before looking at `stop`: close() stores it before it fires.
      wake.reset();
      if (stop.load(std::memory_order_acquire)) break;
      rounds.fetch_add(1, std::memory_order_relaxed);
      std::size_t took = 0;
      bool polled = false;
      {
        std::lock_guard lock(mu);
        if (!error) took = drain(false);
        housekeeping();
        for (const auto& e : entries) polled = polled || !e.attached;
      }
      if (took == 0) ws.wait(polled ? kGather : std::chrono::milliseconds(200));
      else if (!backlog) std::this_thread::sleep_for(kGather);
    }
    std::lock_guard lock(mu);
    if (!error) drain(true);
  }
};

Recorder::Recorder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Result<std::unique_ptr<Recorder>> Recorder::open(const std::string& path, RecorderOptions options) {
  if (options.chunk_size == 0) return fail(Errc::InvalidArgument, "RecorderOptions::chunk_size is 0; expected bytes > 0");
  if (options.profile == RecordProfile::Ros2 && options.format != RecordFormat::Mcap)
    return fail(Errc::InvalidArgument, "the ros2 profile is a kind of MCAP file (a rosbag2 bag); not an LCM log");
  auto impl = std::make_unique<Impl>();
  impl->base_path = path;
  impl->options = options;
  if (auto ok = impl->open_file(0); !ok) return std::unexpected(ok.error());
  impl->ws.attach(impl->wake);
  auto* raw = impl.get();
  impl->thread = std::thread([raw] { raw->run(); });
  return std::unique_ptr<Recorder>(new Recorder(std::move(impl)));
}

Recorder::~Recorder() {
  if (auto ok = close(); !ok) detail::log().error("horus::Recorder: {}", ok.error().message());
}

Result<void> Recorder::already(std::string_view name) {
  return fail(Errc::InvalidArgument, fmt::format("topic '{}' is recorded already", name));
}

bool Recorder::recording(std::string_view name) const {
  std::lock_guard lock(impl_->mu);
  for (const auto& e : impl_->entries)
    if (e.source->topic() == name) return true;
  return false;
}

Result<void> Recorder::add(std::unique_ptr<RecordSource> source) {
  if (!source) return fail(Errc::InvalidArgument, "Recorder::add: no source");
  std::lock_guard lock(impl_->mu);
  if (impl_->closed) return fail(Errc::InvalidArgument, "Recorder::add: the recorder is closed");
  for (const auto& e : impl_->entries)
    if (e.source->topic() == source->topic()) return already(source->topic());
  if (auto why = source->unsupported(impl_->options.format))
    return fail(Errc::InvalidArgument, fmt::format("topic '{}' cannot be recorded as {}: {}", source->topic(),
                                                   to_string(impl_->options.format), *why));
  if (impl_->options.format == RecordFormat::Lcm && source->topic().size() > lcmlog::kMaxChannel)
    return fail(Errc::InvalidArgument, fmt::format("topic '{}' is longer than an LCM channel may be ({} bytes)",
                                                   source->topic(), lcmlog::kMaxChannel));
  Impl::Entry e;
  if (impl_->options.profile == RecordProfile::Ros2) {
    auto ros2 = record_detail::ros2_channel(*source);
    if (!ros2) return std::unexpected(ros2.error());
    for (const auto& other : impl_->entries)
      if (other.ros2->topic == ros2->topic)
        return fail(Errc::InvalidArgument, fmt::format("topics '{}' and '{}' are both the ROS 2 topic {}; a bag holds "
                                                       "a topic once (give one another name: 'ros2: {{name: /...}}')",
                                                       other.source->topic(), source->topic(), ros2->topic));
    e.stats.ros2_topic = ros2->topic;
    e.stats.ros2_type = ros2->type.type;
    e.ros2 = std::move(*ros2);
  }
  e.stats.topic = source->topic();
  e.stats.type = source->type().name;
  e.stats.scope = source->scope();
  e.source = std::move(source);
  if (impl_->mcap)
    if (auto ok = impl_->register_channel(e); !ok) return ok;
  e.attached = e.source->attach(impl_->ws);
  impl_->entries.push_back(std::move(e));
  impl_->wake.fire();  // the thread re-evaluates whether it must poll
  return {};
}

RecorderStats Recorder::stats() const {
  std::lock_guard lock(impl_->mu);
  RecorderStats s;
  s.messages = impl_->messages;
  s.bytes = impl_->bytes;
  s.file_bytes = impl_->closed_bytes + impl_->file_size();
  s.rounds = impl_->rounds.load(std::memory_order_relaxed);
  s.files = impl_->files;
  for (const auto& e : impl_->entries) s.topics.push_back(e.stats);
  if (impl_->closed) s.topics.insert(s.topics.end(), impl_->closed_topics.begin(), impl_->closed_topics.end());
  return s;
}

std::optional<Error> Recorder::error() const {
  std::lock_guard lock(impl_->mu);
  return impl_->error;
}

Result<void> Recorder::flush() {
  std::lock_guard lock(impl_->mu);
  if (impl_->error) return std::unexpected(*impl_->error);
  if (impl_->mcap) return impl_->mcap->flush();
  if (impl_->lcm) return impl_->lcm->flush();
  return {};
}

Result<void> Recorder::close() {
  if (!impl_) return {};
  {
    std::lock_guard lock(impl_->mu);
    if (impl_->closed) return impl_->error ? Result<void>(std::unexpected(*impl_->error)) : Result<void>{};
    impl_->closed = true;
  }
  impl_->stop.store(true, std::memory_order_release);
  impl_->wake.fire();
  if (impl_->thread.joinable()) impl_->thread.join();
  std::lock_guard lock(impl_->mu);
  auto ok = impl_->close_file();
  if (!ok) impl_->fail_with(ok.error());
  for (const auto& e : impl_->entries) impl_->closed_topics.push_back(e.stats);
  impl_->entries.clear();  // the topics close
  if (impl_->error) return std::unexpected(*impl_->error);
  return {};
}

}  // namespace horus

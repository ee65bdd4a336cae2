// The fleet agent's announcer (agent.hpp), a job of the network engine's control thread: it
// scans the host's topics and processes (the local registry, discovery/) and announces them on
// horus.fleet.announce when due, on change and when asked.
#include <unistd.h>

#include <algorithm>
#include <set>

#include "agent.hpp"
#include "horus/log.hpp"
#include "horus/shm/shm_segment.hpp"

namespace horus::fleet::detail {

namespace {

// Unix time of boot (/proc/stat btime), for processes' start times.
std::uint64_t boot_unix_ns() {
  static const std::uint64_t value = [] {
    std::ifstream in("/proc/stat");
    std::string key;
    while (in >> key) {
      if (key == "btime") {
        std::uint64_t s = 0;
        in >> s;
        return static_cast<std::uint64_t>(s) * std::uint64_t{1'000'000'000};
      }
      in.ignore(1 << 16, '\n');
    }
    return std::uint64_t{0};
  }();
  return value;
}

AnnouncedProcess describe_process(pid_t pid) {
  AnnouncedProcess p;
  p.pid = static_cast<std::uint32_t>(pid);
  p.name = read_line(("/proc/" + std::to_string(pid) + "/comm").c_str());
  const std::uint64_t ticks = shm::process_start_time(pid);
  const long hz = ::sysconf(_SC_CLK_TCK);
  if (ticks != 0 && hz > 0) p.start_unix_ns = boot_unix_ns() + ticks * (1'000'000'000ULL / static_cast<std::uint64_t>(hz));
  return p;
}

}  // namespace

std::chrono::steady_clock::time_point Agent::announcer_step(std::chrono::steady_clock::time_point now) {
  using Steady = std::chrono::steady_clock;
  std::unique_lock lock(mutex_);
  if (stopping_) return Steady::time_point::max();
  if (!holder_.load(std::memory_order_relaxed)) return now + settings_.heartbeat;  // tick() wakes it
  if (rescan_) {
    next_scan_ = now;
    rescan_ = false;
  }
  // A full scan every announce period; between them, a look every 500 ms at whether a topic
  // appeared or went (one stat of /dev/shm), which scans at once. A host with many topics
  // scans less often, so that scanning costs at most 0.05% of a core at rest (a scan of 1000
  // topics takes a few ms: one every few seconds) and 1% while topics come and go.
  bool scan_now = now >= next_scan_;
  if (now >= next_look_) {
    next_look_ = now + std::max<Steady::duration>(std::chrono::milliseconds(500), scan_cost_ * 100);
    if (!scanner_) scanner_ = std::make_unique<discovery::Scanner>(shm::shm_namespace(started_with_.env().shm_namespace).value_or(""));
    scan_now = scanner_->topics_changed() || scan_now;
  }
  if (scan_now) {
    lock.unlock();
    const auto t0 = Steady::now();
    scan();
    const auto cost = Steady::now() - t0;
    lock.lock();
    scan_cost_ = cost;
    next_scan_ = now + std::max<Steady::duration>(settings_.announce_period, cost * 2000);
    if (current_.version != sent_version_.load(std::memory_order_relaxed)) announce_due_ = std::min(announce_due_, now);
  }
  // At most one announcement per 100 ms, however many requests arrive. When due, it goes out
  // only if there is news: a request, a change of topics or processes (the version heartbeats
  // carry), or traffic since the last one (its counts and rates). A host at rest sends none:
  // a host that missed one sees the version in our heartbeats and asks.
  if (now >= announce_due_ && now >= last_announce_ + std::chrono::milliseconds(100)) {
    announce_due_ = now + settings_.announce_period;
    const bool news = asked_ || current_.version != sent_version_.load(std::memory_order_relaxed) ||
                      traffic_ != sent_traffic_;
    asked_ = false;
    if (news) {
      lock.unlock();
      current_.sent_unix_ns = static_cast<std::uint64_t>(
          std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
              .count());
      if (auto ok = announce_->send_blocking(current_, std::chrono::milliseconds(20)); !ok && !announce_error_logged_) {
        horus::detail::log().warn("fleet: the announcement did not go out: {}", ok.error().message());
        announce_error_logged_ = true;
      }
      sent_version_.store(current_.version, std::memory_order_relaxed);
      lock.lock();
      sent_traffic_ = traffic_;
      last_announce_ = now;
    }
  }
  return std::min({next_scan_, next_look_, std::max(announce_due_, last_announce_ + std::chrono::milliseconds(100))});
}

void Agent::scan() {
  const auto ns = shm::shm_namespace(started_with_.env().shm_namespace);
  Announcement a;
  a.host_id = self_;
  a.host = name_;
  a.shm_namespace = ns ? *ns : std::string();
  a.heartbeat_ms = static_cast<std::uint32_t>(settings_.heartbeat.count());
  std::set<pid_t> pids;
  std::set<std::uint64_t> typed;
  const auto now = std::chrono::steady_clock::now();
  std::map<std::string, Sample> samples;
  std::uint64_t version = 0xcbf29ce484222325ULL;
  std::uint64_t traffic = 0xcbf29ce484222325ULL;
  if (!scanner_) scanner_ = std::make_unique<discovery::Scanner>(a.shm_namespace);
  for (const auto& e : scanner_->scan()) {
    for (const auto& p : e.processes)
      if (p.alive) pids.insert(p.pid);
    if (e.stale || e.topic.starts_with(detail::kFleetTopicPrefix)) continue;
    AnnouncedTopic t;
    t.name = e.topic;
    t.type_name = e.type_name;
    t.type_hash = e.type_hash;
    t.scope = e.scope;
    t.transport = e.transport;
    t.publishers = e.publishers;
    t.subscribers = e.subscribers;
    t.messages = e.messages_sent;
    t.dropped = e.dropped + e.bridge_dropped;
    t.message_size = e.message_size;
    t.rate_hz = -1;
    if (auto it = samples_.find(e.segment); it != samples_.end()) {
      const double secs = std::chrono::duration<double>(now - it->second.at).count();
      if (secs > 0 && e.messages_sent >= it->second.messages)
        t.rate_hz = static_cast<double>(e.messages_sent - it->second.messages) / secs;
    }
    samples[e.segment] = Sample{e.messages_sent, now};
    if (!e.signature.empty() && typed.insert(e.type_hash).second)
      a.types.push_back(AnnouncedType{e.type_hash, e.signature});
    version = fnv(version, t.name + '\n' + t.type_name + '\n' + t.scope + '\n' + t.transport + '\n' +
                               std::to_string(t.type_hash) + ':' + std::to_string(t.publishers) + ':' +
                               std::to_string(t.subscribers) + '\n');
    traffic = fnv(traffic, std::to_string(t.messages) + ':' + std::to_string(t.dropped) + '\n');
    a.topics.push_back(std::move(t));
  }
  for (pid_t pid : pids) {
    a.processes.push_back(describe_process(pid));
    version = fnv(version, std::to_string(pid) + ':' + a.processes.back().name + '\n');
  }
  samples_ = std::move(samples);
  a.version = version == 0 ? 1 : version;
  traffic_ = traffic;
  // Stay within a slot: drop signatures (then topics) if the host has that much to say.
  while (encoded_too_large(a) && !a.types.empty()) a.types.pop_back();
  while (encoded_too_large(a) && !a.topics.empty()) a.topics.pop_back();
  processes_.store(static_cast<std::uint32_t>(a.processes.size()), std::memory_order_relaxed);
  topics_.store(static_cast<std::uint32_t>(a.topics.size()), std::memory_order_relaxed);
  current_ = std::move(a);
}

bool Agent::encoded_too_large(const Announcement& a) {
  std::size_t n = 256;
  for (const auto& t : a.topics) n += 96 + t.name.size() + t.type_name.size() + t.scope.size() + t.transport.size();
  for (const auto& t : a.types) n += 16 + t.signature.size();
  for (const auto& p : a.processes) n += 24 + p.name.size();
  return n > detail::kAnnouncementBytes - 4096;
}

void Agent::wake_announcer() {
  cv_.notify_all();
  if (const std::uint64_t id = job_.load(); id != 0 && engine_) engine_->wake_job(id);
}

}  // namespace horus::fleet::detail

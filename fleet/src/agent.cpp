// The fleet agent: one per process and network backend, alive while the process has a fleet
// topic (or a horus::Fleet) open on it. When its process holds the host's bridge of
// horus.fleet.heartbeat, it publishes the host's heartbeats and announcements; otherwise it
// only stands by, and takes over with the bridge. Its heartbeats leave from a thread of their
// own (the agent's executor: nothing else runs there, so they leave on time under load); its
// announcements are a job of the network engine's control thread (engine.hpp). Also: this
// host's identity, the fleet topics' options, and fleet::install() (the composition root's
// call: it gives api/ the fleet layer's bridges, horus/detail/network_link.hpp).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "fleet_internal.hpp"
#include "horus/config.hpp"
#include "bridge.hpp"
#include "engine.hpp"
#include "horus/detail/network_link.hpp"
#include "horus/discovery/registry.hpp"
#include "horus/environment.hpp"
#include "horus/executor.hpp"
#include "horus/fleet.hpp"
#include "horus/log.hpp"
#include "horus/shm/shm_segment.hpp"
#include "horus/topic.hpp"
#include "horus/wire/dynamic.hpp"

namespace horus::fleet {

namespace detail {

TopicOptions heartbeat_options(const std::string& transport) {
  TopicOptions o;
  o.backend = Backend::network(transport);
  o.capacity = 16;
  o.slot_size = kHeartbeatBytes;
  o.reliability = net::Reliability::BestEffort;
  o.priority = Priority::High;  // the link budget serves the fleet's liveliness first
  return o;
}

TopicOptions announce_options(const std::string& transport) {
  TopicOptions o;
  o.backend = Backend::network(transport);
  o.capacity = 4;
  o.slot_size = kAnnouncementBytes;
  o.reliability = net::Reliability::Reliable;
  o.priority = Priority::High;
  return o;
}

TopicOptions request_options(const std::string& transport) {
  TopicOptions o;
  o.backend = Backend::network(transport);
  o.capacity = 16;
  o.reliability = net::Reliability::Reliable;
  o.priority = Priority::High;
  return o;
}

std::uint64_t steady_ns() noexcept {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count());
}

std::int64_t unix_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string view_topic(const std::string& transport) { return "horus.fleet.view." + transport; }

TopicOptions view_options() {
  TopicOptions o;
  o.backend = Backend::SharedMemory;  // the host's processes only
  o.capacity = 2;
  o.slot_size = kViewBytes;
  return o;
}

void LinkStats::on_heartbeat(const Heartbeat& h, std::uint64_t self, std::uint64_t now_steady_ns,
                             std::int64_t now_unix_ns) {
  // Loss: the sequence numbers that arrived within the window (a restart starts it again).
  if (!got_.empty() && h.seq <= got_.back().seq) got_.clear();
  got_.push_back({h.seq, now_steady_ns});
  const auto window = static_cast<std::uint64_t>(std::chrono::nanoseconds(kLossWindow).count());
  std::size_t old = 0;
  while (old < got_.size() && now_steady_ns - got_[old].at_ns > window) ++old;
  got_.erase(got_.begin(), got_.begin() + static_cast<std::ptrdiff_t>(old));
  // Round trip and clock offset, from the echo of our own heartbeat.
  for (const auto& e : h.echoes) {
    if (e.host_id != self || e.sent_ns + e.held_ns > now_steady_ns) continue;
    const std::uint64_t rtt = now_steady_ns - e.sent_ns - e.held_ns;
    if (rtt >= 60'000'000'000ULL) continue;
    rtt_ns_ = static_cast<std::int64_t>(rtt);
    if (h.sent_unix_ns == 0) continue;  // a sender without a realtime stamp
    if (samples_.size() == kOffsetSamples) samples_.erase(samples_.begin());
    samples_.push_back({rtt_ns_, h.sent_unix_ns + rtt_ns_ / 2 - now_unix_ns});
    const auto best = std::min_element(samples_.begin(), samples_.end(),
                                       [](const Sample& a, const Sample& b) { return a.rtt_ns < b.rtt_ns; });
    offset_ns_ = best->offset_ns;
    uncertainty_ns_ = best->rtt_ns / 2;
  }
}

double LinkStats::loss() const noexcept {
  if (got_.size() < 10) return -1;
  const std::uint64_t expected = got_.back().seq - got_.front().seq + 1;
  return 1.0 - static_cast<double>(got_.size()) / static_cast<double>(expected);
}

}  // namespace detail

namespace {

std::string read_line(const char* path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

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

std::uint64_t fnv(std::uint64_t h, std::string_view s) noexcept {
  for (char c : s) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

// -- the agent --------------------------------------------------------------------------------

class Agent {
 public:
  explicit Agent(std::string transport) : transport_(std::move(transport)) {
    thread_ = std::thread([this] { run(); });
  }
  ~Agent() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    cv_.notify_all();
    executor_.stop();
    thread_.join();
  }
  Agent(const Agent&) = delete;
  Agent& operator=(const Agent&) = delete;

 private:
  void run() {
    auto settings = fleet_settings();
    if (!settings) {
      horus::detail::log().error("fleet: {}; this host is not announced", settings.error().message());
      return;
    }
    settings_ = *settings;
    if (!settings_.announce) return;  // fleet.announce: false
    // Open the topics; retry while they do not open (a transport busy closing, say).
    for (;;) {
      if (open_topics()) break;
      std::unique_lock lock(mutex_);
      if (cv_.wait_for(lock, std::chrono::seconds(1), [&] { return stopping_; })) return;
    }
    try {
      executor_.subscribe<Heartbeat>(kHeartbeatTopic, detail::heartbeat_options(transport_),
                                     [this](const Heartbeat& h) { on_heartbeat(h); });
      executor_.subscribe<Request>(kRequestTopic, detail::request_options(transport_),
                                   [this](const Request& r) { on_request(r); });
      executor_.every(settings_.heartbeat, [this] { tick(); });
    } catch (const Exception& e) {
      horus::detail::log().error("fleet: {}; this host is not announced", e.what());
      return;
    }
    tick();
    // The announcer: a job of this transport's engine (its topics are open: the engine exists).
    if (const auto* info = net::find_transport(transport_)) {
      if (auto engine = detail::Engine::of(*info)) {
        engine_ = std::move(*engine);
        job_.store(engine_->add_job([this](auto now) { return announcer_step(now); }));
      }
    }
    executor_.spin();
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    cv_.notify_all();
    if (engine_) engine_->remove_job(job_.load());
    heartbeat_.reset();
    announce_.reset();
    request_.reset();
  }

  bool open_topics() {
    auto hb = Topic<Heartbeat>::open(kHeartbeatTopic, detail::heartbeat_options(transport_));
    auto an = Topic<Announcement>::open(kAnnounceTopic, detail::announce_options(transport_));
    auto rq = Topic<Request>::open(kRequestTopic, detail::request_options(transport_));
    for (const Error* e : {hb ? nullptr : &hb.error(), an ? nullptr : &an.error(), rq ? nullptr : &rq.error()}) {
      if (e == nullptr) continue;
      if (!open_error_logged_) horus::detail::log().error("fleet: {}; retrying every second", e->message());
      open_error_logged_ = true;
      return false;
    }
    // Send-only handles: a non-holder may never send on them, and must never hold senders back.
    heartbeat_.emplace(std::move(*hb));
    announce_.emplace(std::move(*an));
    request_.emplace(std::move(*rq));
    if (auto view = Topic<FleetView>::open(detail::view_topic(transport_), detail::view_options()); view) {
      view_.emplace(std::move(*view));
      view_->publish_only();
    } else {
      horus::detail::log().warn("fleet: the fleet view of this host is not kept: {}", view.error().message());
    }
    heartbeat_->publish_only();
    announce_->publish_only();
    request_->publish_only();
    return true;
  }

  void on_heartbeat(const Heartbeat& h) {
    if (h.host_id == 0 || h.host_id == self_) return;
    if (h.host.empty() || h.host.size() > 255 || h.period_ms < kMinHeartbeatMs || h.period_ms > kMaxHeartbeatMs)
      return;  // horus::Fleet counts it as malformed
    const std::uint64_t now = detail::steady_ns();
    // The fleet view: every agent keeps it (it may come to speak for the host), the speaker
    // publishes it. At most kViewHosts (and fleet.max_hosts) hosts: a new one takes the place
    // of the host lost longest ago, or is not tracked (nor echoed) while all of them live.
    auto found = tracked_.find(h.host_id);
    if (found == tracked_.end()) {
      std::vector<std::uint64_t> forgotten;
      const std::size_t max = std::min<std::size_t>(detail::kViewHosts, settings_.max_hosts);
      const bool room = detail::make_room(tracked_, max, lost_since, &forgotten);
      for (const auto id : forgotten) heard_.erase(id);
      if (!room) return;
      found = tracked_.emplace(h.host_id, Tracked{}).first;
      found->second.view.host_id = h.host_id;
      found->second.view.first_seen_unix_ns = detail::unix_ns();
      view_dirty_ = true;
    }
    heard_[h.host_id] = {h.sent_ns, now};
    Tracked& t = found->second;
    const std::int64_t now_unix = host_clock_unix_ns();
    t.link.on_heartbeat(h, self_, now, now_unix);
    ViewedHost& v = t.view;
    if (v.host != h.host || v.period_ms != h.period_ms) view_dirty_ = true;
    v.host = h.host;
    v.period_ms = h.period_ms;
    ++v.heartbeats;
    v.last_seen_unix_ns = now_unix;
    t.last_ns = now;
    if (v.state == static_cast<std::uint32_t>(HostState::Lost)) {
      v.state = static_cast<std::uint32_t>(HostState::Rejoined);
      ++v.rejoins;
      v.lost_since_unix_ns = 0;
      view_dirty_ = true;
    }
    v.rtt_ns = t.link.rtt_ns();
    v.loss = t.link.loss();
    v.clock_offset_ns = t.link.offset_ns();
    v.clock_uncertainty_ns = t.link.uncertainty_ns();
  }

  // The executor's thread, every heartbeat period: hosts lost (as horus::Fleet judges them),
  // and, by the process that speaks for the host, the view: at once when a host joined, was
  // lost or rejoined, else once a second (ages, link figures).
  void keep_view(bool speaker) {
    const std::uint64_t now = detail::steady_ns();
    for (auto& [id, t] : tracked_) {
      ViewedHost& v = t.view;
      const std::uint64_t period = std::uint64_t{v.period_ms} * 1'000'000ULL;
      if (v.state != static_cast<std::uint32_t>(HostState::Lost) && now - t.last_ns > period * (settings_.misses + 1)) {
        v.state = static_cast<std::uint32_t>(HostState::Lost);
        v.lost_since_unix_ns = detail::unix_ns();
        view_dirty_ = true;
      }
    }
    std::vector<std::uint64_t> forgotten;
    detail::forget_lost(tracked_, settings_.forget_after, detail::unix_ns(), lost_since, &forgotten);
    for (const auto id : forgotten) heard_.erase(id);
    if (!forgotten.empty()) view_dirty_ = true;
    if (!speaker || !view_) return;
    if (!view_dirty_ && now - view_sent_ns_ < 1'000'000'000ULL) return;
    FleetView view;
    view.host_id = self_;
    view.version = ++view_version_;
    view.made_unix_ns = detail::unix_ns();
    view.hosts.reserve(tracked_.size());
    for (const auto& [id, t] : tracked_) view.hosts.push_back(t.view);
    view_->send(view);
    view_dirty_ = false;
    view_sent_ns_ = now;
  }

  void on_request(const Request& r) {
    if (r.want_host != 0 && r.want_host != self_) return;
    {
      std::lock_guard lock(mutex_);
      announce_due_ = std::min(announce_due_, std::chrono::steady_clock::now());
      asked_ = true;
    }
    wake_announcer();
  }

  // The executor's thread, every heartbeat period: only the heartbeat, so that it leaves on
  // time however long scanning the host's topics or sending an announcement takes (both on the
  // announcer's thread: with 150 topics under load a scan took up to 270 ms).
  void tick() {
    if (!heartbeat_ || !heartbeat_->is_bridge()) {
      holder_.store(false, std::memory_order_relaxed);
      keep_view(false);
      return;
    }
    if (!holder_.load(std::memory_order_relaxed)) {
      // This process now speaks for the host: announce, and ask every host to, so that this
      // host's processes learn the fleet at once.
      {
        std::lock_guard lock(mutex_);
        announce_due_ = std::chrono::steady_clock::now();
        asked_ = true;
        rescan_ = true;
      }
      holder_.store(true, std::memory_order_relaxed);
      wake_announcer();
      request_->send(Request{self_, 0});
    }
    Heartbeat hb;
    hb.host_id = self_;
    hb.host = name_;
    hb.seq = ++seq_;
    hb.sent_ns = detail::steady_ns();
    hb.sent_unix_ns = host_clock_unix_ns();
    hb.period_ms = static_cast<std::uint32_t>(settings_.heartbeat.count());
    hb.announce_version = sent_version_.load(std::memory_order_relaxed);
    hb.processes = processes_.load(std::memory_order_relaxed);
    hb.topics = topics_.load(std::memory_order_relaxed);
    const std::uint64_t keep_ns = 2'000'000'000ULL + 10 * hb.period_ms * 1'000'000ULL;
    for (auto it = heard_.begin(); it != heard_.end();) {
      const std::uint64_t held = hb.sent_ns - it->second.received_ns;
      if (held > keep_ns) {
        it = heard_.erase(it);
        continue;
      }
      if (hb.echoes.size() < 256) hb.echoes.push_back(HeartbeatEcho{it->first, it->second.sent_ns, held});
      ++it;
    }
    heartbeat_->send(hb);
    keep_view(true);
  }

  // The announcer (a job of the engine's control thread): scans the host's topics (every
  // announce period, at most 500 ms apart) and announces when due, on change, and when asked;
  // idle while another process speaks for the host. Returns when it is due next.
  std::chrono::steady_clock::time_point announcer_step(std::chrono::steady_clock::time_point now) {
    using Clock = std::chrono::steady_clock;
    std::unique_lock lock(mutex_);
    if (stopping_) return Clock::time_point::max();
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
      next_look_ = now + std::max<Clock::duration>(std::chrono::milliseconds(500), scan_cost_ * 100);
      if (!scanner_) scanner_ = std::make_unique<discovery::Scanner>(shm::shm_namespace().value_or(""));
      scan_now = scanner_->topics_changed() || scan_now;
    }
    if (scan_now) {
      lock.unlock();
      const auto t0 = Clock::now();
      scan();
      const auto cost = Clock::now() - t0;
      lock.lock();
      scan_cost_ = cost;
      next_scan_ = now + std::max<Clock::duration>(settings_.announce_period, cost * 2000);
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

  // Makes the announcer due now (a request, or this process now speaks for the host).
  void wake_announcer() {
    cv_.notify_all();
    if (const std::uint64_t id = job_.load(); id != 0 && engine_) engine_->wake_job(id);
  }

  // The host's processes and topics, from its shared-memory segments (the local registry).
  void scan() {
    const auto ns = shm::shm_namespace();
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

  static bool encoded_too_large(const Announcement& a) {
    std::size_t n = 256;
    for (const auto& t : a.topics) n += 96 + t.name.size() + t.type_name.size() + t.scope.size() + t.transport.size();
    for (const auto& t : a.types) n += 16 + t.signature.size();
    for (const auto& p : a.processes) n += 24 + p.name.size();
    return n > detail::kAnnouncementBytes - 4096;
  }

  struct Heard {
    std::uint64_t sent_ns;
    std::uint64_t received_ns;
  };
  struct Sample {
    std::uint64_t messages;
    std::chrono::steady_clock::time_point at;
  };

  const std::string transport_;
  const std::uint64_t self_ = host_id();
  const std::string name_ = host_name();
  FleetSettings settings_;
  Executor executor_;
  std::optional<Topic<Heartbeat>> heartbeat_;
  std::optional<Topic<Announcement>> announce_;
  std::optional<Topic<Request>> request_;
  std::map<std::uint64_t, Heard> heard_;
  struct Tracked {
    ViewedHost view;
    detail::LinkStats link;
    std::uint64_t last_ns = 0;  // its last heartbeat (steady clock)
  };
  std::map<std::uint64_t, Tracked> tracked_;  // the executor's thread's
  static std::int64_t lost_since(const Tracked& t) { return t.view.lost_since_unix_ns; }
  std::optional<Topic<FleetView>> view_;
  bool view_dirty_ = false;
  std::uint64_t view_version_ = 0;
  std::uint64_t view_sent_ns_ = 0;
  std::map<std::string, Sample> samples_;
  Announcement current_;                        // the announcer's
  std::atomic<std::uint64_t> sent_version_{0};  // the announcer writes, heartbeats carry it
  std::atomic<std::uint32_t> processes_{0}, topics_{0};
  std::uint64_t seq_ = 0;
  std::atomic<bool> holder_{false};  // tick() decides, the announcer follows
  bool open_error_logged_ = false;
  bool announce_error_logged_ = false;
  std::mutex mutex_;  // guards what follows
  std::condition_variable cv_;
  std::chrono::steady_clock::time_point announce_due_{};
  std::chrono::steady_clock::time_point next_scan_{}, next_look_{}, last_announce_{};
  std::unique_ptr<discovery::Scanner> scanner_;  // the announcer's: segments stay mapped between scans
  bool rescan_ = false;
  std::chrono::steady_clock::duration scan_cost_{};  // what the last scan took (it spaces the next ones)
  bool asked_ = false;  // a request (or this process now speaks for the host): announce even without news
  std::uint64_t traffic_ = 0, sent_traffic_ = 0;  // the topics' counts at the last scan and the last announcement
  bool stopping_ = false;
  std::shared_ptr<detail::Engine> engine_;  // runs the announcer (set by the agent's thread)
  std::atomic<std::uint64_t> job_{0};
  std::thread thread_;  // last: starts once everything above exists
};

// One agent per transport while something holds it.
std::shared_ptr<void> presence(std::string_view transport) {
  static std::mutex mutex;
  static std::map<std::string, std::weak_ptr<Agent>, std::less<>> agents;
  std::lock_guard lock(mutex);
  auto& slot = agents[std::string(transport)];
  if (auto a = slot.lock()) return a;
  auto a = std::make_shared<Agent>(std::string(transport));
  slot = a;
  return a;
}

}  // namespace

std::uint64_t host_id() {
  static const std::uint64_t id = [] {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    h = fnv(h, read_line("/proc/sys/kernel/random/boot_id"));
    h = fnv(h, "\n" + host_name() + "\n");
    struct stat st{};
    if (::stat("/dev/shm", &st) == 0)
      h = fnv(h, std::to_string(st.st_dev) + ':' + std::to_string(st.st_ino) + '\n');
    if (auto ns = shm::shm_namespace()) h = fnv(h, *ns);
    return h == 0 ? 1 : h;
  }();
  return id;
}

std::int64_t host_clock_unix_ns() noexcept {
  static const std::int64_t shift = [] {
    const std::string& ms = Environment::read().test_clock_offset_ms;
    return ms.empty() ? 0 : std::strtoll(ms.c_str(), nullptr, 10) * 1'000'000LL;
  }();
  return detail::unix_ns() + shift;
}

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

namespace detail {
Presence acquire_presence(const std::string& transport) { return presence(transport); }
}  // namespace detail

void install() { horus::detail::set_network_connector(&detail::Bridge::open); }

}  // namespace horus::fleet

// The fleet agent's thread (agent.hpp: the agent and its jobs), one agent per transport while
// something holds it (presence()); this host's identity, the fleet topics' options, and
// fleet::install() (the composition root's call: it gives api/ the fleet layer's bridges,
// horus/detail/network_link.hpp).
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

#include "agent.hpp"
#include "fleet_internal.hpp"
#include "horus/config.hpp"
#include "bridge.hpp"
#include "engine.hpp"
#include "horus/detail/network_link.hpp"
#include "horus/discovery/registry.hpp"
#include "horus/detail/process.hpp"
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

Agent::Agent(std::string transport, Settings settings)
    : transport_(std::move(transport)), started_with_(std::move(settings)) {
  thread_ = std::thread([this] { run(); });
}

Agent::~Agent() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  cv_.notify_all();
  executor_.stop();
  thread_.join();
}

void Agent::run() {
  auto settings = fleet_settings(started_with_);
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
    if (auto engine = detail::Engine::of(*info, started_with_)) {
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

bool Agent::open_topics() {
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

}  // namespace detail

namespace {

// One agent per transport while something holds it.
struct Agents {
  static constexpr horus::detail::PartSpec kPart{"fleet agents", horus::detail::PartLifetime::UntilExit,
                                                 "weak pointers: an agent ends with the last presence"};
  std::mutex mutex;
  std::map<std::string, std::weak_ptr<detail::Agent>, std::less<>> agents;
};

std::shared_ptr<void> presence(std::string_view transport, const Settings& settings) {
  auto& [mutex, agents] = horus::detail::Process::part<Agents>();
  std::lock_guard lock(mutex);
  auto& slot = agents[std::string(transport)];
  if (auto a = slot.lock()) return a;
  auto a = std::make_shared<detail::Agent>(std::string(transport), settings);
  slot = a;
  return a;
}

}  // namespace

std::uint64_t host_id() {
  static const std::uint64_t id = [] {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    h = detail::fnv(h, detail::read_line("/proc/sys/kernel/random/boot_id"));
    h = detail::fnv(h, "\n" + host_name() + "\n");
    struct stat st{};
    if (::stat("/dev/shm", &st) == 0)
      h = detail::fnv(h, std::to_string(st.st_dev) + ':' + std::to_string(st.st_ino) + '\n');
    if (auto ns = shm::shm_namespace()) h = detail::fnv(h, *ns);
    return h == 0 ? 1 : h;
  }();
  return id;
}

std::int64_t host_clock_unix_ns() noexcept {
  static const std::int64_t shift = [] {
    const std::string ms = horus::detail::Process::get().environment()->test_clock_offset_ms;
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
Presence acquire_presence(const std::string& transport, const Settings& settings) {
  return presence(transport, settings);
}
}  // namespace detail

void install() { horus::detail::set_network_connector(&detail::Bridge::open); }

}  // namespace horus::fleet

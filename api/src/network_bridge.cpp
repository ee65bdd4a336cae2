// The network bridge of a fleet topic (horus/detail/network_bridge.hpp): one per topic and
// process; the one whose process holds the segment's bridge claim has the transport's endpoint
// and moves messages between the host's ring and the network, the others watch the holder and
// take over when it goes.
//
// Holder. Export: a thread sleeps on the ring's doorbell with its own subscriber entry and
// sends every message the host's publishers wrote, at full rate, skipping its own import lane
// (a message never goes back to the network it came from). Import: the transport's thread
// decodes each sample into the bridge's lane. DDS does not deliver a participant's own samples
// back; LCM does, so an echo ledger (hashes of what we sent, for 2 s) drops them.
//
// Receiving. While no handle of the host reads the topic (its processes only publish), the
// holder tells the endpoint to stop receiving (Endpoint::set_receiving): LCM, which brings a
// process's own datagrams back, then costs the publishing host nothing for its own traffic. A
// handle that subscribes rings the ring's doorbell (Ring::add_subscriber), which wakes the
// bridge thread at once to resume; in the holding process the handle's open() resumes it itself.
//
// Takeover. Non-holders sleep on a pidfd of the holder (or 50 ms, for a holder that closes the
// topic without exiting) and claim the bridge when it is gone. The successor adopts the
// entry and the lane its predecessor recorded in the segment (the reaper leaves them), so it
// exports exactly what the predecessor had not read; a message the predecessor died exporting
// counts as dropped. Samples other hosts sent while no endpoint existed are not seen: they
// cannot be counted (no per-sample sequence on these wires).
#include "horus/detail/network_bridge.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <vector>

#include "horus/detail/fleet_presence.hpp"
#include "horus/detail/topic_core.hpp"
#include "horus/log.hpp"
#include "horus/shm/doorbell.hpp"
#include "horus/shm/seqlock_slot.hpp"

namespace horus::detail {

namespace {
using Clock = std::chrono::steady_clock;
constexpr auto kWatchPeriod = std::chrono::milliseconds(50);  // a non-holder looks at the claim
constexpr auto kMatchWait = std::chrono::seconds(1);          // a successor waits for the readers
constexpr auto kImportWait = std::chrono::milliseconds(100);  // a reliable import holds samples for room
constexpr auto kEchoTtl = std::chrono::seconds(2);            // how long our own sample may take to come back

std::atomic<int> g_network_pid{0};  // the process that created this process's transports

// A 64-bit hash of a sample's bytes (the echo ledger), four independent lanes of 8 bytes.
std::uint64_t body_hash(std::span<const std::byte> b) noexcept {
  constexpr std::uint64_t kMul = 0x9E37'79B9'7F4A'7C15ULL;
  std::uint64_t h[4] = {b.size(), 0x243F'6A88'85A3'08D3ULL, 0x1319'8A2E'0370'7344ULL, 0xA409'3822'299F'31D0ULL};
  std::size_t i = 0;
  const std::byte* p = b.data();
  for (; i + 32 <= b.size(); i += 32) {
    for (int k = 0; k < 4; ++k) {
      std::uint64_t w;
      std::memcpy(&w, p + i + 8 * k, 8);
      h[k] = (h[k] ^ w) * kMul;
      h[k] ^= h[k] >> 29;
    }
  }
  std::uint64_t tail = 0;
  for (int shift = 0; i < b.size(); ++i, shift = (shift + 8) & 63) {
    tail ^= static_cast<std::uint64_t>(std::to_integer<std::uint8_t>(p[i])) << shift;
    if (shift == 56) {
      h[0] = (h[0] ^ tail) * kMul;
      tail = 0;
    }
  }
  std::uint64_t r = (h[0] ^ tail) * kMul;
  for (int k = 1; k < 4; ++k) r = (r ^ h[k] ^ (h[k] >> 31)) * kMul;
  return r ^ (r >> 32);
}

// What this bridge sent on a transport that delivers it back (LCM): a sample that arrives with
// the hash of one we sent in the last 2 s is our own and is dropped once. Two identical samples
// from us and another host are indistinguishable: one of them is dropped, the count stays right.
class EchoLedger {
 public:
  void add(std::uint64_t h) {
    std::lock_guard lock(mutex_);
    expire(Clock::now());
    order_.emplace_back(Clock::now(), h);
    ++count_[h];
  }
  bool consume(std::uint64_t h) {
    std::lock_guard lock(mutex_);
    expire(Clock::now());
    auto it = count_.find(h);
    if (it == count_.end()) return false;
    if (--it->second == 0) count_.erase(it);
    return true;
  }

 private:
  void expire(Clock::time_point now) {
    while (!order_.empty() && now - order_.front().first > kEchoTtl) {
      if (auto it = count_.find(order_.front().second); it != count_.end() && --it->second == 0) count_.erase(it);
      order_.pop_front();
    }
  }
  std::mutex mutex_;
  std::deque<std::pair<Clock::time_point, std::uint64_t>> order_;
  std::unordered_map<std::uint64_t, std::uint32_t> count_;
};


int open_pidfd(pid_t pid) noexcept {
#ifdef SYS_pidfd_open
  return static_cast<int>(::syscall(SYS_pidfd_open, pid, 0));
#else
  (void)pid;
  return -1;
#endif
}
}  // namespace

// HORUS_BRIDGE: "0" keeps this process from ever bridging a fleet topic (it still uses them
// through shared memory; another process of the host bridges); "1" or unset: it may.
Result<bool> may_bridge_from_environment() {
  const char* v = std::getenv("HORUS_BRIDGE");
  if (v == nullptr || *v == '\0' || std::string_view(v) == "1") return true;
  if (std::string_view(v) == "0") return false;
  return fail(Errc::Config, fmt::format("HORUS_BRIDGE='{}' is not valid; expected 0 (this process never bridges "
                                        "fleet topics to the network) or 1 (it may; the default)",
                                        v));
}

class NetworkBridge;

// The import pump: one thread per process, running only while some bridge's transport holds
// samples back (a reliable topic whose host subscribers have no room). Every 200 us it lets
// each such bridge take what now fits (NetworkBridge::pump_held). Leaked on purpose: bridges
// may stop during static destruction.
class ImportPump {
 public:
  void add(NetworkBridge* b) {
    std::lock_guard lock(mutex_);
    if (std::find(held_.begin(), held_.end(), b) != held_.end()) return;
    held_.push_back(b);
    if (!thread_started_) {
      thread_started_ = true;
      std::thread([this] { run(); }).detach();
    }
    cv_.notify_all();
  }
  /// After this returns, the pump does not call `b` (it waits for a call in progress).
  void remove(NetworkBridge* b) {
    std::unique_lock lock(mutex_);
    std::erase(held_, b);
    done_.wait(lock, [&] { return current_ != b; });
  }

 private:
  void run();

  std::mutex mutex_;
  std::condition_variable cv_, done_;
  std::vector<NetworkBridge*> held_;
  NetworkBridge* current_ = nullptr;
  bool thread_started_ = false;
};

ImportPump& import_pump() {
  static auto* pump = new ImportPump;
  return *pump;
}

class NetworkBridge final : public net::Listener {
 public:
  NetworkBridge(TopicCore& core, const WireOps& ops, const net::Qos& qos, const net::TransportInfo& info)
      : core_(core), ops_(ops), qos_(qos), info_(info), format_(info.format), wake_fd_(::eventfd(0, EFD_CLOEXEC)) {}
  ~NetworkBridge() {
    if (wake_fd_ >= 0) ::close(wake_fd_);
  }

  TopicCore& core_;
  const WireOps& ops_;
  net::Qos qos_;
  const net::TransportInfo& info_;
  net::WireFormat format_;
  std::string wire_topic_;
  std::shared_ptr<net::Transport> transport_;  // this process's (every process has one: takeover is quick)
  std::unique_ptr<BridgePort> port_;           // the holder's lane and entry; outlives the endpoint
  std::unique_ptr<net::Endpoint> endpoint_;    // the holder's only; reset first: no callback after that
  bool holder_ = false;                        // the bridge thread's (and start()'s) view
  std::mutex receiving_mutex_;                 // update_receiving: the bridge thread, or an opening handle
  std::atomic<bool> receiving_{true};          // what the endpoint was told
  std::atomic<std::int64_t> paused_at_ns_{0};  // when it was told to stop receiving (steady clock)
  std::atomic<bool> endpoint_ready_{false};    // endpoint_ is set (user threads may ask it for counts)
  std::mutex endpoint_mutex_;                  // endpoint_ set or reset, against the import pump
  bool loopback_ = false;                      // the transport delivers our own samples back (LCM)
  EchoLedger ledger_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  int wake_fd_ = -1;
  std::atomic<std::uint64_t> decode_failures_{0};
  std::uint64_t write_retries_ = 0;  // reliable writes that waited for slow readers (bridge thread)
  std::atomic<std::uint64_t> errors_{0};  // incompatible endpoints reported
  std::uint64_t send_failures_ = 0;       // for the log's rate
  std::uint64_t export_lost_seen_ = 0;
  bool hold_ = false;                           // reliable, and the transport holds samples
  std::atomic<bool> held_{false};               // the transport holds samples back for room
  std::atomic<std::int64_t> held_since_ns_{0};  // since when (steady clock)
  std::atomic<bool> stalled_{false};            // a subscriber let kImportWait pass: overwrite
  std::atomic<std::uint64_t> import_stalls_{0}; // for the log's rate

  shm::ShmSegment& segment() const noexcept { return *core_.segment; }
  shm::BridgeState& state() const noexcept { return core_.segment->bridge(); }

  // --- the listener (the transport's threads) ---------------------------------
  void on_sample(const net::Sample& sample) override {
    if (loopback_ && ledger_.consume(body_hash(sample.body))) return;  // our own, back
    if (!port_->deliver(format_, sample)) return;
    state().imported.fetch_add(1, std::memory_order_relaxed);
    // The import wakes the host's handles, not the export thread (it skips these messages);
    // once they fill half the ring, wake it to pass over them, so that its cursor never falls
    // a ring behind (that would count as losses nobody had).
    if (import_lag() > core_.ring.capacity() / 2) core_.ring.wake_waiters(shm::Doorbell::kArmedBridge);
  }
  // Messages of the import lane the export thread has not passed over yet.
  std::uint64_t import_lag() const noexcept {
    const std::uint32_t lane = port_->lane();
    if (lane >= shm::kMaxPublishers || !port_->has_entry()) return 0;
    const std::uint64_t head = core_.ring.lane(lane).head.load(std::memory_order_acquire);
    const std::uint64_t seen = core_.ring.subscriber(port_->entry()).cursor[lane].load(std::memory_order_relaxed);
    return head > seen ? head - seen : 0;
  }
  // Reliable topics on a transport that holds samples (DDS): the transport takes no more than
  // the host's subscribers have room for, and the rest waits in its reader, whose flow control
  // slows the sending host, instead of overwriting. The transport's thread never blocks (it
  // serves every topic and the fleet's heartbeats): the import pump takes the held samples
  // when room appears. A subscriber that leaves the lane full for kImportWait is stuck
  // (stopped, in a debugger): then its oldest messages are overwritten (counted in its
  // dropped_count) until it reads again.
  std::size_t room() override {
    if (!hold_) return SIZE_MAX;
    const std::size_t r = port_->import_room();
    if (r > 0) {  // the subscribers read: not stuck
      stalled_.store(false, std::memory_order_relaxed);
      held_since_ns_.store(0, std::memory_order_relaxed);
      return r;
    }
    if (stalled_.load(std::memory_order_relaxed)) return SIZE_MAX;
    if (held_since_ns_.load(std::memory_order_relaxed) == 0)
      held_since_ns_.store(Clock::now().time_since_epoch().count(), std::memory_order_relaxed);
    if (!held_.exchange(true, std::memory_order_acq_rel)) import_pump().add(this);
    return 0;
  }

  // Whether the transport holds samples back (set by room(), cleared by pump_held()).
  bool holding() const noexcept { return held_.load(std::memory_order_acquire); }

  // The import pump's thread: takes what the transport held once there is room (room() above
  // decides); false when nothing is held any more.
  bool pump_held() noexcept {
    const std::int64_t since_ns = held_since_ns_.load(std::memory_order_relaxed);
    const auto since = Clock::time_point(Clock::duration(since_ns));
    if (since_ns != 0 && Clock::now() - since > kImportWait && !stalled_.exchange(true, std::memory_order_relaxed)) {
      const std::uint64_t n = ++import_stalls_;
      if (n == 1 || n % 64 == 0)
        log().warn("topic '{}': a subscriber on this host has not read for {} ms; the bridge stops holding the {} "
                   "samples back for it and overwrites its oldest messages (counted in its dropped_count()) until it "
                   "reads again ({} time(s) so far)",
                   core_.name, std::chrono::duration_cast<std::chrono::milliseconds>(kImportWait).count(),
                   info_.name, n);
    }
    std::lock_guard lock(endpoint_mutex_);
    if (!endpoint_) return true;  // not open yet: try again
    held_.store(false, std::memory_order_release);  // room() sets it again if it must hold on
    endpoint_->take_held();
    return held_.load(std::memory_order_acquire);
  }

  void on_lost(std::uint64_t count) override {
    const auto before = state().dropped.fetch_add(count, std::memory_order_relaxed);
    // Log the first loss, then at most once per 1024 more (the count is in dropped_count()).
    if (before == 0 || before / 1024 != (before + count) / 1024)
      log().warn("topic '{}': the {} backend lost {} message(s) or datagram(s) ({} so far on this host; they "
                 "count in dropped_count())",
                 core_.name, info_.name, count, before + count);
  }
  void on_error(std::string_view message) override {
    const auto n = errors_.fetch_add(1, std::memory_order_relaxed) + 1;
    if (n <= 16 || n % 1024 == 0) log().error("{} [{}]", message, info_.name);
  }

  // --- becoming the holder ------------------------------------------------------
  Result<void> become_holder(bool takeover) {
    if (!port_) port_ = ops_.make_port(core_);
    const std::uint32_t readers_before = state().matched_subscribers.load(std::memory_order_relaxed);
    bool inherited = false;
    segment().inherit_bridge([&](shm::ShmSegment::Inheritance& in) {
      if (in.export_entry && port_->take_entry(*in.export_entry, in.export_token)) {
        in.export_entry.reset();
        inherited = true;
      }
      if (in.import_lane && port_->take_lane(*in.import_lane, in.import_token)) in.import_lane.reset();
      // It had read a message and died before the transport took it: maybe sent, never twice.
      if (in.inflight != 0) state().dropped.fetch_add(1, std::memory_order_relaxed);
    });
    if (!port_->has_entry() && !port_->take_entry(0, 0))
      return fail(Errc::LimitReached, fmt::format("topic '{}': its bridge found no free subscriber entry (all {} "
                                                  "in use); nothing of this host reaches the fleet",
                                                  core_.name, shm::kMaxSubscribers));
    if (!port_->has_lane() && !port_->take_lane(0, 0))
      return fail(Errc::LimitReached, fmt::format("topic '{}': its bridge found no free publisher lane (all {} "
                                                  "in use); nothing of the fleet reaches this host",
                                                  core_.name, shm::kMaxPublishers));
    segment().record_bridge_export(port_->entry(), port_->entry_token());
    segment().record_bridge_import(port_->lane(), port_->lane_token());
    export_lost_seen_ = port_->export_lost();
    net::EndpointSpec spec;
    spec.topic = core_.name;
    spec.wire_topic = wire_topic_;
    spec.type_name = core_.type_name;
    spec.type_hash = core_.type_hash;
    spec.qos = qos_;
    spec.max_message_bytes = core_.pool ? core_.pool.slot_bytes() : core_.ring.header().payload_size;
    receiving_.store(host_subscribers() != 0, std::memory_order_relaxed);
    spec.receive = receiving_.load(std::memory_order_relaxed);
    auto endpoint = transport_->open(spec, *this);
    if (!endpoint) {
      port_->leave();  // recorded: the next holder adopts them
      return std::unexpected(std::move(endpoint.error()));
    }
    {
      std::lock_guard lock(endpoint_mutex_);
      endpoint_ = std::move(*endpoint);
    }
    holder_ = true;
    endpoint_ready_.store(true, std::memory_order_release);
    if (takeover || inherited) {
      // The readers that matched the predecessor's writer must match ours before the backlog
      // goes out, or a volatile reader would miss it (bounded: a reader may have left).
      const auto until = Clock::now() + kMatchWait;
      while (!stop_.load() && readers_before != 0 && endpoint_->matched_subscribers() < readers_before &&
             Clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    publish_matches();
    return {};
  }

  // The host's subscribing handles, the holder's own entry left out.
  std::uint32_t host_subscribers() const noexcept {
    const std::uint32_t n = core_.ring.subscriber_count();
    return n - (n != 0 && port_ && port_->has_entry() ? 1u : 0u);
  }

  // Stops or resumes receiving as the host's subscribers come and go: the bridge thread, and a
  // handle of the holding process that subscribes (its open() returns once the bridge receives;
  // a handle of another process rings the bridge thread awake, which resumes at once).
  void update_receiving() noexcept {
    std::lock_guard lock(receiving_mutex_);
    if (!endpoint_ready_.load(std::memory_order_acquire)) return;
    const bool want = host_subscribers() != 0;
    if (want == receiving_.load(std::memory_order_relaxed)) return;
    receiving_.store(want, std::memory_order_relaxed);
    if (!want) paused_at_ns_.store(Clock::now().time_since_epoch().count(), std::memory_order_relaxed);
    endpoint_->set_receiving(want);
  }

  // Sleeps until the host's publishers wrote a message to export, a subscriber appeared on a
  // topic that does not receive, or `deadline`.
  void wait_for_work(Clock::time_point deadline) noexcept {
    // As a bridge (doorbell.hpp): what the import writes does not wake this thread.
    const shm::WaitItem item{&core_.ring.doorbell(), &core_.ring.subscriber(port_->entry()).waiting,
                             [](const void* c) noexcept {
                               const auto& b = *static_cast<const NetworkBridge*>(c);
                               return b.core_.ring.has_unread_except(b.port_->entry(), b.port_->entry_token(),
                                                                     b.port_->lane()) ||
                                      b.import_lag() > b.core_.ring.capacity() / 2 ||
                                      (!b.receiving_.load(std::memory_order_relaxed) && b.host_subscribers() != 0);
                             },
                             this, shm::Doorbell::kArmedBridge};
    shm::wait_any({&item, 1}, deadline);
  }

  void publish_matches() noexcept {
    if (!endpoint_) return;
    try {
      state().matched_publishers.store(endpoint_->matched_publishers(), std::memory_order_relaxed);
      state().matched_subscribers.store(endpoint_->matched_subscribers(), std::memory_order_relaxed);
    } catch (...) {
    }
  }

  // --- exporting --------------------------------------------------------------
  bool send(const void* msg) {
    auto report = [&](const Error& error) {
      state().dropped.fetch_add(1, std::memory_order_relaxed);
      if (++send_failures_ == 1 || send_failures_ % 1024 == 0)
        log().error("topic '{}': the {} backend did not send a {} sample: {} ({} so far; counted in "
                    "dropped_count())",
                    core_.name, info_.name, core_.type_name, error.message(), send_failures_);
      return true;  // go on with the next message
    };
    auto n = ops_.encoded_size(format_, msg);
    if (!n) return report(n.error());
    struct Context {
      NetworkBridge* self;
      const void* msg;
      bool echo;  // our sample may come back: note it in the ledger
    } ctx{this, msg,
          loopback_ && (receiving_.load(std::memory_order_relaxed) ||
                        Clock::now().time_since_epoch().count() - paused_at_ns_.load(std::memory_order_relaxed) <
                            std::chrono::duration_cast<Clock::duration>(kEchoTtl).count())};
    const net::BodyWriter writer{[](void* c, std::span<std::byte> body) {
                                   const auto& x = *static_cast<const Context*>(c);
                                   x.self->ops_.encode(x.self->format_, x.msg, body);
                                   if (x.echo) x.self->ledger_.add(body_hash(body));
                                 },
                                 &ctx};
    state().inflight.store(1, std::memory_order_relaxed);
    auto ok = endpoint_->write(*n, writer);
    // Reliable: a writer that timed out waiting for its readers to catch up keeps the message
    // and tries again (back-pressure, not a loss), until the topic closes.
    while (!ok && ok.error().code() == Errc::Timeout && qos_.reliability == net::Reliability::Reliable &&
           !stop_.load(std::memory_order_relaxed)) {
      ++write_retries_;
      ok = endpoint_->write(*n, writer);
    }
    state().inflight.store(0, std::memory_order_relaxed);
    if (!ok) [[unlikely]]
      return report(ok.error());
    state().exported.fetch_add(1, std::memory_order_relaxed);
    return true;
  }

  void export_pending() {
    const ExportSink sink{this, [](void* c, const void* msg) { return static_cast<NetworkBridge*>(c)->send(msg); }};
    while (port_->export_pending(port_->lane(), sink) != 0) {
    }
    if (const std::uint64_t lost = port_->export_lost(); lost > export_lost_seen_) {
      state().dropped.fetch_add(lost - export_lost_seen_, std::memory_order_relaxed);
      export_lost_seen_ = lost;
    }
  }

  // --- the bridge thread -----------------------------------------------------------
  // Sleeps until the holder may have gone: its pidfd readable (it exited), a wake-up (stop),
  // or kWatchPeriod (a holder that closed the topic and lives on).
  void watch(pid_t& watched, int& pidfd, bool backing_off) {
    const pid_t holder = segment().bridge_holder();
    if (holder != watched) {
      if (pidfd >= 0) ::close(pidfd);
      pidfd = holder > 0 ? open_pidfd(holder) : -1;
      watched = holder;
    }
    if (holder == 0 && !backing_off) return;  // nobody: claim at once
    pollfd fds[2] = {{wake_fd_, POLLIN, 0}, {pidfd, POLLIN, 0}};
    ::poll(fds, pidfd >= 0 ? 2 : 1, static_cast<int>(kWatchPeriod.count()));
  }

  void run() {
    pid_t watched = 0;
    int pidfd = -1;
    auto next_match = Clock::now();
    auto retry_at = Clock::time_point{};
    while (!stop_.load(std::memory_order_acquire)) {
      if (!holder_) {
        const bool backing_off = Clock::now() < retry_at;
        const auto claim = backing_off ? shm::ShmSegment::BridgeClaim::Held : segment().claim_bridge();
        if (claim == shm::ShmSegment::BridgeClaim::Held) {
          watch(watched, pidfd, backing_off);
          continue;
        }
        const bool takeover = claim == shm::ShmSegment::BridgeClaim::TookOver;
        if (auto ok = become_holder(takeover); !ok) {
          log().error("topic '{}': this process could not take over the host's bridge to {}: {}; retrying in 1 s",
                      core_.name, info_.name, ok.error().message());
          segment().release_bridge();
          retry_at = Clock::now() + std::chrono::seconds(1);
          continue;
        }
        log().info("topic '{}': this process (pid {}) now bridges the host to {}{}", core_.name, ::getpid(),
                   info_.name, takeover ? " (it took over from a process that is gone)" : "");
      }
      export_pending();
      update_receiving();
      const auto now = Clock::now();
      if (now >= next_match) {
        publish_matches();
        next_match = now + kWatchPeriod;
      }
      wait_for_work(now + kWatchPeriod);
    }
    if (holder_) export_pending();  // what the host's publishers sent before the topic closed
    if (pidfd >= 0) ::close(pidfd);
    done_.store(true, std::memory_order_release);
  }

  Result<void> start() {
    auto may = may_bridge_from_environment();
    if (!may) return std::unexpected(std::move(may.error()));
    if (!*may) return {};  // HORUS_BRIDGE=0: no transport, no thread; shared memory only
    auto transport = info_.open();  // the transport reads its own settings (HORUS_DOMAIN_ID, HORUS_LCM_URL)
    if (!transport) return std::unexpected(std::move(transport.error()));
    transport_ = std::move(*transport);
    loopback_ = transport_->delivers_own_samples();
    hold_ = qos_.reliability == net::Reliability::Reliable && transport_->holds_samples();
    const auto claim = segment().claim_bridge();
    if (claim == shm::ShmSegment::BridgeClaim::Claimed || claim == shm::ShmSegment::BridgeClaim::TookOver) {
      if (auto ok = become_holder(claim == shm::ShmSegment::BridgeClaim::TookOver); !ok) {
        segment().release_bridge();
        return ok;
      }
    }
    thread_ = std::thread([this] { run(); });
    return {};
  }

  void stop() noexcept {
    stop_.store(true, std::memory_order_release);
    if (wake_fd_ >= 0) {
      const std::uint64_t one = 1;
      (void)!::write(wake_fd_, &one, sizeof(one));
    }
    if (thread_.joinable()) {
      // The thread may sleep on the doorbell: ring it (a spurious wake-up for other waiters).
      while (true) {
        core_.ring.wake_waiters();
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        if (done_.load(std::memory_order_acquire)) break;
      }
      thread_.join();
    }
    {
      std::lock_guard receiving(receiving_mutex_);  // no opening handle is inside update_receiving()
      std::lock_guard lock(endpoint_mutex_);        // the import pump is not inside take_held()
      endpoint_ready_.store(false, std::memory_order_release);
      endpoint_.reset();  // no callback after this
    }
    import_pump().remove(this);
    if (holder_) {
      state().matched_publishers.store(0, std::memory_order_relaxed);
      state().matched_subscribers.store(0, std::memory_order_relaxed);
      port_->leave();  // recorded in the segment: the next holder adopts them
      segment().release_bridge();
    }
    port_.reset();
  }
  std::atomic<bool> done_{false};
};

void ImportPump::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    cv_.wait(lock, [&] { return !held_.empty(); });
    const std::vector<NetworkBridge*> now = held_;
    for (NetworkBridge* b : now) {
      if (std::find(held_.begin(), held_.end(), b) == held_.end()) continue;  // removed meanwhile
      current_ = b;
      lock.unlock();
      const bool still = b->pump_held();
      lock.lock();
      current_ = nullptr;
      done_.notify_all();
      // Nothing held when it returned; but a transport thread that held a sample since then
      // found b still listed and did not add it again: keep it for the next pass.
      if (!still && !b->holding()) std::erase(held_, b);
    }
    lock.unlock();
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    lock.lock();
  }
}

void NetworkBridgeDeleter::operator()(NetworkBridge* b) const noexcept {
  if (b == nullptr) return;
  if (b->core_.pid != current_pid()) {
    // A forked child's copy: the bridge's thread and the participant's threads live in the
    // parent only. Deleting the endpoint here would hang or tell peers the parent's are gone.
    return;
  }
  b->stop();
  delete b;
}

Result<void> connect_network(TopicCore& core, const WireOps& ops, const net::Qos& qos, const TopicOptions& options) {
  const auto* info = net::find_transport(core.backend.transport());
  if (info == nullptr)
    return fail(Errc::Config,
                fmt::format("topic '{}': this build of horus has no {} backend", core.name, to_string(core.backend)));
  if (!ops.expressible(info->format))
    return fail(Errc::Config, "topic '" + core.name + "': " + core.type_name +
                                  " cannot travel over LCM: it has a variable-size array of variable-size arrays "
                                  "or an array of size 0, which LCM types cannot express (horus/wire/"
                                  "lcm_mapping.hpp); use another backend for it");
  std::lock_guard lock(core.net_mutex);
  if (core.net) {
    // The topic's bridge exists: a handle asking for another QoS is an error, not ignored.
    const net::Qos have = core.net->qos_;
    if ((options.reliability && *options.reliability != have.reliability) ||
        (options.durability && *options.durability != have.durability))
      return fail(Errc::ConfigMismatch,
                  "topic '" + core.name + "' is open in this process as " +
                      std::string(net::to_string(have.reliability)) + ", " +
                      std::string(net::to_string(have.durability)) +
                      "; cannot open it with another reliability or durability (open it with the same, or "
                      "without either to accept them)");
    core.net->update_receiving();  // this handle subscribed: a paused bridge of this process resumes now
    return {};
  }
  if (const int owner = g_network_pid.load(); owner != 0 && owner != current_pid())
    return fail(Errc::Io, fmt::format("topic '{}': this process was forked from pid {} after that process used {}; "
                                      "network transports (DDS participants, LCM instances) do not survive fork() "
                                      "(their threads stay in the parent). Open network topics before forking only "
                                      "in the process that keeps them, or exec the child",
                                      core.name, owner, to_string(core.backend)));
  auto wire = info->wire_name(core.name);
  if (!wire) return std::unexpected(std::move(wire.error()));
  std::unique_ptr<NetworkBridge, NetworkBridgeDeleter> bridge(new NetworkBridge(core, ops, qos, *info));
  bridge->wire_topic_ = std::move(*wire);
  // The bridge is the topic's before its endpoint exists: samples may arrive (on the
  // transport's threads) as soon as it does. User threads see core.net after this returns.
  auto& b = *bridge;
  core.net = std::move(bridge);
  if (auto ok = b.start(); !ok) {
    core.net.reset();
    return ok;
  }
  g_network_pid.store(current_pid());
  // Only a process that may bridge announces the host (the agent publishes through the bridge).
  if (b.transport_ && !core.name.starts_with(kFleetTopicPrefix)) core.fleet_presence = acquire_fleet_presence(info->name);
  return {};
}

namespace {
std::atomic<FleetPresenceHook> g_fleet_hook{nullptr};
}  // namespace

void set_fleet_presence_hook(FleetPresenceHook hook) noexcept { g_fleet_hook.store(hook); }

FleetPresence acquire_fleet_presence(std::string_view transport) {
  const FleetPresenceHook hook = g_fleet_hook.load();
  return hook == nullptr ? nullptr : hook(transport);
}

std::uint64_t network_dropped(const TopicCore& core) noexcept {
  return core.segment && core.net ? core.segment->bridge().dropped.load(std::memory_order_relaxed) : 0;
}

namespace {
// Remote writers (readers) the host's bridge matched: asked of the endpoint in the holding
// process, read from the segment (published every 50 ms) in the others.
std::uint32_t matched(const TopicCore& core, bool writers) noexcept {
  const NetworkBridge& b = *core.net;
  if (b.endpoint_ready_.load(std::memory_order_acquire)) {
    try {
      return writers ? b.endpoint_->matched_publishers() : b.endpoint_->matched_subscribers();
    } catch (...) {
    }
  }
  const auto& s = core.segment->bridge();
  return (writers ? s.matched_publishers : s.matched_subscribers).load(std::memory_order_relaxed);
}
}  // namespace

std::uint32_t network_publishers(const TopicCore& core) noexcept {
  const std::uint32_t lanes = core.ring.publisher_count();
  if (!core.segment || !core.net) return lanes;
  const auto& b = core.segment->bridge();
  const std::uint32_t bridge_lane = b.import_token.load(std::memory_order_relaxed) != 0 && lanes != 0 ? 1 : 0;
  return lanes - bridge_lane + matched(core, true);
}

std::uint32_t network_subscribers(const TopicCore& core) noexcept {
  const std::uint32_t entries = core.ring.subscriber_count();
  if (!core.segment || !core.net) return entries;
  const auto& b = core.segment->bridge();
  const std::uint32_t bridge_entry = b.export_token.load(std::memory_order_relaxed) != 0 && entries != 0 ? 1 : 0;
  return entries - bridge_entry + matched(core, false);
}

std::uint32_t network_waiters(const TopicCore& core) noexcept {
  const std::uint32_t all = core.ring.doorbell().waiters();
  if (!core.segment || !core.net) return all;
  const auto& b = core.segment->bridge();
  const std::uint64_t token = b.export_token.load(std::memory_order_relaxed);
  const std::uint32_t entry = b.export_entry.load(std::memory_order_relaxed);
  if (token == 0 || entry >= shm::kMaxSubscribers) return all;
  // Every waiter of the ring registers in the doorbell and in its subscriber entry's share
  // (waitset.cpp), one after the other: the bridge's export thread, woken by the same message
  // as the caller's, may be between the two. Counting the shares of the other entries leaves
  // the bridge out without that race.
  std::uint32_t n = 0;
  const std::uint32_t hwm = core.ring.header().sub_hwm.load(std::memory_order_acquire);
  for (std::uint32_t i = 0; i < std::min(hwm, shm::kMaxSubscribers); ++i) {
    const auto& e = core.ring.subscriber(i);
    if (i == entry && e.owner.load(std::memory_order_relaxed) == token) continue;
    n += e.waiting.count.load(std::memory_order_relaxed);
  }
  return n;
}

bool network_holds_bridge(const TopicCore& core) noexcept {
  if (!core.segment || !core.net) return false;
  return static_cast<int>(core.segment->bridge().owner.load(std::memory_order_acquire) >> 32) == current_pid();
}

std::uint64_t network_errors(const TopicCore& core) noexcept {
  return core.net ? core.net->errors_.load(std::memory_order_relaxed) : 0;
}
std::uint64_t network_decode_failures(const TopicCore& core) noexcept {
  return core.net ? core.net->decode_failures_.load(std::memory_order_relaxed) : 0;
}

void report_network_decode_failure(TopicCore& core, const std::string& what) {
  const auto n = core.net->decode_failures_.fetch_add(1, std::memory_order_relaxed) + 1;
  // Host-wide too, in the segment: any process (horus topic info, horus::Fleet) can see it.
  if (core.segment) core.segment->bridge().malformed.fetch_add(1, std::memory_order_relaxed);
  if (n == 1 || n % 1024 == 0)
    log().error("topic '{}': a {} sample from the network does not decode as {} ({}); dropped ({} so far)",
                core.name, core.type_name, core.net->format_ == net::WireFormat::Lcm ? "an LCM message" : "XCDR1",
                what, n);
}

}  // namespace horus::detail

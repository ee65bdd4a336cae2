// The bridge of one fleet topic in one process (api/'s NetworkLink): no thread of its own, it is
// served by the process's network engine (engine.hpp).
//
// Holder (the process holding the segment's bridge claim). Export: the host's publishers'
// messages, read through a subscriber entry of its own (skipping its import lane: a message
// never goes back to the network it came from). In this process the publishing thread exports
// inline, right after its send (export_inline: no thread is woken); messages of the host's other
// processes wake the engine (the ring's doorbell forwards to it), whose export thread exports
// them (service). One exporter at a time (export_busy_), and the one that stops looks again, so
// every message goes out exactly once and in each publisher's order. Import: the transport's
// thread decodes each sample into the bridge's lane. DDS does not deliver a participant's own
// samples back; LCM does, so an echo ledger (hashes of what we sent, for 2 s) drops them.
//
// Receiving. While no handle of the host reads the topic, the holder tells the endpoint to stop
// receiving (Endpoint::set_receiving); a subscribing handle rings the doorbell, which wakes the
// engine to resume at once; in this process the handle's open() resumes it itself.
//
// The hand-over. The bridge follows the host's publisher: a process that publishes on the topic
// asks the holder, which does not, for the bridge, so that its sends export inline (no wake-up
// of another process between a send and the network). The asker opens its endpoint first and
// waits until it matched what the holder's did; the holder then exports what the ring holds,
// closes its endpoint, records its entry and lane and hands the claim word over (no other
// process can claim in between); the asker adopts them. Only while the topic's import is quiet
// (200 ms without a sample from the network): a sample the holder no longer takes and the asker
// does not take yet is counted as dropped, and there is none when nothing comes.
//
// Takeover. Watchers (every other process with the topic open) let their engine's control
// thread watch the holder: a pidfd per holder process, and the host's count of claims given up
// (a holder that closes the topic and lives on; engine_board.hpp). The successor adopts the entry and the lane its
// predecessor recorded in the segment (the reaper leaves them), so it exports exactly what the
// predecessor had not read; a message the predecessor died exporting counts as dropped. Until the
// remote readers that matched the predecessor match the successor (at most 1 s), its export
// waits (the gate), so a volatile reader does not miss the backlog.
#pragma once

#include <sys/types.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <span>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine.hpp"
#include "fleet_internal.hpp"
#include "horus/detail/network_link.hpp"
#include "horus/detail/topic_core.hpp"
#include "horus/settings.hpp"
#include "ros2_graph.hpp"
#include "ros2_wire.hpp"

namespace horus::fleet::detail {

// What this bridge sent on a transport that delivers it back (LCM): a sample that arrives with
// the hash of one we sent in the last 2 s is our own and is dropped once. Two identical samples
// from us and another host are indistinguishable: one of them is dropped, the count stays right.
class EchoLedger {
 public:
  void add(std::uint64_t h);
  bool consume(std::uint64_t h);

 private:
  void expire(Clock::time_point now);
  std::mutex mutex_;
  std::deque<std::pair<Clock::time_point, std::uint64_t>> order_;
  std::unordered_map<std::uint64_t, std::uint32_t> count_;
};

// The host's link budget (network.max_bandwidth): how far ahead of now the link may be booked
// for a Normal topic to go, and for a Low one (High always goes).
inline constexpr std::chrono::milliseconds kLinkTolerance{50};
inline constexpr std::chrono::milliseconds kLinkLowTolerance{10};

/// A successor (after a takeover) waits this long at most for the remote readers to match.
inline constexpr auto kMatchWait = std::chrono::seconds(1);
/// Once our writer matched the remote readers, how long they may still take to match it: a DDS
/// reader drops what comes from a writer it has not matched yet (a best-effort one never gets it
/// again; a volatile reliable one starts after it), and no reader says when it matched. 3x the
/// time our side took to match (how long discovery takes on this machine now), at least
/// kDiscoverySettle, at most kDiscoverySettleMax. The asker of a hand-over waits it before it
/// asks; a successor after a takeover before the backlog goes out.
inline constexpr auto kDiscoverySettle = std::chrono::milliseconds(300);
inline constexpr auto kDiscoverySettleMax = std::chrono::seconds(3);
inline Clock::duration discovery_settle(Clock::duration our_match) noexcept {
  return std::clamp<Clock::duration>(3 * our_match, kDiscoverySettle, kDiscoverySettleMax);
}
/// A successor after a takeover waits at least this long instead: its participant knew the remote
/// readers already, so its own match takes no time and says nothing of theirs. On a loaded machine
/// (CI: two cores, four multi-host tests and two sanitizer builds at once) a remote Fast DDS reader
/// once matched the successor's writer more than 300 ms after ours matched it, and missed the first
/// message of the backlog, which nobody could count. The backlog waits in the ring (a loss there,
/// if the ring fills, is counted).
inline constexpr auto kTakeoverSettle = std::chrono::seconds(1);
/// A 64-bit hash of a sample's bytes (the echo ledger; bridge.cpp).
std::uint64_t body_hash(std::span<const std::byte> b) noexcept;
/// The steady clock in ns (the bridge's timestamps).
inline std::int64_t now_ns() noexcept { return Clock::now().time_since_epoch().count(); }

class Bridge final : public horus::detail::NetworkLink, public net::Listener, public Served {
 public:
  static Result<std::unique_ptr<horus::detail::NetworkLink>> open(horus::detail::TopicCore& core,
                                                                   const horus::detail::WireOps& ops,
                                                                   const net::Qos& qos,
                                                                   const TopicOptions& options,
                                                                   const Settings& settings);
  ~Bridge() override;

  // -- NetworkLink (user threads) ------------------------------------------------
  Result<void> join(const TopicOptions& options) override;
  std::uint64_t dropped() const noexcept override;
  std::uint32_t remote_publishers() const noexcept override { return remote(true); }
  std::uint32_t remote_subscribers() const noexcept override { return remote(false); }
  std::uint64_t errors() const noexcept override { return errors_.load(std::memory_order_relaxed); }
  void on_publisher() noexcept override;

  // -- net::Listener (the transport's threads) --------------------------------------
  void on_sample(const net::Sample& sample) override;
  std::size_t room() override;
  void on_lost(std::uint64_t count) override;
  void on_error(std::string_view message) override;
  void on_matched() override;

  // -- the engine (engine.hpp's Served) ------------------------------------------------
  void service() noexcept override;
  bool pump_held() noexcept override;
  bool holding() const noexcept override { return held_.load(std::memory_order_acquire); }
  Clock::time_point control(Clock::time_point now, bool gone) noexcept override;
  pid_t watched_pid() const noexcept override;
  bool is_holder() const noexcept override { return holder_.load(std::memory_order_acquire); }
  const std::string& name() const noexcept { return core_.name; }

 private:
  Bridge(horus::detail::TopicCore& core, const horus::detail::WireOps& ops, const net::Qos& qos,
         std::shared_ptr<Engine> engine, std::shared_ptr<net::Transport> transport);
  shm::ShmSegment& segment() const noexcept { return *core_.segment; }
  shm::BridgeState& state() const noexcept { return core_.segment->bridge(); }

  Result<void> become_holder(bool takeover);
  void attach() noexcept;  // holder and endpoint open: the doorbell forwards to the engine
  void leave() noexcept;   // stop: final export, give the claim, lane and entry up
  std::uint64_t import_lag() const noexcept;
  std::uint32_t host_subscribers() const noexcept;
  void update_receiving() noexcept;
  void publish_matches() noexcept;
  std::uint32_t remote(bool writers) const noexcept;  // remote writers (true) or readers matched

  // The hand-over: the bridge follows the host's publisher (bridge.cpp, "the hand-over").
  enum class Ask { Idle, Matching, Asked };
  Clock::time_point handover_step(Clock::time_point now, std::uint64_t owner) noexcept;  // a publishing watcher
  Clock::time_point ask_if_quiet(Clock::time_point now, std::uint64_t owner, bool holder_alive,
                                 std::uint64_t mine) noexcept;
  Clock::time_point ask_once_matched(Clock::time_point now, std::uint64_t owner, bool holder_alive,
                                     std::uint64_t mine) noexcept;
  Clock::time_point wait_for_answer(Clock::time_point now, std::uint64_t owner, bool holder_alive,
                                    std::uint64_t mine) noexcept;
  void cancel_ask(bool refused) noexcept;
  Clock::time_point hand_over(Clock::time_point now) noexcept;  // the holder, asked (control thread)
  void finish_hand_over() noexcept;
  std::optional<Clock::time_point> hand_over_due(Clock::time_point now) noexcept;
  void asked_done() noexcept;
  bool owns_lane(pid_t pid, bool skip_import) const noexcept;
  Result<void> open_endpoint(bool receive);
  void close_endpoint() noexcept;

  // Export: one exporter at a time; the one that stops looks again (release_export).
  static void export_inline_trampoline(void* self) noexcept;
  void activate_inline() noexcept;
  bool flush_stash() noexcept;  // the message a write left for later (backlog_): true once sent
  void export_inline() noexcept;
  void drain() noexcept;
 public:
  /// Sets the egress budget (Bridge::open, from the opening handle's options and the host's link
  /// budget in the configuration file `file`, or none).
  void set_budget(const TopicOptions& options, const Config* file) noexcept;
 private:
  void release_export() noexcept;
  bool has_export_work() const noexcept;
  bool send(const void* msg);
  // A topic mapped onto ROS 2 (ros2_wire.hpp): its bytes are the ROS 2 type's.
  void map_ros2(Ros2Wire wire);
  Result<std::size_t> encoded_size(const void* msg) const;
  void encode(const void* msg, std::span<std::byte> body) const noexcept;
  bool decode_ros2(const net::Sample& sample, void* out, const ByteSink* sink) const;

  horus::detail::TopicCore& core_;
  const horus::detail::WireOps& ops_;
  net::Qos qos_;
  std::shared_ptr<Engine> engine_;
  std::shared_ptr<net::Transport> transport_;  // the engine's, for this topic (Engine::transport_for)
  const net::TransportInfo& info_;
  net::WireFormat format_;
  std::string wire_topic_;
  std::optional<Ros2Wire> ros2_;  // mapped onto ROS 2 (TopicOptions::ros2)
  std::shared_ptr<Ros2Graph> ros2_graph_;  // its node on the ROS 2 graph (ros_discovery_info)
  ros2::Context ros2_context_;    // views of ros2_'s frame ids
  horus::detail::ForeignDecoder foreign_{};
  mutable std::atomic<std::uint64_t> ros2_refused_{0};          // samples the type could not hold
  mutable std::atomic<std::int64_t> ros2_refused_logged_ns_{0};  // when that was last logged
  const int creator_pid_;
  std::unique_ptr<horus::detail::BridgePort> port_;  // the holder's lane and entry; outlives the endpoint
  std::unique_ptr<net::Endpoint> endpoint_;          // the holder's only; reset first: no callback after that
  std::atomic<bool> holder_{false};
  std::atomic<bool> attached_{false};          // the doorbell forwards to the engine
  std::uint64_t forward_ = 0;                  // what it forwards to
  std::mutex receiving_mutex_;                 // update_receiving: the engine, or an opening handle
  std::atomic<bool> receiving_{true};          // what the endpoint was told
  std::atomic<std::int64_t> paused_at_ns_{0};  // when it was told to stop receiving (steady clock)
  std::atomic<bool> endpoint_ready_{false};    // endpoint_ is set (user threads may ask it for counts)
  mutable std::mutex endpoint_mutex_;                // endpoint_ set or reset, against the import pump
  bool loopback_ = false;                      // the transport delivers our own samples back (LCM)
  EchoLedger ledger_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> export_busy_{false};       // someone exports now
  std::atomic<bool> gated_{false};             // a successor waits for the readers to match
  std::atomic<bool> matches_changed_{false};   // the endpoint's matched counts changed (on_matched)
  Clock::time_point gate_until_{};
  Clock::time_point gate_opened_{};            // the successor's endpoint opened
  Clock::time_point gate_matched_{};           // it matched gate_readers_ (then the settle)
  std::uint32_t gate_readers_ = 0;
  std::uint64_t seen_owner_ = ~std::uint64_t{0};  // the claim word at the control thread's last look
  bool retry_claim_ = false;                   // a takeover failed: retry_at_
  Clock::time_point retry_at_{};
  std::uint64_t write_retries_ = 0;        // reliable writes that waited for slow readers
  // A reliable write that timed out on an engine thread: the encoded message waits here (the
  // exporter's, under export_busy_) and the topic exports nothing else until it went out.
  std::vector<std::byte> stash_;
  std::atomic<bool> backlog_{false};
  // The egress budget (TopicOptions::max_rate_hz, max_bandwidth), the exporter's: over budget, the
  // newest message waits here (encoded) for its turn; a newer one replaces it (counted).
  struct Budget {
    std::int64_t min_interval_ns = 0;  // 0: no rate limit
    double bytes_per_ns = 0;           // 0: no bandwidth limit
    double tokens = 0;                 // bytes the bucket holds now
    std::int64_t filled_ns = 0;        // when tokens was last brought up to date
    std::int64_t last_sent_ns = 0;
    bool any_sent = false;
    bool active() const noexcept { return min_interval_ns > 0 || bytes_per_ns > 0; }
    bool allows(std::int64_t now, std::size_t bytes) noexcept;  // brings the bucket up to date
    void spend(std::int64_t now, std::size_t bytes) noexcept;
  } budget_;
  // The host's link budget (network.max_bandwidth: shared by the host's bridges on the engine
  // board) and this topic's tolerance there, by its priority.
  double link_ns_per_byte_ = 0;  // 0: no link budget
  std::int64_t link_tolerance_ns_ = 0;
  Priority priority_ = Priority::Normal;
  bool budgeted() const noexcept { return budget_.active() || link_ns_per_byte_ > 0; }
  bool admit(std::int64_t now, std::size_t bytes) noexcept;  // the topic's budget, then the link's
  std::vector<std::byte> latest_;
  bool has_latest_ = false;
  bool budget_logged_ = false;
  void budget_drop() noexcept;
  bool flush_latest() noexcept;  // true when nothing waits
  bool gave_up_ = false;  // closing, a write timed out: the rest is counted as dropped (exporter's)
  std::atomic<std::uint64_t> errors_{0};   // incompatible endpoints reported
  std::uint64_t send_failures_ = 0;        // for the log's rate
  std::uint64_t export_lost_seen_ = 0;
  bool hold_ = false;                           // reliable, and the transport holds samples
  std::atomic<bool> held_{false};               // the transport holds samples back for room
  std::atomic<std::int64_t> held_since_ns_{0};  // since when (steady clock)
  std::atomic<bool> stalled_{false};            // a subscriber let kImportWait pass: overwrite
  std::atomic<std::uint64_t> import_stalls_{0}; // for the log's rate
  // The hand-over. The control thread's, but publishes_ (set by a user thread's first send).
  std::atomic<bool> publishes_{false};          // a handle of this process took a lane
  std::atomic<bool> becoming_{false};           // become_holder() runs (the import pump waits for it)
  Ask ask_ = Ask::Idle;
  Clock::time_point ask_next_{};                // when a publishing watcher looks again
  Clock::time_point ask_until_{};               // when matching or asking gives up
  Clock::time_point rang_at_{};                 // when it last rang the holder
  Clock::duration ask_backoff_ = std::chrono::seconds(5);  // grows with each refusal
  std::uint32_t ask_readers_ = 0;               // the holder's matched readers when we opened
  std::uint32_t ask_writers_ = 0;               // and its matched writers
  Clock::time_point ask_opened_{};              // when we opened our endpoint to ask
  Clock::time_point ask_matched_{};             // when it matched what the holder's did (or {})
  std::uint64_t handing_to_ = 0;                // the holder, accepted: whom the claim goes to
  Clock::time_point handing_at_{};              // and when (the settle after its endpoint closed)
  std::uint64_t quiet_imported_ = ~std::uint64_t{0};  // the segment's import count at the last look
  Clock::time_point quiet_since_{};
  bool prematched_ = false;                     // the endpoint matched before the bridge came: no gate
  bool port_stale_ = false;                     // handed over: port_'s entry and lane went with the claim
  std::vector<std::unique_ptr<horus::detail::BridgePort>> retired_ports_;  // freed with the bridge
  std::atomic<std::int64_t> last_import_ns_{0}; // the holder's last import (steady clock)
  std::int64_t handover_looked_ns_ = 0;         // the export thread's: when it last passed a request on
  Presence presence_;                           // released last in ~Bridge (after leave())
};

/// A later handle's options against the bridge's QoS: Errc::ConfigMismatch when they differ.
Result<void> check_qos(const std::string& topic, const net::Qos& have, const TopicOptions& options);


}  // namespace horus::fleet::detail

// The shared state of one topic in this process (TopicCore): the memory its ring lives in, the
// ring, the large-data pool and, for fleet topics, the network bridge. Every handle of the topic
// holds it. Opening, the per-topic reports (logged, rate-limited) and the pool's leases live in
// api/src/topic_core.cpp. Internal to horus: users include <horus/topic.hpp>.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "horus/backend.hpp"
#include "horus/detail/process.hpp"
#include "horus/topic_options.hpp"
#include "horus/error.hpp"
#include "horus/transport_registry.hpp"
#include "horus/shm/heap_region.hpp"
#include "horus/shm/pool.hpp"
#include "horus/shm/ring.hpp"
#include "horus/shm/shm_segment.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {
struct Settings;
}

namespace horus::detail {

/// A message type as the topic registry and a segment's header see it.
struct TypeInfo {
  std::string_view name;
  std::uint64_t hash;
  std::uint32_t size;        // sizeof(T) (a pooled type: sizeof(T::Descriptor)); for a serialized type,
                             // the default largest encoded message
  bool serialized = false;   // variable-size: slots hold [length][encoded bytes]
  std::uint64_t pool_bytes = 0;  // large data: default bytes per pool slot (0: no pool)
  std::string (*signature)() = nullptr;  // reflect::type_signature<T>: written into a new segment
};

class NetworkLink;  // network_link.hpp

/// What a verbose handle logs with (TopicOptions::verbose, log_level, log_rate_hz).
struct TrafficLogSettings {
  LogLevel level = LogLevel::Info;
  double rate_hz = kDefaultLogRateHz;  // 0: every message
};

/// A topic's limit on traffic lines in this process (TopicOptions::log_rate_hz), shared by its
/// verbose handles: a token bucket of rate_hz lines a second that holds one second's lines (at
/// least one), so a topic that sends now and then loses none. Lines over it are held back:
/// counted, and the next line written says how many (traffic_log.hpp). While the bucket is empty
/// a line is held back without the lock: one load and one atomic add.
class TrafficLimiter {
 public:
  /// Whether a line may be written at `now_ns` (steady clock): nothing when over the rate (the
  /// line is counted as held back); else how many were held back since the last line written.
  std::optional<std::uint64_t> admit(const TrafficLogSettings& s, std::int64_t now_ns) noexcept;
  /// Lines held back since the last one written, and in all.
  std::uint64_t held() const noexcept { return held_.load(std::memory_order_relaxed); }
  std::uint64_t held_total() const noexcept;
  /// The settings of the last line asked for (what the topic's close reports with).
  TrafficLogSettings last_settings() const noexcept;

 private:
  std::atomic<std::int64_t> empty_until_{0};  // steady ns: the bucket has no line before then
  std::atomic<std::uint64_t> held_{0};
  mutable std::mutex mutex_;
  double tokens_ = -1;  // below 0: no line asked for yet (the bucket starts full)
  std::int64_t last_ns_ = 0;
  std::uint64_t held_reported_ = 0;  // held back, and said so in a line
  TrafficLogSettings last_;
};

/// The shared state of one topic in this process: its ring and the memory it lives in.
struct TopicCore {
  std::string name;
  std::string type_name;
  std::uint64_t type_hash = 0;
  std::uint32_t payload_size = 0;  // ring payload: sizeof(T), or 8 + largest encoded message
  bool serialized = false;
  Backend backend = Backend::InProcess;
  const net::TransportInfo* transport = nullptr;  // a fleet topic's, found once when it opened
  int pid = 0;                             // the process that opened it (a forked child opens its own)
  shm::HeapRegion region;                  // Scope::Process
  std::optional<shm::ShmSegment> segment;  // Scope::Host and Scope::Fleet
  shm::Ring ring;
  shm::Pool pool;                // large data only
  std::uint32_t participant = 0;  // our index in the segment's participant table (what pins pool slots)
  shm::Pool::Claimer claimer;     // this process, as the pool records who writes a slot
  std::atomic<std::int64_t> last_reap_ns{0};  // reap_dead_participants' rate limit

  // Fleet topics: how this process's handles hand their messages to the network while it
  // holds the host's bridge (doorbell.hpp, InlineExport; set by the bridge).
  shm::InlineExport inline_export;
  // Fleet topics: samples from the network that did not decode (the transport's thread).
  std::atomic<std::uint64_t> net_decode_failures{0};
  // Verbose handles: the topic's limit on traffic lines in this process.
  TrafficLimiter traffic;
  // Fleet topics: this process's network bridge (horus/detail/network_link.hpp: the host's
  // bridge when this process holds it, else a watcher that takes over). Declared last: it goes
  // first, so the engine stops serving it and its callbacks end before the ring is gone.
  // net_mutex serializes its creation.
  std::mutex net_mutex;
  std::unique_ptr<NetworkLink> net;

  TopicCore() = default;
  TopicCore(const TopicCore&) = delete;
  TopicCore& operator=(const TopicCore&) = delete;
  ~TopicCore();
};

/// Finds or creates the topic `name` for a message type; checks name, type and configuration.
/// `settings`: the open's (horus/settings.hpp), which the topic's placement reads (its backend
/// when `options` has none, the shared-memory namespace and mode).
Result<std::shared_ptr<TopicCore>> open_core(std::string_view name, const TypeInfo& type,
                                             const TopicOptions& options, const Settings& settings);
/// A host-unique, non-zero identity for a handle's lane and subscriber entry: (pid << 32) | n.
std::uint64_t next_token() noexcept;
/// Logs (once per handle) that a send found no free lane / a receive no free subscriber entry.
void report_no_lane(const TopicCore& core);
void report_no_subscriber_slot(const TopicCore& core);
/// Logs a serialized message refused for its size, or a received one that did not decode.
void report_too_large(const TopicCore& core, std::size_t size, std::uint64_t count);
void report_decode_failure(const TopicCore& core, const std::string& what, std::uint64_t count);
/// The error send_blocking returns for a message over the slot size.
Error too_large_error(const TopicCore& core, std::size_t size);
/// Logs (first and every 1024th) that a large-data send found every pool slot of its lane pinned.
void report_pool_exhausted(const TopicCore& core, std::uint64_t count);
/// Logs (first and every 1024th) a large-data message refused because its metadata does not
/// describe its bytes (e.g. an Image edited through JSON).
void report_inconsistent(const TopicCore& core, std::uint64_t count);
/// The error for the same, from send_blocking or loan().
Error pool_exhausted_error(const TopicCore& core);
/// The errors of a send that found every publisher lane taken, and of a ring that stayed full.
Error no_lane_error(const TopicCore& core, std::string_view what);
Error ring_full_error(const TopicCore& core, std::chrono::nanoseconds timeout);
/// The error of a handle that found every subscriber entry of its topic taken.
Error subscriber_limit_error(std::string_view topic);

// current_pid() (horus/detail/process.hpp): leases compare it with their topic's to do nothing in
// a forked child, which must not release its parent's pins.
/// Shared memory: releases what processes that died held (pins, lanes, subscriber entries), at
/// most once per 50 ms per topic; true when some process was reaped.
bool reap_dead_participants(TopicCore& core);
/// Pool leases: a received message unpins its slot; a loan dropped unsent gives its slot back.
void release_pin(const void* core, std::uint64_t slot, std::uint64_t participant) noexcept;
void release_loan(const void* core, std::uint64_t slot, std::uint64_t gen) noexcept;

}  // namespace horus::detail

HORUS_API_END

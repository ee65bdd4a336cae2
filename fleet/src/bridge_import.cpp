// What a fleet topic's bridge receives (bridge.hpp): the import, receiving as the host's
// subscribers come and go, the matched counts and what the transport reports.
#include "bridge.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>

#include "horus/detail/bridge_port.hpp"
#include "horus/log.hpp"
#include "horus/shm/doorbell.hpp"

namespace horus::fleet::detail {

using horus::detail::log;

namespace {
constexpr auto kImportWait = std::chrono::milliseconds(100);  // a reliable import holds samples for room
}  // namespace

// --- receiving -------------------------------------------------------------------------------

void Bridge::on_sample(const net::Sample& sample) {
  if (!holder_.load(std::memory_order_acquire)) [[unlikely]] {
    // An endpoint opened for a hand-over: the holder imports until it hands the bridge over.
    // A sample that comes after that and before this process holds it is not imported: counted.
    if (state().owner.load(std::memory_order_acquire) == segment().bridge_word())
      state().dropped.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (loopback_ && ledger_.consume(body_hash(sample.body))) return;  // our own, back
  if (!(ros2_ && ros2_->conversion != nullptr ? port_->deliver_foreign(foreign_, sample) : port_->deliver(format_, sample)))
    return;
  last_import_ns_.store(now_ns(), std::memory_order_relaxed);
  state().imported.fetch_add(1, std::memory_order_relaxed);
  // The import wakes the host's handles, not the export (it skips these messages); once they
  // fill half the ring, let the engine pass over them, so that the export cursor never falls a
  // ring behind (that would count as losses nobody had).
  // Through the doorbell's bridge class: one wake-up per time the engine armed it, not per sample.
  if (import_lag() > core_.ring.capacity() / 2) core_.ring.wake_waiters(shm::Doorbell::kArmedBridge);
}

// --- a topic mapped onto ROS 2 ---------------------------------------------------------------

void Bridge::map_ros2(Ros2Wire wire) {
  ros2_ = std::move(wire);
  ros2_context_ = ros2_->context();
  foreign_ = {this, [](const void* self, const net::Sample& sample, void* out, const ByteSink* sink) {
                return static_cast<const Bridge*>(self)->decode_ros2(sample, out, sink);
              }};
}

Result<std::size_t> Bridge::encoded_size(const void* msg) const {
  if (ros2_ && ros2_->conversion != nullptr) return ros2_->conversion->encoded_size(msg, ros2_context_);
  return ops_.encoded_size(format_, msg);
}

void Bridge::encode(const void* msg, std::span<std::byte> body) const noexcept {
  if (ros2_ && ros2_->conversion != nullptr) return ros2_->conversion->encode(msg, ros2_context_, body);
  ops_.encode(format_, msg, body);
}

// A ROS 2 sample into the topic's type. One the type cannot hold (more beams, a longer name) is
// dropped and counted in the topic's dropped count, and said at most once a second; one that is
// not the ROS 2 type is a decode failure (counted, logged).
bool Bridge::decode_ros2(const net::Sample& sample, void* out, const ByteSink* sink) const {
  auto ok = ros2_->conversion->decode(sample.body, sample.little_endian, out, sink);
  if (ok) return true;
  if (ok.error().malformed) {
    horus::detail::report_network_decode_failure(core_, ok.error().what);
    return false;
  }
  state().dropped.fetch_add(1, std::memory_order_relaxed);
  const std::uint64_t n = ros2_refused_.fetch_add(1, std::memory_order_relaxed) + 1;
  const std::int64_t now = now_ns();
  std::int64_t last = ros2_refused_logged_ns_.load(std::memory_order_relaxed);
  if (now - last >= std::chrono::duration_cast<Clock::duration>(std::chrono::seconds(1)).count() &&
      ros2_refused_logged_ns_.compare_exchange_strong(last, now, std::memory_order_relaxed))
    log().warn("topic '{}': a ROS 2 sample ({}) does not fit {} and was dropped: {} ({} so far, counted in "
               "dropped_count())",
               core_.name, ros2_->type, core_.type_name, ok.error().what, n);
  return false;
}

std::uint64_t Bridge::import_lag() const noexcept {
  const std::uint32_t lane = port_->lane();
  if (lane >= shm::kMaxPublishers || !port_->has_entry()) return 0;
  const std::uint64_t head = core_.ring.lane(lane).head.load(std::memory_order_acquire);
  const std::uint64_t seen = core_.ring.subscriber(port_->entry()).cursor[lane].load(std::memory_order_relaxed);
  return head > seen ? head - seen : 0;
}

// Reliable topics on a transport that holds samples (DDS): the transport takes no more than the
// host's subscribers have room for, and the rest waits in its reader, whose flow control slows
// the sending host, instead of overwriting. The transport's thread never blocks (it serves every
// topic and the fleet's heartbeats): the engine pumps the held samples when room appears. A
// subscriber that leaves the lane full for kImportWait is stuck (stopped, in a debugger): then
// its oldest messages are overwritten (counted in its dropped_count) until it reads again.
std::size_t Bridge::room() {
  if (!hold_ || !holder_.load(std::memory_order_acquire)) return SIZE_MAX;
  const std::size_t r = port_->import_room();
  if (r > 0) {  // the subscribers read: not stuck
    stalled_.store(false, std::memory_order_relaxed);
    held_since_ns_.store(0, std::memory_order_relaxed);
    return r;
  }
  if (stalled_.load(std::memory_order_relaxed)) return SIZE_MAX;
  if (held_since_ns_.load(std::memory_order_relaxed) == 0) held_since_ns_.store(now_ns(), std::memory_order_relaxed);
  if (!held_.exchange(true, std::memory_order_acq_rel)) engine_->pump(*this);
  return 0;
}

bool Bridge::pump_held() noexcept {
  const std::int64_t since_ns = held_since_ns_.load(std::memory_order_relaxed);
  const auto since = Clock::time_point(Clock::duration(since_ns));
  if (since_ns != 0 && Clock::now() - since > kImportWait && !stalled_.exchange(true, std::memory_order_relaxed)) {
    const std::uint64_t n = ++import_stalls_;
    if (n == 1 || n % 64 == 0)
      log().warn("topic '{}': a subscriber on this host has not read for {} ms; the bridge stops holding the {} "
                 "samples back for it and overwrites its oldest messages (counted in its dropped_count()) until it "
                 "reads again ({} time(s) so far)",
                 core_.name, std::chrono::duration_cast<std::chrono::milliseconds>(kImportWait).count(), info_.name,
                 n);
  }
  std::lock_guard lock(endpoint_mutex_);
  if (!endpoint_)  // not open yet: try again (a bridge handed over has nothing to pump)
    return holder_.load(std::memory_order_acquire) || becoming_.load(std::memory_order_acquire);
  held_.store(false, std::memory_order_release);  // room() sets it again if it must hold on
  endpoint_->take_held();
  return held_.load(std::memory_order_acquire);
}

void Bridge::on_lost(std::uint64_t count) {
  if (!holder_.load(std::memory_order_acquire)) return;  // a hand-over's endpoint: the holder counts
  const auto before = state().dropped.fetch_add(count, std::memory_order_relaxed);
  // Log the first loss, then at most once per 1024 more (the count is in dropped_count()).
  if (before == 0 || before / 1024 != (before + count) / 1024)
    log().warn("topic '{}': the {} backend lost {} message(s) or datagram(s) ({} so far on this host; they "
               "count in dropped_count())",
               core_.name, info_.name, count, before + count);
}

void Bridge::on_matched() {
  // The transport's thread: the export thread asks the endpoint and publishes the counts.
  matches_changed_.store(true, std::memory_order_release);
  engine_->notify(*this);
}

void Bridge::on_error(std::string_view message) {
  const auto n = errors_.fetch_add(1, std::memory_order_relaxed) + 1;
  if (n <= 16 || n % 1024 == 0) log().error("{} [{}]", message, info_.name);
}

// The host's subscribing handles, the holder's own entry left out.
std::uint32_t Bridge::host_subscribers() const noexcept {
  const std::uint32_t n = core_.ring.subscriber_count();
  return n - (n != 0 && port_ && port_->has_entry() ? 1u : 0u);
}

// Stops or resumes receiving as the host's subscribers come and go: the engine, and a handle
// of the holding process that subscribes (its open() returns once the bridge receives; a
// handle of another process rings the doorbell, which wakes the engine to resume at once).
void Bridge::update_receiving() noexcept {
  std::lock_guard lock(receiving_mutex_);
  if (!endpoint_ready_.load(std::memory_order_acquire)) return;
  const bool want = host_subscribers() != 0;
  if (want == receiving_.load(std::memory_order_relaxed)) return;
  receiving_.store(want, std::memory_order_relaxed);
  if (!want) paused_at_ns_.store(now_ns(), std::memory_order_relaxed);
  endpoint_->set_receiving(want);
}

void Bridge::publish_matches() noexcept {
  if (!endpoint_ready_.load(std::memory_order_acquire)) return;
  std::lock_guard lock(endpoint_mutex_);  // a hand-over closes it on the control thread
  if (!endpoint_ || !holder_.load(std::memory_order_acquire)) return;
  try {
    state().matched_publishers.store(endpoint_->matched_publishers(), std::memory_order_relaxed);
    state().matched_subscribers.store(endpoint_->matched_subscribers(), std::memory_order_relaxed);
  } catch (...) {
  }
}

// --- reports -----------------------------------------------------------------------------------

std::uint64_t Bridge::dropped() const noexcept { return state().dropped.load(std::memory_order_relaxed); }

// Remote writers (readers) the host's bridge matched: asked of the endpoint in the holding
// process, read from the segment (published by the holder's engine) in the others.
std::uint32_t Bridge::remote(bool writers) const noexcept {
  if (endpoint_ready_.load(std::memory_order_acquire)) {
    std::lock_guard lock(endpoint_mutex_);  // a hand-over closes it on the export thread
    if (endpoint_) try {
      return writers ? endpoint_->matched_publishers() : endpoint_->matched_subscribers();
    } catch (...) {
    }
  }
  return (writers ? state().matched_publishers : state().matched_subscribers).load(std::memory_order_relaxed);
}

}  // namespace horus::fleet::detail

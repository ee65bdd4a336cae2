// LocalPort<Payload>: one handle's place in its topic's ring. It holds the topic (TopicCore)
// and two leases on the ring: a publisher lane (RingWriter, taken at the first send) and a
// subscriber entry (RingReader, taken when the handle opens). Role switching lives here: a
// handle whose first call is a send becomes a pure publisher and gives its subscriber entry
// back; a later receive takes one again. The leases are released while the ring is still mapped,
// also on move assignment, so the handles built on a port move with `= default`.
// Internal to horus: users include <horus/topic.hpp>.
#pragma once

#include <cstdint>
#include <memory>
#include <utility>

#include "horus/detail/topic_core.hpp"
#include "horus/shm/ring.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::detail {

void network_publisher(TopicCore& core) noexcept;  // network_link.hpp

/// What one handle counts (TopicMetrics).
struct HandleCounters {
  std::uint64_t send_failures = 0;
  std::uint64_t recv_failures = 0;
  std::uint64_t too_large = 0;        // messages refused for their size
  std::uint64_t decode_failures = 0;  // read but not decoded (corrupt serialized slots, bad descriptors)
  std::uint64_t undelivered = 0;      // read by recv() but not decoded (not counted as received)
};

template <class Payload>
class LocalPort {
 public:
  LocalPort() = default;
  explicit LocalPort(std::shared_ptr<TopicCore> core)
      : core_(std::move(core)), writer_(core_->ring, next_token()), reader_(core_->ring, next_token()) {
    // A fleet topic's sends export inline while this process bridges it (InlineExport).
    if (is_network(core_->backend)) writer_.set_inline_export(&core_->inline_export);
  }
  LocalPort(LocalPort&&) noexcept = default;
  /// Gives this port's lane and subscriber entry back while its ring is still mapped (the
  /// core goes last), then takes the other's.
  LocalPort& operator=(LocalPort&& o) noexcept {
    if (this == &o) return *this;
    writer_ = std::move(o.writer_);
    reader_ = std::move(o.reader_);
    core_ = std::move(o.core_);
    counters = o.counters;
    received = o.received;
    no_lane_reported_ = o.no_lane_reported_;
    no_sub_reported_ = o.no_sub_reported_;
    return *this;
  }
  ~LocalPort() = default;  // reader_, writer_, then core_ (declared first)

  TopicCore& core() const noexcept { return *core_; }
  const std::shared_ptr<TopicCore>& shared_core() const noexcept { return core_; }
  shm::RingWriter<Payload>& writer() noexcept { return writer_; }
  const shm::RingWriter<Payload>& writer() const noexcept { return writer_; }
  shm::RingReader<Payload>& reader() noexcept { return reader_; }
  const shm::RingReader<Payload>& reader() const noexcept { return reader_; }

  /// A lane to write to: claims one at the first send (false, logged once, when all are taken).
  [[gnu::always_inline]] bool ensure_lane() { return writer_.has_lane() || become_publisher(); }
  /// A subscriber entry to read with: takes one again after a pure publisher's first receive.
  [[gnu::always_inline]] bool ensure_subscribed() { return reader_.subscribed() || resubscribe(); }

  /// True once this handle has used a receiving method (then its first send keeps it subscribed).
  bool receives() const noexcept { return received || counters.recv_failures != 0 || reader_.delivered() != 0; }

  /// A handle that will only publish gives its subscriber entry back now, as its first send would.
  void publish_only() noexcept {
    if (!receives()) reader_.unsubscribe();
  }

  HandleCounters counters;
  bool received = false;   // has_message/pending_count/read_latest were called

 private:
  [[gnu::noinline]] bool become_publisher() {
    if (writer_.ensure_lane()) {
      if (!receives()) reader_.unsubscribe();  // a pure publisher: stop counting as a subscriber
      if (is_network(core_->backend)) network_publisher(*core_);  // the bridge may follow it here
      return true;
    }
    if (!no_lane_reported_) report_no_lane(*core_);
    no_lane_reported_ = true;
    return false;
  }

  [[gnu::noinline]] bool resubscribe() {
    if (reader_.subscribe()) return true;
    if (!no_sub_reported_) report_no_subscriber_slot(*core_);
    no_sub_reported_ = true;
    return false;
  }

  std::shared_ptr<TopicCore> core_;  // first: outlives writer_ and reader_
  shm::RingWriter<Payload> writer_;
  shm::RingReader<Payload> reader_;
  bool no_lane_reported_ = false;
  bool no_sub_reported_ = false;
};

}  // namespace horus::detail

HORUS_API_END

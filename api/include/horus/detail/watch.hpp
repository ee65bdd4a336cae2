// A topic handle's deadline and lifespan (TopicOptions::deadline, ::lifespan; horus/topic.hpp),
// and whether it logs its traffic (TopicOptions::verbose): what a send or a receive does beyond
// moving the message, behind one test (active()). Internal to horus: users include <horus/topic.hpp>.
//
// Deadline: a miss is each full period without a message, counted lazily from the times the
// handle saw messages (no thread, no timer): a gap of 2.5 periods is 2 misses. Lifespan: a
// message whose own timestamp (timestamp_ns, or CmdVel's stamp_nanos: Unix ns, as the
// publisher set it) is older than the lifespan when the handle takes it is not delivered.
#pragma once

#include <chrono>
#include <concepts>
#include <cstdint>
#include <optional>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// The Unix time in ns a message carries (its `timestamp_ns` member or method, or `stamp_nanos`),
/// or 0 when its type has none: what a lifespan is measured from.
template <class T>
std::uint64_t message_timestamp_ns(const T& m) noexcept {
  if constexpr (requires { { m.timestamp_ns() } -> std::convertible_to<std::uint64_t>; })
    return static_cast<std::uint64_t>(m.timestamp_ns());
  else if constexpr (requires { { m.timestamp_ns } -> std::convertible_to<std::uint64_t>; })
    return static_cast<std::uint64_t>(m.timestamp_ns);
  else if constexpr (requires { { m.stamp_nanos } -> std::convertible_to<std::uint64_t>; })
    return static_cast<std::uint64_t>(m.stamp_nanos);
  else
    return 0;
}

namespace detail {

class Watch {
 public:
  using Clock = std::chrono::steady_clock;

  Watch() = default;
  Watch(std::optional<std::chrono::nanoseconds> deadline, std::optional<std::chrono::nanoseconds> lifespan,
        bool logs = false) noexcept
      : active_((deadline && deadline->count() > 0) || (lifespan && lifespan->count() > 0) || logs),
        logs_(logs),
        deadline_ns_(deadline && deadline->count() > 0 ? deadline->count() : 0),
        lifespan_ns_(lifespan && lifespan->count() > 0 ? lifespan->count() : 0),
        last_ns_(now_ns()) {}

  /// True when sends and receives have more to do than move the message.
  bool active() const noexcept { return active_; }
  /// True when the handle logs its traffic.
  bool logs() const noexcept { return logs_; }
  /// read_latest: true when `sent` (the topic's messages sent so far) changed since the last
  /// call, so that polling the same newest message logs it once.
  bool newer_latest(std::uint64_t sent) noexcept {
    if (sent == latest_sent_) return false;
    latest_sent_ = sent;
    return true;
  }
  std::chrono::nanoseconds deadline() const noexcept { return std::chrono::nanoseconds(deadline_ns_); }
  std::chrono::nanoseconds lifespan() const noexcept { return std::chrono::nanoseconds(lifespan_ns_); }

  /// A message taken: false when it expired (counted), true to deliver it (the deadline's
  /// clock starts again).
  template <class T>
  bool take(const T& m) noexcept {
    if (!fresh(m)) {
      ++expired_;
      return false;
    }
    if (!sent_) event(now_ns());
    return true;
  }
  /// False when m's timestamp is older than the lifespan.
  template <class T>
  bool fresh(const T& m) const noexcept {
    if (lifespan_ns_ == 0) return true;
    const std::uint64_t stamp = message_timestamp_ns(m);
    if (stamp == 0) return true;
    const auto now =
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    return now - static_cast<std::int64_t>(stamp) <= lifespan_ns_;
  }
  /// A message sent: from now on the deadline measures this handle's sends (offered deadline).
  void sent() noexcept {
    if (deadline_ns_ == 0) return;
    if (!sent_) {  // the periods before were counted on what it received
      sent_ = true;
      last_ns_ = now_ns();
      return;
    }
    event(now_ns());
  }

  std::uint64_t missed() const noexcept { return missed_ + periods(now_ns()); }
  std::uint64_t expired() const noexcept { return expired_; }
  /// When the next miss will be counted if no message comes; nothing without a deadline.
  std::optional<Clock::time_point> next_miss() const noexcept {
    if (deadline_ns_ == 0) return std::nullopt;
    const std::int64_t due = last_ns_ + static_cast<std::int64_t>(periods(now_ns()) + 1) * deadline_ns_;
    return Clock::time_point(std::chrono::duration_cast<Clock::duration>(std::chrono::nanoseconds(due)));
  }
  /// How long since the last message (received, or sent by a publishing handle).
  std::chrono::nanoseconds silent_for() const noexcept { return std::chrono::nanoseconds(now_ns() - last_ns_); }

 private:
  static std::int64_t now_ns() noexcept {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
  }
  std::uint64_t periods(std::int64_t now) const noexcept {
    return deadline_ns_ != 0 && now > last_ns_ ? static_cast<std::uint64_t>((now - last_ns_) / deadline_ns_) : 0;
  }
  void event(std::int64_t now) noexcept {
    if (deadline_ns_ == 0) return;
    missed_ += periods(now);
    last_ns_ = now;
  }

  // First, where every send and receive reads it: the handle's hot lines end here.
  bool active_ = false;
  bool logs_ = false;
  std::int64_t deadline_ns_ = 0;
  std::int64_t lifespan_ns_ = 0;
  std::int64_t last_ns_ = 0;  // steady ns: the last message, or the handle's opening
  std::uint64_t missed_ = 0;  // misses counted up to last_ns_
  std::uint64_t expired_ = 0;
  std::uint64_t latest_sent_ = ~std::uint64_t{0};  // newer_latest()
  bool sent_ = false;         // the handle publishes: the deadline measures its sends
};

}  // namespace detail
}  // namespace horus

HORUS_API_END

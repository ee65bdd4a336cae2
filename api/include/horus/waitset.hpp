// horus::WaitSet and horus::Trigger: one thread waits for messages on several topics (of any
// types) and for triggers, without polling.
//
//   horus::Topic<horus::msg::Imu> imu("imu");
//   horus::Topic<horus::msg::Odometry> odom("odom");
//   horus::Trigger shutdown;                       // fire() from another thread or a signal handler
//   horus::WaitSet ws;
//   const auto imu_id = ws.attach(imu);
//   ws.attach(odom);
//   const auto stop_id = ws.attach(shutdown);
//   for (;;) {
//     const auto r = ws.wait(std::chrono::milliseconds(100));
//     if (r.contains(stop_id)) break;
//     if (r.contains(imu_id)) while (auto m = imu.recv()) { ... }
//     ...
//   }
//
// Readiness is a level, as in ROS 2 and iceoryx wait sets: a topic is ready while its handle has
// an unread message, a trigger while it is fired (until reset()). wait() returns at once when
// something is ready already. A waiting thread sleeps in the kernel (futex_waitv over the
// topics' doorbells, horus/shm/doorbell.hpp) and uses no CPU.
//
// Defined corner cases (tested in tests/unit/test_waitset.cpp):
// - attach() and detach() may be called from any thread, also while another thread waits: the
//   wait picks the change up at once.
// - A topic handle destroyed while attached is detached by itself: it is never reported again,
//   and size() no longer counts it. A moved handle stays attached (the attachment follows it).
//   Attaching makes a handle a subscriber for good (its first send does not drop that).
// - A Trigger is a handle on shared state: copies fire the same trigger, and an attached
//   trigger stays attached (and can be fired through its copies) after one copy is destroyed.
// - Destroying a WaitSet while other threads wait on it wakes them: their wait() returns with
//   closed() true, and the destructor returns once they have left. (A wait that starts after
//   the destructor began is a use after destruction, as for any object.)
// - At most kMaxAttachments attachments (the kernel's futex_waitv limit, less one for the
//   wait set's own wake-ups): attach() beyond that throws Errc::LimitReached.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "horus/detail/waiting.hpp"
#include "horus/error.hpp"
#include "horus/shm/doorbell.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

template <class T>
class Topic;

/// A flag one thread (or a signal handler) fires to wake whoever waits on it.
class Trigger {
 public:
  Trigger();
  /// Sets the trigger and wakes every WaitSet waiting on it. Async-signal-safe (atomics and
  /// one futex syscall; nothing allocated, no lock).
  void fire() noexcept;
  /// Clears the trigger (it stays ready until then).
  void reset() noexcept;
  bool fired() const noexcept;

  struct State {
    shm::Doorbell bell;
    std::atomic<bool> fired{false};
  };

 private:
  friend class WaitSet;
  std::shared_ptr<State> state_;
};

class WaitSet {
 public:
  /// Names one attachment (unique within the wait set, never reused).
  using Id = std::uint64_t;
  static constexpr std::size_t kMaxAttachments = shm::kMaxWaitItems - 1;

  /// What a wait found.
  struct Result {
    std::vector<Id> ready;  // attachments ready when wait() returned, in the order attached
    bool closed_ = false;
    /// True when `id` was ready.
    bool contains(Id id) const noexcept;
    /// Nothing was ready before the timeout.
    bool timed_out() const noexcept { return ready.empty() && !closed_; }
    /// The wait set was destroyed while this wait was under way.
    bool closed() const noexcept { return closed_; }
  };

  WaitSet();
  ~WaitSet();
  WaitSet(const WaitSet&) = delete;
  WaitSet& operator=(const WaitSet&) = delete;

  /// Attaches a topic handle (it subscribes if it was a pure publisher). Throws horus::Exception
  /// with Errc::LimitReached when the wait set is full or the topic has no free subscriber entry.
  template <class T>
  Id attach(Topic<T>& topic) {
    auto target = topic.wait_target();
    if (!target) throw Exception(no_subscriber_error(topic.name()));
    return attach_target(std::move(*target));
  }
  /// Attaches a trigger (the wait set shares its state).
  Id attach(const Trigger& trigger);
  /// Detaches; false when `id` is not attached (any more).
  bool detach(Id id);
  /// Attachments (topic handles destroyed since are not counted).
  std::size_t size() const;

  /// Waits up to `timeout` (zero or negative: only looks) for an attachment to be ready.
  Result wait(std::chrono::nanoseconds timeout);
  /// Waits until an attachment is ready (or the wait set is destroyed).
  Result wait();
  /// Waits until `deadline`.
  Result wait_until(std::chrono::steady_clock::time_point deadline);

  struct State;  // api/src/waitset.cpp

 private:
  Id attach_target(detail::WaitTarget target);
  static Error no_subscriber_error(std::string_view topic);
  std::shared_ptr<State> state_;
};

}  // namespace horus

HORUS_API_END

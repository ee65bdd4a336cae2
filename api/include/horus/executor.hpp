// horus::Executor: callbacks for topics and timers, run by the thread that spins.
//
//   horus::Executor ex;
//   ex.subscribe<horus::msg::Imu>("imu", [&](const horus::msg::Imu& m) { fuse(m); });
//   ex.every(std::chrono::milliseconds(10), [&] { pose.send(current()); });   // 100 Hz
//   std::signal(SIGINT, [](int) { g_executor->stop(); });
//   ex.spin();                                   // until stop()
//
// - Callbacks of one executor never run at the same time: one thread spins at a time (a second
//   spinning thread waits for the first), and every callback runs on the spinning thread.
// - Messages of one topic are handled in order (FIFO per publisher, as recv() gives them); a
//   busy topic yields after 64 messages, so topics and timers take turns.
// - A callback gets `const T&`; large data (Image, PointCloud) is the received message itself,
//   its bytes still in shared memory (no copy).
// - An exception thrown by a callback is caught, logged (first and every 1024th) and counted in
//   callback_errors(); the executor goes on.
// - every(period, f) runs f at a fixed rate (the spec's .rate()): at start + k * period. A call
//   that comes too late to keep up skips the missed ticks (counted in timer_overruns()) rather
//   than running them in a burst.
// - stop() may be called from any thread and from a signal handler (async-signal-safe): the
//   spin returns after the callback running now. A stop() before spin() makes the next spin
//   return at once; each spin that returns for a stop clears it.
// - subscribe(), every() and remove() may be called from any thread, also from a callback.
// - While a thread waits in spin it sleeps in the kernel (WaitSet); it uses no CPU.
// - on_deadline_missed(id, f): a watchdog. A subscription opened with TopicOptions::deadline
//   (or a file's `deadline:`) calls f on the spinning thread when a full period passed without
//   a message (the spin wakes for it; messages already waiting are handled first).
#pragma once

#include <atomic>
#include <chrono>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "horus/backend.hpp"
#include "horus/error.hpp"
#include "horus/metrics.hpp"
#include "horus/topic.hpp"
#include "horus/waitset.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// What Executor::on_deadline_missed reports (as DDS's requested-deadline-missed status).
struct DeadlineMissed {
  std::string_view topic;
  std::uint64_t total_count = 0;         // periods missed since the subscription opened
  std::uint64_t total_count_change = 0;  // since the previous call
  std::chrono::nanoseconds silent_for{}; // since the subscription's last message (or its opening)
};

class Executor {
 public:
  /// Names a subscription or a timer (for remove()).
  using Id = std::uint64_t;
  /// Messages one topic may handle in a row before the others get a turn.
  static constexpr std::size_t kBatch = 64;

  Executor();
  ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  /// Opens topic `name` and calls `callback(const T&)` for each message. Throws horus::Exception
  /// when the topic does not open (bad name, type mismatch, ...).
  template <class T, class F>
    requires std::invocable<F&, const T&>
  Id subscribe(std::string_view name, F&& callback) {
    return subscribe<T>(name, TopicOptions{}, std::forward<F>(callback));
  }
  template <class T, class F>
    requires std::invocable<F&, const T&>
  Id subscribe(std::string_view name, const TopicOptions& options, F&& callback) {
    auto topic = Topic<T>::open(name, options);
    if (!topic) throw Exception(std::move(topic.error()));
    auto sub = std::make_shared<Subscription<T, std::decay_t<F>>>(std::move(*topic), std::forward<F>(callback));
    const WaitSet::Id wid = waitset_.attach(sub->topic);
    return add_subscription(wid, std::move(sub));
  }

  /// Calls `callback` every `period` (> 0; Errc::InvalidArgument otherwise), first one period
  /// from now.
  Id every(std::chrono::nanoseconds period, std::function<void()> callback);

  /// Calls `callback` each time subscription `id` misses its deadline (TopicOptions::deadline:
  /// a full period without a message), on the spinning thread. Replaces an earlier callback.
  /// Throws horus::Exception (Errc::InvalidArgument) for an unknown id, a timer, or a topic
  /// without a deadline.
  void on_deadline_missed(Id subscription, std::function<void(const DeadlineMissed&)> callback);

  /// Removes a subscription (its topic handle is closed) or a timer; false when unknown.
  bool remove(Id id);

  /// Runs callbacks until stop().
  void spin();
  /// Runs callbacks for `duration` (or until stop()).
  void spin_for(std::chrono::nanoseconds duration);
  /// Waits up to `timeout` for work, runs what is ready (each ready topic up to kBatch
  /// messages, due timers) and returns the number of callbacks run. Does not clear a stop().
  std::size_t spin_once(std::chrono::nanoseconds timeout);
  /// Makes spin()/spin_for() return. Async-signal-safe.
  void stop() noexcept { stop_.fire(); }

  /// The metrics of a subscription's topic handle (messages received, dropped, ...); nothing
  /// for an unknown id or a timer.
  std::optional<TopicMetrics> metrics(Id id) const;

  /// Callbacks that threw (each logged).
  std::uint64_t callback_errors() const noexcept { return errors_.load(std::memory_order_relaxed); }
  /// Callbacks run so far (topics and timers).
  std::uint64_t callbacks_run() const noexcept { return runs_.load(std::memory_order_relaxed); }
  /// Timer ticks skipped because a callback came too late to keep the rate.
  std::uint64_t timer_overruns() const noexcept { return overruns_.load(std::memory_order_relaxed); }

 private:
  struct Handler {
    virtual ~Handler() = default;
    // Handles up to `max` waiting messages; returns how many.
    virtual std::size_t drain(Executor& ex, std::size_t max) = 0;
    virtual TopicMetrics metrics() const = 0;
    // The deadline (TopicOptions::deadline), on the spinning thread.
    virtual std::chrono::nanoseconds deadline() const = 0;
    virtual std::optional<std::chrono::steady_clock::time_point> next_miss() const = 0;
    virtual std::uint64_t missed() const = 0;
    virtual std::chrono::nanoseconds silent_for() const = 0;
    virtual bool pending() = 0;  // a message waits (handled before a miss is reported)
    virtual std::string_view name() const = 0;
  };
  template <class T, class F>
  struct Subscription final : Handler {
    Subscription(Topic<T>&& t, F&& f) : topic(std::move(t)), callback(std::move(f)) {}
    Subscription(Topic<T>&& t, const F& f) : topic(std::move(t)), callback(f) {}
    std::size_t drain(Executor& ex, std::size_t max) override {
      std::size_t n = 0;
      while (n < max && topic.has_message()) {
        auto m = topic.recv();
        if (!m) continue;  // a corrupt slot skipped (counted by the topic)
        ++n;
        try {
          callback(std::as_const(*m));
        } catch (...) {
          ex.callback_failed(topic.name());
        }
      }
      ex.runs_.fetch_add(n, std::memory_order_relaxed);
      return n;
    }
    TopicMetrics metrics() const override { return topic.metrics(); }
    std::chrono::nanoseconds deadline() const override { return topic.watch_.deadline(); }
    std::optional<std::chrono::steady_clock::time_point> next_miss() const override { return topic.watch_.next_miss(); }
    std::uint64_t missed() const override { return topic.watch_.missed(); }
    std::chrono::nanoseconds silent_for() const override { return topic.watch_.silent_for(); }
    bool pending() override { return topic.has_message(); }
    std::string_view name() const override { return topic.name(); }
    Topic<T> topic;
    F callback;
  };
  struct Timer {
    Id id;
    std::chrono::nanoseconds period;
    std::chrono::steady_clock::time_point next;
    std::function<void()> callback;
  };

  struct Watchdog {
    std::function<void(const DeadlineMissed&)> callback;
    std::uint64_t reported = 0;
  };

  Id add_subscription(WaitSet::Id wid, std::shared_ptr<Handler> handler);
  std::size_t report_deadline_misses();
  std::chrono::steady_clock::time_point next_deadline_miss() const;
  void callback_failed(std::string_view what) noexcept;
  std::size_t run_due_timers();
  std::chrono::steady_clock::time_point next_timer() const;
  void spin_until(std::chrono::steady_clock::time_point deadline);

  WaitSet waitset_;
  Trigger stop_;
  WaitSet::Id stop_id_ = 0;
  Trigger wake_;  // a timer was added: the wait takes the new deadline
  WaitSet::Id wake_id_ = 0;
  std::mutex spin_mutex_;               // one spinning thread at a time
  mutable std::mutex mutex_;            // handlers_ and timers_
  std::map<Id, std::shared_ptr<Handler>> handlers_;  // by WaitSet::Id
  std::map<Id, std::shared_ptr<Timer>> timers_;
  std::map<Id, std::shared_ptr<Watchdog>> watchdogs_;  // by subscription
  Id next_timer_id_ = Id{1} << 62;  // timer ids never meet WaitSet ids
  std::atomic<std::uint64_t> errors_{0};
  std::atomic<std::uint64_t> runs_{0};
  std::atomic<std::uint64_t> overruns_{0};
};

}  // namespace horus

HORUS_API_END

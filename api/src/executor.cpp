// horus::Executor (horus/executor.hpp): a WaitSet over its topics and its stop trigger, with
// the next timer's deadline as the wait's deadline.
#include "horus/executor.hpp"

#include <algorithm>
#include <exception>
#include <string>

#include "horus/log.hpp"

namespace horus {

using Clock = std::chrono::steady_clock;

Executor::Executor() {
  stop_id_ = waitset_.attach(stop_);
  wake_id_ = waitset_.attach(wake_);
}

Executor::~Executor() = default;

Executor::Id Executor::add_subscription(WaitSet::Id wid, std::shared_ptr<Handler> handler) {
  std::lock_guard lock(mutex_);
  handlers_.emplace(wid, std::move(handler));
  return wid;
}

Executor::Id Executor::every(std::chrono::nanoseconds period, std::function<void()> callback) {
  if (period <= std::chrono::nanoseconds::zero())
    throw Exception(Error(Errc::InvalidArgument, "Executor::every: period " + std::to_string(period.count()) +
                                                     " ns; expected a positive period"));
  if (!callback) throw Exception(Error(Errc::InvalidArgument, "Executor::every: empty callback"));
  auto t = std::make_shared<Timer>(Timer{0, period, Clock::now() + period, std::move(callback)});
  Id id = 0;
  {
    std::lock_guard lock(mutex_);
    id = t->id = next_timer_id_++;
    timers_.emplace(id, std::move(t));
  }
  wake_.fire();  // a spin waiting with an older deadline takes this timer's
  return id;
}

void Executor::on_deadline_missed(Id subscription, std::function<void(const DeadlineMissed&)> callback) {
  auto invalid = [&](std::string why) {
    return Exception(Error(Errc::InvalidArgument, "Executor::on_deadline_missed: " + std::move(why)));
  };
  if (!callback) throw invalid("empty callback");
  {
    std::lock_guard lock(mutex_);
    auto it = handlers_.find(subscription);
    if (it == handlers_.end()) throw invalid("no subscription has id " + std::to_string(subscription));
    if (it->second->deadline() <= std::chrono::nanoseconds::zero())
      throw invalid("topic '" + std::string(it->second->name()) +
                    "' has no deadline; expected one in TopicOptions::deadline or the configuration file");
    auto w = std::make_shared<Watchdog>();
    w->callback = std::move(callback);
    auto old = watchdogs_.find(subscription);
    if (old != watchdogs_.end()) w->reported = old->second->reported;  // replaced: no repeat
    watchdogs_[subscription] = std::move(w);
  }
  wake_.fire();  // a spin waiting with an older deadline takes this one's
}

bool Executor::remove(Id id) {
  std::shared_ptr<Handler> gone;  // destroyed outside the lock
  {
    std::lock_guard lock(mutex_);
    if (timers_.erase(id) != 0) return true;
    watchdogs_.erase(id);
    auto it = handlers_.find(id);
    if (it == handlers_.end()) return false;
    gone = std::move(it->second);
    handlers_.erase(it);
  }
  waitset_.detach(id);
  return true;
}

std::optional<TopicMetrics> Executor::metrics(Id id) const {
  std::lock_guard lock(mutex_);
  auto it = handlers_.find(id);
  if (it == handlers_.end()) return std::nullopt;
  return it->second->metrics();
}

void Executor::callback_failed(std::string_view what) noexcept {
  const std::uint64_t n = errors_.fetch_add(1, std::memory_order_relaxed) + 1;
  if (n != 1 && n % 1024 != 0) return;
  std::string why = "an unknown exception";
  try {
    throw;
  } catch (const std::exception& e) {
    why = e.what();
  } catch (...) {
  }
  try {
    detail::log().error("executor: a callback for {} threw: {} ({} callbacks have thrown so far); going on", what, why, n);
  } catch (...) {
  }
}

Clock::time_point Executor::next_timer() const {
  std::lock_guard lock(mutex_);
  auto next = Clock::time_point::max();
  for (const auto& [id, t] : timers_) next = std::min(next, t->next);
  return next;
}

std::size_t Executor::run_due_timers() {
  std::vector<std::shared_ptr<Timer>> due;
  const auto now = Clock::now();
  {
    std::lock_guard lock(mutex_);
    for (const auto& [id, t] : timers_)
      if (t->next <= now) due.push_back(t);
  }
  for (auto& t : due) {
    // The next tick on the fixed grid; ticks already past are skipped, not run in a burst.
    t->next += t->period;
    if (t->next <= now) {
      const auto behind = (now - t->next) / t->period + 1;
      overruns_.fetch_add(static_cast<std::uint64_t>(behind), std::memory_order_relaxed);
      t->next += behind * t->period;
    }
    try {
      t->callback();
    } catch (...) {
      callback_failed("a timer");
    }
  }
  runs_.fetch_add(due.size(), std::memory_order_relaxed);
  return due.size();
}

// The watched subscriptions' next misses (their handles are read on the spinning thread only).
Clock::time_point Executor::next_deadline_miss() const {
  std::lock_guard lock(mutex_);
  auto next = Clock::time_point::max();
  for (const auto& [id, w] : watchdogs_) {
    auto h = handlers_.find(id);
    if (h == handlers_.end()) continue;
    if (const auto due = h->second->next_miss()) next = std::min(next, *due);
  }
  return next;
}

std::size_t Executor::report_deadline_misses() {
  std::vector<std::pair<std::shared_ptr<Handler>, std::shared_ptr<Watchdog>>> watched;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [id, w] : watchdogs_)
      if (auto h = handlers_.find(id); h != handlers_.end()) watched.emplace_back(h->second, w);
  }
  std::size_t n = 0;
  for (auto& [h, w] : watched) {
    const std::uint64_t missed = h->missed();
    if (missed <= w->reported) continue;
    if (h->pending()) {  // a message came meanwhile: handle it first (it may end the silence)
      n += h->drain(*this, kBatch);
      if (h->missed() <= w->reported) continue;
    }
    const std::uint64_t total = h->missed();
    const DeadlineMissed event{h->name(), total, total - w->reported, h->silent_for()};
    w->reported = total;
    ++n;
    runs_.fetch_add(1, std::memory_order_relaxed);
    try {
      w->callback(event);
    } catch (...) {
      callback_failed("a deadline watchdog");
    }
  }
  return n;
}

std::size_t Executor::spin_once(std::chrono::nanoseconds timeout) {
  std::lock_guard spinning(spin_mutex_);
  std::size_t n = run_due_timers() + report_deadline_misses();
  const auto deadline = std::min({n != 0 ? Clock::now() : detail::deadline_after(timeout), next_timer(),
                                  next_deadline_miss()});
  const WaitSet::Result r = waitset_.wait_until(deadline);
  if (r.contains(wake_id_)) wake_.reset();  // before the timers are looked at again
  for (const WaitSet::Id id : r.ready) {
    if (id == stop_id_ || id == wake_id_) continue;
    std::shared_ptr<Handler> h;
    {
      std::lock_guard lock(mutex_);
      auto it = handlers_.find(id);
      if (it == handlers_.end()) continue;  // removed meanwhile
      h = it->second;
    }
    n += h->drain(*this, kBatch);
  }
  return n + run_due_timers() + report_deadline_misses();
}

void Executor::spin_until(Clock::time_point deadline) {
  for (;;) {
    if (stop_.fired()) {
      stop_.reset();
      return;
    }
    const auto now = Clock::now();
    if (now >= deadline) return;
    spin_once(deadline == Clock::time_point::max() ? std::chrono::nanoseconds::max()
                                                   : std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - now));
  }
}

void Executor::spin() { spin_until(Clock::time_point::max()); }

void Executor::spin_for(std::chrono::nanoseconds duration) { spin_until(detail::deadline_after(duration)); }

}  // namespace horus

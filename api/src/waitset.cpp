// Blocking receive: a handle's wait (detail/waiting.hpp), Trigger and WaitSet (horus/waitset.hpp).
// All of them sleep through shm::wait_any on doorbells (horus/shm/doorbell.hpp).
#include "horus/waitset.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <string>
#include <utility>

#include "horus/detail/topic_core.hpp"
#include "horus/detail/waiting.hpp"
#include "horus/shm/doorbell.hpp"
#include "horus/shm/ring.hpp"

namespace horus {

namespace detail {

WaitClock::time_point deadline_after(std::chrono::nanoseconds timeout) noexcept {
  const auto now = WaitClock::now();
  if (timeout <= std::chrono::nanoseconds::zero()) return now;
  if (timeout >= std::chrono::duration_cast<std::chrono::nanoseconds>(WaitClock::time_point::max() - now))
    return WaitClock::time_point::max();
  return now + std::chrono::duration_cast<WaitClock::duration>(timeout);
}

namespace {
// A subscriber entry as a wait item sees it.
struct EntryCtx {
  const shm::Ring* ring;
  std::uint32_t entry;
  std::uint64_t token;
};
bool entry_ready(const void* ctx) noexcept {
  const auto& c = *static_cast<const EntryCtx*>(ctx);
  return c.ring->has_unread(c.entry, c.token);
}
shm::WaitItem entry_item(const EntryCtx& c) noexcept {
  return shm::WaitItem{&c.ring->doorbell(), &c.ring->subscriber(c.entry).waiting, &entry_ready, &c};
}
// The handle behind an attachment still owns its entry (it was not destroyed).
bool entry_alive(const shm::Ring& ring, std::uint32_t entry, std::uint64_t token) noexcept {
  const auto& e = ring.subscriber(entry);
  return e.state.load(std::memory_order_acquire) == shm::SubscriberEntry::kActive &&
         e.owner.load(std::memory_order_relaxed) == token;
}
}  // namespace

bool wait_for_unread(const TopicCore& core, std::uint32_t entry, std::uint64_t token,
                     WaitClock::time_point deadline) noexcept {
  const EntryCtx ctx{&core.ring, entry, token};
  const shm::WaitItem item = entry_item(ctx);
  return shm::wait_any({&item, 1}, deadline);
}

}  // namespace detail

// -- Trigger ----------------------------------------------------------------

Trigger::Trigger() : state_(std::make_shared<State>()) { state_->bell.process_private = 1; }

void Trigger::fire() noexcept {
  state_->fired.store(true, std::memory_order_seq_cst);
  // Waiters arm the doorbell, then look at `fired`; ring_doorbell fences before it looks at the
  // armed bit, so either they see the flag or it sees them armed (no race: the waiter count
  // is not consulted here, unlike a publisher's send).
  shm::ring_doorbell(state_->bell);
}

void Trigger::reset() noexcept { state_->fired.store(false, std::memory_order_seq_cst); }

bool Trigger::fired() const noexcept { return state_->fired.load(std::memory_order_seq_cst); }

// -- WaitSet ----------------------------------------------------------------

struct WaitSet::State {
  struct Attachment {
    Id id = 0;
    detail::WaitTarget topic;                // a topic handle, or
    std::shared_ptr<Trigger::State> trigger;  // a trigger
  };
  mutable std::mutex mutex;
  std::condition_variable left;  // a wait ended (the destructor waits for all to end)
  std::vector<Attachment> list;
  Id next_id = 1;
  int active = 0;  // waits under way (mutex)
  shm::Doorbell bell;  // rung when the list changes or the wait set closes
  std::atomic<std::uint32_t> generation{0};
  std::atomic<bool> closed{false};

  State() { bell.process_private = 1; }

  // Wakes waits so that they take the list again (or see `closed`).
  void changed() noexcept {
    generation.fetch_add(1, std::memory_order_seq_cst);
    (void)bell.word.load(std::memory_order_seq_cst);  // pairs with the waiters' arming (Trigger::fire)
    shm::ring_doorbell(bell);
  }
  // Drops attachments whose topic handle was destroyed (mutex held).
  void prune() {
    std::erase_if(list, [](const Attachment& a) {
      return a.topic.core && !detail::entry_alive(a.topic.core->ring, a.topic.entry, a.topic.token);
    });
  }
};

bool WaitSet::Result::contains(Id id) const noexcept { return std::find(ready.begin(), ready.end(), id) != ready.end(); }

WaitSet::WaitSet() : state_(std::make_shared<State>()) {}

WaitSet::~WaitSet() {
  State& st = *state_;
  st.closed.store(true, std::memory_order_seq_cst);
  st.changed();
  std::unique_lock lock(st.mutex);
  st.left.wait(lock, [&] { return st.active == 0; });
}

Error WaitSet::no_subscriber_error(std::string_view topic) {
  return Error(Errc::LimitReached, "topic '" + std::string(topic) + "': all " + std::to_string(shm::kMaxSubscribers) +
                                       " subscriber entries are in use; cannot attach the handle to a wait set "
                                       "(close other handles)");
}

WaitSet::Id WaitSet::attach_target(detail::WaitTarget target) {
  State& st = *state_;
  Id id = 0;
  {
    std::lock_guard lock(st.mutex);
    st.prune();
    if (st.list.size() >= kMaxAttachments)
      throw Exception(Error(Errc::LimitReached, "wait set: cannot attach more than " + std::to_string(kMaxAttachments) +
                                                    " topics and triggers (the kernel's futex_waitv limit); "
                                                    "use another WaitSet"));
    id = st.next_id++;
    st.list.push_back({id, std::move(target), nullptr});
  }
  st.changed();
  return id;
}

WaitSet::Id WaitSet::attach(const Trigger& trigger) {
  State& st = *state_;
  Id id = 0;
  {
    std::lock_guard lock(st.mutex);
    st.prune();
    if (st.list.size() >= kMaxAttachments)
      throw Exception(Error(Errc::LimitReached, "wait set: cannot attach more than " + std::to_string(kMaxAttachments) +
                                                    " topics and triggers (the kernel's futex_waitv limit); "
                                                    "use another WaitSet"));
    id = st.next_id++;
    st.list.push_back({id, {}, trigger.state_});
  }
  st.changed();
  return id;
}

bool WaitSet::detach(Id id) {
  State& st = *state_;
  bool found = false;
  {
    std::lock_guard lock(st.mutex);
    found = std::erase_if(st.list, [id](const State::Attachment& a) { return a.id == id; }) != 0;
  }
  if (found) st.changed();
  return found;
}

std::size_t WaitSet::size() const {
  std::lock_guard lock(state_->mutex);
  state_->prune();
  return state_->list.size();
}

WaitSet::Result WaitSet::wait(std::chrono::nanoseconds timeout) { return wait_until(detail::deadline_after(timeout)); }

WaitSet::Result WaitSet::wait() { return wait_until(std::chrono::steady_clock::time_point::max()); }

namespace {
struct SelfCtx {
  const WaitSet::State* st;
  std::uint32_t generation;
};
struct TriggerCtx {
  const Trigger::State* st;
};
bool trigger_ready(const void* ctx) noexcept {
  return static_cast<const TriggerCtx*>(ctx)->st->fired.load(std::memory_order_seq_cst);
}
}  // namespace

WaitSet::Result WaitSet::wait_until(std::chrono::steady_clock::time_point deadline) {
  const std::shared_ptr<State> keep = state_;
  State& st = *keep;
  {
    std::lock_guard lock(st.mutex);
    ++st.active;
  }
  Result r;
  std::vector<State::Attachment> list;
  for (;;) {
    std::uint32_t gen = 0;
    {
      std::lock_guard lock(st.mutex);
      st.prune();
      list = st.list;
      gen = st.generation.load(std::memory_order_seq_cst);
    }
    if (st.closed.load(std::memory_order_seq_cst)) {
      r.closed_ = true;
      break;
    }
    // Contexts first (the items point into them), then the items, the wait set's own last.
    std::vector<detail::EntryCtx> entries(list.size());
    std::vector<TriggerCtx> triggers(list.size());
    std::vector<shm::WaitItem> items;
    items.reserve(list.size() + 1);
    for (std::size_t i = 0; i < list.size(); ++i) {
      const auto& a = list[i];
      if (a.trigger) {
        triggers[i].st = a.trigger.get();
        items.push_back({&a.trigger->bell, nullptr, &trigger_ready, &triggers[i]});
      } else {
        entries[i] = {&a.topic.core->ring, a.topic.entry, a.topic.token};
        items.push_back(detail::entry_item(entries[i]));
      }
    }
    const SelfCtx self{&st, gen};
    items.push_back({&st.bell, nullptr,
                     [](const void* ctx) noexcept {
                       const auto& s = *static_cast<const SelfCtx*>(ctx);
                       return s.st->closed.load(std::memory_order_seq_cst) ||
                              s.st->generation.load(std::memory_order_seq_cst) != s.generation;
                     },
                     &self});
    shm::wait_any(items, deadline);
    if (st.closed.load(std::memory_order_seq_cst)) {
      r.closed_ = true;
      break;
    }
    for (std::size_t i = 0; i < list.size(); ++i)
      if (items[i].ready(items[i].ctx)) r.ready.push_back(list[i].id);
    if (!r.ready.empty() || std::chrono::steady_clock::now() >= deadline) break;
    // The list changed (or a wake-up found nothing ready): take it again and wait on.
  }
  {
    std::lock_guard lock(st.mutex);
    --st.active;
  }
  st.left.notify_all();
  return r;
}

}  // namespace horus

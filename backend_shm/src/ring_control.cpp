// The ring's control plane: claiming and releasing lanes and subscriber entries (by owner
// token), and the counts. The protocol and the memory order are described in ring_control.hpp.
#include <signal.h>

#include <algorithm>
#include <cerrno>
#include <atomic>
#include <optional>

#include "horus/shm/doorbell.hpp"
#include "horus/shm/ring_control.hpp"
#include "horus/shm/ring_layout.hpp"

namespace horus::shm {

namespace {
// Raises an atomic high-water mark to at least v.
void raise_to(std::atomic<std::uint32_t>& hwm, std::uint32_t v) {
  std::uint32_t cur = hwm.load(std::memory_order_relaxed);
  while (cur < v && !hwm.compare_exchange_weak(cur, v, std::memory_order_acq_rel)) {
  }
}
}  // namespace

std::optional<std::uint32_t> Ring::claim_lane(std::uint64_t token) const noexcept {
  for (std::uint32_t i = 0; i < kMaxPublishers; ++i) {
    std::uint64_t expected = 0;
    if (lanes_[i].owner.compare_exchange_strong(expected, token, std::memory_order_acq_rel)) {
      raise_to(hdr_->lane_hwm, i + 1);
      return i;
    }
  }
  return std::nullopt;
}

void Ring::release_lane(std::uint32_t lane, std::uint64_t token) const noexcept {
  std::uint64_t expected = token;
  lanes_[lane].owner.compare_exchange_strong(expected, 0, std::memory_order_acq_rel);
}

std::optional<std::uint32_t> Ring::add_subscriber(std::uint64_t token) const noexcept {
  for (std::uint32_t i = 0; i < kMaxSubscribers; ++i) {
    auto& e = subs_[i];
    std::uint32_t expected = SubscriberEntry::kFree;
    if (!e.state.compare_exchange_strong(expected, SubscriberEntry::kClaiming, std::memory_order_acq_rel)) continue;
    // Relaxed: nobody else looks at the entry until the release store of kActive below.
    e.owner.store(token, std::memory_order_relaxed);
    for (std::uint32_t l = 0; l < kMaxPublishers; ++l)
      e.cursor[l].store(lanes_[l].head.load(std::memory_order_acquire), std::memory_order_relaxed);
    e.state.store(SubscriberEntry::kActive, std::memory_order_release);
    raise_to(hdr_->sub_hwm, i + 1);
    // A fleet topic's bridge that stopped receiving (nobody read here) sleeps on the doorbell
    // and resumes when it sees a subscriber: ring it (a no-op when nobody waits).
    ring_doorbell(hdr_->doorbell);
    return i;
  }
  return std::nullopt;
}

void Ring::remove_subscriber(std::uint32_t entry, std::uint64_t token) const noexcept {
  auto& e = subs_[entry];
  if (e.owner.load(std::memory_order_relaxed) != token) return;
  // Losses it never noticed stay counted in the topic's total after it leaves.
  const std::uint64_t unnoticed = unnoticed_losses(entry);
  if (unnoticed != 0) hdr_->dropped_total.fetch_add(unnoticed, std::memory_order_relaxed);
  // A waiter that died blocked (or a handle closed while another thread waits on it) leaves
  // its registrations: they leave the doorbell's count with the entry (doorbell.hpp).
  if (const std::uint32_t w = e.waiting.count.exchange(0, std::memory_order_acq_rel); w != 0)
    hdr_->doorbell.state.fetch_sub(w * Doorbell::kWaiter, std::memory_order_acq_rel);
  e.owner.store(0, std::memory_order_relaxed);
  e.state.store(SubscriberEntry::kFree, std::memory_order_release);
  // A fleet topic's bridge stops receiving when the host's last subscriber leaves: tell it.
  if ((hdr_->doorbell.state.load(std::memory_order_relaxed) >> 32) != 0) ring_doorbell(hdr_->doorbell, Doorbell::kArmedBridge);
}

bool Ring::adopt_lane(std::uint32_t lane, std::uint64_t from, std::uint64_t to) const noexcept {
  if (lane >= kMaxPublishers || from == 0 || to == 0) return false;
  return lanes_[lane].owner.compare_exchange_strong(from, to, std::memory_order_acq_rel);
}

bool Ring::adopt_subscriber(std::uint32_t entry, std::uint64_t from, std::uint64_t to) const noexcept {
  if (entry >= kMaxSubscribers || from == 0 || to == 0) return false;
  auto& e = subs_[entry];
  if (e.state.load(std::memory_order_acquire) != SubscriberEntry::kActive) return false;
  if (!e.owner.compare_exchange_strong(from, to, std::memory_order_acq_rel)) return false;
  if (const std::uint32_t w = e.waiting.count.exchange(0, std::memory_order_acq_rel); w != 0)
    hdr_->doorbell.state.fetch_sub(w * Doorbell::kWaiter, std::memory_order_acq_rel);
  return true;
}

bool Ring::wake_waiters(std::uint32_t classes) const noexcept { return ring_doorbell(hdr_->doorbell, classes); }

std::uint32_t Ring::reap_dead_waiters() const noexcept {
  std::uint32_t reaped = 0;
  const std::uint32_t hwm = std::min(hdr_->sub_hwm.load(std::memory_order_acquire), kMaxSubscribers);
  for (std::uint32_t i = 0; i < hwm; ++i) {
    auto& share = subs_[i].waiting;
    if (share.count.load(std::memory_order_relaxed) == 0) continue;
    const pid_t pid = share.pid.load(std::memory_order_relaxed);
    if (pid <= 0 || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    if (const std::uint32_t n = share.count.exchange(0, std::memory_order_acq_rel); n != 0) {
      hdr_->doorbell.state.fetch_sub(n * Doorbell::kWaiter, std::memory_order_acq_rel);
      reaped += n;
    }
  }
  return reaped;
}

bool Ring::has_unread(std::uint32_t entry, std::uint64_t token) const noexcept {
  return has_unread_except(entry, token, kMaxPublishers);
}

bool Ring::has_unread_except(std::uint32_t entry, std::uint64_t token, std::uint32_t skip) const noexcept {
  const auto& e = subs_[entry];
  if (e.state.load(std::memory_order_acquire) != SubscriberEntry::kActive ||
      e.owner.load(std::memory_order_relaxed) != token)
    return false;
  const std::uint32_t lanes = std::min(hdr_->lane_hwm.load(std::memory_order_acquire), kMaxPublishers);
  for (std::uint32_t l = 0; l < lanes; ++l)
    if (l != skip && lanes_[l].head.load(std::memory_order_acquire) > e.cursor[l].load(std::memory_order_relaxed))
      return true;
  return false;
}

std::uint32_t Ring::publisher_count() const noexcept {
  std::uint32_t n = 0;
  const std::uint32_t hwm = std::min(hdr_->lane_hwm.load(std::memory_order_acquire), kMaxPublishers);
  for (std::uint32_t i = 0; i < hwm; ++i) n += lanes_[i].owner.load(std::memory_order_acquire) != 0 ? 1u : 0u;
  return n;
}

std::uint32_t Ring::subscriber_count() const noexcept {
  std::uint32_t n = 0;
  const std::uint32_t hwm = std::min(hdr_->sub_hwm.load(std::memory_order_acquire), kMaxSubscribers);
  for (std::uint32_t i = 0; i < hwm; ++i)
    n += subs_[i].state.load(std::memory_order_acquire) == SubscriberEntry::kActive ? 1u : 0u;
  return n;
}

std::uint64_t Ring::space_limit(std::uint32_t lane, std::uint64_t head, std::uint64_t self) const noexcept {
  // Without subscribers, act as if one sat at `head`: a cached limit must stay valid for a
  // subscriber that joins later (its cursor starts at the head of that moment, >= head).
  std::uint64_t limit = head + capacity_;
  const std::uint32_t hwm = std::min(hdr_->sub_hwm.load(std::memory_order_acquire), kMaxSubscribers);
  for (std::uint32_t i = 0; i < hwm; ++i) {
    const auto& e = subs_[i];
    if (e.state.load(std::memory_order_acquire) != SubscriberEntry::kActive) continue;
    if (self != 0 && e.owner.load(std::memory_order_relaxed) == self) continue;  // never wait for yourself
    limit = std::min(limit, e.cursor[lane].load(std::memory_order_acquire) + capacity_);
  }
  return limit;
}

std::uint64_t Ring::unnoticed_losses(std::uint32_t entry) const noexcept {
  const auto& e = subs_[entry];
  const std::uint32_t lanes = std::min(hdr_->lane_hwm.load(std::memory_order_acquire), kMaxPublishers);
  std::uint64_t n = 0;
  for (std::uint32_t l = 0; l < lanes; ++l) {
    const std::uint64_t head = lanes_[l].head.load(std::memory_order_acquire);
    const std::uint64_t cur = e.cursor[l].load(std::memory_order_acquire);
    if (head > cur + capacity_) n += head - cur - capacity_;
  }
  return n;
}

std::uint64_t Ring::undetected_losses() const noexcept {
  std::uint64_t n = 0;
  const std::uint32_t hwm = std::min(hdr_->sub_hwm.load(std::memory_order_acquire), kMaxSubscribers);
  for (std::uint32_t i = 0; i < hwm; ++i)
    if (subs_[i].state.load(std::memory_order_acquire) == SubscriberEntry::kActive) n += unnoticed_losses(i);
  return n;
}

std::uint64_t Ring::total_sent() const noexcept {
  std::uint64_t n = 0;
  const std::uint32_t lanes = std::min(hdr_->lane_hwm.load(std::memory_order_acquire), kMaxPublishers);
  for (std::uint32_t l = 0; l < lanes; ++l) n += lanes_[l].head.load(std::memory_order_acquire);
  return n;
}

}  // namespace horus::shm

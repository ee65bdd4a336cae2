// The bridge of a fleet topic in its segment (shm_segment.hpp): which process of the host holds
// it (claim_bridge, release_bridge, bridge_holder), the subscriber entry and lane it holds in
// the ring (record_bridge_export/import), and their hand-over to a successor (inherit_bridge's
// lock_inheritance / unlock_inheritance).
#include "horus/shm/shm_segment.hpp"

#include "horus/shm/engine_board.hpp"

#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>

#include "segment_internal.hpp"

namespace horus::shm {

namespace {
std::uint64_t claim_word(pid_t pid, std::uint32_t slot) noexcept {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(pid)) << 32) | (slot + 1u);
}

// Whether the holder `word` names is a live process still attached as that participant (its
// entry is freed when it detaches or is reaped, and may then go to another process).
bool bridge_holder_alive(const SegmentHeader& h, std::uint64_t word) noexcept {
  const auto pid = static_cast<pid_t>(word >> 32);
  const auto slot = static_cast<std::uint32_t>(word & 0xffff'ffffu) - 1u;
  if (slot >= kMaxParticipants) return false;
  const Participant& e = h.participants[slot];
  if (static_cast<pid_t>(e.pid.load(std::memory_order_acquire)) != pid) return false;
  return process_alive(pid, e.start_time.load(std::memory_order_relaxed));
}
}  // namespace

ShmSegment::BridgeClaim ShmSegment::claim_bridge() noexcept {
  if (header_ == nullptr || slot_ >= kMaxParticipants) return BridgeClaim::Held;
  const std::uint64_t mine = claim_word(::getpid(), slot_);
  BridgeState& b = header_->bridge;
  std::uint64_t cur = b.owner.load(std::memory_order_acquire);
  for (;;) {
    if (cur == mine) return BridgeClaim::Ours;
    const bool takeover = cur != 0;
    if (takeover && bridge_holder_alive(*header_, cur)) return BridgeClaim::Held;
    if (b.owner.compare_exchange_strong(cur, mine, std::memory_order_acq_rel)) {
      b.claims.fetch_add(1, std::memory_order_relaxed);
      b.claimed_unix_ns.store(detail::now_unix_ns(), std::memory_order_relaxed);
      return takeover ? BridgeClaim::TookOver : BridgeClaim::Claimed;
    }
  }
}

void ShmSegment::release_bridge() noexcept {
  if (header_ == nullptr || slot_ >= kMaxParticipants) return;
  std::uint64_t mine = claim_word(::getpid(), slot_);
  // Watchers of other processes see a release on the engine board (a holder that exits is
  // seen through its pidfd instead).
  if (header_->bridge.owner.compare_exchange_strong(mine, 0, std::memory_order_acq_rel)) note_bridge_released();
}

std::uint64_t ShmSegment::bridge_word() const noexcept {
  return header_ == nullptr || slot_ >= kMaxParticipants ? 0 : claim_word(::getpid(), slot_);
}

bool ShmSegment::bridge_word_alive(std::uint64_t word) const noexcept {
  return header_ != nullptr && word != 0 && bridge_holder_alive(*header_, word);
}

bool ShmSegment::transfer_bridge(std::uint64_t to) noexcept {
  if (header_ == nullptr || slot_ >= kMaxParticipants || to == 0) return false;
  std::uint64_t mine = claim_word(::getpid(), slot_);
  if (!header_->bridge.owner.compare_exchange_strong(mine, to, std::memory_order_acq_rel)) return false;
  header_->bridge.claims.fetch_add(1, std::memory_order_relaxed);
  header_->bridge.claimed_unix_ns.store(detail::now_unix_ns(), std::memory_order_relaxed);
  note_bridge_released();  // the host's watchers look again (they watch the new holder from now on)
  return true;
}

void ShmSegment::record_bridge_export(std::uint32_t entry, std::uint64_t token) noexcept {
  if (header_ == nullptr) return;
  header_->bridge.export_entry.store(entry, std::memory_order_relaxed);
  header_->bridge.export_token.store(token, std::memory_order_release);
}

void ShmSegment::record_bridge_import(std::uint32_t lane, std::uint64_t token) noexcept {
  if (header_ == nullptr) return;
  header_->bridge.import_lane.store(lane, std::memory_order_relaxed);
  header_->bridge.import_token.store(token, std::memory_order_release);
}

bool ShmSegment::lock_inheritance(Inheritance& in) noexcept {
  if (header_ == nullptr || fd_ < 0 || !detail::lock_with_deadline(fd_)) return false;
  BridgeState& b = header_->bridge;
  in.export_token = b.export_token.load(std::memory_order_acquire);
  in.import_token = b.import_token.load(std::memory_order_acquire);
  in.inflight = b.inflight.exchange(0, std::memory_order_acq_rel);
  const std::uint32_t entry = b.export_entry.load(std::memory_order_relaxed);
  const std::uint32_t lane = b.import_lane.load(std::memory_order_relaxed);
  // Only what still carries the recorded token (a graceful predecessor may have freed them).
  if (in.export_token != 0 && entry < kMaxSubscribers &&
      ring_.subscriber(entry).owner.load(std::memory_order_acquire) == in.export_token &&
      ring_.subscriber(entry).state.load(std::memory_order_acquire) == SubscriberEntry::kActive)
    in.export_entry = entry;
  if (in.import_token != 0 && lane < kMaxPublishers &&
      ring_.lane(lane).owner.load(std::memory_order_acquire) == in.import_token)
    in.import_lane = lane;
  return true;
}

void ShmSegment::unlock_inheritance(const Inheritance& in) noexcept {
  BridgeState& b = header_->bridge;
  // Whatever the new holder did not adopt is freed now (it would never be reaped otherwise).
  if (in.export_entry) ring_.remove_subscriber(*in.export_entry, in.export_token);
  if (in.import_lane) ring_.release_lane(*in.import_lane, in.import_token);
  std::uint64_t t = in.export_token;
  b.export_token.compare_exchange_strong(t, 0, std::memory_order_acq_rel);
  t = in.import_token;
  b.import_token.compare_exchange_strong(t, 0, std::memory_order_acq_rel);
  ::flock(fd_, LOCK_UN);
}

pid_t ShmSegment::bridge_holder() const noexcept {
  if (header_ == nullptr) return 0;
  const std::uint64_t cur = header_->bridge.owner.load(std::memory_order_acquire);
  return cur != 0 && bridge_holder_alive(*header_, cur) ? static_cast<pid_t>(cur >> 32) : 0;
}

}  // namespace horus::shm

#include "horus/shm/pool.hpp"

#include "horus/shm/shm_segment.hpp"  // process_alive

#include <algorithm>
#include <limits>
#include <new>

namespace horus::shm {

namespace {
constexpr std::uint64_t round_up(std::uint64_t v, std::uint64_t a) noexcept { return (v + a - 1) / a * a; }

struct Layout {
  std::uint64_t stride, slots_offset, data_offset, total;
};

Layout layout_of(const PoolConfig& cfg) noexcept {
  Layout l{};
  l.stride = round_up(cfg.slot_bytes, kPoolPage);
  l.slots_offset = round_up(sizeof(PoolHeader), kCacheLine);
  const std::uint64_t n = std::uint64_t{cfg.slots_per_lane} * kMaxPublishers;
  l.data_offset = round_up(l.slots_offset + n * sizeof(PoolSlot), kPoolPage);
  l.total = l.data_offset + n * l.stride;
  return l;
}
}  // namespace

std::optional<std::string> Pool::check_config(const PoolConfig& cfg) {
  if (cfg.slot_bytes == 0 || cfg.slot_bytes > (std::uint64_t{1} << 31))
    return "pool slot size " + std::to_string(cfg.slot_bytes) + " is out of range; expected 1 byte to 2 GiB";
  if (cfg.slots_per_lane < 2 || cfg.slots_per_lane > kMaxPoolSlotsPerLane)
    return "pool slots per publisher " + std::to_string(cfg.slots_per_lane) + " is out of range; expected 2 to " +
           std::to_string(kMaxPoolSlotsPerLane);
  const std::uint64_t n = std::uint64_t{cfg.slots_per_lane} * kMaxPublishers;
  if (round_up(cfg.slot_bytes, kPoolPage) > (std::uint64_t{1} << 46) / n)
    return "pool of " + std::to_string(n) + " slots of " + std::to_string(cfg.slot_bytes) + " bytes is too large";
  return std::nullopt;
}

std::size_t Pool::required_size(const PoolConfig& cfg) noexcept { return layout_of(cfg).total; }

Pool Pool::format(void* region, const PoolConfig& cfg) noexcept {
  const Layout l = layout_of(cfg);
  auto* h = new (region) PoolHeader{};
  h->magic = kPoolMagic;
  h->slot_bytes = cfg.slot_bytes;
  h->slot_stride = l.stride;
  h->slots_per_lane = cfg.slots_per_lane;
  h->lanes = kMaxPublishers;
  h->slots_offset = l.slots_offset;
  h->data_offset = l.data_offset;
  h->total_size = l.total;
  h->participants.store(1, std::memory_order_relaxed);  // a process-local topic has participant 0
  auto* base = static_cast<std::byte*>(region);
  for (std::uint32_t i = 0; i < cfg.slots_per_lane * kMaxPublishers; ++i)
    new (base + l.slots_offset + i * sizeof(PoolSlot)) PoolSlot{};
  return attach(region);
}

std::optional<std::string> Pool::validate(const void* region, std::size_t size) {
  if (size < sizeof(PoolHeader)) return "the pool is cut off";
  const auto* h = static_cast<const PoolHeader*>(region);
  if (h->magic != kPoolMagic) return "the pool header has a wrong magic number";
  if (h->lanes != kMaxPublishers) return "the pool has " + std::to_string(h->lanes) + " lanes";
  const PoolConfig cfg{h->slot_bytes, h->slots_per_lane};
  if (auto err = check_config(cfg)) return "the pool header is invalid: " + *err;
  const Layout l = layout_of(cfg);
  if (h->slot_stride != l.stride || h->slots_offset != l.slots_offset || h->data_offset != l.data_offset ||
      h->total_size != l.total || l.total > size)
    return "the pool header does not match its layout";
  return std::nullopt;
}

Pool Pool::attach(void* region) noexcept {
  Pool p;
  p.hdr_ = static_cast<PoolHeader*>(region);
  auto* base = static_cast<std::byte*>(region);
  p.slot_bytes_ = p.hdr_->slot_bytes;
  p.stride_ = p.hdr_->slot_stride;
  p.data_offset_ = p.hdr_->data_offset;
  p.slots_per_lane_ = p.hdr_->slots_per_lane;
  p.lanes_ = p.hdr_->lanes;
  p.slots_ = reinterpret_cast<PoolSlot*>(base + p.hdr_->slots_offset);
  p.data_ = reinterpret_cast<std::uint8_t*>(base + p.data_offset_);
  return p;
}

bool Pool::pinned(const PoolSlot& s) const noexcept {
  // Sequentially consistent with admit(): a participant admitted before it pinned is counted.
  const std::uint32_t n = std::min(hdr_->participants.load(std::memory_order_seq_cst), kMaxParticipants);
  for (std::uint32_t p = 0; p < n; ++p)
    if (s.pins[p].load(std::memory_order_seq_cst) != 0) return true;
  return false;
}

void Pool::admit(std::uint32_t p) const noexcept {
  if (p >= kMaxParticipants) return;
  std::uint32_t n = hdr_->participants.load(std::memory_order_seq_cst);
  while (n < p + 1 && !hdr_->participants.compare_exchange_weak(n, p + 1, std::memory_order_seq_cst)) {
  }
}

std::optional<Pool::Claim> Pool::claim(std::uint32_t lane, const Claimer& me, std::uint64_t max_stamp) const noexcept {
  const std::uint32_t n = slots_per_lane_;
  const std::uint32_t first = lane * n;
  // Candidates from the oldest: a lane has at most 64 slots, so a few passes over it are cheap.
  std::uint64_t tried = 0;
  for (std::uint32_t attempt = 0; attempt < n; ++attempt) {
    std::uint32_t best = n;
    std::uint64_t best_stamp = std::numeric_limits<std::uint64_t>::max();
    for (std::uint32_t k = 0; k < n; ++k) {
      if ((tried >> k) & 1u) continue;
      const std::uint64_t st = slots_[first + k].stamp.load(std::memory_order_relaxed);
      if (st > max_stamp) {
        tried |= std::uint64_t{1} << k;
        continue;
      }
      if (st < best_stamp) {
        best_stamp = st;
        best = k;
      }
    }
    if (best == n) break;
    tried |= std::uint64_t{1} << best;
    PoolSlot& s = slots_[first + best];
    if (pinned(s)) continue;
    const std::uint64_t old = s.gen.load(std::memory_order_acquire);
    if ((old & 1u) != 0) {
      // Being written: a loan of a live process (ours included, even of a handle since closed)
      // stays its own; a writer that died mid-write left it, and no descriptor names it.
      const auto pid = s.claimer_pid.load(std::memory_order_relaxed);
      const auto start = s.claimer_start.load(std::memory_order_relaxed);
      if (pid == me.pid && start == me.start_time) continue;
      if (process_alive(static_cast<pid_t>(pid), start)) continue;
    }
    const std::uint64_t gen = (old & 1u) == 0 ? old + 1 : old + 2;
    s.claimer_pid.store(me.pid, std::memory_order_relaxed);
    s.claimer_start.store(me.start_time, std::memory_order_relaxed);
    s.gen.store(gen, std::memory_order_seq_cst);
    if (pinned(s)) {  // a subscriber pinned it meanwhile: leave it to them
      s.gen.store(old, std::memory_order_seq_cst);
      continue;
    }
    return Claim{first + best, gen};
  }
  return std::nullopt;
}

std::uint64_t Pool::publish(const Claim& c, std::uint64_t stamp) const noexcept {
  PoolSlot& s = slots_[c.slot];
  s.stamp.store(stamp, std::memory_order_relaxed);
  s.gen.store(c.gen + 1, std::memory_order_release);
  return c.gen + 1;
}

bool Pool::abandon(const Claim& c) const noexcept {
  PoolSlot& s = slots_[c.slot];
  // Published already (the usual case, a sent loan): a load, not a locked write to a line
  // subscribers are reading.
  if (s.gen.load(std::memory_order_acquire) != c.gen) return false;
  // Only the claim's holder publishes it, and it is giving it back: stamp 0 (reused first) may
  // be stored before the generation changes, never after (the slot could be taken by then).
  s.stamp.store(0, std::memory_order_relaxed);
  std::uint64_t expected = c.gen;
  // c.gen + 1 is a generation no descriptor carries.
  return s.gen.compare_exchange_strong(expected, c.gen + 1, std::memory_order_acq_rel);
}

bool Pool::pin(std::uint32_t i, std::uint64_t gen, std::uint32_t p) const noexcept {
  if (i >= slot_count() || p >= kMaxParticipants || (gen & 1u) != 0) return false;
  if (p >= hdr_->participants.load(std::memory_order_relaxed)) admit(p);  // writers must look at our pins
  PoolSlot& s = slots_[i];
  s.pins[p].fetch_add(1, std::memory_order_seq_cst);
  if (s.gen.load(std::memory_order_seq_cst) == gen) return true;
  s.pins[p].fetch_sub(1, std::memory_order_release);
  return false;
}

void Pool::unpin(std::uint32_t i, std::uint32_t p) const noexcept {
  // Release: our reads of the bytes happen before a writer that sees the pin gone rewrites them.
  slots_[i].pins[p].fetch_sub(1, std::memory_order_release);
}

void Pool::release_participant(std::uint32_t p) const noexcept {
  if (p >= kMaxParticipants) return;
  for (std::uint32_t i = 0; i < slot_count(); ++i) slots_[i].pins[p].store(0, std::memory_order_release);
}

std::uint32_t Pool::pinned_slots() const noexcept {
  std::uint32_t n = 0;
  for (std::uint32_t i = 0; i < slot_count(); ++i) n += pinned(slots_[i]) ? 1u : 0u;
  return n;
}

}  // namespace horus::shm

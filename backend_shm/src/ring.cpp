#include "horus/shm/ring.hpp"

#include <new>

namespace horus::shm {

namespace {
constexpr std::uint64_t align_up(std::uint64_t v, std::uint64_t a) { return (v + a - 1) / a * a; }

struct Offsets {
  std::uint64_t lanes, subs, slots, total;
};

Offsets offsets_for(const RingConfig& cfg) {
  Offsets o{};
  o.lanes = align_up(sizeof(RingHeader), kCacheLine);
  o.subs = align_up(o.lanes + sizeof(LaneHeader) * kMaxPublishers, kCacheLine);
  o.slots = align_up(o.subs + sizeof(SubscriberEntry) * kMaxSubscribers, kCacheLine);
  o.total = o.slots + static_cast<std::uint64_t>(kMaxPublishers) * cfg.capacity * slot_stride_for(cfg.payload_size);
  return o;
}

// Raises an atomic high-water mark to at least v.
void raise_to(std::atomic<std::uint32_t>& hwm, std::uint32_t v) {
  std::uint32_t cur = hwm.load(std::memory_order_relaxed);
  while (cur < v && !hwm.compare_exchange_weak(cur, v, std::memory_order_acq_rel)) {
  }
}
}  // namespace

std::size_t Ring::required_size(const RingConfig& cfg) noexcept { return offsets_for(cfg).total; }

std::optional<std::string> Ring::check_config(const RingConfig& cfg) {
  if (cfg.capacity == 0 || !std::has_single_bit(cfg.capacity))
    return "capacity " + std::to_string(cfg.capacity) + " is not a power of two (expected 1, 2, 4, ... " +
           std::to_string(kMaxCapacity) + ")";
  if (cfg.capacity > kMaxCapacity)
    return "capacity " + std::to_string(cfg.capacity) + " exceeds the maximum of " + std::to_string(kMaxCapacity);
  if (cfg.payload_size == 0) return "message size is 0 bytes";
  if (cfg.payload_size > (1u << 30)) return "message size " + std::to_string(cfg.payload_size) + " exceeds 1 GiB";
  return std::nullopt;
}

Ring::Ring(std::byte* base) noexcept
    : hdr_(std::launder(reinterpret_cast<RingHeader*>(base))),
      lanes_(std::launder(reinterpret_cast<LaneHeader*>(base + hdr_->lanes_offset))),
      subs_(std::launder(reinterpret_cast<SubscriberEntry*>(base + hdr_->subs_offset))),
      slots_(base + hdr_->slots_offset),
      capacity_(hdr_->capacity),
      stride_(hdr_->slot_stride) {}

Ring Ring::format(void* region, const RingConfig& cfg) noexcept {
  auto* base = static_cast<std::byte*>(region);
  const Offsets o = offsets_for(cfg);
  auto* hdr = new (base) RingHeader{};
  hdr->magic = kRingMagic;
  hdr->layout_version = kLayoutVersion;
  hdr->capacity = cfg.capacity;
  hdr->payload_size = cfg.payload_size;
  hdr->slot_stride = slot_stride_for(cfg.payload_size);
  hdr->type_hash = cfg.type_hash;
  hdr->lanes_offset = o.lanes;
  hdr->subs_offset = o.subs;
  hdr->slots_offset = o.slots;
  hdr->total_size = o.total;
  for (std::uint32_t i = 0; i < kMaxPublishers; ++i) new (base + o.lanes + i * sizeof(LaneHeader)) LaneHeader{};
  for (std::uint32_t i = 0; i < kMaxSubscribers; ++i)
    new (base + o.subs + i * sizeof(SubscriberEntry)) SubscriberEntry{};
  // Slots need no construction: a zero sequence means "never written". The caller publishes
  // the region to other threads (the registry's mutex) only after this returns.
  return Ring(base);
}

std::optional<std::string> Ring::validate(const void* region, std::size_t size) {
  if (size < sizeof(RingHeader)) return "region of " + std::to_string(size) + " bytes is too small for a ring header";
  const auto* hdr = static_cast<const RingHeader*>(region);
  if (hdr->magic != kRingMagic) return "bad magic number (not a horus ring)";
  if (hdr->layout_version != kLayoutVersion)
    return "layout version " + std::to_string(hdr->layout_version) + ", expected " + std::to_string(kLayoutVersion);
  if (auto err = check_config({hdr->capacity, hdr->payload_size, hdr->type_hash})) return err;
  const Offsets o = offsets_for({hdr->capacity, hdr->payload_size, hdr->type_hash});
  if (hdr->slot_stride != slot_stride_for(hdr->payload_size) || hdr->lanes_offset != o.lanes ||
      hdr->subs_offset != o.subs || hdr->slots_offset != o.slots || hdr->total_size != o.total)
    return "corrupt ring header (offsets do not match its capacity and message size)";
  if (hdr->total_size > size)
    return "ring needs " + std::to_string(hdr->total_size) + " bytes but the region has " + std::to_string(size);
  return std::nullopt;
}

Ring Ring::attach(void* region) noexcept { return Ring(static_cast<std::byte*>(region)); }

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
    e.owner.store(token, std::memory_order_relaxed);
    for (std::uint32_t l = 0; l < kMaxPublishers; ++l)
      e.cursor[l].store(lanes_[l].head.load(std::memory_order_acquire), std::memory_order_relaxed);
    e.state.store(SubscriberEntry::kActive, std::memory_order_release);
    raise_to(hdr_->sub_hwm, i + 1);
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
  e.owner.store(0, std::memory_order_relaxed);
  e.state.store(SubscriberEntry::kFree, std::memory_order_release);
}

std::uint32_t Ring::publisher_count() const noexcept {
  std::uint32_t n = 0;
  const std::uint32_t hwm = hdr_->lane_hwm.load(std::memory_order_acquire);
  for (std::uint32_t i = 0; i < hwm; ++i) n += lanes_[i].owner.load(std::memory_order_acquire) != 0 ? 1u : 0u;
  return n;
}

std::uint32_t Ring::subscriber_count() const noexcept {
  std::uint32_t n = 0;
  const std::uint32_t hwm = hdr_->sub_hwm.load(std::memory_order_acquire);
  for (std::uint32_t i = 0; i < hwm; ++i)
    n += subs_[i].state.load(std::memory_order_acquire) == SubscriberEntry::kActive ? 1u : 0u;
  return n;
}

std::uint64_t Ring::space_limit(std::uint32_t lane, std::uint64_t head, std::uint64_t self) const noexcept {
  // Without subscribers, act as if one sat at `head`: a cached limit must stay valid for a
  // subscriber that joins later (its cursor starts at the head of that moment, >= head).
  std::uint64_t limit = head + capacity_;
  const std::uint32_t hwm = hdr_->sub_hwm.load(std::memory_order_acquire);
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
  const std::uint32_t lanes = hdr_->lane_hwm.load(std::memory_order_acquire);
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
  const std::uint32_t hwm = hdr_->sub_hwm.load(std::memory_order_acquire);
  for (std::uint32_t i = 0; i < hwm; ++i)
    if (subs_[i].state.load(std::memory_order_acquire) == SubscriberEntry::kActive) n += unnoticed_losses(i);
  return n;
}

std::uint64_t Ring::total_sent() const noexcept {
  std::uint64_t n = 0;
  const std::uint32_t lanes = hdr_->lane_hwm.load(std::memory_order_acquire);
  for (std::uint32_t l = 0; l < lanes; ++l) n += lanes_[l].head.load(std::memory_order_acquire);
  return n;
}

}  // namespace horus::shm

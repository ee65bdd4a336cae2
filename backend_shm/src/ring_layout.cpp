// The ring region: its offsets, formatting a zero-filled region and validating one that
// another process formatted (the map is in ring_layout.hpp).
#include <bit>
#include <new>
#include <optional>
#include <string>

#include "horus/shm/ring_control.hpp"
#include "horus/shm/ring_layout.hpp"

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
      stride_(hdr_->slot_stride),
      payload_size_(hdr_->payload_size) {}

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
  hdr->doorbell.process_private = cfg.process_private ? 1u : 0u;
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

}  // namespace horus::shm

// The broadcast ring behind every local topic.
//
// One ring serves many publishers and many subscribers. Each publisher owns a
// *lane* (a single-writer ring of `capacity` slots), so a send is a handful of
// plain stores: no lock, no read-modify-write, no syscall. Each subscriber keeps
// one cursor per lane and reads every lane in turn, so it sees every message of
// every publisher exactly once and in each publisher's order. A full lane
// overwrites its oldest slot; a subscriber that finds its next slot overwritten
// counts the messages it lost and moves to the oldest one still there.
//
// The memory is one flat region with a fixed layout and offsets only (no
// pointers), so the same code runs on heap memory (process-local topics) and on
// a POSIX shared-memory segment:
//
//   offset 0                    RingHeader            (constants, lane/sub high-water marks, drop total)
//   lanes_offset                LaneHeader[kMaxPublishers]    (owner token, head)
//   subs_offset                 SubscriberEntry[kMaxSubscribers] (state, owner, cursor per lane)
//   slots_offset                lane 0: slot[capacity] | lane 1: slot[capacity] | ...
//
//   slot = [ seq : u64 ][ payload : payload_size rounded up to 8 ]   stride: power of two <= 64 B,
//                                                                   else a multiple of 64 B, so a
//                                                                   small slot never straddles lines
//
// Per-slot sequence (a seqlock): for lane sequence number s, the writer stores
// seq = 2s+1 (writing), the payload, then seq = 2s+2 (committed). A reader that
// wants message s loads seq, copies the payload, and loads seq again: it accepts
// the copy only if both loads saw 2s+2. Anything smaller means "not written
// yet", anything larger means "overwritten: message s is lost". A writer that
// dies mid-write leaves an odd seq, which readers treat as "not written yet", so
// a torn message is never returned. Payload words are copied with
// acquire/release atomic accesses: on x86 those are plain moves, and the code
// stays within the C++ memory model (and ThreadSanitizer can check it).
#pragma once

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>
#include <type_traits>

namespace horus::shm {

inline constexpr std::size_t kCacheLine = 64;
/// Publishers (sending handles) a topic can have at once.
inline constexpr std::uint32_t kMaxPublishers = 32;
/// Subscribers (receiving handles) a topic can have at once.
inline constexpr std::uint32_t kMaxSubscribers = 64;
/// Largest number of slots per lane.
inline constexpr std::uint32_t kMaxCapacity = 1u << 20;
inline constexpr std::uint64_t kRingMagic = 0x3147'4E52'5355'524FULL;  // "ORUSRNG1"
inline constexpr std::uint32_t kLayoutVersion = 1;

struct alignas(kCacheLine) RingHeader {
  // Written once by format(), read-only afterwards.
  std::uint64_t magic;
  std::uint32_t layout_version;
  std::uint32_t capacity;       // slots per lane, a power of two
  std::uint32_t payload_size;   // bytes of one message
  std::uint32_t slot_stride;    // bytes between slots
  std::uint64_t type_hash;      // layout hash of the message type
  std::uint64_t lanes_offset;
  std::uint64_t subs_offset;
  std::uint64_t slots_offset;
  std::uint64_t total_size;
  // Read by every receive; changes only when a new lane or subscriber slot is first used.
  alignas(kCacheLine) std::atomic<std::uint32_t> lane_hwm;  // lanes [0, lane_hwm) may hold data
  std::atomic<std::uint32_t> sub_hwm;                       // entries [0, sub_hwm) may be active
  // Written by publishers: the lane that sent last (for read_latest).
  alignas(kCacheLine) std::atomic<std::uint32_t> latest_lane;
  // Written by subscribers when they detect a loss (slow path only).
  alignas(kCacheLine) std::atomic<std::uint64_t> dropped_total;
};

struct alignas(kCacheLine) LaneHeader {
  std::atomic<std::uint64_t> owner;                     // 0: free, else the publisher's token
  alignas(kCacheLine) std::atomic<std::uint64_t> head;  // next sequence number to write
};

struct alignas(kCacheLine) SubscriberEntry {
  static constexpr std::uint32_t kFree = 0, kClaiming = 1, kActive = 2;
  std::atomic<std::uint32_t> state;
  std::atomic<std::uint64_t> owner;
  // Next sequence the subscriber will read, per lane (published after each read).
  alignas(kCacheLine) std::atomic<std::uint64_t> cursor[kMaxPublishers];
};

static_assert(std::atomic<std::uint64_t>::is_always_lock_free, "the ring needs lock-free 64-bit atomics");
static_assert(std::atomic<std::uint32_t>::is_always_lock_free, "the ring needs lock-free 32-bit atomics");
static_assert(std::is_standard_layout_v<RingHeader> && std::is_standard_layout_v<LaneHeader> &&
                  std::is_standard_layout_v<SubscriberEntry>,
              "ring structures live in shared memory and must have a fixed layout");

/// A hint to the CPU inside a spin loop.
inline void cpu_relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

/// What reading one slot found.
/// Corrupt: a committed serialized slot whose length exceeds the topic's limit (only a
/// damaged shared segment can hold one); the reader skips it and counts it.
enum class ReadStatus { Ok, Empty, Lost, Corrupt };

/// Bytes between consecutive slots for a payload of the given size.
constexpr std::uint32_t slot_stride_for(std::uint32_t payload_size) noexcept {
  const std::uint32_t raw = 8 + ((payload_size + 7u) & ~7u);
  if (raw <= kCacheLine) return std::bit_ceil(raw);
  return static_cast<std::uint32_t>((raw + kCacheLine - 1) / kCacheLine * kCacheLine);
}

/// Default slots per lane: 16 to 1024, more for small messages (about 64 KiB per lane).
constexpr std::uint32_t default_capacity(std::uint32_t payload_size) noexcept {
  const std::uint32_t by_size = std::bit_floor(std::max<std::uint32_t>(1u, (64u * 1024u) / slot_stride_for(payload_size)));
  return std::clamp<std::uint32_t>(by_size, 16u, 1024u);
}

// ---------------------------------------------------------------------------
// Slot access. The payload area is 8-byte aligned; T is never accessed in place.

namespace detail {
inline std::uint64_t load_word(const std::byte* p) noexcept {
  return std::atomic_ref<std::uint64_t>(*const_cast<std::uint64_t*>(reinterpret_cast<const std::uint64_t*>(p)))
      .load(std::memory_order_acquire);
}
inline void store_word(std::byte* p, std::uint64_t w) noexcept {
  std::atomic_ref<std::uint64_t>(*reinterpret_cast<std::uint64_t*>(p)).store(w, std::memory_order_release);
}
inline std::atomic_ref<std::uint64_t> seq_of(std::byte* slot) noexcept {
  return std::atomic_ref<std::uint64_t>(*reinterpret_cast<std::uint64_t*>(slot));
}
inline std::uint64_t load_seq(const std::byte* slot, std::memory_order mo) noexcept {
  return std::atomic_ref<std::uint64_t>(*const_cast<std::uint64_t*>(reinterpret_cast<const std::uint64_t*>(slot)))
      .load(mo);
}
}  // namespace detail

// Bulk copies into and out of a slot that another thread may be writing. A seqlock reader
// may copy bytes while they change and then throws the copy away (the sequence moved), so
// these copies race by design. With ThreadSanitizer they are word-by-word atomics, so the
// race detector checks the protocol; otherwise they are memcpy ordered by fences, as in
// rigtorp::Seqlock and the Linux kernel's seqcount: word atomics cannot be vectorised and
// cost 5x a memcpy on a 32 KiB message (bench/bench_messages.cpp).
#if defined(__SANITIZE_THREAD__)
#define HORUS_SHM_ATOMIC_BULK_COPY 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define HORUS_SHM_ATOMIC_BULK_COPY 1
#endif
#endif

namespace detail {
/// Copies n bytes into slot memory (dst 8-byte aligned); the caller has stored an odd sequence.
inline void copy_to_slot(std::byte* dst, const std::byte* src, std::size_t n) noexcept {
#ifdef HORUS_SHM_ATOMIC_BULK_COPY
  const std::size_t full = n / 8;
  for (std::size_t i = 0; i < full; ++i) {
    std::uint64_t w;
    std::memcpy(&w, src + i * 8, 8);
    store_word(dst + i * 8, w);
  }
  if (n % 8 != 0) {
    std::uint64_t w = 0;
    std::memcpy(&w, src + full * 8, n % 8);
    store_word(dst + full * 8, w);
  }
#else
  std::atomic_thread_fence(std::memory_order_release);  // the odd sequence is visible before any byte
  std::memcpy(dst, src, n);
#endif
}

/// Copies n bytes out of slot memory (src 8-byte aligned); the caller then re-checks the sequence.
inline void copy_from_slot(std::byte* dst, const std::byte* src, std::size_t n) noexcept {
#ifdef HORUS_SHM_ATOMIC_BULK_COPY
  const std::size_t full = n / 8;
  for (std::size_t i = 0; i < full; ++i) {
    const std::uint64_t w = load_word(src + i * 8);
    std::memcpy(dst + i * 8, &w, 8);
  }
  if (n % 8 != 0) {
    const std::uint64_t w = load_word(src + full * 8);
    std::memcpy(dst + full * 8, &w, n % 8);
  }
#else
  std::memcpy(dst, src, n);
  std::atomic_thread_fence(std::memory_order_acquire);  // every byte is read before the sequence re-check
#endif
}
}  // namespace detail

/// Fixed-size messages above this size are copied with copy_to_slot / copy_from_slot (memcpy);
/// smaller ones word by word, which is faster for a few words.
inline constexpr std::size_t kBulkCopyBytes = 256;

/// Writes message number `seq` of a lane into its slot (single writer per lane).
template <class T>
[[gnu::always_inline]] inline void write_slot(std::byte* slot, std::uint64_t seq, const T& msg) noexcept {
  static_assert(std::is_trivially_copyable_v<T>, "ring slots carry trivially copyable messages");
  constexpr std::size_t kFull = sizeof(T) / 8;
  constexpr std::size_t kTail = sizeof(T) % 8;
  auto sq = detail::seq_of(slot);
  sq.store(2 * seq + 1, std::memory_order_relaxed);
  std::byte* dst = slot + 8;
  const auto* src = reinterpret_cast<const std::byte*>(&msg);
  if constexpr (sizeof(T) > kBulkCopyBytes) {
    detail::copy_to_slot(dst, src, sizeof(T));
    sq.store(2 * seq + 2, std::memory_order_release);
    return;
  }
  for (std::size_t i = 0; i < kFull; ++i) {
    std::uint64_t w;
    std::memcpy(&w, src + i * 8, 8);
    detail::store_word(dst + i * 8, w);
  }
  if constexpr (kTail != 0) {
    std::uint64_t w = 0;
    std::memcpy(&w, src + kFull * 8, kTail);
    detail::store_word(dst + kFull * 8, w);
  }
  sq.store(2 * seq + 2, std::memory_order_release);
}

/// Reads message number `seq` of a lane from its slot into `out` (never torn: when the result
/// is not Ok, a large `out` may hold a discarded partial copy and must not be used).
template <class T>
[[gnu::always_inline]] inline ReadStatus read_slot(const std::byte* slot, std::uint64_t seq, T& out) noexcept {
  static_assert(std::is_trivially_copyable_v<T>, "ring slots carry trivially copyable messages");
  constexpr std::size_t kWords = (sizeof(T) + 7) / 8;
  const std::uint64_t want = 2 * seq + 2;
  const std::uint64_t v1 = detail::load_seq(slot, std::memory_order_acquire);
  if (v1 != want) return v1 < want ? ReadStatus::Empty : ReadStatus::Lost;
  if constexpr (sizeof(T) > kBulkCopyBytes) {
    detail::copy_from_slot(reinterpret_cast<std::byte*>(&out), slot + 8, sizeof(T));
    return detail::load_seq(slot, std::memory_order_relaxed) == want ? ReadStatus::Ok : ReadStatus::Lost;
  }
  alignas(T) std::byte buf[kWords * 8];
  const std::byte* src = slot + 8;
  for (std::size_t i = 0; i < kWords; ++i) {
    const std::uint64_t w = detail::load_word(src + i * 8);
    std::memcpy(buf + i * 8, &w, 8);
  }
  if (detail::load_seq(slot, std::memory_order_relaxed) != want) return ReadStatus::Lost;
  std::memcpy(static_cast<void*>(&out), buf, sizeof(T));
  return ReadStatus::Ok;
}

// ---------------------------------------------------------------------------
// Serialized (variable-size) messages. The payload of such a ring is a length word and the
// encoded bytes:  slot = [ seq : u64 ][ length : u64 ][ bytes, padded to 8 ]
// payload_size is 8 + the largest encoded message the topic accepts.

/// A serialized message as read from a slot, into a buffer of `capacity` bytes (Topic sizes
/// it to the topic's limit; it is not zero-filled, so untouched pages cost no memory).
struct ByteMessage {
  std::unique_ptr<std::byte[]> bytes;
  std::size_t capacity = 0;
  std::uint32_t size = 0;  // bytes of the message just read

  void reserve(std::size_t n) {
    if (capacity == n) return;
    bytes.reset(new std::byte[n]);
    capacity = n;
  }
  std::span<const std::byte> view() const noexcept { return {bytes.get(), size}; }
};

/// Largest encoded message a ring with this payload size carries.
constexpr std::uint32_t max_serialized_size(std::uint32_t payload_size) noexcept {
  return payload_size > 8 ? payload_size - 8 : 0;
}

/// Writes the encoded message number `seq` (at most max_serialized_size bytes) into its slot.
inline void write_slot(std::byte* slot, std::uint64_t seq, std::span<const std::byte> msg) noexcept {
  auto sq = detail::seq_of(slot);
  sq.store(2 * seq + 1, std::memory_order_relaxed);
  detail::store_word(slot + 8, msg.size());
  detail::copy_to_slot(slot + 16, msg.data(), msg.size());
  sq.store(2 * seq + 2, std::memory_order_release);
}

/// Reads the encoded message number `seq`. A committed length larger than out.capacity (a
/// corrupt slot) reads as Corrupt, so the message is skipped and counted, never returned.
inline ReadStatus read_slot(const std::byte* slot, std::uint64_t seq, ByteMessage& out) noexcept {
  const std::uint64_t want = 2 * seq + 2;
  const std::uint64_t v1 = detail::load_seq(slot, std::memory_order_acquire);
  if (v1 != want) return v1 < want ? ReadStatus::Empty : ReadStatus::Lost;
  const std::uint64_t len = detail::load_word(slot + 8);
  if (len > out.capacity) {
    // Overwritten since v1 (then Lost), or damaged (then Corrupt).
    return detail::load_seq(slot, std::memory_order_acquire) == want ? ReadStatus::Corrupt : ReadStatus::Lost;
  }
  detail::copy_from_slot(out.bytes.get(), slot + 16, static_cast<std::size_t>(len));
  if (detail::load_seq(slot, std::memory_order_relaxed) != want) return ReadStatus::Lost;
  out.size = static_cast<std::uint32_t>(len);
  return ReadStatus::Ok;
}

/// True if the slot holds message `seq` or a later one (something to read at `seq`).
inline bool slot_has(const std::byte* slot, std::uint64_t seq) noexcept {
  return detail::load_seq(slot, std::memory_order_acquire) >= 2 * seq + 2;
}

// ---------------------------------------------------------------------------

struct RingConfig {
  std::uint32_t capacity = 0;      // slots per lane (power of two)
  std::uint32_t payload_size = 0;  // bytes per message
  std::uint64_t type_hash = 0;
};

/// A non-owning view of a formatted ring region. Copyable; all state lives in the region.
class Ring {
 public:
  Ring() = default;

  /// Bytes a region needs for this configuration.
  static std::size_t required_size(const RingConfig& cfg) noexcept;
  /// Checks a configuration; returns an error text or nothing.
  static std::optional<std::string> check_config(const RingConfig& cfg);
  /// Initialises a zero-filled region of at least required_size(cfg) bytes.
  static Ring format(void* region, const RingConfig& cfg) noexcept;
  /// Attaches to a region formatted by format(); returns an error text on a bad header.
  static std::optional<std::string> validate(const void* region, std::size_t size);
  static Ring attach(void* region) noexcept;

  RingHeader& header() const noexcept { return *hdr_; }
  LaneHeader& lane(std::uint32_t i) const noexcept { return lanes_[i]; }
  SubscriberEntry& subscriber(std::uint32_t i) const noexcept { return subs_[i]; }
  std::byte* lane_slots(std::uint32_t lane) const noexcept {
    return slots_ + static_cast<std::size_t>(lane) * capacity_ * stride_;
  }
  std::uint32_t capacity() const noexcept { return capacity_; }
  std::uint32_t stride() const noexcept { return stride_; }
  explicit operator bool() const noexcept { return hdr_ != nullptr; }

  /// Claims a free lane for a publisher; returns its index, or nothing when all are taken.
  std::optional<std::uint32_t> claim_lane(std::uint64_t token) const noexcept;
  void release_lane(std::uint32_t lane, std::uint64_t token) const noexcept;
  /// Claims a subscriber entry whose cursors start at the lanes' current heads.
  std::optional<std::uint32_t> add_subscriber(std::uint64_t token) const noexcept;
  void remove_subscriber(std::uint32_t entry, std::uint64_t token) const noexcept;

  std::uint32_t publisher_count() const noexcept;
  std::uint32_t subscriber_count() const noexcept;
  /// The lowest head at which writing into `lane` would overwrite a message an active
  /// subscriber has not read: the slowest cursor + capacity, at most head + capacity. The
  /// subscriber entry owned by `self` (the writer's own handle) is not waited for.
  std::uint64_t space_limit(std::uint32_t lane, std::uint64_t head, std::uint64_t self) const noexcept;
  /// Messages subscriber `entry` lagged beyond capacity (overwritten) and has not yet noticed.
  std::uint64_t unnoticed_losses(std::uint32_t entry) const noexcept;
  /// The same, summed over all active subscribers.
  std::uint64_t undetected_losses() const noexcept;
  /// Messages sent on the topic since it was created (all lanes).
  std::uint64_t total_sent() const noexcept;

 private:
  explicit Ring(std::byte* base) noexcept;
  RingHeader* hdr_ = nullptr;
  LaneHeader* lanes_ = nullptr;
  SubscriberEntry* subs_ = nullptr;
  std::byte* slots_ = nullptr;
  std::uint32_t capacity_ = 0;
  std::uint32_t stride_ = 0;
};

// ---------------------------------------------------------------------------

/// The sending side of one handle: owns a lane once it has sent. Not thread-safe.
/// T is a trivially copyable message, or ByteMessage for serialized messages (write_bytes).
template <class T>
class RingWriter {
 public:
  static constexpr bool kBytes = std::is_same_v<T, ByteMessage>;

  RingWriter() = default;
  RingWriter(Ring ring, std::uint64_t token) noexcept : ring_(ring), token_(token), stride_(ring.stride()) {}
  RingWriter(RingWriter&& o) noexcept { *this = std::move(o); }
  RingWriter& operator=(RingWriter&& o) noexcept {
    if (this != &o) {
      release();
      ring_ = o.ring_;
      token_ = o.token_;
      lane_ = o.lane_;
      head_ = o.head_;
      mask_ = o.mask_;
      slots_ = o.slots_;
      lane_head_ = o.lane_head_;
      latest_ = o.latest_;
      space_limit_ = o.space_limit_;
      claim_head_ = o.claim_head_;
      sent_before_ = o.sent_before_;
      stride_ = o.stride_;
      o.lane_ = kNoLane;
      o.slots_ = nullptr;
    }
    return *this;
  }
  ~RingWriter() { release(); }

  bool has_lane() const noexcept { return slots_ != nullptr; }
  /// The lane this writer owns (when has_lane()).
  std::uint32_t lane() const noexcept { return lane_; }
  /// The lane's next sequence number (messages ever written to it).
  std::uint64_t head() const noexcept { return head_; }
  /// Claims a lane; false when every lane of the topic is in use.
  bool ensure_lane() noexcept {
    if (has_lane()) return true;
    auto lane = ring_.claim_lane(token_);
    if (!lane) return false;
    lane_ = *lane;
    lane_head_ = &ring_.lane(lane_).head;
    head_ = lane_head_->load(std::memory_order_acquire);
    claim_head_ = head_;
    mask_ = ring_.capacity() - 1;
    latest_ = &ring_.header().latest_lane;
    space_limit_ = 0;
    slots_ = ring_.lane_slots(lane_);
    return true;
  }

  /// Publishes; overwrites the oldest slot of the lane when it is full. Requires ensure_lane().
  [[gnu::always_inline]] void write(const T& msg) noexcept
    requires(!kBytes)
  {
    commit(msg);
  }

  /// Publishes an encoded message of at most max_serialized_size(payload_size) bytes.
  void write_bytes(std::span<const std::byte> msg) noexcept
    requires kBytes
  {
    commit(msg);
  }

  /// Largest encoded message write_bytes() accepts.
  std::uint32_t max_bytes() const noexcept { return max_serialized_size(ring_.header().payload_size); }

  /// True if write() would not overwrite a message some other subscriber has not read. The limit
  /// is cached (like rigtorp's SPSCQueue caches the read index): subscribers' cursors are
  /// read again only when the cached limit is reached.
  bool has_space(std::uint64_t self_subscriber) noexcept {
    if (head_ < space_limit_) return true;
    space_limit_ = ring_.space_limit(lane_, head_, self_subscriber);
    return head_ < space_limit_;
  }

  /// Reads the subscribers' cursors again (has_space() caches what it read).
  void refresh_space(std::uint64_t self_subscriber) noexcept {
    space_limit_ = ring_.space_limit(lane_, head_, self_subscriber);
  }

  /// After has_space() returned true: every subscriber (but the caller's own) has read the
  /// lane's messages below this sequence number.
  std::uint64_t read_by_all() const noexcept {
    const std::uint64_t cap = mask_ + 1;
    return space_limit_ >= cap ? space_limit_ - cap : 0;
  }

  /// Messages written through this writer (derived from the lane head: no counter on the hot path).
  std::uint64_t sent() const noexcept { return sent_before_ + (has_lane() ? head_ - claim_head_ : 0); }

  void release() noexcept {
    if (has_lane()) {
      sent_before_ += head_ - claim_head_;
      ring_.release_lane(lane_, token_);
    }
    lane_ = kNoLane;
    slots_ = nullptr;
  }

 private:
  static constexpr std::uint32_t kNoLane = ~0u;

  std::size_t stride() const noexcept {
    if constexpr (kBytes) return stride_;
    else return slot_stride_for(sizeof(T));
  }

  template <class P>
  [[gnu::always_inline]] void commit(const P& msg) noexcept {
    const std::uint64_t s = head_;
    write_slot(slots_ + (s & mask_) * stride(), s, msg);
    head_ = s + 1;
    lane_head_->store(s + 1, std::memory_order_release);
    // Only written when it changes, so one publisher keeps this line shared and cheap.
    if (latest_->load(std::memory_order_relaxed) != lane_) latest_->store(lane_, std::memory_order_relaxed);
  }

  // Hot fields first, read on every write.
  std::byte* slots_ = nullptr;  // this lane's slots; null until a lane is claimed
  std::uint64_t head_ = 0;
  std::uint64_t mask_ = 0;
  std::atomic<std::uint64_t>* lane_head_ = nullptr;
  std::atomic<std::uint32_t>* latest_ = nullptr;
  std::uint32_t lane_ = kNoLane;
  std::uint64_t space_limit_ = 0;  // head values below this are known to have space
  std::uint64_t claim_head_ = 0;   // head when the lane was claimed
  std::uint64_t sent_before_ = 0;  // messages sent through lanes released earlier
  Ring ring_;
  std::uint64_t token_ = 0;
  std::size_t stride_ = 0;  // used for ByteMessage only (fixed-size T: a constant)
};

/// The receiving side of one handle: a cursor per lane. Not thread-safe.
/// T is a trivially copyable message, or ByteMessage for serialized messages.
template <class T>
class RingReader {
 public:
  static constexpr bool kBytes = std::is_same_v<T, ByteMessage>;

  RingReader() = default;
  RingReader(Ring ring, std::uint64_t token) noexcept
      : slots_(ring.lane_slots(0)),
        mask_(ring.capacity() - 1),
        lane_bytes_(static_cast<std::size_t>(ring.capacity()) * ring.stride()),
        stride_(ring.stride()),
        lane_hwm_(&ring.header().lane_hwm),
        ring_(ring),
        token_(token) {}
  RingReader(RingReader&& o) noexcept { *this = std::move(o); }
  RingReader& operator=(RingReader&& o) noexcept {
    if (this != &o) {
      unsubscribe();
      slots_ = o.slots_;
      mask_ = o.mask_;
      lane_bytes_ = o.lane_bytes_;
      stride_ = o.stride_;
      lane_hwm_ = o.lane_hwm_;
      shared_cursor_ = o.shared_cursor_;
      next_lane_ = o.next_lane_;
      ring_ = o.ring_;
      token_ = o.token_;
      entry_ = o.entry_;
      lost_ = o.lost_;
      lost_before_ = o.lost_before_;
      skipped_ = o.skipped_;
      delivered_before_ = o.delivered_before_;
      corrupt_ = o.corrupt_;
      corrupt_before_ = o.corrupt_before_;
      std::copy(std::begin(o.cursor_), std::end(o.cursor_), std::begin(cursor_));
      std::copy(std::begin(o.start_), std::end(o.start_), std::begin(start_));
      o.entry_ = kNone;
      o.shared_cursor_ = nullptr;
    }
    return *this;
  }
  ~RingReader() { unsubscribe(); }

  bool subscribed() const noexcept { return shared_cursor_ != nullptr; }
  /// Starts receiving: every message sent from now on is delivered. False when the topic is full.
  bool subscribe() noexcept {
    if (subscribed()) return true;
    auto e = ring_.add_subscriber(token_);
    if (!e) return false;
    entry_ = *e;
    shared_cursor_ = ring_.subscriber(entry_).cursor;
    for (std::uint32_t l = 0; l < kMaxPublishers; ++l)
      start_[l] = cursor_[l] = shared_cursor_[l].load(std::memory_order_relaxed);
    lost_before_ += lost_;
    corrupt_before_ += corrupt_;
    skipped_ = lost_ = corrupt_ = 0;
    return true;
  }
  void unsubscribe() noexcept {
    if (subscribed()) {
      delivered_before_ = delivered();
      ring_.remove_subscriber(entry_, token_);
    }
    entry_ = kNone;
    shared_cursor_ = nullptr;
  }

  /// The token of this reader's subscriber entry (0 when not subscribed).
  std::uint64_t token() const noexcept { return subscribed() ? token_ : 0; }

  /// Messages read() returned (derived from the cursors: no counter on the hot path).
  std::uint64_t delivered() const noexcept {
    if (!subscribed()) return delivered_before_;
    std::uint64_t advanced = 0;
    for (std::uint32_t l = 0; l < kMaxPublishers; ++l) advanced += cursor_[l] - start_[l];
    return delivered_before_ + advanced - lost_ - skipped_ - corrupt_;
  }

  /// Takes the next unread message (round-robin over publishers, FIFO within each).
  [[gnu::always_inline]] bool read(T& out) noexcept {
    const std::uint32_t lanes = lane_hwm_->load(std::memory_order_acquire);
    std::uint32_t lane = next_lane_;
    for (std::uint32_t k = 0; k < lanes; ++k, ++lane) {
      if (lane >= lanes) lane = 0;
      if (read_lane(lane, out)) {
        next_lane_ = lane + 1;
        return true;
      }
    }
    return false;
  }

  /// True if read() would return a message.
  bool has_message() const noexcept {
    const std::uint32_t lanes = lane_hwm_->load(std::memory_order_acquire);
    for (std::uint32_t l = 0; l < lanes; ++l)
      if (slot_has(slot_of(l, cursor_[l]), cursor_[l])) return true;
    return false;
  }

  /// Unread messages still in the ring.
  std::uint64_t pending() const noexcept {
    const std::uint32_t lanes = lane_hwm_->load(std::memory_order_acquire);
    std::uint64_t n = 0;
    for (std::uint32_t l = 0; l < lanes; ++l) {
      const std::uint64_t head = ring_.lane(l).head.load(std::memory_order_acquire);
      if (head > cursor_[l]) n += std::min<std::uint64_t>(head - cursor_[l], ring_.capacity());
    }
    return n;
  }

  /// Corrupt slots read() skipped (serialized messages only; see ReadStatus::Corrupt).
  std::uint64_t corrupt() const noexcept { return corrupt_before_ + corrupt_; }

  /// Messages this subscriber lost to overwrites, including ones not yet noticed by read().
  std::uint64_t lost() const noexcept {
    // The shared cursors mirror cursor_ (published on every advance).
    return lost_before_ + lost_ + (subscribed() ? ring_.unnoticed_losses(entry_) : 0);
  }

  /// Copies the newest message of the topic. When subscribed, everything published before it
  /// counts as read (skipped; losses among them still count as lost), so read() then returns
  /// only newer messages.
  bool read_latest(T& out) noexcept {
    std::uint64_t heads[kMaxPublishers];
    for (int attempt = 0; attempt < 64; ++attempt) {
      // Snapshot every head first: messages sent after this point are never skipped.
      const std::uint32_t lanes = lane_hwm_->load(std::memory_order_acquire);
      for (std::uint32_t l = 0; l < lanes; ++l) heads[l] = ring_.lane(l).head.load(std::memory_order_acquire);
      std::uint32_t lane = ring_.header().latest_lane.load(std::memory_order_acquire);
      if (lane >= lanes || heads[lane] == 0) {
        // The hint is not visible yet: take any lane that has data.
        lane = lanes;
        for (std::uint32_t l = 0; l < lanes; ++l)
          if (heads[l] != 0) lane = l;
        if (lane == lanes) return false;
      }
      // Never go back behind a message this handle already received.
      const std::uint64_t pos = subscribed() ? std::max(heads[lane], cursor_[lane]) : heads[lane];
      const ReadStatus st = read_slot(slot_of(lane, pos - 1), pos - 1, out);
      if (st == ReadStatus::Corrupt) return false;  // the newest message is unreadable (read() counts it)
      if (st != ReadStatus::Ok) {
        cpu_relax();
        continue;
      }
      if (subscribed()) {
        heads[lane] = pos;
        skip_to(heads, lanes);
      }
      return true;
    }
    return false;
  }

 private:
  static constexpr std::uint32_t kNone = ~0u;

  const std::byte* slot_of(std::uint32_t lane, std::uint64_t seq) const noexcept {
    if constexpr (kBytes) return slots_ + lane * lane_bytes_ + (seq & mask_) * stride_;
    else return slots_ + lane * lane_bytes_ + (seq & mask_) * slot_stride_for(sizeof(T));
  }

  [[gnu::always_inline]] bool read_lane(std::uint32_t lane, T& out) noexcept {
    for (;;) {
      const std::uint64_t c = cursor_[lane];
      switch (read_slot(slot_of(lane, c), c, out)) {
        case ReadStatus::Ok:
          cursor_[lane] = c + 1;
          shared_cursor_[lane].store(c + 1, std::memory_order_relaxed);
          return true;
        case ReadStatus::Empty:
          return false;
        case ReadStatus::Lost:
          skip_lost(lane);
          break;
        case ReadStatus::Corrupt:
          ++corrupt_;
          cursor_[lane] = c + 1;
          shared_cursor_[lane].store(c + 1, std::memory_order_relaxed);
          break;
      }
    }
  }

  void advance(std::uint32_t lane, std::uint64_t to) noexcept {
    cursor_[lane] = to;
    shared_cursor_[lane].store(to, std::memory_order_relaxed);
  }

  // Marks everything before heads[] as read: messages still in the ring are skipped, those
  // already overwritten are lost (so dropped counts never go down).
  [[gnu::noinline]] void skip_to(const std::uint64_t* heads, std::uint32_t lanes) noexcept {
    const std::uint64_t cap = ring_.capacity();
    for (std::uint32_t l = 0; l < lanes; ++l) {
      const std::uint64_t to = heads[l];
      if (cursor_[l] >= to) continue;
      const std::uint64_t oldest = to > cap ? to - cap : 0;
      const std::uint64_t gone = oldest > cursor_[l] ? oldest - cursor_[l] : 0;
      skipped_ += to - cursor_[l] - gone;
      lost_ += gone;
      advance(l, to);
      if (gone != 0) ring_.header().dropped_total.fetch_add(gone, std::memory_order_relaxed);
    }
  }

  // Slow path: message cursor_[lane] was overwritten; move to the oldest one still there.
  [[gnu::noinline]] void skip_lost(std::uint32_t lane) noexcept {
    const std::uint64_t c = cursor_[lane];
    const std::uint64_t head = ring_.lane(lane).head.load(std::memory_order_acquire);
    const std::uint64_t cap = ring_.capacity();
    // The oldest message that can still be there is head - cap (unless a write of `head` is
    // under way; then reading it fails again and we come back here one step further).
    const std::uint64_t oldest = head > cap ? head - cap : 0;
    const std::uint64_t next = std::max(c + 1, oldest);
    lost_ += next - c;
    advance(lane, next);  // first, so the topic-wide sum never counts these twice
    ring_.header().dropped_total.fetch_add(next - c, std::memory_order_relaxed);
  }

  // Hot fields first, read on every receive.
  const std::byte* slots_ = nullptr;  // lane 0's first slot
  std::uint64_t mask_ = 0;
  std::size_t lane_bytes_ = 0;
  std::size_t stride_ = 0;  // used for ByteMessage only (fixed-size T: a constant)
  const std::atomic<std::uint32_t>* lane_hwm_ = nullptr;
  std::atomic<std::uint64_t>* shared_cursor_ = nullptr;  // our entry's cursors; null when not subscribed
  std::uint32_t next_lane_ = 0;
  std::uint64_t cursor_[kMaxPublishers]{};
  Ring ring_;
  std::uint64_t token_ = 0;
  std::uint32_t entry_ = kNone;
  std::uint64_t lost_ = 0;              // overwritten before we read them (this subscription)
  std::uint64_t lost_before_ = 0;       // the same, for earlier subscriptions of this handle
  std::uint64_t skipped_ = 0;           // passed over by read_latest (this subscription)
  std::uint64_t delivered_before_ = 0;  // returned by read() in earlier subscriptions
  std::uint64_t corrupt_ = 0;           // skipped by read() as corrupt (this subscription)
  std::uint64_t corrupt_before_ = 0;    // the same, for earlier subscriptions
  std::uint64_t start_[kMaxPublishers]{};
};

}  // namespace horus::shm

// One ring slot and its sequence protocol (a seqlock), for fixed-size and serialized messages.
//
//   slot = [ seq : u64 ][ payload : payload_size rounded up to 8 ]      (layout: ring_layout.hpp)
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
//
// Why each access has the order it has:
// - The committing store 2s+2 is a release and the reader's first load an acquire: that pair
//   is the happens-before edge that makes the payload of message s visible to the reader.
// - The "writing" store 2s+1 is relaxed. What keeps it ahead of the payload is what follows
//   it: every payload word is a release store, so a reader whose copy saw even one word of the
//   new message also sees 2s+1 or later when it loads seq again, and throws its copy away.
//   The memcpy path gets the same order from a release fence between the odd store and the
//   copy (and an acquire fence after the reader's copy), the way the kernel's seqcount does.
// - The reader's second load of seq is relaxed: the acquire word loads before it (or the
//   acquire fence after a memcpy) already keep it after the copy.
// Only the lane's owner writes a slot, so the writer never races another writer here.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <type_traits>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::shm {

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

}  // namespace horus::shm

HORUS_API_END

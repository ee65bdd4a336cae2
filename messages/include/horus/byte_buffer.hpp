// horus::ByteBuffer: the bytes of a large-data message (Image, PointCloud, DepthImage, Tensor).
//
// A buffer either owns its bytes (a heap vector) or borrows them from somewhere that outlives
// it, in practice a slot of a topic's shared-memory pool (backend_shm/pool.hpp):
//
//   * a received image borrows its pool slot read-only: no copy on receipt. The first write
//     through a non-const accessor copies the bytes into the buffer's own storage (copy on
//     write), so a subscriber never changes what another subscriber sees;
//   * a loaned image (Topic::loan) borrows a pool slot writable: the publisher fills it in
//     place, and sending it copies nothing.
//
// Like a vector's iterators, a span or pointer from data() of a read-only borrow is invalidated
// by the first write (which copies the bytes and releases the slot): take views after writing
// (`img.copy_from(img.data())` on a received image reads a released slot).
//
// Copying a ByteBuffer copies the bytes into owned storage (a copy never pins a pool slot);
// moving it moves the borrow. When a borrowing buffer is destroyed, its lease is released,
// which unpins the pool slot.
//
// For reflection, JSON, fmt and the codec a ByteBuffer is a sequence of u8, exactly like the
// std::vector<std::uint8_t> it replaces (same type signature, same hash, same wire format).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

class ByteBuffer {
 public:
  using value_type = std::uint8_t;
  using size_type = std::size_t;
  using iterator = std::uint8_t*;
  using const_iterator = const std::uint8_t*;

  /// What keeps borrowed bytes valid, and what to call when they are no longer used.
  struct Lease {
    std::shared_ptr<const void> owner;                                                  // keeps the memory mapped
    void (*release)(const void* owner, std::uint64_t a, std::uint64_t b) noexcept = nullptr;  // may be null
    std::uint64_t a = 0, b = 0;                                                         // passed to release
  };

  ByteBuffer() = default;
  /// Owns `n` zero bytes.
  explicit ByteBuffer(std::size_t n) : owned_(n, std::uint8_t{0}) {}
  /// Takes ownership of a vector's bytes.
  ByteBuffer(std::vector<std::uint8_t> v) noexcept : owned_(std::move(v)) {}  // NOLINT: implicit on purpose
  /// Borrows `size` bytes at `data`, kept valid by `lease`; writable or read-only (copy on write).
  static ByteBuffer borrow(std::uint8_t* data, std::size_t size, Lease lease, bool writable) noexcept {
    ByteBuffer b;
    b.ptr_ = data;
    b.size_ = size;
    b.lease_ = std::move(lease);
    b.writable_ = writable;
    return b;
  }

  ByteBuffer(const ByteBuffer& o) : owned_(o.begin(), o.end()) {}
  ByteBuffer& operator=(const ByteBuffer& o) {
    if (this != &o) {
      std::vector<std::uint8_t> v(o.begin(), o.end());
      reset_borrow();
      owned_ = std::move(v);
    }
    return *this;
  }
  ByteBuffer(ByteBuffer&& o) noexcept
      : owned_(std::move(o.owned_)),
        ptr_(std::exchange(o.ptr_, nullptr)),
        size_(std::exchange(o.size_, 0)),
        lease_(std::move(o.lease_)),
        writable_(std::exchange(o.writable_, false)) {
    o.lease_.release = nullptr;
  }
  ByteBuffer& operator=(ByteBuffer&& o) noexcept {
    if (this != &o) {
      reset_borrow();
      take(std::move(o));
    }
    return *this;
  }
  ~ByteBuffer() { reset_borrow(); }

  // -- reading (never copies) ------------------------------------------------
  std::size_t size() const noexcept { return ptr_ != nullptr ? size_ : owned_.size(); }
  bool empty() const noexcept { return size() == 0; }
  const std::uint8_t* data() const noexcept { return ptr_ != nullptr ? ptr_ : owned_.data(); }
  const_iterator begin() const noexcept { return data(); }
  const_iterator end() const noexcept { return data() + size(); }
  const std::uint8_t& operator[](std::size_t i) const noexcept { return data()[i]; }
  std::span<const std::uint8_t> view() const noexcept { return {data(), size()}; }

  /// True when the bytes are borrowed (from a pool slot) rather than owned.
  bool borrowed() const noexcept { return ptr_ != nullptr; }
  /// True when writes go to the bytes in place (owned, or a writable borrow such as a loan).
  bool writable() const noexcept { return ptr_ == nullptr || writable_; }

  // -- writing (a read-only borrow is copied into owned storage first) --------
  std::uint8_t* data() { return make_writable(); }
  iterator begin() { return make_writable(); }
  iterator end() { return make_writable() + size(); }
  std::uint8_t& operator[](std::size_t i) { return make_writable()[i]; }
  std::span<std::uint8_t> mutable_view() { return {make_writable(), size()}; }

  /// Resizes; a borrow of another size becomes owned (the new bytes are zero).
  void resize(std::size_t n) {
    if (ptr_ != nullptr && n == size_) return;
    detach();
    owned_.resize(n);
  }
  void clear() noexcept {
    reset_borrow();
    owned_.clear();
  }
  void reserve(std::size_t n) {
    if (ptr_ == nullptr) owned_.reserve(n);
  }
  /// Replaces the bytes; a writable borrow of the same size is overwritten in place.
  template <class It>
  void assign(It first, It last) {
    const auto n = static_cast<std::size_t>(std::distance(first, last));
    if (ptr_ != nullptr && writable_ && n == size_) {
      if constexpr (std::is_pointer_v<It> && sizeof(*first) == 1 &&
                    std::is_trivially_copyable_v<std::remove_cvref_t<decltype(*first)>>) {
        if (n != 0) std::memcpy(ptr_, first, n);  // a byte loop here cost 4x a memcpy on images
      } else {
        std::uint8_t* p = ptr_;
        for (; first != last; ++first) *p++ = static_cast<std::uint8_t>(*first);
      }
      return;
    }
    std::vector<std::uint8_t> v(first, last);
    reset_borrow();
    owned_ = std::move(v);
  }
  void assign(std::size_t n, std::uint8_t value) {
    if (ptr_ != nullptr && writable_ && n == size_) {
      if (n != 0) std::memset(ptr_, value, n);
      return;
    }
    reset_borrow();
    owned_.assign(n, value);
  }

  /// The bytes as a vector: moved out when owned, copied when borrowed. Leaves this empty.
  std::vector<std::uint8_t> take_vector() && {
    std::vector<std::uint8_t> v = ptr_ != nullptr ? std::vector<std::uint8_t>(begin(), end()) : std::move(owned_);
    clear();
    return v;
  }
  std::vector<std::uint8_t> to_vector() const { return {begin(), end()}; }

  friend bool operator==(const ByteBuffer& a, const ByteBuffer& b) noexcept {
    return a.size() == b.size() && (a.size() == 0 || std::memcmp(a.data(), b.data(), a.size()) == 0);
  }

 private:
  std::uint8_t* make_writable() {
    if (ptr_ != nullptr && !writable_) detach();
    return ptr_ != nullptr ? ptr_ : owned_.data();
  }
  // A borrow becomes owned bytes (copied), releasing the lease.
  void detach() {
    if (ptr_ == nullptr) return;
    std::vector<std::uint8_t> v(ptr_, ptr_ + size_);
    reset_borrow();
    owned_ = std::move(v);
  }
  void reset_borrow() noexcept {
    if (ptr_ == nullptr) return;
    if (lease_.release != nullptr) lease_.release(lease_.owner.get(), lease_.a, lease_.b);
    lease_ = Lease{};
    ptr_ = nullptr;
    size_ = 0;
    writable_ = false;
  }
  void take(ByteBuffer&& o) noexcept {
    owned_ = std::move(o.owned_);  // leaves o.owned_ empty (same allocator)
    ptr_ = std::exchange(o.ptr_, nullptr);
    size_ = std::exchange(o.size_, 0);
    lease_ = std::exchange(o.lease_, Lease{});
    writable_ = std::exchange(o.writable_, false);
  }

  std::vector<std::uint8_t> owned_;
  std::uint8_t* ptr_ = nullptr;  // non-null: borrowed
  std::size_t size_ = 0;
  Lease lease_;
  bool writable_ = false;
};

namespace reflect::detail {
// A ByteBuffer reflects, prints, converts to JSON and encodes as the seq<u8> it stands for.
template <>
struct is_std_vector<ByteBuffer> : std::true_type {};
}  // namespace reflect::detail

/// A wire decoder's option (horus::cdr::decode, horus::lcm::decode): where the bytes of a
/// ByteBuffer field go (by default, a buffer of its own). A topic lends a pool slot, so a
/// received image is copied once: from the sample into the slot. `place` makes `out` a
/// writable buffer of `n` bytes, or returns false.
struct ByteSink {
  void* context = nullptr;
  bool (*place)(void* context, std::size_t n, ByteBuffer& out) = nullptr;
};

}  // namespace horus

HORUS_API_END

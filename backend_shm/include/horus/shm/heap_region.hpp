// Zero-filled, page-aligned memory for process-local rings.
//
// Anonymous mmap gives the same properties as a shared-memory segment: zero
// pages, fixed addresses, and memory that is committed only when touched (the
// lanes of publishers that never appear cost no RAM).
#pragma once

#include <cstddef>
#include <utility>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::shm {

class HeapRegion {
 public:
  HeapRegion() = default;
  /// Maps `size` zeroed bytes; throws std::bad_alloc when the system refuses.
  explicit HeapRegion(std::size_t size);
  HeapRegion(HeapRegion&& o) noexcept : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)) {}
  HeapRegion& operator=(HeapRegion&& o) noexcept {
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    return *this;
  }
  HeapRegion(const HeapRegion&) = delete;
  HeapRegion& operator=(const HeapRegion&) = delete;
  ~HeapRegion();

  void* data() const noexcept { return data_; }
  std::size_t size() const noexcept { return size_; }

 private:
  void* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace horus::shm

HORUS_API_END

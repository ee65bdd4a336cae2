#include "horus/shm/heap_region.hpp"

#include <sys/mman.h>

#include <new>

namespace horus::shm {

HeapRegion::HeapRegion(std::size_t size) : size_(size) {
  void* p = ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  data_ = p;
}

HeapRegion::~HeapRegion() {
  if (data_ != nullptr) ::munmap(data_, size_);
}

}  // namespace horus::shm

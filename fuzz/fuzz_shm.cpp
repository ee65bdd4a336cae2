// libFuzzer target: a topic's shared-memory segment as another process could leave it (segment
// header, signature, ring, pool). The input's first byte picks the topic the harness opens (a
// fixed-size message, a serialized one, large data with a pool), the rest is the file. The
// harness marks itself as a live participant of the file (else horus reclaims an abandoned
// file by formatting it, and the fuzzer's bytes are never read), then: the read-only view of the
// tools (SegmentView), the attach of a topic (ShmSegment::open: header, ring and pool checks),
// and a subscriber that reads what the lanes hold.
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstring>
#include <memory>
#include <string>

#include "horus/shm/ring.hpp"
#include "horus/shm/shm_segment.hpp"

namespace {

using namespace horus::shm;

std::size_t participants_offset() {
  static const std::size_t off = [] {
    auto h = std::make_unique<SegmentHeader>();
    return static_cast<std::size_t>(reinterpret_cast<const char*>(&h->participants[0]) -
                                    reinterpret_cast<const char*>(h.get()));
  }();
  return off;
}

struct Fixed {
  std::uint8_t bytes[40];
};

template <class T>
void read_some(const Ring& ring, std::size_t capacity) {
  RingReader<T> r(ring, (std::uint64_t{static_cast<std::uint32_t>(::getpid())} << 32) | 7u);
  if (!r.subscribe()) return;
  T out{};
  if constexpr (std::is_same_v<T, ByteMessage>) out.reserve(capacity);
  (void)r.pending();
  (void)r.has_message();
  for (int i = 0; i < 64 && r.read(out); ++i) {
  }
  (void)r.read_latest(out);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const std::string ns = "fuzz" + std::to_string(::getpid());
  static const std::string name = segment_name(ns, "t");
  std::string file(reinterpret_cast<const char*>(data + 1), size - 1);
  // This process is participant 0 (alive, with its start time): the segment is attached, not reclaimed.
  const std::size_t at = participants_offset();
  if (file.size() >= at + 16) {
    const auto pid = static_cast<std::uint32_t>(::getpid());
    const std::uint64_t start = process_start_time(::getpid());
    std::memcpy(file.data() + at, &pid, sizeof pid);
    std::memcpy(file.data() + at + 8, &start, sizeof start);
  }
  const int fd = ::shm_open(name.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return 0;
  const bool written = ::write(fd, file.data(), file.size()) == static_cast<ssize_t>(file.size());
  ::close(fd);
  if (written) {
    if (auto view = SegmentView::open(name)) {
      (void)view->signature();
      (void)view->ring().publisher_count();
      (void)view->ring().subscriber_count();
      (void)view->ring().undetected_losses();
      if (view->pool()) (void)view->pool().pinned_slots();
    }
    SegmentSpec spec;
    const std::uint8_t kind = data[0] % 3;
    spec.type_name = kind == 0 ? "fuzz::Fixed" : kind == 1 ? "fuzz::Bytes" : "fuzz::Large";
    spec.type_hash = 0x1234u + kind;
    spec.serialized = kind != 0;
    spec.payload_size = kind == 0 ? sizeof(Fixed) : 8 + 1024;
    spec.capacity = 4;
    spec.payload_required = false;
    spec.pool_required = false;
    if (kind == 2) {
      spec.pool_slot_bytes = 4096;
      spec.pool_slots_per_lane = 2;
    }
    if (auto seg = ShmSegment::open(ns, "t", spec)) {
      if (kind == 0) read_some<Fixed>(seg->ring(), 0);
      else read_some<ByteMessage>(seg->ring(), max_serialized_size(seg->ring().payload_size()));
    }
  }
  ::shm_unlink(name.c_str());
  return 0;
}

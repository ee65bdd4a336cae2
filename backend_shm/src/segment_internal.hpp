// What shm_segment.cpp and segment_bridge.cpp share, internal to backend_shm/src: the
// membership lock with its deadline and the wall clock the segment header records.
#pragma once

#include <cstdint>

namespace horus::shm::detail {

// flock with a deadline: a holder that died has released the lock; a live one holds it only
// while it changes membership, so waiting seconds means something is wrong.
bool lock_with_deadline(int fd);

// Now, in nanoseconds since the Unix epoch (system_clock).
std::uint64_t now_unix_ns();

}  // namespace horus::shm::detail

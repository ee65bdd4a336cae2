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
// This header includes the whole ring; each part has its own header:
//   ring_layout.hpp    the region's layout (map of the memory), constants, strides, RingConfig
//   seqlock_slot.hpp   the per-slot sequence protocol; fixed-size and serialized (ByteMessage) slots
//   ring_control.hpp   Ring: the view of a region, claiming lanes and subscriber entries, counts,
//                      and the memory order of the heads and cursors
//   ring_writer.hpp    RingWriter<T>, the sending hot path
//   ring_reader.hpp    RingReader<T>, the receiving hot path
#pragma once

// What this header included before it was split, for files that rely on it.
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
#include <type_traits>
#include <vector>

#include "horus/shm/ring_control.hpp"
#include "horus/shm/ring_layout.hpp"
#include "horus/shm/ring_reader.hpp"
#include "horus/shm/ring_writer.hpp"
#include "horus/shm/seqlock_slot.hpp"

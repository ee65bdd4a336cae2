// What horus-fanout reads of the machine and of itself, besides its measurements: the RSS, the
// /dev/shm files of a topic, the TSC flags and the open-file limit. A file of its own so that
// horus_fanout.cpp keeps to the measurements and their tables.
#pragma once

#include <cstdint>
#include <string>
#include <utility>

namespace horus::bench::fanout {

/// This process's resident set, in KiB (/proc/self/statm).
long rss_kib();

/// The /dev/shm files of a topic: size (virtual) and allocated bytes.
std::pair<std::uint64_t, std::uint64_t> segment_bytes(const std::string& topic);

/// Whether /proc/cpuinfo has constant_tsc and nonstop_tsc (cross-process TSC stamps compare).
bool tsc_is_invariant();

/// Raises the soft limit of open files to the hard one (1000 topics hold many descriptors).
void raise_fd_limit();

}  // namespace horus::bench::fanout

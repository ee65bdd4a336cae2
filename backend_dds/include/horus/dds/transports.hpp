// The DDS transports: one participant per process and configuration, shared by every topic
// that uses it (released when the last topic closes). Built when the packages are present
// (HORUS_WITH_CYCLONEDDS, HORUS_WITH_FASTDDS); Topic<T> reaches them through
// HORUS_BACKEND=cyclonedds|fastdds or TopicOptions::backend.
#pragma once

#include <memory>

#include "horus/error.hpp"
#include "horus/network.hpp"

namespace horus::dds {

/// Cyclone DDS (C API): UDP only (its iceoryx shared-memory transport is off), XCDR1.
Result<std::shared_ptr<net::Transport>> cyclone_transport(const net::Config& config);

/// Fast DDS (C++ API): UDPv4 only (no shared-memory transport, no data sharing), XCDR1.
Result<std::shared_ptr<net::Transport>> fastdds_transport(const net::Config& config);

}  // namespace horus::dds

// Blocking receive, not a template: api/src/waiting.cpp. A handle waits on its topic's doorbell
// (horus/shm/doorbell.hpp) for its own subscriber entry to have an unread message; a WaitSet
// holds a WaitTarget per attached handle. Internal to horus: users include <horus/topic.hpp>
// and <horus/waitset.hpp>.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::detail {

struct TopicCore;

/// One subscribing handle, as a wait sees it: its topic (kept mapped) and subscriber entry.
struct WaitTarget {
  std::shared_ptr<TopicCore> core;
  std::uint32_t entry = 0;
  std::uint64_t token = 0;
};

using WaitClock = std::chrono::steady_clock;

/// now + timeout, saturating (a huge timeout waits forever: WaitClock::time_point::max()).
WaitClock::time_point deadline_after(std::chrono::nanoseconds timeout) noexcept;

/// Blocks until subscriber `entry` (owned by `token`) of the topic has an unread message, or
/// `deadline`; true when it has one.
bool wait_for_unread(const TopicCore& core, std::uint32_t entry, std::uint64_t token,
                     WaitClock::time_point deadline) noexcept;

}  // namespace horus::detail

HORUS_API_END

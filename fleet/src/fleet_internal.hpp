// What the fleet agent (agent.cpp), the bridges (bridge.cpp) and horus::Fleet (fleet.cpp) share: how the fleet
// layer's topics are opened, and this host's identity.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

#include "horus/backend.hpp"
#include "horus/fleet_messages.hpp"

namespace horus::fleet::detail {

/// The prefix of the fleet layer's own topics (they do not keep the host announced).
inline constexpr std::string_view kFleetTopicPrefix = "horus.fleet.";


/// The fleet layer's topics on `transport`: heartbeats best effort, announcements and requests
/// reliable; the slot sizes bound what a host can announce.
inline constexpr std::size_t kHeartbeatBytes = 16 * 1024;
inline constexpr std::size_t kAnnouncementBytes = 256 * 1024;
TopicOptions heartbeat_options(const std::string& transport);
TopicOptions announce_options(const std::string& transport);
TopicOptions request_options(const std::string& transport);

/// Nanoseconds of the steady clock (what heartbeats carry and echo).
std::uint64_t steady_ns() noexcept;

}  // namespace horus::fleet::detail

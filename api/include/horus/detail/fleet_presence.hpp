// How a fleet topic keeps its host visible to the fleet, without api/ knowing the fleet layer.
//
// The fleet layer (discovery/: announcements, heartbeats, horus::Fleet) installs a hook once,
// from the composition root (horus::horus). Each fleet topic's bridge then holds a presence for
// its transport while it is open: the first presence of a transport starts this process's fleet
// agent for it (which announces the host when this process holds the host's bridge of
// horus.fleet.heartbeat), the last one released stops it. Topics named horus.fleet.* (the
// agent's own) hold none. Internal to horus.
#pragma once

#include <memory>
#include <string_view>

#include "horus/error.hpp"

namespace horus::detail {

/// The prefix of the fleet layer's own topics.
inline constexpr std::string_view kFleetTopicPrefix = "horus.fleet.";

using FleetPresence = std::shared_ptr<void>;
using FleetPresenceHook = FleetPresence (*)(std::string_view transport);

/// Installed by the fleet layer; later calls replace it (nullptr removes it).
void set_fleet_presence_hook(FleetPresenceHook hook) noexcept;
/// Keeps this host announced on `transport` while held: nullptr when no hook is installed.
/// Fleet topics take one (but the fleet layer's own, horus.fleet.*), and so does horus::Fleet.
FleetPresence acquire_fleet_presence(std::string_view transport);
/// Whether this process may bridge fleet topics (HORUS_BRIDGE is not 0): only such a process
/// can announce its host.
Result<bool> may_bridge_from_environment();

}  // namespace horus::detail

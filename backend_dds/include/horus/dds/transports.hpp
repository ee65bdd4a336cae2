// The DDS transports: one participant per process and configuration, shared by every topic
// that uses it (released when the last topic closes). Built when the packages are present
// (HORUS_WITH_CYCLONEDDS, HORUS_WITH_FASTDDS); each registers itself by name
// (horus/transport_registry.hpp), and Topic<T> reaches it through
// HORUS_BACKEND=cyclonedds|fastdds or TopicOptions::backend. With libhorus.so (HORUS_SHARED) the
// two transports are plug-ins (docs/ABI.md): topic_name is in the library, the rest in
// <libdir>/horus0/libhorus-<name>.so, reached through net::find_transport(name).
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "horus/error.hpp"
#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::dds {

/// The DDS topic name of a horus topic: "horus/" + the name with '.' made '/'
/// ("fleet.robot_1.pose" -> "horus/fleet/robot_1/pose"). DDS topic names allow letters,
/// digits, '_' and '/' only, so a name with '-' is an error (InvalidName); so is a name that
/// breaks horus's own rules (validate_topic_name).
Result<std::string> topic_name(std::string_view topic);

/// The USER_DATA of every horus participant: "enclave=/;", as ROS 2's rmw layers give theirs (its
/// security enclave, the root one), so that ROS 2's graph tools see a ROS 2 participant.
inline constexpr std::string_view kParticipantUserData = "enclave=/;";

/// Adds the transport to the registry ("cyclonedds" / "fastdds", XCDR1, topic_name, and a
/// factory that reads HORUS_DOMAIN_ID and HORUS_DDS_LOCALHOST). Defined only when built.
void register_cyclonedds();
void register_fastdds();

/// Cyclone DDS (C API): UDP only (its iceoryx shared-memory transport is off), XCDR1.
Result<std::shared_ptr<net::Transport>> cyclone_transport(const net::Config& config);

/// Fast DDS (C++ API): UDPv4 only (no shared-memory transport, no data sharing), XCDR1.
/// `control`: the second participant of the process, for the fleet layer's own topics
/// (net::TransportInfo::open_control).
Result<std::shared_ptr<net::Transport>> fastdds_transport(const net::Config& config, bool control = false);

}  // namespace horus::dds

HORUS_API_END

// The environment variables horus reads, read in one place.
//
// Only core/src/environment.cpp calls getenv, and only the process context
// (horus/detail/process.hpp) calls read(). An operation takes the snapshot with the
// configuration file once (horus::Settings, api/include/horus/settings.hpp) and passes it, or
// values from it, down as parameters: a transport opens with a net::Config, the fleet agent with
// FleetSettings.
// An empty string means unset (horus treats `VAR=` as unset everywhere).
#pragma once

#include <string>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

struct Environment {
  std::string config;              // HORUS_CONFIG: the configuration file
  std::string backend;             // HORUS_BACKEND: auto, shm, inproc, cyclonedds, fastdds, lcm
  std::string domain_id;           // HORUS_DOMAIN_ID: the DDS domain
  std::string dds_localhost;       // HORUS_DDS_LOCALHOST: DDS on loopback only
  std::string horus_lcm_url;       // HORUS_LCM_URL: the LCM URL of horus's topics
  std::string lcm_default_url;     // LCM_DEFAULT_URL: liblcm's own variable, when HORUS_LCM_URL is unset
  std::string peers;               // HORUS_PEERS: unicast discovery to these hosts, multicast off
  std::string security;            // HORUS_SECURITY: enforce, permissive or off (DDS-Security)
  std::string security_keystore;   // HORUS_SECURITY_KEYSTORE: the keystore directory
  std::string security_identity;   // HORUS_SECURITY_IDENTITY: this host's identity in it
  std::string fleet_heartbeat_ms;  // HORUS_FLEET_HEARTBEAT_MS: the fleet layer's heartbeat period
  std::string bridge;              // HORUS_BRIDGE: 0 keeps this process from bridging fleet topics
  std::string shm_namespace;       // HORUS_NAMESPACE: the shared-memory namespace
  std::string shm_mode;            // HORUS_SHM_MODE: the mode of new segments
  std::string log_level;           // HORUS_LOG_LEVEL: the library logger's level
  std::string log_topics;          // HORUS_LOG_TOPICS: topics whose traffic is logged (patterns, `!` for off)
  std::string ros2_node;           // HORUS_ROS2_NODE: this process's node on the ROS 2 graph ([/namespace/]name)
  std::string test_clock_offset_ms;  // HORUS_TEST_CLOCK_OFFSET_MS: tests only, shifts this host's heartbeat clock

  /// The variables as they are now.
  static Environment read();
  bool operator==(const Environment&) const = default;
};

}  // namespace horus

HORUS_API_END

#include "horus/environment.hpp"

#include <cstdlib>

namespace horus {

namespace {
std::string variable(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr ? std::string(v) : std::string();
}
}  // namespace

Environment Environment::read() {
  Environment e;
  e.config = variable("HORUS_CONFIG");
  e.backend = variable("HORUS_BACKEND");
  e.domain_id = variable("HORUS_DOMAIN_ID");
  e.dds_localhost = variable("HORUS_DDS_LOCALHOST");
  e.horus_lcm_url = variable("HORUS_LCM_URL");
  e.peers = variable("HORUS_PEERS");
  e.security = variable("HORUS_SECURITY");
  e.security_keystore = variable("HORUS_SECURITY_KEYSTORE");
  e.security_identity = variable("HORUS_SECURITY_IDENTITY");
  e.test_clock_offset_ms = variable("HORUS_TEST_CLOCK_OFFSET_MS");
  e.lcm_default_url = variable("LCM_DEFAULT_URL");
  e.fleet_heartbeat_ms = variable("HORUS_FLEET_HEARTBEAT_MS");
  e.bridge = variable("HORUS_BRIDGE");
  e.shm_namespace = variable("HORUS_NAMESPACE");
  e.shm_mode = variable("HORUS_SHM_MODE");
  e.log_level = variable("HORUS_LOG_LEVEL");
  e.log_topics = variable("HORUS_LOG_TOPICS");
  e.ros2_node = variable("HORUS_ROS2_NODE");
  return e;
}

}  // namespace horus

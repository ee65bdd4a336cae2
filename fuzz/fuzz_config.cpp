// libFuzzer target: the configuration file (HORUS_CONFIG) as YAML text: sections, keys, rules,
// quantities (bandwidths, durations), patterns; then a choice for a few topic names, and the
// network settings the file gives (its security: section checked as a transport would).
#include <string_view>

#include "horus/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto c = horus::Config::parse(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
  if (!c) return 0;
  for (const char* topic : {"robot.cmd_vel", "fleet.camera.front", "a"}) (void)c->match(topic);
  (void)horus::net::config_of(*c);
  return 0;
}

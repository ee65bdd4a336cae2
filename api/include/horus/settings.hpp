// What one operation takes from the process once and passes down: the settings.
//
// Opening a topic, a horus::Fleet or the fleet agent starts with Settings::current(): the
// process context's environment snapshot (horus::detail::Process) and the configuration file
// HORUS_CONFIG names in it. The operation then passes that object, or the values it needs from
// it, to every layer below: the topic's choice, its placement in shared memory, its bridge, the
// network engine, the agent. No layer asks the process for a setting on its own; only
// Settings::current() does (and the logger, for its level, before anything else runs).
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "horus/config.hpp"
#include "horus/environment.hpp"
#include "horus/error.hpp"
#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

struct Settings {
  std::shared_ptr<const Environment> environment;  // never null
  const Config* file = nullptr;                    // HORUS_CONFIG's file; nullptr: none

  const Environment& env() const noexcept { return *environment; }

  /// The process's settings now: the context's snapshot and the file it names (read once per
  /// value of HORUS_CONFIG). An error names the file and what is wrong in it.
  static Result<Settings> current();
  /// The process's environment with `file` in place of HORUS_CONFIG's (nullptr: no file): what
  /// a program would get if HORUS_CONFIG named it (`horus config explain --file`).
  static Settings with_file(const Config* file);
};

/// The transports' settings: the environment (HORUS_DOMAIN_ID, HORUS_DDS_LOCALHOST,
/// HORUS_LCM_URL, LCM_DEFAULT_URL) over the file's `network:` section (net::config_from).
Result<net::Config> network_config(const Settings& settings);
/// A topic's choice (horus/config.hpp's choose()) from these settings.
Result<TopicChoice> choose(std::string_view topic, const TopicOptions& code, const Settings& settings);
/// The fleet layer's settings and transport (horus/config.hpp's fleet_settings()).
Result<FleetSettings> fleet_settings(const Settings& settings);
Result<std::string> fleet_transport(const Settings& settings);

}  // namespace horus

HORUS_API_END

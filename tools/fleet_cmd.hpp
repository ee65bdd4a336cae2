// horus fleet (fleet_cmd.cpp), and what the topic commands (topic_cmd.cpp) share of the fleet
// layer: where the fleet is watched, opening it, waiting for its hosts, a host's topic as JSON.
#pragma once

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>

#include "horus/fleet.hpp"

namespace horus::tools {

// Where the fleet commands look: --backend, else HORUS_BACKEND's network backend, else the file's
// network.backend; empty when none is configured (the commands then stay on this host).
std::string fleet_transport(const std::string& backend_flag);

// The fleet layer on `transport`, or nothing with `error` set.
std::unique_ptr<horus::Fleet> open_fleet(const std::string& transport, std::string& error);

// Waits `wait` for the fleet's hosts to answer (open() asked each to announce itself), or
// less: once every host heard of has announced and a quarter of `wait` passed (or `stop`).
void settle(const horus::Fleet& fleet, std::chrono::milliseconds wait, const std::atomic<bool>& stop);

// One topic a host announces, as horus fleet --json and horus topic list --json print it.
nlohmann::json fleet_topic_json(const horus::FleetTopic& t);

// horus fleet [--json] [--once] [--wait MS] [--duration S] [--backend B].
int cmd_fleet(const std::string& backend, bool json, bool once, int wait_ms, double duration_s,
              const std::atomic<bool>& stop);

}  // namespace horus::tools

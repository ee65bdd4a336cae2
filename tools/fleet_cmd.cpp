// horus fleet (fleet_cmd.hpp): the fleet's hosts as a live table or JSON, through the fleet
// layer (horus/fleet.hpp); and the pieces of it the topic commands share (fleet_transport,
// open_fleet, settle, fleet_topic_json).
#include "fleet_cmd.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "horus/config.hpp"
#include "horus/fleet.hpp"
#include "horus/security/keystore.hpp"

namespace horus::tools {

namespace {

using clock_type = std::chrono::steady_clock;

// Whether this host's fleet participants run under DDS-Security: decided, as in every process
// of the host, by its configuration (net::Security) and its identity's files. Under it, every
// host the fleet layer hears passed DDS-Security's authentication and access control.
struct SecurityState {
  bool secure = false;
  std::string text;  // one line for the table
  nlohmann::json json;
};

SecurityState read_security_state(const std::string& transport) {
  SecurityState s;
  const auto net = horus::net::config_from_environment();
  const net::Security sec = net ? net->security : net::Security{};
  std::optional<security::ParticipantFiles> files;
  if (transport != "lcm" && sec.mode != net::SecurityMode::Off) {
    auto got = security::secure_participant(sec, "horus fleet");
    if (got) files = std::move(*got);
  }
  s.secure = files.has_value();
  s.json = {{"mode", std::string(net::to_string(sec.mode))}, {"authenticated", s.secure}};
  if (s.secure) {
    s.json["identity"] = sec.identity;
    s.json["subject"] = files->subject;
    s.json["keystore"] = sec.keystore;
    s.text = fmt::format("security: {}, this host is {} ({}): every host listed was authenticated by DDS-Security "
                         "with the keystore's CA ({})",
                         net::to_string(sec.mode), sec.identity, files->subject, sec.keystore);
  } else {
    s.text = fmt::format("security: {}: hosts are not authenticated (any host on the network can join{})",
                         net::to_string(sec.mode),
                         transport == "lcm" ? "; LCM has no security" : "; see `horus security` and security: in the configuration file");
  }
  return s;
}

// Once per run: the live table refreshes every second, and the check reads and verifies the
// identity's certificates and signatures.
const SecurityState& security_state(const std::string& transport) {
  static const SecurityState state = read_security_state(transport);
  return state;
}

}  // namespace

std::string fleet_transport(const std::string& backend_flag) {
  if (!backend_flag.empty()) return backend_flag;
  auto t = horus::fleet_transport();
  return t ? *t : std::string();
}

std::unique_ptr<horus::Fleet> open_fleet(const std::string& transport, std::string& error) {
  horus::FleetOptions o;
  o.transport = transport;
  auto f = horus::Fleet::open(o);
  if (!f) {
    error = f.error().message();
    return nullptr;
  }
  return std::move(*f);
}

// Waits (at most `wait`) until every host that is not lost has announced itself, after a quarter
// of `wait` (for hosts to show up, and announcements with their topics' rates to come). Hosts
// the host's fleet view knows are there from the start, lost ones included: a lost host is
// not waited for.
void settle(const horus::Fleet& fleet, std::chrono::milliseconds wait, const std::atomic<bool>& stop) {
  const auto start = clock_type::now();
  while (!stop.load() && clock_type::now() - start < wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (clock_type::now() - start < wait / 4) continue;
    const auto hosts = fleet.hosts();
    if (!hosts.empty() && std::any_of(hosts.begin(), hosts.end(), [](const auto& h) { return h.self; }) &&
        std::all_of(hosts.begin(), hosts.end(),
                    [](const auto& h) { return h.announced || h.state == horus::HostState::Lost; }))
      return;
  }
}

nlohmann::json fleet_topic_json(const horus::FleetTopic& t) {
  nlohmann::json j = {{"topic", t.name},
                      {"type", t.type_name},
                      {"type_hash", fmt::format("{:016x}", t.type_hash)},
                      {"scope", t.scope},
                      {"publishers", t.publishers},
                      {"subscribers", t.subscribers},
                      {"messages", t.messages},
                      {"dropped", t.dropped},
                      {"message_size", t.message_size},
                      {"decodable", !t.signature.empty()}};
  if (t.scope == "fleet") j["transport"] = t.transport;
  if (t.rate_hz >= 0) j["rate_hz"] = t.rate_hz;
  return j;
}

namespace {

nlohmann::json fleet_json(const horus::Fleet& fleet) {
  auto hosts = nlohmann::json::array();
  for (const auto& h : fleet.hosts()) {
    auto procs = nlohmann::json::array();
    for (const auto& p : h.processes) procs.push_back({{"pid", p.pid}, {"name", p.name}, {"start_unix_ns", p.start_unix_ns}});
    auto topics = nlohmann::json::array();
    for (const auto& t : h.topics) topics.push_back(fleet_topic_json(t));
    nlohmann::json j = {{"host", h.name},
                        {"id", fmt::format("{:016x}", h.id)},
                        {"state", h.state == horus::HostState::Lost ? "lost" : "alive"},
                        {"rejoined", h.state == horus::HostState::Rejoined},
                        {"rejoins", h.rejoins},
                        {"self", h.self},
                        {"age_ms", h.heartbeat_age.count()},
                        {"period_ms", h.period.count()},
                        {"heartbeats", h.heartbeats},
                        {"loss", h.loss >= 0 ? nlohmann::json(h.loss) : nlohmann::json(nullptr)},
                        {"clock_offset_us", h.clock_offset ? nlohmann::json(h.clock_offset->count()) : nlohmann::json(nullptr)},
                        {"clock_uncertainty_us",
                         h.clock_uncertainty ? nlohmann::json(h.clock_uncertainty->count()) : nlohmann::json(nullptr)},
                        {"last_seen_unix_ms", h.last_seen_unix_ms},
                        {"lost_since_unix_ms", h.lost_since_unix_ms != 0 ? nlohmann::json(h.lost_since_unix_ms) : nlohmann::json(nullptr)},
                        {"announced", h.announced},
                        {"namespace", h.shm_namespace},
                        {"processes", procs},
                        {"topics", topics}};
    j["rtt_us"] = h.rtt ? nlohmann::json(h.rtt->count()) : nlohmann::json(nullptr);
    hosts.push_back(std::move(j));
  }
  const SecurityState& security = security_state(fleet.transport());
  for (auto& h : hosts) h["authenticated"] = security.secure;
  return {{"transport", fleet.transport()}, {"malformed", fleet.malformed()}, {"security", security.json}, {"hosts", hosts}};
}

void print_fleet_table(const horus::Fleet& fleet) {
  const auto hosts = fleet.hosts();
  const SecurityState& security = security_state(fleet.transport());
  fmt::print("fleet on {}: {} host{}\n{}\n", fleet.transport(), hosts.size(), hosts.size() == 1 ? "" : "s", security.text);
  fmt::print("{:<24} {:<9} {:>8} {:>9} {:>6} {:>10} {:>6} {:>7} {:>7} {:>5}\n", "host", "state", "age ms", "rtt us", "loss",
             "offset ms", "procs", "fleet", "topics", "auth");
  for (const auto& h : hosts) {
    std::size_t fleet_topics = 0;
    for (const auto& t : h.topics) fleet_topics += t.scope == "fleet" ? 1 : 0;
    std::string state(horus::to_string(h.state));
    if (h.rejoins > 0) state += fmt::format(" ({}x)", h.rejoins);
    fmt::print("{:<24} {:<9} {:>8} {:>9} {:>6} {:>10} {:>6} {:>7} {:>7} {:>5}\n", h.name + (h.self ? " *" : ""), state,
               h.heartbeat_age.count(), h.rtt ? std::to_string(h.rtt->count()) : "-",
               h.loss >= 0 ? fmt::format("{:.0f}%", h.loss * 100) : "-",
               h.clock_offset ? fmt::format("{:+.1f}", static_cast<double>(h.clock_offset->count()) / 1000.0) : "-",
               h.announced ? std::to_string(h.processes.size()) : "?", h.announced ? std::to_string(fleet_topics) : "?",
               h.announced ? std::to_string(h.topics.size()) : "?", security.secure ? "yes" : "no");
  }
  if (const auto bad = fleet.malformed(); bad != 0) fmt::print("{} malformed announcement(s) ignored\n", bad);
}

// When no other host answered: what to check, on stderr (the table or JSON stays parseable).
void hint_when_alone(const horus::Fleet& fleet, int wait_ms) {
  for (const auto& h : fleet.hosts())
    if (!h.self) return;
  std::string msg = fmt::format("horus fleet: no other host answered within {} ms on {}.\n", wait_ms, fleet.transport());
  const auto net = horus::net::config_from_environment();
  if (fleet.transport() == "lcm") {
    msg += "  Check that the other hosts use the same LCM URL with ttl=1 (the default ttl=0 never leaves a host), a "
           "multicast route on every host (ip route show 224.0.0.0/4), and a network that passes multicast (LCM "
           "has no unicast discovery: on Wi-Fi that filters multicast, use cyclonedds or fastdds with "
           "HORUS_PEERS).\n";
  } else if (net && !net->peers.empty()) {
    std::string list;
    for (const auto& p : net->peers) list += (list.empty() ? "" : ", ") + p;
    msg += fmt::format("  Discovery is unicast to the peers ({}: {}): check that they run horus on the same DDS "
                       "domain ({}) with peers that name this host, and that no firewall drops UDP between them.\n",
                       net->peers_origin, list, net->domain_id);
  } else {
    msg += fmt::format(
        "  Check that the other hosts use the same DDS domain ({}), HORUS_DDS_LOCALHOST unset, a multicast route "
        "(ip route show 224.0.0.0/4), and a network that passes multicast (discovery goes to 239.255.0.1).\n"
        "  Wi-Fi access points often filter multicast: list the other hosts in HORUS_PEERS=10.0.0.2,robot-3 (or "
        "network.peers in the configuration file) on every host, for unicast discovery.\n",
        net ? net->domain_id : 0u);
  }
  fmt::print(stderr, "{}", msg);
}

}  // namespace

int cmd_fleet(const std::string& backend, bool json, bool once, int wait_ms, double duration_s,
              const std::atomic<bool>& stop) {
  const std::string transport = fleet_transport(backend);
  if (transport.empty()) {
    fmt::print(stderr, "horus fleet: no network backend to watch the fleet on; set HORUS_BACKEND=cyclonedds|fastdds|lcm, "
                       "network.backend in the configuration file (HORUS_CONFIG), or --backend\n");
    return 2;
  }
  std::string error;
  auto fleet = open_fleet(transport, error);
  if (!fleet) {
    fmt::print(stderr, "horus fleet: {}\n", error);
    return 2;
  }
  settle(*fleet, std::chrono::milliseconds(wait_ms), stop);
  if (once) {
    if (json) fmt::print("{}\n", fleet_json(*fleet).dump(2));
    else print_fleet_table(*fleet);
    std::fflush(stdout);
    hint_when_alone(*fleet, wait_ms);
    return 0;
  }
  const auto end = clock_type::now() + std::chrono::duration_cast<clock_type::duration>(
                                           std::chrono::duration<double>(duration_s > 0 ? duration_s : 1e9));
  const bool tty = ::isatty(1) != 0;
  bool hinted = false;
  while (!stop.load() && clock_type::now() < end) {
    if (json) {
      fmt::print("{}\n", fleet_json(*fleet).dump());
    } else {
      if (tty) fmt::print("\033[H\033[2J");
      print_fleet_table(*fleet);
      if (!tty) fmt::print("\n");
    }
    std::fflush(stdout);
    if (!std::exchange(hinted, true)) hint_when_alone(*fleet, wait_ms);
    const auto next = clock_type::now() + std::chrono::seconds(1);
    while (!stop.load() && clock_type::now() < std::min(next, end)) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
}

}  // namespace horus::tools

// The settings an operation takes once (horus/settings.hpp): the process context's snapshot and
// the configuration file it names, and what the layers get from them (the transports' network
// settings, the fleet layer's). The only file above core that asks the process for its settings.
#include "horus/settings.hpp"

#include <fmt/format.h>

#include <charconv>
#include <list>
#include <mutex>
#include <optional>
#include <utility>

#include "horus/detail/process.hpp"

namespace horus {

namespace {
// The file HORUS_CONFIG names, read once per value of the variable (a program sets it before its
// first topic; a test may change it). Configurations stay alive: choices made earlier keep
// pointing at theirs.
struct ConfigFiles {
  static constexpr horus::detail::PartSpec kPart{"configuration files", horus::detail::PartLifetime::UntilExit,
                                                 "a topic's choice points at its file while the topic is open"};
  std::mutex mutex;
  std::optional<std::string> cached_path;
  std::optional<Result<const Config*>> cached;
  std::list<Config> loaded;
};

Result<const Config*> file_from(const Environment& env) {
  auto& [mutex, cached_path, cached, loaded] = horus::detail::Process::part<ConfigFiles>();
  const std::string& path = env.config;
  std::lock_guard lock(mutex);
  if (cached_path == path && cached) return *cached;
  cached_path = path;
  if (path.empty()) return *(cached = Result<const Config*>(nullptr));
  auto c = Config::load(path);
  if (!c)
    return *(cached = Result<const Config*>(
                 std::unexpected(Error(Errc::Config, "HORUS_CONFIG=" + path + ": " + c.error().message()))));
  return *(cached = Result<const Config*>(&loaded.emplace_back(std::move(*c))));
}

net::FileDefaults file_defaults(const Config* config) {
  if (config == nullptr) return {};
  const auto& n = config->network();
  const auto& s = config->security();
  net::FileDefaults d;
  d.domain_id = n.domain_id;
  d.localhost_only = n.localhost_only;
  d.lcm_url = n.lcm_url;
  d.peers = n.peers;
  d.link_bandwidth = n.max_bandwidth;
  d.security_mode = s.mode;
  d.security_keystore = s.keystore;
  d.security_identity = s.identity;
  d.security_line = s.line;
  d.origin = "configuration file '" + config->file() + "'";
  d.lcm_url_line = n.lcm_url_line;
  d.peers_line = n.peers_line;
  return d;
}

// HORUS_FLEET_HEARTBEAT_MS, when set, in milliseconds.
Result<std::optional<std::uint64_t>> heartbeat_override(const Environment& env) {
  if (env.fleet_heartbeat_ms.empty()) return std::nullopt;
  const std::string_view text(env.fleet_heartbeat_ms);
  std::uint64_t v = 0;
  auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || p != text.data() + text.size() || v < kMinHeartbeatMs || v > kMaxHeartbeatMs)
    return fail(Errc::Config, fmt::format("HORUS_FLEET_HEARTBEAT_MS='{}' is not a heartbeat period; expected "
                                          "milliseconds from {} to {}",
                                          text, kMinHeartbeatMs, kMaxHeartbeatMs));
  return v;
}
}  // namespace

Result<Settings> Settings::current() {
  Settings s;
  s.environment = horus::detail::Process::get().environment();
  auto file = file_from(*s.environment);
  if (!file) return std::unexpected(std::move(file.error()));
  s.file = *file;
  return s;
}

Settings Settings::with_file(const Config* file) {
  Settings s;
  s.environment = horus::detail::Process::get().environment();
  s.file = file;
  return s;
}

Result<net::Config> network_config(const Settings& settings) {
  return net::config_from(settings.env(), file_defaults(settings.file));
}

Result<std::string> fleet_transport(const Settings& settings) {
  const Environment& env = settings.env();
  if (!env.backend.empty()) {
    auto b = backend_from(env.backend);
    if (!b) return std::unexpected(b.error());
    if (b->scope() == Scope::Fleet) return std::string(b->transport());
  }
  if (settings.file != nullptr && settings.file->network().backend) return *settings.file->network().backend;
  return std::string();
}

Result<FleetSettings> fleet_settings(const Settings& settings) {
  FleetSettings out;
  if (settings.file != nullptr) {
    const FleetSection& f = settings.file->fleet();
    if (f.announce) out.announce = *f.announce;
    if (f.heartbeat_ms) out.heartbeat = std::chrono::milliseconds(*f.heartbeat_ms);
    if (f.announce_ms) out.announce_period = std::chrono::milliseconds(*f.announce_ms);
    if (f.misses) out.misses = *f.misses;
    if (f.max_hosts) out.max_hosts = *f.max_hosts;
    if (f.forget_after) out.forget_after = *f.forget_after;
  }
  auto heartbeat = heartbeat_override(settings.env());
  if (!heartbeat) return std::unexpected(std::move(heartbeat.error()));
  if (*heartbeat) out.heartbeat = std::chrono::milliseconds(**heartbeat);
  auto transport = fleet_transport(settings);
  if (!transport) return std::unexpected(transport.error());
  out.transport = std::move(*transport);
  return out;
}

// --- the same for a caller that has not taken the settings (the CLI, Python, a program) --------

Result<Backend> backend_from_environment() { return backend_from(horus::detail::Process::get().environment()->backend); }

Result<const Config*> config_from_environment() { return file_from(*horus::detail::Process::get().environment()); }

Result<net::Config> net::config_of(const horus::Config& file) { return net::config_from(Environment{}, file_defaults(&file)); }

Result<net::Config> net::config_from_environment() {
  auto settings = Settings::current();
  if (!settings) return std::unexpected(std::move(settings.error()));
  return network_config(*settings);
}

Result<net::Config> net::config_from_environment(const horus::Config* file) {
  return network_config(Settings::with_file(file));
}

Result<TopicChoice> choose(std::string_view topic, const TopicOptions& code, const Config* config) {
  return choose(topic, code, Settings::with_file(config));
}

Result<TopicChoice> choose(std::string_view topic, const TopicOptions& code) {
  auto settings = Settings::current();
  if (!settings) return std::unexpected(std::move(settings.error()));
  return choose(topic, code, *settings);
}

Result<std::string> fleet_transport() {
  auto settings = Settings::current();
  if (!settings) return std::unexpected(std::move(settings.error()));
  return fleet_transport(*settings);
}

Result<FleetSettings> fleet_settings() {
  auto settings = Settings::current();
  if (!settings) return std::unexpected(std::move(settings.error()));
  return fleet_settings(*settings);
}

}  // namespace horus

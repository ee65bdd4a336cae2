#include "horus/network.hpp"

#include "horus/environment.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <vector>

namespace horus::net {

std::string_view to_string(Reliability r) noexcept {
  return r == Reliability::Reliable ? "reliable" : "best effort";
}

std::string_view to_string(Durability d) noexcept {
  return d == Durability::TransientLocal ? "transient local" : "volatile";
}

std::string_view to_string(SecurityMode m) noexcept {
  switch (m) {
    case SecurityMode::Off: return "off";
    case SecurityMode::Permissive: return "permissive";
    case SecurityMode::Enforce: return "enforce";
  }
  return "?";
}

std::string_view to_string(Protection p) noexcept { return p == Protection::Sign ? "sign" : "encrypt"; }

std::string check_peer(std::string_view peer) {
  if (peer.empty()) return "is empty";
  if (peer.size() > 253) return "is longer than a host name (253 characters)";
  bool digits_and_dots = true;
  for (const char c : peer) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '.';
    if (!ok) return fmt::format("has '{}', which no host name or IPv4 address has", c);
    digits_and_dots = digits_and_dots && (c == '.' || (c >= '0' && c <= '9'));
  }
  if (peer.front() == '.' || peer.front() == '-' || peer.back() == '.' || peer.find("..") != std::string_view::npos)
    return "is not a host name (a dot or '-' at an end, or two dots)";
  if (digits_and_dots) {  // then an IPv4 address: four numbers 0..255
    int parts = 0;
    std::size_t at = 0;
    while (at <= peer.size()) {
      const std::size_t dot = std::min(peer.find('.', at), peer.size());
      const std::string_view part = peer.substr(at, dot - at);
      if (part.empty() || part.size() > 3 || std::stoi(std::string(part)) > 255) return "is not an IPv4 address";
      ++parts;
      at = dot + 1;
    }
    if (parts != 4) return "is not an IPv4 address (four numbers 0 to 255)";
  }
  return {};
}

namespace {

// The security settings: each of HORUS_SECURITY, HORUS_SECURITY_KEYSTORE and
// HORUS_SECURITY_IDENTITY over the file's security.mode, .keystore and .identity. With a
// keystore and no mode, the mode is enforce; a mode other than off needs both the keystore and
// the identity.
Result<Security> security_from(const Environment& env, const FileDefaults& file) {
  Security s;
  std::string mode_origin;
  const std::string file_origin = file.origin + (file.security_line > 0 ? fmt::format(", line {}", file.security_line) : "");
  std::optional<SecurityMode> mode = file.security_mode;
  if (mode) mode_origin = file_origin + ", security.mode";
  if (!env.security.empty()) {
    const std::string_view v(env.security);
    if (v == "enforce") mode = SecurityMode::Enforce;
    else if (v == "permissive") mode = SecurityMode::Permissive;
    else if (v == "off") mode = SecurityMode::Off;
    else
      return fail(Errc::Config, fmt::format("HORUS_SECURITY={}: expected enforce (DDS-Security on every fleet topic, "
                                            "nothing opens without it), permissive (secure when the identity's files "
                                            "are there) or off",
                                            v));
    mode_origin = "environment variable HORUS_SECURITY";
  }
  // A variable over the file's key: the value and where it came from.
  const auto pick = [&](const std::string& variable, const char* name, const std::optional<std::string>& key,
                        const char* key_name, std::string& value) -> std::string {
    if (!variable.empty()) {
      value = variable;
      return std::string("environment variable ") + name;
    }
    if (!key) return {};
    value = *key;
    return file_origin + ", " + key_name;
  };
  const std::string keystore_origin =
      pick(env.security_keystore, "HORUS_SECURITY_KEYSTORE", file.security_keystore, "security.keystore", s.keystore);
  const std::string identity_origin =
      pick(env.security_identity, "HORUS_SECURITY_IDENTITY", file.security_identity, "security.identity", s.identity);
  if (!mode) {
    if (s.keystore.empty()) return Security{};
    mode = SecurityMode::Enforce;
    mode_origin = keystore_origin + " (a keystore without a mode: enforce)";
  }
  s.mode = *mode;
  if (s.mode == SecurityMode::Off) return Security{};
  if (s.keystore.empty())
    return fail(Errc::Config, fmt::format("{} is {} but no keystore is given; set HORUS_SECURITY_KEYSTORE or the "
                                          "configuration file's security.keystore (a directory made by `horus security "
                                          "keystore init`)",
                                          mode_origin, to_string(s.mode)));
  if (s.identity.empty())
    return fail(Errc::Config, fmt::format("{} is {} but this host's identity is not given; set HORUS_SECURITY_IDENTITY "
                                          "or the configuration file's security.identity (a name made by `horus security "
                                          "host create {} NAME`)",
                                          mode_origin, to_string(s.mode), s.keystore));
  if (const auto ok = validate_identity_name(s.identity); !ok)
    return fail(Errc::Config, fmt::format("{}: {}", identity_origin, ok.error().message()));
  s.origin = mode_origin;
  return s;
}

}  // namespace

Result<void> validate_identity_name(std::string_view name) {
  const auto rule = "expected 1 to 64 letters, digits, '_', '-' or '.', not starting with '.' or '-' (e.g. robot1)";
  if (name.empty() || name.size() > 64 || name.front() == '.' || name.front() == '-')
    return fail(Errc::Config, fmt::format("identity name '{}' is not valid; {}", name, rule));
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
    if (!ok) return fail(Errc::Config, fmt::format("identity name '{}' has '{}'; {}", name, c, rule));
  }
  return {};
}

Result<Config> config_from(const Environment& env, const FileDefaults& file) {
  Config config;
  config.domain_id = file.domain_id.value_or(0);
  config.localhost_only = file.localhost_only.value_or(false);
  config.link_bandwidth = file.link_bandwidth.value_or(0);
  if (!env.domain_id.empty()) {
    const std::string_view v(env.domain_id);
    std::uint32_t id = 0;
    bool ok = v.size() <= 3;
    for (char c : v) {
      ok = ok && c >= '0' && c <= '9';
      if (ok) id = id * 10 + static_cast<std::uint32_t>(c - '0');
    }
    if (!ok || id > kMaxDomainId)
      return fail(Errc::Config, fmt::format("HORUS_DOMAIN_ID={}: expected a DDS domain id, an integer from 0 to {} "
                                            "(the RTPS port mapping has no room above {})",
                                            v, kMaxDomainId, kMaxDomainId));
    config.domain_id = id;
  }
  if (!env.dds_localhost.empty()) {
    const std::string_view v(env.dds_localhost);
    if (v == "1" || v == "true" || v == "yes" || v == "on") {
      config.localhost_only = true;
    } else if (v == "0" || v == "false" || v == "no" || v == "off") {
      config.localhost_only = false;
    } else {
      return fail(Errc::Config, fmt::format("HORUS_DDS_LOCALHOST={}: expected 1, true, yes, on (loopback only) or "
                                            "0, false, no, off (the LAN)",
                                            v));
    }
  }
  if (!env.peers.empty()) {
    // A comma- or space-separated list.
    std::vector<std::string> peers;
    std::string_view rest(env.peers);
    std::size_t index = 0;
    while (!rest.empty()) {
      const std::size_t cut = rest.find_first_of(", ");
      const std::string_view entry = rest.substr(0, cut);
      rest = cut == std::string_view::npos ? std::string_view{} : rest.substr(cut + 1);
      if (entry.empty()) continue;
      ++index;
      if (const std::string why = check_peer(entry); !why.empty())
        return fail(Errc::Config, fmt::format("HORUS_PEERS={}: peer {} '{}' {}; expected host names or IPv4 addresses "
                                              "separated by commas (HORUS_PEERS=10.0.0.2,robot-3)",
                                              env.peers, index, entry, why));
      peers.emplace_back(entry);
    }
    if (peers.empty())
      return fail(Errc::Config, fmt::format("HORUS_PEERS={} names no host; expected host names or IPv4 addresses "
                                            "separated by commas (HORUS_PEERS=10.0.0.2,robot-3)",
                                            env.peers));
    config.peers = std::move(peers);
    config.peers_origin = "environment variable HORUS_PEERS";
  } else if (file.peers && !file.peers->empty()) {
    config.peers = *file.peers;
    config.peers_origin = file.origin + (file.peers_line > 0 ? fmt::format(", line {}", file.peers_line) : "") +
                          ", network.peers";
  }
  // The URL is checked by the LCM transport, which knows its syntax; the origin names it.
  if (!env.horus_lcm_url.empty()) {
    config.lcm_url = env.horus_lcm_url;
    config.lcm_url_origin = "environment variable HORUS_LCM_URL";
  } else if (!env.lcm_default_url.empty()) {
    config.lcm_url = env.lcm_default_url;
    config.lcm_url_origin = "environment variable LCM_DEFAULT_URL";
  } else if (file.lcm_url) {
    config.lcm_url = *file.lcm_url;
    config.lcm_url_origin = file.origin + (file.lcm_url_line > 0 ? fmt::format(", line {}", file.lcm_url_line) : "") +
                            ", network.lcm_url";
  }
  auto security = security_from(env, file);
  if (!security) return std::unexpected(std::move(security.error()));
  config.security = std::move(*security);
  return config;
}

}  // namespace horus::net

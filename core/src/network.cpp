#include "horus/network.hpp"

#include "horus/environment.hpp"

#include <fmt/format.h>

namespace horus::net {

std::string_view to_string(Reliability r) noexcept {
  return r == Reliability::Reliable ? "reliable" : "best effort";
}

std::string_view to_string(Durability d) noexcept {
  return d == Durability::TransientLocal ? "transient local" : "volatile";
}

Result<Config> config_from(const Environment& env, const FileDefaults& file) {
  Config config;
  config.domain_id = file.domain_id.value_or(0);
  config.localhost_only = file.localhost_only.value_or(false);
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
  // The URL is checked by the LCM transport, which knows its syntax; the origin names it.
  if (!env.horus_lcm_url.empty()) {
    config.lcm_url = env.horus_lcm_url;
    config.lcm_url_origin = "environment variable HORUS_LCM_URL";
  } else if (!env.lcm_default_url.empty()) {
    config.lcm_url = env.lcm_default_url;
    config.lcm_url_origin = "environment variable LCM_DEFAULT_URL";
  } else if (file.lcm_url) {
    config.lcm_url = *file.lcm_url;
    config.lcm_url_origin = file.origin + ", network.lcm_url";
  }
  return config;
}

}  // namespace horus::net

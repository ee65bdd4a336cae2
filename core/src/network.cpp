#include "horus/network.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <mutex>
#include <utility>

namespace horus::net {

std::string_view to_string(Reliability r) noexcept {
  return r == Reliability::Reliable ? "reliable" : "best effort";
}

std::string_view to_string(Durability d) noexcept {
  return d == Durability::TransientLocal ? "transient local" : "volatile";
}

namespace {
std::mutex g_file_mutex;
FileDefaults g_file;  // guarded by g_file_mutex
}  // namespace

void set_file_defaults(FileDefaults defaults) {
  std::lock_guard lock(g_file_mutex);
  g_file = std::move(defaults);
}

FileDefaults file_defaults() {
  std::lock_guard lock(g_file_mutex);
  return g_file;
}

Result<Config> config_from_environment() {
  Config config;
  const FileDefaults file = file_defaults();
  config.domain_id = file.domain_id.value_or(0);
  config.localhost_only = file.localhost_only.value_or(false);
  if (const char* env = std::getenv("HORUS_DOMAIN_ID"); env != nullptr && *env != '\0') {
    const std::string_view v(env);
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
  if (const char* env = std::getenv("HORUS_DDS_LOCALHOST"); env != nullptr && *env != '\0') {
    const std::string_view v(env);
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
  return config;
}

}  // namespace horus::net

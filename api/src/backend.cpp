// Scopes and backends: names, availability, HORUS_BACKEND, and wire names through the registry.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "horus/backend.hpp"
#include "horus/names.hpp"
#include "horus/transport_registry.hpp"

namespace horus {

std::string_view to_string(Scope s) noexcept {
  switch (s) {
    case Scope::Process: return "process";
    case Scope::Host: return "host";
    case Scope::Fleet: return "fleet";
  }
  return "unknown";
}

std::string_view to_string(Priority p) noexcept {
  switch (p) {
    case Priority::Low: return "low";
    case Priority::Normal: return "normal";
    case Priority::High: return "high";
  }
  return "?";
}

std::string_view to_string(LogLevel l) noexcept {
  switch (l) {
    case LogLevel::Trace: return "trace";
    case LogLevel::Debug: return "debug";
    case LogLevel::Info: return "info";
    case LogLevel::Warn: return "warn";
    case LogLevel::Error: return "error";
  }
  return "?";
}

std::optional<LogLevel> log_level_from(std::string_view name) noexcept {
  for (LogLevel l : {LogLevel::Trace, LogLevel::Debug, LogLevel::Info, LogLevel::Warn, LogLevel::Error})
    if (to_string(l) == name) return l;
  return std::nullopt;
}

std::string_view to_string(const Backend& b) noexcept {
  switch (b.scope()) {
    case Scope::Process: return "inproc";
    case Scope::Host: return "shm";
    case Scope::Fleet: return b.transport();
  }
  return "unknown";
}

bool backend_available(const Backend& b) noexcept {
  if (b.scope() != Scope::Fleet) return true;
  if (net::find_transport(b.transport()) == nullptr) return false;
  try {
    return net::load_transport(b.transport()).has_value();  // a plug-in: whether it loads
  } catch (...) {
    return false;
  }
}

namespace {
// The transports horus ships, named in messages even when this build lacks them.
constexpr std::array<std::string_view, 3> kShipped{Backend::CycloneDds.transport(), Backend::FastDds.transport(),
                                                   Backend::Lcm.transport()};

// The fleet transports HORUS_BACKEND may name: the registered ones, and the ones horus ships.
std::string valid_backends() {
  std::string out = "auto, shm, inproc";
  auto names = net::transport_names();
  for (std::string_view shipped : kShipped)
    if (std::find(names.begin(), names.end(), shipped) == names.end()) names.emplace_back(shipped);
  for (std::size_t i = 0; i < names.size(); ++i) out += (i + 1 == names.size() ? " or " : ", ") + names[i];
  return out;
}
}  // namespace

Result<Backend> backend_from(std::string_view v) {
  if (v.empty()) return Backend::SharedMemory;
  if (v == "auto" || v == "shm") return Backend::SharedMemory;
  if (v == "inproc") return Backend::InProcess;
  if (const auto* t = net::find_transport(v)) return Backend::network(t->name);
  for (std::string_view shipped : kShipped)
    if (v == shipped)
      return fail(Errc::Config, fmt::format("HORUS_BACKEND={}: this build of horus has no {} backend (its Debian "
                                            "package was missing when horus was built; scripts/install-deps.sh "
                                            "installs it)",
                                            v, v));
  return fail(Errc::Config, fmt::format("HORUS_BACKEND={}: unknown backend; expected {}", v, valid_backends()));
}

Result<std::string> wire_name(const Backend& b, std::string_view topic) {
  if (b.scope() != Scope::Fleet) {
    if (auto ok = validate_topic_name(topic); !ok) return std::unexpected(std::move(ok.error()));
    return std::string(topic);
  }
  const auto* t = net::find_transport(b.transport());
  if (t == nullptr)
    return fail(Errc::Config, fmt::format("topic '{}': this build of horus has no {} backend", topic, b.transport()));
  return t->wire_name(topic);
}
}  // namespace horus

#include "horus/transport_registry.hpp"

#include <fmt/format.h>

#include <deque>
#include <mutex>

namespace horus::net {

std::string_view to_string(WireFormat f) noexcept {
  switch (f) {
    case WireFormat::Xcdr1: return "xcdr1";
    case WireFormat::Lcm: return "lcm";
  }
  return "unknown";
}

namespace {
struct Transports {
  std::mutex mutex;
  std::deque<std::pair<std::string, TransportInfo>> entries;  // a deque: found pointers stay valid
};

Transports& transports() {
  static Transports t;
  return t;
}
}  // namespace

Result<void> register_transport(const TransportInfo& info) {
  if (info.name.empty() || info.wire_name == nullptr || info.open == nullptr)
    return fail(Errc::Config, fmt::format("transport '{}': a transport needs a name, a wire_name and an open "
                                          "function",
                                          info.name));
  auto& t = transports();
  std::lock_guard lock(t.mutex);
  for (const auto& [name, have] : t.entries) {
    if (name != info.name) continue;
    if (have.format == info.format && have.wire_name == info.wire_name && have.open == info.open &&
        have.open_control == info.open_control && have.check == info.check)
      return {};
    return fail(Errc::Config, fmt::format("transport '{}' is already registered with other functions; expected "
                                          "one registration per name",
                                          info.name));
  }
  auto& [name, entry] = t.entries.emplace_back(std::string(info.name), info);
  entry.name = name;  // the registry owns the name
  return {};
}

const TransportInfo* find_transport(std::string_view name) noexcept {
  auto& t = transports();
  std::lock_guard lock(t.mutex);
  for (const auto& [n, info] : t.entries)
    if (n == name) return &info;
  return nullptr;
}

std::vector<std::string> transport_names() {
  auto& t = transports();
  std::lock_guard lock(t.mutex);
  std::vector<std::string> out;
  for (const auto& [n, info] : t.entries) out.push_back(n);
  return out;
}

}  // namespace horus::net

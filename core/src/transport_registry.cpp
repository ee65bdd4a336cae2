#include "horus/transport_registry.hpp"

#include <dlfcn.h>
#include <fmt/format.h>

#include <array>
#include <atomic>
#include <cstdlib>
#include <deque>
#include <mutex>
#include <utility>

#include "horus/detail/process.hpp"

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
  static constexpr horus::detail::PartSpec kPart{"transports", horus::detail::PartLifetime::UntilExit,
                                                 "filled before main; a topic keeps a pointer to its entry"};
  std::mutex mutex;
  std::deque<std::pair<std::string, TransportInfo>> entries;  // a deque: found pointers stay valid
};

Transports& transports() { return horus::detail::Process::part<Transports>(); }

// The plug-ins: a few slots, each with its own pair of open functions (function pointers carry no
// state: slot I's are plugin_open<I>). What the plug-in registers as it loads goes into its slot.
using OpenFn = Result<std::shared_ptr<Transport>> (*)(const Config&);
struct Plugin {
  std::string name;  // empty: a free slot
  std::atomic<OpenFn> open{nullptr};
  std::atomic<OpenFn> open_control{nullptr};
  bool tried = false;  // under the plug-ins' mutex
  std::string error;   // why it did not load
};
constexpr std::size_t kPluginSlots = 8;
struct Plugins {
  static constexpr horus::detail::PartSpec kPart{"transport plug-ins", horus::detail::PartLifetime::UntilExit,
                                                 "filled before main; a loaded plug-in stays loaded"};
  std::mutex mutex;  // loading; never held while a plug-in's function runs
  std::array<Plugin, kPluginSlots> slots;
};
Plugins& plugins() { return horus::detail::Process::part<Plugins>(); }

// Without the mutex: names are written only by register_transport_plugin, before main() (the
// composition root), and this runs inside a plug-in's load, which holds the mutex.
Plugin* plugin_named(std::string_view name) noexcept {
  for (auto& p : plugins().slots)
    if (!p.name.empty() && p.name == name) return &p;
  return nullptr;
}

Result<void> load_slot(Plugin& p) {
  auto& all = plugins();
  std::lock_guard lock(all.mutex);
  if (!p.tried) {
    p.tried = true;
    const std::string file = transport_plugin_directory() + "/libhorus-" + p.name + ".so";
    // RTLD_LOCAL: nothing of the plug-in (nor of the DDS library under it) is seen by symbol
    // lookups of what loads later; it registers itself (register_transport) as it loads.
    void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* why = ::dlerror();
      p.error = fmt::format("the {} transport is a plug-in that did not load from {}: {} (install it beside "
                            "libhorus.so.0, e.g. the libhorus0 package, or set HORUS_PLUGIN_PATH to its directory)",
                            p.name, file, why != nullptr ? why : "unknown error");
    } else if (p.open.load() == nullptr) {
      p.error = fmt::format("the {} transport's plug-in {} loaded but registered no transport named '{}'", p.name,
                            file, p.name);
    }
  }
  if (!p.error.empty()) return fail(Errc::Config, p.error);
  return {};
}

Result<std::shared_ptr<Transport>> open_slot(std::size_t i, const Config& config, bool control) {
  Plugin& p = plugins().slots[i];
  if (auto ok = load_slot(p); !ok) return std::unexpected(std::move(ok.error()));
  OpenFn fn = control ? p.open_control.load() : nullptr;
  if (fn == nullptr) fn = p.open.load();
  return fn(config);
}

template <std::size_t I>
Result<std::shared_ptr<Transport>> plugin_open(const Config& config) {
  return open_slot(I, config, false);
}
template <std::size_t I>
Result<std::shared_ptr<Transport>> plugin_open_control(const Config& config) {
  return open_slot(I, config, true);
}
template <std::size_t... I>
constexpr std::array<std::pair<OpenFn, OpenFn>, kPluginSlots> slot_functions(std::index_sequence<I...>) {
  return {std::pair<OpenFn, OpenFn>{&plugin_open<I>, &plugin_open_control<I>}...};
}
constexpr auto kSlotFunctions = slot_functions(std::make_index_sequence<kPluginSlots>{});
}  // namespace

std::string transport_plugin_directory() {
  if (const char* env = std::getenv("HORUS_PLUGIN_PATH"); env != nullptr && *env != '\0') return env;
  Dl_info info{};
  if (::dladdr(reinterpret_cast<void*>(&transport_plugin_directory), &info) != 0 && info.dli_fname != nullptr) {
    std::string self = info.dli_fname;
    const auto slash = self.rfind('/');
    return (slash == std::string::npos ? std::string(".") : self.substr(0, slash)) + "/horus0";
  }
  return "horus0";
}

Result<void> register_transport_plugin(const TransportInfo& info, bool control) {
  if (info.name.empty() || info.wire_name == nullptr)
    return fail(Errc::Config, fmt::format("transport '{}': a plug-in transport needs a name and a wire_name", info.name));
  auto& all = plugins();
  std::size_t slot = kPluginSlots;
  {
    std::lock_guard lock(all.mutex);
    for (std::size_t i = 0; i < kPluginSlots; ++i)
      if (all.slots[i].name == info.name) return {};  // registered already
    for (std::size_t i = 0; i < kPluginSlots && slot == kPluginSlots; ++i)
      if (all.slots[i].name.empty()) slot = i;
    if (slot == kPluginSlots)
      return fail(Errc::Config, fmt::format("transport '{}': at most {} transports may be plug-ins", info.name,
                                            kPluginSlots));
    all.slots[slot].name = std::string(info.name);
  }
  // The registry's entry: the caller's name, format and wire_name, the slot's loading functions.
  TransportInfo loading = info;
  loading.open = kSlotFunctions[slot].first;
  loading.open_control = control ? kSlotFunctions[slot].second : nullptr;
  return register_transport(loading);
}

Result<void> load_transport(std::string_view name) {
  if (Plugin* p = plugin_named(name)) return load_slot(*p);
  if (find_transport(name) == nullptr) return fail(Errc::Config, fmt::format("no transport named '{}'", name));
  return {};
}

Result<void> register_transport(const TransportInfo& info) {
  if (info.name.empty() || info.wire_name == nullptr || info.open == nullptr)
    return fail(Errc::Config, fmt::format("transport '{}': a transport needs a name, a wire_name and an open "
                                          "function",
                                          info.name));
  // A plug-in registering itself as it loads: its functions go into its slot.
  if (Plugin* p = plugin_named(info.name); p != nullptr && info.open != kSlotFunctions[static_cast<std::size_t>(p - plugins().slots.data())].first) {
    p->open_control.store(info.open_control);
    p->open.store(info.open);
    return {};
  }
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

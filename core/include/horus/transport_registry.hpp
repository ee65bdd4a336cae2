// The transports this process can use, by name. Each network backend (backend_dds/,
// backend_lcm/, or a user's own) registers a TransportInfo once; api/ finds it by the name a
// topic asks for (HORUS_BACKEND=cyclonedds, TopicOptions) and never includes a backend header.
// Only the package target horus::horus knows which transports a build has: it compiles a small
// generated file that calls each built backend's registration function before main().
//
//   horus::net::register_transport({"mynet", WireFormat::Xcdr1, &my_wire_name, &my_open});
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "horus/error.hpp"
#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::net {

/// How a transport's samples are encoded; Topic<T>'s bridge encodes and decodes T with it.
///   Xcdr1  OMG XCDR1, final extensibility, with the 4-byte encapsulation stripped (DDS)
///   Lcm    lcm-gen's encoding: 8-byte fingerprint, then big-endian fields (LCM)
enum class WireFormat : std::uint8_t { Xcdr1, Lcm };
std::string_view to_string(WireFormat f) noexcept;

/// What a transport tells the registry about itself.
struct TransportInfo {
  /// "cyclonedds", "fastdds", "lcm": what HORUS_BACKEND and horus::Backend name.
  std::string_view name;
  WireFormat format = WireFormat::Xcdr1;
  /// The transport's name for a horus topic (a DDS topic name, an LCM channel), or
  /// Errc::InvalidName naming the topic and the transport's rule. The topic name has passed
  /// validate_topic_name.
  Result<std::string> (*wire_name)(std::string_view topic) = nullptr;
  /// The transport of `config` (created on first use, then shared per configuration). The
  /// caller passes the process's settings (horus::net::config_from_environment()).
  Result<std::shared_ptr<Transport>> (*open)(const Config& config) = nullptr;
  /// Optional: a second instance for the fleet layer's own topics (heartbeats, announcements)
  /// with sockets and receive threads of its own, so that under load they do not wait behind
  /// the data in one socket and one thread (Fast DDS: a second participant; LCM udpm: the next
  /// port, so that a process whose data endpoints only publish has no socket receiving the data
  /// channels). nullptr: open() serves them too (Cyclone DDS's participants of a domain share
  /// one network stack).
  Result<std::shared_ptr<Transport>> (*open_control)(const Config& config) = nullptr;
  /// Optional: checks the transport's settings in `config` without opening anything (`horus
  /// config check`: LCM's URL and its refusal of peers); the error names where each came from.
  Result<void> (*check)(const Config& config) = nullptr;

  /// Whether topic `topic` travels on the control instance: the fleet layer's own topics
  /// (kControlTopicPrefix), when the transport has one. The one rule for the fleet layer, the
  /// CLI's readers and the tests that stand in for either.
  bool on_control(std::string_view topic) const noexcept {
    return open_control != nullptr && topic.starts_with(kControlTopicPrefix);
  }
  /// The instance `topic` travels on (open_control or open, by on_control).
  Result<std::shared_ptr<Transport>> open_for(std::string_view topic, const Config& config) const {
    return on_control(topic) ? open_control(config) : open(config);
  }

  /// The names of the fleet layer's own topics (fleet/include/horus/fleet_messages.hpp).
  static constexpr std::string_view kControlTopicPrefix = "horus.fleet.";
};

/// Adds a transport. Registering the same name again with the same functions does nothing;
/// with other functions it is an error (Errc::Config), as is an empty name or a missing function.
Result<void> register_transport(const TransportInfo& info);

/// Adds a transport whose implementation is a plug-in, a shared object loaded the first time the
/// transport is opened (libhorus.so's DDS transports: a program that uses none does not load
/// Fast DDS or Cyclone DDS). `info` gives the name, the format and the wire_name (which must not
/// need the plug-in); its open functions are the registry's own, which load
/// `<transport_plugin_directory()>/libhorus-<name>.so` and then call the functions the plug-in
/// registers with register_transport() under the same name as it loads. `control`: the plug-in
/// has an open_control.
Result<void> register_transport_plugin(const TransportInfo& info, bool control);

/// Loads the plug-in of the transport `name` if it is one and not loaded yet. An error names the
/// file and what dlopen said (Errc::Config); a transport that is no plug-in is loaded already.
Result<void> load_transport(std::string_view name);

/// Where the transports' plug-ins are: $HORUS_PLUGIN_PATH when set, else the directory "horus0"
/// beside the library that holds this registry (libhorus.so.0: <libdir>/horus0).
std::string transport_plugin_directory();

/// The transport registered under `name`, or nullptr.
const TransportInfo* find_transport(std::string_view name) noexcept;

/// The names of the registered transports, in registration order.
std::vector<std::string> transport_names();

}  // namespace horus::net

HORUS_API_END

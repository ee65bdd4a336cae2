// The seam between api/ and the fleet layer (fleet/): what a fleet topic's handles know of the
// network, not a template and no transport header.
//
// A fleet topic lives in shared memory like a host topic; in addition, exactly one process of
// the host bridges it to the network (fleet/: the bridge per topic, on the process's network
// engine). api/ sees that bridge as a NetworkLink owned by the topic's TopicCore, made by the
// connector the fleet layer installs (from the composition root, horus::horus), and knows the
// message type to it only through a WireOps table and the BridgePort it makes
// (horus/detail/bridge_port.hpp), so T never reaches a transport.
// Internal to horus: users include <horus/topic.hpp>.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "horus/backend.hpp"
#include "horus/byte_buffer.hpp"
#include "horus/topic_options.hpp"
#include "horus/error.hpp"
#include "horus/network.hpp"
#include "horus/transport_registry.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {
struct Settings;
}

namespace horus::detail {

struct TopicCore;

/// What the bridge sends a message with (the export side's sink).
struct ExportSink {
  void* ctx;
  bool (*send)(void* ctx, const void* msg);  // msg: a T
};

/// Decodes a sample of another wire type than the topic's own (a ROS 2 message, ros2/) into a T.
struct ForeignDecoder {
  const void* context;
  /// Fills *out (a default-constructed T) from the sample; large data goes where `sink` places
  /// it. False: the sample gave no message (the decoder counted and reported why).
  bool (*decode)(const void* context, const net::Sample& sample, void* out, const ByteSink* sink);
};

/// The bridge's own handle of the topic: a lane it imports into and a subscriber entry it
/// exports from. Made per type (bridge_port.hpp); used by one bridge, the import side on the
/// transport's thread and the export side by one exporter at a time (they share no state).
class BridgePort {
 public:
  virtual ~BridgePort() = default;
  // -- import: a lane ------------------------------------------------------
  /// Claims a lane, or adopts the predecessor's (`from` != 0); false when none is available.
  virtual bool take_lane(std::uint32_t lane, std::uint64_t from) = 0;
  virtual bool has_lane() const = 0;
  virtual std::uint32_t lane() const = 0;
  virtual std::uint64_t lane_token() const = 0;
  /// Decodes a sample and writes it into the ring; false when it did not decode or was refused.
  virtual bool deliver(net::WireFormat format, const net::Sample& sample) = 0;
  /// The same for a sample that `decoder` decodes (a topic mapped onto ROS 2).
  virtual bool deliver_foreign(const ForeignDecoder& decoder, const net::Sample& sample) = 0;
  /// How many messages the lane takes before one would overwrite a message some subscriber has
  /// not read (the bridge's own export entry, which passes over this lane, aside).
  virtual std::size_t import_room() = 0;
  // -- export: a subscriber entry ------------------------------------------
  /// Subscribes, or adopts the predecessor's entry (`from` != 0); false when none is available.
  virtual bool take_entry(std::uint32_t entry, std::uint64_t from) = 0;
  virtual bool has_entry() const = 0;
  virtual std::uint32_t entry() const = 0;
  virtual std::uint64_t entry_token() const = 0;
  /// Reads every unread message but those of lane `own` and hands each to `sink`; returns how
  /// many it read. Stops early (false from sink: the transport refused it) after that message.
  virtual std::size_t export_pending(std::uint32_t own, const ExportSink& sink) = 0;
  /// Messages the export side lost to overwrites (it lagged a full ring behind).
  virtual std::uint64_t export_lost() const = 0;
  /// Lets go of the lane and the entry without freeing them: a successor adopts them.
  virtual void leave() = 0;
};

/// What the bridge knows of a message type: one table per type.
struct WireOps {
  /// False when the type cannot travel in `format` (LCM: a vector of vectors, an empty array).
  bool (*expressible)(net::WireFormat format) noexcept;
  /// The encoded size of *msg; Errc::MessageTooLarge when the format cannot carry it.
  Result<std::size_t> (*encoded_size)(net::WireFormat format, const void* msg);
  /// Encodes *msg into exactly encoded_size bytes (the transport's buffer).
  void (*encode)(net::WireFormat format, const void* msg, std::span<std::byte> body) noexcept;
  /// The bridge's handle of the topic (non-owning: the core owns the bridge).
  std::unique_ptr<BridgePort> (*make_port)(TopicCore& core);
};

/// This process's side of a fleet topic's bridge (fleet/src/bridge.cpp). Owned by the topic's
/// TopicCore; destroyed before its ring (the link stops exporting and gives the claim up).
class NetworkLink {
 public:
  virtual ~NetworkLink() = default;
  /// Another handle of the topic opens in this process: a handle asking for another
  /// reliability or durability than the bridge has is Errc::ConfigMismatch; a subscribing one
  /// resumes a paused bridge at once.
  virtual Result<void> join(const TopicOptions& options) = 0;
  /// Messages lost on the way, host-wide (the segment's count).
  virtual std::uint64_t dropped() const noexcept = 0;
  /// Remote writers / readers matched by the host's bridge.
  virtual std::uint32_t remote_publishers() const noexcept = 0;
  virtual std::uint32_t remote_subscribers() const noexcept = 0;
  /// Problems this process's bridge reported (incompatible endpoints).
  virtual std::uint64_t errors() const noexcept = 0;
  /// A handle of this process took a publisher lane (its first send): the bridge may move to
  /// this process (the hand-over: a publisher's sends export inline).
  virtual void on_publisher() noexcept {}
};

/// What the fleet layer installs: makes the bridge of a fleet topic's first handle in this
/// process. `qos` holds the type's defaults with the options' overrides; `settings` are the
/// open's (horus/settings.hpp): the bridge, the network engine and the agent take theirs from it.
using NetworkConnector = Result<std::unique_ptr<NetworkLink>> (*)(TopicCore& core, const WireOps& ops,
                                                                   const net::Qos& qos, const TopicOptions& options,
                                                                   const Settings& settings);
/// Installed once, before main(), by the composition root (fleet::install()).
void set_network_connector(NetworkConnector connector) noexcept;

/// A fleet topic's handle connects: the first one of the topic in this process makes the
/// bridge (through the installed connector), later ones join it.
Result<void> connect_network(TopicCore& core, const WireOps& ops, const net::Qos& qos, const TopicOptions& options,
                             const Settings& settings);
/// The same for a handle that Topic<T>::make opens: the QoS from the type's defaults
/// (`type_qos`'s reliability and durability) and the options (which win), the ring's depth;
/// `ops` null is an error naming the type (a library without its standard codec).
Result<void> connect_topic(TopicCore& core, const WireOps* ops, net::Qos type_qos, const TopicOptions& options,
                           std::string_view type_name, const Settings& settings);
/// What a handle of a fleet topic reports (zero on other topics): messages lost on the way
/// (host-wide: the bridge's dropped count), remote writers and readers matched by the host's
/// bridge, the bridge's own lane and entry (not user handles), problems this process's
/// bridge reported (incompatible endpoints) and samples it could not decode.
std::uint64_t network_dropped(const TopicCore& core) noexcept;
std::uint32_t network_publishers(const TopicCore& core) noexcept;   // remote writers + local lanes
std::uint32_t network_subscribers(const TopicCore& core) noexcept;  // remote readers + local entries
std::uint64_t network_errors(const TopicCore& core) noexcept;
/// True when this process holds the host's bridge of the topic (a fleet topic).
bool network_holds_bridge(const TopicCore& core) noexcept;
/// A handle of a fleet topic took a publisher lane (LocalPort: its first send).
void network_publisher(TopicCore& core) noexcept;
/// Threads blocked on the topic's doorbell on this host, the bridge's own registration not counted.
std::uint32_t network_waiters(const TopicCore& core) noexcept;
std::uint64_t network_decode_failures(const TopicCore& core) noexcept;
/// Logs (first and every 1024th) a received sample that did not decode, and counts it.
void report_network_decode_failure(TopicCore& core, const std::string& what);

}  // namespace horus::detail

HORUS_API_END

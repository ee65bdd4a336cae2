// The network path of a fleet topic, not a template: api/src/network_bridge.cpp. The bridge of a
// topic in this process owns the transport's endpoint and listener and the handle that writes
// received samples into the topic's local ring. All it knows of the message type is a WireOps
// table made from the reflection (horus/detail/wire_ops.hpp), so T never reaches a transport.
// Internal to horus: users include <horus/topic.hpp>.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "horus/backend.hpp"
#include "horus/error.hpp"
#include "horus/network.hpp"
#include "horus/transport_registry.hpp"

namespace horus::detail {

struct TopicCore;

/// What the bridge knows of a message type: one table per type.
struct WireOps {
  /// False when the type cannot travel in `format` (LCM: a vector of vectors, an empty array).
  bool (*expressible)(net::WireFormat format) noexcept;
  /// The encoded size of *msg; Errc::MessageTooLarge when the format cannot carry it.
  Result<std::size_t> (*encoded_size)(net::WireFormat format, const void* msg);
  /// Encodes *msg into exactly encoded_size bytes (the transport's buffer).
  void (*encode)(net::WireFormat format, const void* msg, std::span<std::byte> body) noexcept;
  /// The receiving side: a publishing handle of the topic (made once per topic and process)
  /// that decodes each sample and writes it into the local ring.
  void* (*make_receiver)(TopicCore& core);
  void (*destroy_receiver)(void* receiver) noexcept;
  void (*deliver)(void* receiver, net::WireFormat format, const net::Sample& sample);
};

/// A fleet topic's handle connects: the first one of the topic in this process creates the
/// bridge (its receiver first, then the endpoint, so no sample arrives before the receiver).
/// `qos` holds the type's defaults with the options' overrides; a later handle asking for another
/// reliability or durability than the endpoint has is Errc::ConfigMismatch.
Result<void> connect_network(TopicCore& core, const WireOps& ops, const net::Qos& qos, const TopicOptions& options);
/// Encodes and sends one message; false on failure (logged, first and every 1024th of `failures`).
bool network_send(TopicCore& core, const void* msg, std::uint64_t& failures);
/// The transport brings this process's own samples back (LCM): a send goes to the network only.
bool network_loopback(const TopicCore& core) noexcept;
/// Tells the endpoint whether a handle of this process reads the topic (Endpoint::set_receiving),
/// when that changed. Never called from the transport's threads.
void network_receiving(TopicCore& core, bool on) noexcept;
/// pub_count(): the process's publishing handles (the receiver's lane not counted) plus the
/// remote writers matched; sub_count()'s remote part: the remote readers matched.
std::uint32_t network_pub_count(const TopicCore& core) noexcept;
std::uint32_t network_subscribers(const TopicCore& core) noexcept;
/// What the transport reported for the topic: messages lost (dropped_count), incompatible
/// endpoints (network_errors), samples that did not decode (metrics().decode_failures()).
std::uint64_t network_lost(const TopicCore& core) noexcept;
std::uint64_t network_errors(const TopicCore& core) noexcept;
std::uint64_t network_decode_failures(const TopicCore& core) noexcept;
/// The receiver took a lane (it counts no more in pub_count()).
void network_receiver_publishing(TopicCore& core) noexcept;
/// Logs (first and every 1024th) a received sample that did not decode, and counts it.
void report_network_decode_failure(TopicCore& core, const std::string& what);
/// The error of a send_blocking whose sample the transport refused.
Error network_send_error(const TopicCore& core);

}  // namespace horus::detail

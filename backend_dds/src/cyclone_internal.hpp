// The pieces of the Cyclone DDS transport (private to backend_dds): the transport
// (cyclone_transport.cpp: domain, participant, discovery of remote types, the per-domain cache)
// and the endpoint (cyclone_endpoint.cpp: topic, writer, reader, QoS errors).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <dds/dds.h>

#include "cyclone_sertype.hpp"
#include "horus/error.hpp"
#include "horus/network.hpp"
#include "horus/transport/endpoint_gate.hpp"
#include <cstring>

#include "horus/transport/linger.hpp"
#include "horus/transport/remote_types.hpp"
#include "horus/transport/shared_cache.hpp"

namespace horus::dds::cyclone {

inline constexpr std::uint32_t kTakeBatch = 16;

/// An entity's GUID, or nothing (no entity: 0).
inline std::optional<net::Guid> guid_of(dds_entity_t entity) {
  dds_guid_t g;
  if (entity <= 0 || dds_get_guid(entity, &g) < 0) return std::nullopt;
  net::Guid out;
  static_assert(sizeof(g.v) == out.size());
  std::memcpy(out.data(), g.v, out.size());
  return out;
}

std::string dds_error(dds_return_t rc);

struct QosDeleter {
  void operator()(dds_qos_t* q) const noexcept { dds_delete_qos(q); }
};
using QosPtr = std::unique_ptr<dds_qos_t, QosDeleter>;
struct ListenerDeleter {
  void operator()(dds_listener_t* l) const noexcept { dds_delete_listener(l); }
};
using ListenerPtr = std::unique_ptr<dds_listener_t, ListenerDeleter>;

/// "topic 'fleet.pose' (DDS topic 'horus/fleet/pose')".
std::string endpoint_label(const net::EndpointSpec& spec);

/// The part of an endpoint that Cyclone's threads and the transport's discovery watcher reach.
/// Every listener call goes through its gate.
class EndpointCore {
 public:
  EndpointCore(const net::EndpointSpec& spec, net::Listener& listener)
      : spec_(spec), gate_(listener, endpoint_label(spec)) {}

  const net::EndpointSpec& spec() const noexcept { return spec_; }
  const std::string& label() const noexcept { return gate_.label(); }

  void report(std::string_view message) noexcept {
    gate_.run([&](net::EndpointGate::Calls& calls) { calls.error(message); });
  }
  /// Samples Cyclone reports lost before they reached the reader (a reliable KEEP_LAST writer
  /// that dropped unacknowledged samples, a best-effort gap): added to dropped_count().
  void lost(std::uint64_t count) noexcept {
    gate_.run([&](net::EndpointGate::Calls& calls) { calls.lost(count); });
  }
  /// The matched remote writers or readers changed.
  void matched() noexcept {
    gate_.run([&](net::EndpointGate::Calls& calls) { calls.matched(); });
  }
  /// After this returns, the listener is never called again.
  void close() noexcept { gate_.close(); }
  /// Takes every sample the reader holds and hands the valid ones to the listener.
  void take_all(dds_entity_t reader) noexcept;

 private:
  void deliver(net::EndpointGate::Calls& calls, const ddsi_serdata* sample) noexcept;

  const net::EndpointSpec spec_;
  net::EndpointGate gate_;
  std::vector<std::byte> scratch_;  // used inside the gate only
};

class CycloneTransport final : public net::Transport, public std::enable_shared_from_this<CycloneTransport> {
  struct Private {};

 public:
  static constexpr std::string_view kCacheName = "Cyclone DDS participants";  // its net::SharedCache
  CycloneTransport(Private, net::CacheTicket ticket, const net::Config& config)
      : ticket_(std::move(ticket)), config_(config) {}
  CycloneTransport(const CycloneTransport&) = delete;
  CycloneTransport& operator=(const CycloneTransport&) = delete;
  ~CycloneTransport() override;

  /// Called by the cache, under its lock.
  static Result<std::shared_ptr<CycloneTransport>> create(net::CacheTicket ticket, const net::Config& config);

  std::string_view name() const noexcept override { return "cyclonedds"; }
  bool holds_samples() const noexcept override { return true; }
  bool secure() const noexcept override { return secure_; }
  std::optional<net::Guid> participant_guid() const override { return guid_of(participant_); }
  std::vector<Remote> remote_endpoints() const override { return remote_types_.remotes(); }
  Result<std::unique_ptr<net::Endpoint>> open(const net::EndpointSpec& spec, net::Listener& listener) override;

  const net::Config& config() const noexcept { return config_; }
  dds_entity_t participant() const noexcept { return participant_; }
  /// Before a reliable writer is deleted: waits until its readers acknowledged what it wrote
  /// (net::process_linger(), horus/transport/linger.hpp: its bound and when it does not wait).
  /// Cyclone's own linger, WriterLingerDuration, is off: 1 s per writer, one after the other.
  void linger(dds_entity_t writer) noexcept;
  net::RemoteTypes& remote_types() noexcept { return remote_types_; }

 private:
  static void on_publication(dds_entity_t reader, void* arg);
  static void on_subscription(dds_entity_t reader, void* arg);
  void take_builtin(dds_entity_t reader, bool publisher) noexcept;

  net::CacheTicket ticket_;  // first: removes the cache entry after everything else is gone
  const net::Config config_;
  dds_entity_t domain_ = 0;
  dds_entity_t participant_ = 0;
  dds_guid_t guid_{};
  bool secure_ = false;  // DDS-Security on (set by create)
  net::RemoteTypes remote_types_;  // our endpoints by topic, remote endpoints by built-in instance
};

class CycloneEndpoint final : public net::Endpoint {
 public:
  CycloneEndpoint(std::shared_ptr<CycloneTransport> transport, std::shared_ptr<EndpointCore> core)
      : transport_(std::move(transport)), core_(std::move(core)) {}
  CycloneEndpoint(const CycloneEndpoint&) = delete;
  CycloneEndpoint& operator=(const CycloneEndpoint&) = delete;
  ~CycloneEndpoint() override;

  /// The topic (raw-bytes sertype), writer and reader.
  Result<void> create();
  void mark_registered() noexcept { registered_ = true; }

  Result<void> write(std::size_t body_size, const net::BodyWriter& writer) override;
  void take_held() noexcept override {
    if (reader_ != 0) core_->take_all(reader_);
  }
  std::uint32_t matched_publishers() const override;
  std::uint32_t matched_subscribers() const override;
  std::optional<net::Guid> writer_guid() const override { return guid_of(writer_); }
  std::optional<net::Guid> reader_guid() const override { return guid_of(reader_); }

 private:
  std::shared_ptr<CycloneTransport> transport_;  // keeps the participant alive
  std::shared_ptr<EndpointCore> core_;
  bool registered_ = false;  // in the transport's remote-type watcher
  ddsi_sertype* sertype_ = nullptr;
  dds_entity_t topic_ = 0;
  dds_entity_t writer_ = 0;
  dds_entity_t reader_ = 0;
};

}  // namespace horus::dds::cyclone

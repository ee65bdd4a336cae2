// The network bridge of a fleet topic (horus/detail/network_bridge.hpp): the transport found by
// name in the registry, its endpoint, the listener that hands samples to the topic's receiver,
// and what the transport reports (losses, errors, samples that do not decode).
#include "horus/detail/network_bridge.hpp"

#include <fmt/format.h>

#include <atomic>
#include <mutex>

#include "horus/detail/topic_core.hpp"
#include "horus/log.hpp"

namespace horus::detail {

class NetworkBridge final : public net::Listener {
 public:
  NetworkBridge(TopicCore& core, const WireOps& ops, const net::Qos& qos) : core_(core), ops_(ops), qos_(qos) {}

  TopicCore& core_;
  const WireOps& ops_;
  net::Qos qos_;
  net::WireFormat format_ = net::WireFormat::Xcdr1;
  bool loopback_ = false;  // the transport delivers our own samples back (LCM): send skips the ring
  std::shared_ptr<net::Transport> transport_;
  std::unique_ptr<net::Endpoint> endpoint_;  // reset first: no callback after that
  void* receiver_ = nullptr;                 // ops_.make_receiver; destroyed after the endpoint
  std::mutex mutex_;                         // one sample at a time into the receiver
  std::atomic<bool> receiver_publishing_{false};  // the receiver holds a ring lane
  std::atomic<bool> receiving_{true};             // what the endpoint was last told (set_receiving)
  std::atomic<std::uint64_t> decode_failures_{0};
  std::atomic<std::uint64_t> errors_{0};  // incompatible endpoints reported
  std::atomic<std::uint64_t> lost_{0};    // messages the transport reported lost

  void on_sample(const net::Sample& sample) override {
    std::lock_guard lock(mutex_);
    if (receiver_ != nullptr) ops_.deliver(receiver_, format_, sample);
  }
  void on_lost(std::uint64_t count) override {
    const auto before = lost_.fetch_add(count, std::memory_order_relaxed);
    // Log the first loss, then at most once per 1024 more (the count is in dropped_count()).
    if (before == 0 || before / 1024 != (before + count) / 1024)
      log().warn("topic '{}': the {} backend lost {} message(s) or datagram(s) ({} so far; they count in "
                 "dropped_count()). On LCM the kernel dropped datagrams because the socket receive buffer was "
                 "full: large messages need a larger buffer (HORUS_LCM_URL=...?recv_buf_size=N and sysctl "
                 "net.core.rmem_max)",
                 core_.name, transport_->name(), count, before + count);
  }
  void on_error(std::string_view message) override {
    const auto n = errors_.fetch_add(1, std::memory_order_relaxed) + 1;
    if (n <= 16 || n % 1024 == 0) log().error("{} [{}]", message, transport_->name());
  }
};

void NetworkBridgeDeleter::operator()(NetworkBridge* b) const noexcept {
  if (b == nullptr) return;
  if (b->core_.pid != current_pid()) {
    // A forked child's copy: the participant's threads live in the parent only. Deleting the
    // endpoint here would hang or tell peers that the parent's endpoints are gone: leave it.
    return;
  }
  b->endpoint_.reset();  // no callback after this
  if (b->receiver_ != nullptr) b->ops_.destroy_receiver(b->receiver_);
  delete b;
}

namespace {
std::atomic<int> g_network_pid{0};  // the process that created this process's transports

// Creates the topic's bridge: receiver, then endpoint. The caller holds core.net_mutex.
Result<void> attach(TopicCore& core, const WireOps& ops, const net::Qos& qos) {
  if (const int owner = g_network_pid.load(); owner != 0 && owner != current_pid())
    return fail(Errc::Io, fmt::format("topic '{}': this process was forked from pid {} after that process used {}; "
                                      "network transports (DDS participants, LCM instances) do not survive fork() "
                                      "(their threads stay in the parent). Open network topics before forking only "
                                      "in the process that keeps them, or exec the child",
                                      core.name, owner, to_string(core.backend)));
  const net::TransportInfo* info = net::find_transport(core.backend.transport());
  if (info == nullptr)
    return fail(Errc::Config,
                fmt::format("topic '{}': this build of horus has no {} backend", core.name, to_string(core.backend)));
  auto wire = info->wire_name(core.name);
  if (!wire) return std::unexpected(std::move(wire.error()));
  auto transport = info->open();  // the transport reads its own settings (HORUS_DOMAIN_ID, HORUS_LCM_URL)
  if (!transport) return std::unexpected(std::move(transport.error()));
  std::unique_ptr<NetworkBridge, NetworkBridgeDeleter> bridge(new NetworkBridge(core, ops, qos));
  bridge->format_ = info->format;
  bridge->transport_ = std::move(*transport);
  bridge->loopback_ = bridge->transport_->delivers_own_samples();
  bridge->receiver_ = ops.make_receiver(core);
  net::EndpointSpec spec;
  spec.topic = core.name;
  spec.wire_topic = std::move(*wire);
  spec.type_name = core.type_name;
  spec.type_hash = core.type_hash;
  spec.qos = qos;
  // The bridge is the topic's before the endpoint exists: samples may arrive (on the transport's
  // threads) as soon as it does, and the receiver reports through core.net. User threads see
  // core.net only after this returns (they wait on net_mutex).
  auto& b = *bridge;
  core.net = std::move(bridge);
  auto endpoint = b.transport_->open(spec, b);
  if (!endpoint) {
    core.net.reset();
    return std::unexpected(std::move(endpoint.error()));
  }
  b.endpoint_ = std::move(*endpoint);
  g_network_pid.store(current_pid());
  return {};
}
}  // namespace

Result<void> connect_network(TopicCore& core, const WireOps& ops, const net::Qos& qos, const TopicOptions& options) {
  const auto* info = net::find_transport(core.backend.transport());
  if (info != nullptr && !ops.expressible(info->format))
    return fail(Errc::Config, "topic '" + core.name + "': " + core.type_name +
                                  " cannot travel over LCM: it has a variable-size array of variable-size arrays "
                                  "or an array of size 0, which LCM types cannot express (horus/wire/"
                                  "lcm_mapping.hpp); use another backend for it");
  std::lock_guard lock(core.net_mutex);
  if (!core.net) return attach(core, ops, qos);
  // The topic's endpoint exists: a handle asking for another QoS is an error, not ignored.
  const net::Qos have = core.net->qos_;
  if ((options.reliability && *options.reliability != have.reliability) ||
      (options.durability && *options.durability != have.durability))
    return fail(Errc::ConfigMismatch,
                "topic '" + core.name + "' is open in this process as " + std::string(net::to_string(have.reliability)) +
                    ", " + std::string(net::to_string(have.durability)) +
                    "; cannot open it with another reliability or durability (open it with the same, or "
                    "without either to accept them)");
  return {};
}

bool network_send(TopicCore& core, const void* msg, std::uint64_t& failures) {
  auto& b = *core.net;
  auto report = [&](const Error& error) {
    if (++failures == 1 || failures % 1024 == 0)
      log().error("topic '{}': the {} backend did not send a {} sample: {} ({} so far)", core.name,
                  to_string(core.backend), core.type_name, error.message(), failures);
    return false;
  };
  auto n = b.ops_.encoded_size(b.format_, msg);
  if (!n) return report(n.error());
  struct Context {
    const WireOps* ops;
    net::WireFormat format;
    const void* msg;
  } ctx{&b.ops_, b.format_, msg};
  const net::BodyWriter writer{[](void* c, std::span<std::byte> body) {
                                 const auto& x = *static_cast<const Context*>(c);
                                 x.ops->encode(x.format, x.msg, body);
                               },
                               &ctx};
  if (auto ok = b.endpoint_->write(*n, writer); !ok) [[unlikely]]
    return report(ok.error());
  return true;
}

bool network_loopback(const TopicCore& core) noexcept { return core.net && core.net->loopback_; }

void network_receiving(TopicCore& core, bool on) noexcept {
  if (!core.net || core.net->receiving_.load(std::memory_order_acquire) == on) return;
  // A mutex of its own: the endpoint may wait for the transport's receive thread, which never
  // takes this one (only user threads call here).
  static std::mutex receiving_mutex;
  std::lock_guard lock(receiving_mutex);
  if (core.net->receiving_.load(std::memory_order_acquire) == on) return;
  core.net->receiving_.store(on, std::memory_order_release);
  core.net->endpoint_->set_receiving(on);
}

std::uint32_t network_pub_count(const TopicCore& core) noexcept {
  // The receiver (which writes what arrives into the ring) holds a lane once a sample arrived.
  const std::uint32_t receiver = core.net->receiver_publishing_.load(std::memory_order_acquire) ? 1 : 0;
  return core.ring.publisher_count() - receiver + core.net->endpoint_->matched_publishers();
}

std::uint32_t network_subscribers(const TopicCore& core) noexcept { return core.net->endpoint_->matched_subscribers(); }

std::uint64_t network_lost(const TopicCore& core) noexcept {
  return core.net ? core.net->lost_.load(std::memory_order_relaxed) : 0;
}
std::uint64_t network_errors(const TopicCore& core) noexcept { return core.net->errors_.load(std::memory_order_relaxed); }
std::uint64_t network_decode_failures(const TopicCore& core) noexcept {
  return core.net->decode_failures_.load(std::memory_order_relaxed);
}

void network_receiver_publishing(TopicCore& core) noexcept {
  core.net->receiver_publishing_.store(true, std::memory_order_release);
}

void report_network_decode_failure(TopicCore& core, const std::string& what) {
  const auto n = core.net->decode_failures_.fetch_add(1, std::memory_order_relaxed) + 1;
  if (n == 1 || n % 1024 == 0)
    log().error("topic '{}': a {} sample from the network does not decode as {} ({}); dropped ({} so far)",
                core.name, core.type_name, core.net->format_ == net::WireFormat::Lcm ? "an LCM message" : "XCDR1",
                what, n);
}

Error network_send_error(const TopicCore& core) {
  return Error(Errc::Io, fmt::format("topic '{}': the {} backend did not send the message (the log says why); "
                                     "message not sent",
                                     core.name, to_string(core.backend)));
}

}  // namespace horus::detail

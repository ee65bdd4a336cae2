// The seam to the fleet layer (horus/detail/network_link.hpp): a fleet topic's first handle in
// this process asks the installed connector for the topic's bridge; the per-handle reports read
// the bridge's counts and the segment's host-wide state.
#include "horus/detail/network_link.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>

#include "horus/detail/topic_core.hpp"
#include "horus/log.hpp"

namespace horus::detail {

namespace {
std::atomic<NetworkConnector> g_connector{nullptr};
}  // namespace

void set_network_connector(NetworkConnector connector) noexcept { g_connector.store(connector); }

Result<void> connect_network(TopicCore& core, const WireOps& ops, const net::Qos& qos, const TopicOptions& options,
                             const Settings& settings) {
  std::lock_guard lock(core.net_mutex);
  if (core.net) return core.net->join(options);
  const NetworkConnector connect = g_connector.load();
  if (connect == nullptr)
    return fail(Errc::Config, fmt::format("topic '{}' is a {} topic, but this program has no fleet layer: link it "
                                          "with horus::horus (the package target), which installs the network "
                                          "transports and the fleet layer",
                                          core.name, to_string(core.backend)));
  auto link = connect(core, ops, qos, options, settings);
  if (!link) return std::unexpected(std::move(link.error()));
  core.net = std::move(*link);
  return {};
}

Result<void> connect_topic(TopicCore& core, const WireOps* ops, net::Qos type_qos, const TopicOptions& options,
                           std::string_view type_name, const Settings& settings) {
  if (ops == nullptr)
    return fail(Errc::TypeMismatch, fmt::format("topic '{}': the horus library has no network codec for {} (it was "
                                                "built with HORUS_STANDARD_TYPES=OFF, or its headers and library "
                                                "are of different versions)",
                                                core.name, type_name));
  net::Qos qos = type_qos;
  qos.reliability = options.reliability.value_or(type_qos.reliability);
  qos.durability = options.durability.value_or(type_qos.durability);
  qos.depth = core.ring.capacity();
  qos.deadline_ns = options.deadline.value_or(std::chrono::nanoseconds::zero()).count();
  qos.lifespan_ns = options.lifespan.value_or(std::chrono::nanoseconds::zero()).count();
  qos.priority = static_cast<std::int8_t>(options.priority == Priority::High  ? 1
                                          : options.priority == Priority::Low ? -1
                                                                              : 0);
  return connect_network(core, *ops, qos, options, settings);
}

std::uint64_t network_dropped(const TopicCore& core) noexcept {
  return core.segment && core.net ? core.net->dropped() : 0;
}

std::uint32_t network_publishers(const TopicCore& core) noexcept {
  const std::uint32_t lanes = core.ring.publisher_count();
  if (!core.segment || !core.net) return lanes;
  const auto& b = core.segment->bridge();
  const std::uint32_t bridge_lane = b.import_token.load(std::memory_order_relaxed) != 0 && lanes != 0 ? 1 : 0;
  return lanes - bridge_lane + core.net->remote_publishers();
}

std::uint32_t network_subscribers(const TopicCore& core) noexcept {
  const std::uint32_t entries = core.ring.subscriber_count();
  if (!core.segment || !core.net) return entries;
  const auto& b = core.segment->bridge();
  const std::uint32_t bridge_entry = b.export_token.load(std::memory_order_relaxed) != 0 && entries != 0 ? 1 : 0;
  return entries - bridge_entry + core.net->remote_subscribers();
}

std::uint32_t network_waiters(const TopicCore& core) noexcept {
  const std::uint32_t all = core.ring.doorbell().waiters();
  if (!core.segment || !core.net) return all;
  const auto& b = core.segment->bridge();
  const std::uint64_t token = b.export_token.load(std::memory_order_relaxed);
  const std::uint32_t entry = b.export_entry.load(std::memory_order_relaxed);
  if (token == 0 || entry >= shm::kMaxSubscribers) return all;
  // Every waiter of the ring registers in the doorbell and in its subscriber entry's share
  // (waitset.cpp); the bridge's engine registers with the share of its export entry. Counting
  // the shares of the other entries leaves the bridge out.
  std::uint32_t n = 0;
  const std::uint32_t hwm = std::min(core.ring.header().sub_hwm.load(std::memory_order_acquire), shm::kMaxSubscribers);
  for (std::uint32_t i = 0; i < std::min(hwm, shm::kMaxSubscribers); ++i) {
    const auto& e = core.ring.subscriber(i);
    if (i == entry && e.owner.load(std::memory_order_relaxed) == token) continue;
    n += e.waiting.count.load(std::memory_order_relaxed);
  }
  return n;
}

bool network_holds_bridge(const TopicCore& core) noexcept {
  if (!core.segment || !core.net) return false;
  return static_cast<int>(core.segment->bridge().owner.load(std::memory_order_acquire) >> 32) == current_pid();
}

void network_publisher(TopicCore& core) noexcept {
  if (core.net) core.net->on_publisher();
}

std::uint64_t network_errors(const TopicCore& core) noexcept { return core.net ? core.net->errors() : 0; }

std::uint64_t network_decode_failures(const TopicCore& core) noexcept {
  return core.net_decode_failures.load(std::memory_order_relaxed);
}

// The transport's thread, possibly before connect_network() has stored core.net (samples may
// arrive as soon as the bridge's endpoint exists): only the core's own counter is used.
void report_network_decode_failure(TopicCore& core, const std::string& what) {
  // Host-wide too, in the segment: any process (horus topic info, horus::Fleet) can see it.
  if (core.segment) core.segment->bridge().malformed.fetch_add(1, std::memory_order_relaxed);
  const auto n = core.net_decode_failures.fetch_add(1, std::memory_order_relaxed) + 1;
  if (n != 1 && n % 1024 != 0) return;
  const auto* info = net::find_transport(core.backend.transport());
  const bool lcm = info != nullptr && info->format == net::WireFormat::Lcm;
  log().error("topic '{}': a {} sample from the network does not decode as {} ({}); dropped ({} so far)", core.name,
              core.type_name, lcm ? "an LCM message" : "XCDR1", what, n);
}

}  // namespace horus::detail

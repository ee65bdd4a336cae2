// The members of horus::Topic<T> defined out of the class (opening, send_blocking, the network
// paths): included at the end of horus/topic.hpp. Internal to horus.
#pragma once

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>

#include "horus/config.hpp"
#include "horus/topic.hpp"

namespace horus {

template <class T>
Result<Topic<T>> Topic<T>::make(std::string_view name, const TopicOptions& requested) {
  // Code > environment > HORUS_CONFIG's file > defaults (horus/config.hpp).
  auto resolved = resolve_topic_options(name, requested);
  if (!resolved) return std::unexpected(std::move(resolved.error()));
  const TopicOptions& options = *resolved;
  const detail::TypeInfo type{horus::type_name<T>(), horus::type_hash<T>, Codec::kPayloadBytes, kSerialized,
                              Codec::kPoolBytes};
  auto core = detail::open_core(name, type, options);
  if (!core) return std::unexpected(std::move(core.error()));
  Topic topic(std::move(*core));
  if (!topic.port_.reader().subscribe())
    return fail(Errc::LimitReached, "topic '" + std::string(name) + "' already has " +
                                        std::to_string(shm::kMaxSubscribers) +
                                        " subscribing handles; close some before opening more");
  auto& c = topic.core();
  if (is_network(c.backend)) {
    const net::Qos qos{options.reliability.value_or(net::default_qos<T>::reliability),
                       options.durability.value_or(net::default_qos<T>::durability), c.ring.capacity()};
    if (auto ok = detail::connect_network(c, kWireOps, qos, options); !ok) return std::unexpected(std::move(ok.error()));
    topic.port_.networked = true;
    topic.net_lost_base_ = detail::network_lost(c);
    if (detail::network_loopback(c)) detail::network_receiving(c, true);
  }
  return topic;
}

template <class T>
Result<void> Topic<T>::send_blocking(const T& msg, std::chrono::nanoseconds timeout) {
  using clock = std::chrono::steady_clock;
  if (!port_.ensure_lane()) {
    ++port_.counters.send_failures;
    return std::unexpected(detail::no_lane_error(core(), "message not sent"));
  }
  if (!codec_.prepare(port_, msg)) {  // once: the retries below send what it prepared
    ++port_.counters.send_failures;
    return std::unexpected(codec_.refusal(port_, msg));
  }
  struct Blocking {  // a full pool is the returned error (counted once), not a log line per retry
    Codec& codec;
    explicit Blocking(Codec& c) : codec(c) { codec.set_blocking(true); }
    ~Blocking() { codec.set_blocking(false); }
  } blocking(codec_);
  if (port_.networked && detail::network_loopback(core())) [[unlikely]] {
    // LCM: no flow control and nothing to wait for (the ring is filled by what comes back);
    // a send the transport refuses is that error, not a timeout.
    if (network_send(msg)) return {};
    return std::unexpected(detail::network_send_error(core()));
  }
  if (try_commit(msg)) return {};
  const auto deadline = clock::now() + timeout;
  for (int i = 0; i < 256; ++i) {
    shm::cpu_relax();
    if (try_commit(msg)) return {};
  }
  for (int i = 0; i < 8; ++i) {
    std::this_thread::yield();
    if (try_commit(msg)) return {};
  }
  for (auto now = clock::now(); now < deadline; now = clock::now()) {
    std::this_thread::sleep_for(std::min<clock::duration>(std::chrono::microseconds(100), deadline - now));
    if (try_commit(msg)) return {};
    // A subscriber that died with unread messages must not hold us back: reap (every 50 ms).
    if (detail::reap_dead_participants(core()) && try_commit(msg)) return {};
  }
  ++port_.counters.send_failures;
  if (auto e = codec_.full_error(port_)) return std::unexpected(std::move(*e));
  return std::unexpected(detail::ring_full_error(core(), timeout));
}

template <class T>
void Topic<T>::send_networked(const T& msg) {
  if (core().pid != detail::current_pid()) [[unlikely]] {
    ++port_.counters.send_failures;
    return;
  }
  if (detail::network_loopback(core())) {  // it comes back through the network, once
    // A lane: this handle counts in pub_count(), and a pure publisher stops receiving. Large
    // data too large or inconsistent is refused here, as on other backends.
    if (!port_.ensure_lane() || (kPooled && !codec_.prepare(port_, msg))) [[unlikely]] {
      ++port_.counters.send_failures;
      return;
    }
    network_send(msg);
    return;
  }
  if (send_local(msg)) network_send(msg);
}

template <class T>
void Topic<T>::deliver(void* receiver, net::WireFormat format, const net::Sample& sample) {
  auto& r = *static_cast<Receiver*>(receiver);
  auto& core = r.port.core();
  // LCM brings back everything this process sends: when every handle of the topic here only
  // publishes, nobody reads the ring, so nothing is decoded.
  if (detail::network_loopback(core) && core.ring.subscriber_count() == 0) return;
  if (!r.port.writer().has_lane()) [[unlikely]] {
    if (!r.port.ensure_lane()) {
      ++r.port.counters.send_failures;
      return;
    }
    detail::network_receiver_publishing(core);
  }
  r.codec.deliver(r.port, format, sample);
}

}  // namespace horus

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
                              Codec::kPoolBytes, &reflect::type_signature<T>};
  auto core = detail::open_core(name, type, options);
  if (!core) return std::unexpected(std::move(core.error()));
  Topic topic(std::move(*core));
  topic.watch_ = detail::Watch(options.deadline, options.lifespan);
  if (!topic.port_.reader().subscribe())
    return fail(Errc::LimitReached, "topic '" + std::string(name) + "' already has " +
                                        std::to_string(shm::kMaxSubscribers) +
                                        " subscribing handles; close some before opening more");
  auto& c = topic.core();
  if (is_network(c.backend)) {
    const net::Qos qos{options.reliability.value_or(net::default_qos<T>::reliability),
                       options.durability.value_or(net::default_qos<T>::durability), c.ring.capacity(),
                       options.deadline.value_or(std::chrono::nanoseconds::zero()).count(),
                       options.lifespan.value_or(std::chrono::nanoseconds::zero()).count(),
                       static_cast<std::int8_t>(options.priority == Priority::High  ? 1
                                                : options.priority == Priority::Low ? -1
                                                                                    : 0)};
    if (auto ok = detail::connect_network(c, kWireOps, qos, options); !ok) return std::unexpected(std::move(ok.error()));
    topic.net_dropped_base_ = detail::network_dropped(c);
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
  if (try_commit(msg)) return committed();
  const auto deadline = clock::now() + timeout;
  for (int i = 0; i < 256; ++i) {
    shm::cpu_relax();
    if (try_commit(msg)) return committed();
  }
  for (int i = 0; i < 8; ++i) {
    std::this_thread::yield();
    if (try_commit(msg)) return committed();
  }
  for (auto now = clock::now(); now < deadline; now = clock::now()) {
    std::this_thread::sleep_for(std::min<clock::duration>(std::chrono::microseconds(100), deadline - now));
    if (try_commit(msg)) return committed();
    // A subscriber that died with unread messages must not hold us back: reap (every 50 ms).
    if (detail::reap_dead_participants(core()) && try_commit(msg)) return committed();
  }
  ++port_.counters.send_failures;
  if (auto e = codec_.full_error(port_)) return std::unexpected(std::move(*e));
  return std::unexpected(detail::ring_full_error(core(), timeout));
}

}  // namespace horus

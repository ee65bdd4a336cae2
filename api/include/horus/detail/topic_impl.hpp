// The members of horus::Topic<T> defined out of the class (opening, send_blocking, the network
// paths): included at the end of horus/topic.hpp. Internal to horus.
#pragma once

#include <sched.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <string>

#include "horus/config.hpp"
#include "horus/settings.hpp"
#include "horus/topic.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

template <class T>
Result<Topic<T>> Topic<T>::make(std::string_view name, const TopicOptions& requested) {
  // The settings, taken once and passed down (horus/settings.hpp); code > environment >
  // HORUS_CONFIG's file > defaults (horus/config.hpp).
  auto settings = Settings::current();
  if (!settings) return std::unexpected(std::move(settings.error()));
  auto choice = choose(name, requested, *settings);
  if (!choice) return std::unexpected(std::move(choice.error()));
  const TopicOptions options = options_of(*choice, requested);
  const detail::TypeInfo type{horus::type_name<T>(), horus::type_hash<T>, Codec::kPayloadBytes, kSerialized,
                              Codec::kPoolBytes, &reflect::type_signature<T>};
  auto core = detail::open_core(name, type, options, *settings);
  if (!core) return std::unexpected(std::move(core.error()));
  Topic topic(std::move(*core));
  if (choice->verbose) {
    auto traffic = detail::start_traffic_log(topic.core(), *choice);
    if (!traffic) return std::unexpected(std::move(traffic.error()));
    topic.traffic_ = *traffic;
  }
  topic.watch_ = detail::Watch(options.deadline, options.lifespan, choice->verbose);
  topic.port_.writer().observe(topic.watch_.active());  // its sends reach after_send's watch
  if (!topic.port_.reader().subscribe()) return std::unexpected(detail::subscriber_limit_error(name));
  auto& c = topic.core();
  if (is_network(c.backend)) {
    const net::Qos defaults{net::default_qos<T>::reliability, net::default_qos<T>::durability};
    if (auto ok = detail::connect_topic(c, wire_ops(), defaults, options, horus::type_name<T>(), *settings);
        !ok)
      return std::unexpected(std::move(ok.error()));
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
  if (try_commit(msg)) return committed(msg);
  const auto deadline = clock::now() + timeout;
  for (int i = 0; i < 256; ++i) {
    shm::cpu_relax();
    if (try_commit(msg)) return committed(msg);
  }
  for (int i = 0; i < 8; ++i) {
    ::sched_yield();  // <sched.h> and nanosleep: <thread> costs every node's file 0.1 s to compile
    if (try_commit(msg)) return committed(msg);
  }
  for (auto now = clock::now(); now < deadline; now = clock::now()) {
    const auto nap = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::min<clock::duration>(std::chrono::microseconds(100), deadline - now));
    const ::timespec ts{0, static_cast<long>(nap.count())};
    ::nanosleep(&ts, nullptr);
    if (try_commit(msg)) return committed(msg);
    // A subscriber that died with unread messages must not hold us back: reap (every 50 ms).
    if (detail::reap_dead_participants(core()) && try_commit(msg)) return committed(msg);
  }
  ++port_.counters.send_failures;
  if (auto e = codec_.full_error(port_)) return std::unexpected(std::move(*e));
  return std::unexpected(detail::ring_full_error(core(), timeout));
}

}  // namespace horus

HORUS_API_END

// Send/receive statistics of one Topic handle (topic.metrics()).
#pragma once

#include <cstdint>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

class TopicMetrics {
 public:
  TopicMetrics() = default;
  TopicMetrics(std::uint64_t sent, std::uint64_t received, std::uint64_t send_failures, std::uint64_t recv_failures,
               std::uint64_t dropped, std::uint64_t topic_sent, std::uint64_t decode_failures = 0) noexcept
      : sent_(sent),
        received_(received),
        send_failures_(send_failures),
        recv_failures_(recv_failures),
        dropped_(dropped),
        topic_sent_(topic_sent),
        decode_failures_(decode_failures) {}

  /// Messages this handle published.
  std::uint64_t messages_sent() const noexcept { return sent_; }
  /// Messages this handle received (recv/try_recv that returned a message).
  std::uint64_t messages_received() const noexcept { return received_; }
  /// Failed sends: try_send on a full ring, send_blocking timeouts, sends refused for lack of a
  /// lane, serialized messages refused because they exceed the topic's slot size.
  std::uint64_t send_failures() const noexcept { return send_failures_; }
  /// Receives that found nothing (recv/try_recv on an empty ring).
  std::uint64_t recv_failures() const noexcept { return recv_failures_; }
  /// Same as Topic::dropped_count() at the time of the call.
  std::uint64_t messages_dropped() const noexcept { return dropped_; }
  /// Messages published on the topic by all handles since it was created.
  std::uint64_t topic_messages_sent() const noexcept { return topic_sent_; }
  /// Serialized messages this handle read but could not decode (corrupt slots); skipped.
  std::uint64_t decode_failures() const noexcept { return decode_failures_; }

 private:
  std::uint64_t sent_ = 0, received_ = 0, send_failures_ = 0, recv_failures_ = 0, dropped_ = 0, topic_sent_ = 0, decode_failures_ = 0;
};

}  // namespace horus

HORUS_API_END

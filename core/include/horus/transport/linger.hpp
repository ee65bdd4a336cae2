// net::Linger: how long a transport's reliable writer waits, before it is deleted, for its
// readers to acknowledge what it wrote (both DDS transports).
//
// A writer deleted with a sample some reader has not acknowledged takes the sample with it: a
// datagram the network lost is repaired by the writer only (heartbeat, negative acknowledgement,
// resend), and a volatile reader that matches a successor never gets it. So a closing writer
// waits, at most kWait. Once a wait ran out (a reader that does not answer: a link down, a host
// gone), no writer of the process waits for kQuiet (one instance per process, process_linger():
// a process with many topics and two participants still ends within one bound).
//
// Measured on Fast DDS (three namespace hosts of two processes, 2 vCPUs under load): a closing
// writer's readers acknowledged within 21-74 ms; without the wait, about one run in 20 lost a
// publisher's last message to one host (ctest -R ThreeHostsOfTwoProcesses).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::net {

class Linger {
 public:
  static constexpr std::chrono::milliseconds kWait{250};
  static constexpr std::chrono::seconds kQuiet{5};

  /// Runs `wait(kWait)` (true when every reader acknowledged) unless a wait ran out less than
  /// kQuiet ago.
  template <class Wait>
  void before_delete(Wait&& wait) noexcept {
    const auto now = std::chrono::steady_clock::now().time_since_epoch();
    if (now.count() < quiet_until_.load(std::memory_order_relaxed)) return;
    if (!wait(kWait))
      quiet_until_.store((now + std::chrono::duration_cast<std::chrono::steady_clock::duration>(kQuiet)).count(),
                         std::memory_order_relaxed);
  }

 private:
  std::atomic<std::int64_t> quiet_until_{0};  // steady clock ticks
};

/// The process's one Linger (every transport's writers).
inline Linger& process_linger() noexcept {
  static Linger linger;
  return linger;
}

}  // namespace horus::net

HORUS_API_END

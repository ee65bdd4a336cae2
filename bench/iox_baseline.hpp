// iceoryx 2.0 cross-process ping-pong baseline for horus-latency-shm.
//
// Neither RouDi nor an iceoryx runtime lives in the benchmark process: RouDi, when it shuts
// down, SIGTERMs (then SIGKILLs) every process still registered with it, and a runtime stays
// registered until its process exits. So pingpong() execs two helpers, `self --iox-ping` (on
// the caller's CPUs) and `self --iox-pong` (pinned to child_cpu), and reads the RTTs back.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench_common.hpp"

namespace horus::bench::iox {

/// A private iox-roudi (config in a temp dir); SIGTERM on destruction, SIGKILL after 5 s.
class Roudi {
 public:
  static std::optional<Roudi> start(std::string* why);
  Roudi(Roudi&& o) noexcept;
  Roudi(const Roudi&) = delete;
  Roudi& operator=(const Roudi&) = delete;
  Roudi& operator=(Roudi&&) = delete;
  ~Roudi();

 private:
  Roudi(pid_t pid, std::string dir) : pid_(pid), dir_(std::move(dir)) {}
  pid_t pid_ = -1;
  std::string dir_;
};

/// The helper processes (each registers its own runtime); return a process exit code.
int pong_main(std::size_t payload_bytes, std::uint64_t rounds);
int ping_main(std::size_t payload_bytes, std::uint64_t rounds, int out_fd);

/// Call first thing in main(): runs a helper when argv[1] is --iox-ping, --iox-pong,
/// --iox-fan-sub or --iox-fan-pub.
std::optional<int> child_main(int argc, char** argv);

/// Fan-out through RouDi's shared memory: one publisher helper to n subscriber helpers, each
/// blocked in an iceoryx WaitSet (HAS_DATA), a 16-byte sample (sequence, TSC at send) every
/// `gap` once every subscriber has the previous one. ticks[sub][message]: TSC ticks from send
/// to receipt (0: never received). Empty on failure (why says what failed).
std::vector<std::vector<std::uint64_t>> fanout(int n, std::uint64_t messages, std::uint64_t gap_us,
                                               const std::string& self_exe, std::string* why = nullptr);

/// One-way latencies (RTT/2, ns) of `rounds` ping-pongs of payload_bytes through RouDi's
/// shared memory (zero-copy: only the 8-byte sequence number is written). Empty on failure.
std::vector<double> pingpong(std::size_t payload_bytes, std::uint64_t rounds, int child_cpu, const TscClock& tsc,
                             const std::string& self_exe, std::string* why = nullptr);

}  // namespace horus::bench::iox

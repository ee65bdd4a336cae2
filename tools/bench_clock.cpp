// horus bench ping's one-way latency by clock (bench_cmd_internal.hpp): the echo times matched
// with the ping's own, and the pong's clock against ours.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>

#include "bench_cmd_internal.hpp"
#include "horus/fleet.hpp"

namespace horus::tools::bench_detail {

void ClockSamples::resolve(std::int64_t base, std::int64_t offset, PingResult& r) const {
  for (const auto& m : matched_) {
    const std::int64_t pong = m.pong - offset - base;  // on our steady clock
    const std::int64_t there = pong - m.sent, back = m.received - pong;
    if (there < 0 || back < 0) ++r.clock_below_zero;
    r.forward.add(static_cast<std::uint64_t>(std::max<std::int64_t>(0, there)));
    r.back.add(static_cast<std::uint64_t>(std::max<std::int64_t>(0, back)));
  }
}

// The pong's clock against ours, for one-way by clock: r.clock_*.
void choose_clock(const BenchArgs& a, const std::string& hostid, Fleet* fleet, PingResult& r) {
  if (r.pong_hostid == hostid) {
    r.clock_source = "same host";
    return;
  }
  if (a.clocks_synced) {
    r.clock_source = "synced";
    return;
  }
  if (fleet == nullptr) return;  // clock_why says why
  for (const auto& h : fleet->hosts()) {
    if (fmt::format("{:016x}", h.id) != r.pong_hostid) continue;
    if (!h.clock_offset) {
      r.clock_why = fmt::format("the fleet has no clock offset for {} yet (none of its heartbeats was echoed); "
                                "--clocks-synced uses the clocks as they are",
                                h.name);
      return;
    }
    r.clock_source = "fleet";
    r.clock_offset_ns = std::chrono::nanoseconds(*h.clock_offset).count();
    r.clock_uncertainty_ns = h.clock_uncertainty ? std::chrono::nanoseconds(*h.clock_uncertainty).count() : 0;
    return;
  }
  r.clock_why = fmt::format("the fleet view has no host {} ({}): is the fleet layer off there (fleet.announce: false)?",
                            r.pong_host, r.pong_hostid);
}

}  // namespace horus::tools::bench_detail

// horus bench ping / pong / local (bench_cmd.cpp, bench_ping.cpp, bench_local.cpp): round trips
// through ordinary horus topics, and the local paths beside the machine's true floor.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

namespace horus::tools {

struct BenchArgs {
  std::string prefix = "bench";  // --topic-prefix: topics PREFIX.control, PREFIX.ping.TYPE, PREFIX.pong.TYPE
  std::string type;              // --type (default Pose2D; with --size only: CompressedImage or Image)
  std::uint64_t size = 0;        // --size BYTES
  double rate = 1000;            // --rate HZ
  bool flood = false;            // --flood: as fast as the window allows
  std::uint32_t window = 0;      // --window: messages in flight with --flood (0: half the ring)
  double duration = 5;           // --duration S
  std::uint64_t count = 0;       // --count N (instead of --duration)
  double warmup = 2;             // --warmup S
  double handshake = 0;          // seconds the pong may take to answer (0: the warm-up; horus bench local: longer)
  double timeout = 1;            // --timeout S: an echo later than this is lost
  bool remote = false;           // --remote: the pong must be on another host
  bool clocks_synced = false;    // --clocks-synced: the hosts' clocks agree (PTP): no offset for one-way by clock
  bool spin = false;             // --spin: poll instead of sleeping in recv_for
  bool quiet = false;            // --quiet: no progress line
  std::string json, csv, plot;   // output files ("-": stdout for json and csv)
  std::string backend;           // --backend: inproc | shm | a transport (default: the configuration's)
  // pong
  bool once = false;             // --once: exit after one run
  int cpu = -1;                  // --cpu: pin the echo threads (horus bench local's child)
};

int cmd_bench_ping(const BenchArgs& args, const std::atomic<bool>& stop);
int cmd_bench_pong(const BenchArgs& args, const std::atomic<bool>& stop);
int cmd_bench_local(const BenchArgs& args, const std::atomic<bool>& stop);

}  // namespace horus::tools

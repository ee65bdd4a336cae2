// horus_py_peer: the C++ side of the Python benchmark (bench/python/bench_python.py), and the
// C++ pair it is compared with in the same run.
//
//   horus_py_peer pong <prefix> <cmdvel|image> <seconds>
//       answers every message on <prefix>.ping with one on <prefix>.pong (a CmdVel with the same
//       stamp; an Image of the same size from a loan, nothing copied, with the same timestamp),
//       spinning on recv(); says "ready"; ends at <seconds> or when stdin closes
//   horus_py_peer ping <prefix> <cmdvel|image> <count> [<height> <width>]
//       the C++ ping against that pong: prints the round trips' "p50 p99 p999 min" in ns
//   horus_py_peer local <count>
//       send + recv of a CmdVel on one thread, per pair: "p50 p99 p999 min" in ns
//
// The pong runs on the last CPU, ping and local on CPU 0 (as bench_python.py's own side).
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "../bench_common.hpp"
#include "horus/horus.hpp"

namespace {

using Clock = std::chrono::steady_clock;
namespace msg = horus::msg;

bool stdin_closed() {
  pollfd p{0, POLLIN, 0};
  if (::poll(&p, 1, 0) <= 0) return false;
  char c;
  return ::read(0, &c, 1) <= 0;
}

std::uint64_t ns_since(Clock::time_point t0) {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count());
}

void print(std::vector<double>& ns) {
  const auto p = horus::bench::percentiles(ns);
  std::printf("%.0f %.0f %.0f %.0f\n", p.p50, p.p99, p.p999, p.min);
}

// The stamp a message carries: CmdVel's stamp_nanos, an Image's timestamp_ns.
std::uint64_t stamp(const msg::CmdVel& m) { return m.stamp_nanos; }
std::uint64_t stamp(const msg::Image& m) { return m.timestamp_ns(); }

template <class T>
int pong(const std::string& prefix, double seconds) {
  auto in = horus::Topic<T>::open(prefix + ".ping");
  auto out = horus::Topic<T>::open(prefix + ".pong");
  if (!in || !out) {
    std::fprintf(stderr, "horus_py_peer: %s\n", (!in ? in.error() : out.error()).message().c_str());
    return 3;
  }
  out->publish_only();
  std::printf("ready\n");
  std::fflush(stdout);
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::uint64_t polls = 0;
  while (Clock::now() < end) {
    auto m = in->recv();
    if (!m) {
      _mm_pause();
      if ((++polls & 0xFFFFF) == 0 && stdin_closed()) break;
      continue;
    }
    if constexpr (std::is_same_v<T, msg::Image>) {
      auto loan = out->loan(*msg::Image::describe(m->height(), m->width(), m->encoding()));
      if (!loan) continue;
      (*loan)->set_timestamp_ns(m->timestamp_ns());
      out->send(std::move(*loan));
    } else {
      out->send(*m);
    }
  }
  return 0;
}

template <class T>
int ping(const std::string& prefix, int count, std::uint32_t height, std::uint32_t width) {
  auto out = horus::Topic<T>::open(prefix + ".ping");
  auto in = horus::Topic<T>::open(prefix + ".pong");
  if (!in || !out) {
    std::fprintf(stderr, "horus_py_peer: %s\n", (!in ? in.error() : out.error()).message().c_str());
    return 3;
  }
  std::vector<double> rtt;
  rtt.reserve(static_cast<std::size_t>(count));
  const int warmup = count / 10;
  for (int i = 0; i < count + warmup; ++i) {
    const auto seq = static_cast<std::uint64_t>(i + 1);
    const auto t0 = Clock::now();
    if constexpr (std::is_same_v<T, msg::Image>) {
      auto loan = out->loan(*msg::Image::describe(height, width, msg::ImageEncoding::Rgb8));
      if (!loan) return 4;
      (*loan)->set_timestamp_ns(seq);
      out->send(std::move(*loan));
    } else {
      msg::CmdVel m = msg::CmdVel::make(1.0f, 0.5f);
      m.stamp_nanos = seq;
      out->send(m);
    }
    for (;;) {
      auto r = in->recv();
      if (r && stamp(*r) == seq) break;
      if (!r) _mm_pause();
      if (ns_since(t0) > 2'000'000'000ull) {
        std::fprintf(stderr, "horus_py_peer: no pong for ping %d in 2 s\n", i);
        return 5;
      }
    }
    if (i >= warmup) rtt.push_back(static_cast<double>(ns_since(t0)));
  }
  print(rtt);
  return 0;
}

int local(int count) {
  horus::Topic<msg::CmdVel> pub("bench.py.local");
  horus::Topic<msg::CmdVel> sub("bench.py.local");
  std::vector<double> ns;
  ns.reserve(static_cast<std::size_t>(count));
  msg::CmdVel m = msg::CmdVel::make(1.0f, 0.5f);
  for (int i = 0; i < count; ++i) {
    const auto t0 = Clock::now();
    pub.send(m);
    auto r = sub.recv();
    const auto t = ns_since(t0);
    if (!r) return 4;
    ns.push_back(static_cast<double>(t));
  }
  print(ns);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  horus::bench::pin_to_cpu(mode == "pong" ? horus::bench::cpu_count() - 1 : 0);
  if (mode == "pong" && argc == 5) {
    const std::string type = argv[3];
    return type == "image" ? pong<msg::Image>(argv[2], std::atof(argv[4])) : pong<msg::CmdVel>(argv[2], std::atof(argv[4]));
  }
  if (mode == "ping" && (argc == 5 || argc == 7)) {
    const std::string type = argv[3];
    const int n = std::atoi(argv[4]);
    const auto h = static_cast<std::uint32_t>(argc == 7 ? std::atoi(argv[5]) : 1080);
    const auto w = static_cast<std::uint32_t>(argc == 7 ? std::atoi(argv[6]) : 1920);
    return type == "image" ? ping<msg::Image>(argv[2], n, h, w) : ping<msg::CmdVel>(argv[2], n, h, w);
  }
  if (mode == "local" && argc == 3) return local(std::atoi(argv[2]));
  std::fprintf(stderr,
               "usage: horus_py_peer pong PREFIX cmdvel|image SECONDS | ping PREFIX cmdvel|image COUNT [H W] | local COUNT\n");
  return 2;
}

// horus-latency-shm: cross-process latency and throughput of shared-memory topics, with the
// floor measured in the same run.
//
//   * the true floor: the better of a one-line and a two-line bounce between the two processes
//     through a MAP_SHARED page (cache_floor.hpp), every spin with pause, as in the measured paths;
//   * horus Topic<CmdVel> (16 B), a 1 KiB message, and a 1920x1080 RGB Image through the pool
//     (a loan: zero-copy; and send() of an existing image: one copy into the pool): ping-pong
//     between two processes (fork), one-way = RTT/2, p50/p99/p99.9;
//   * the baseline, iceoryx 2.0 from Debian (when found at build time): the same ping-pong for
//     16 B, 1 KiB and a 6 MB chunk through a private iox-roudi this tool starts and stops;
//   * throughput: CmdVel messages per second from one process to another, lossless
//     (try_send until accepted).
// Parent and child are pinned to two CPUs (--cpus). Blocks of floor and horus rounds are
// interleaved and the ratio to the floor is the median over blocks of the per-block ratio,
// because on a shared VM the floor itself moves from run to run.
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <stdexcept>
#include <atomic>
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "dds/bench_types.hpp"  // the 1 KiB message
#include "horus/detail/cache_floor.hpp"
#include "horus/horus.hpp"
#include "horus/messages.hpp"
#ifdef HORUS_BENCH_ICEORYX
#include "iox_baseline.hpp"
#endif

namespace hb = horus::bench;

namespace {

inline void hb_relax() { hb::spin_pause(); }

// Start and end flags between the two processes (off the measured path).
struct alignas(128) Line {
  std::atomic<std::uint64_t> v{0};
};
struct Shared {
  Line ready;
  Line done;
};

Shared* map_shared() {
  void* p = ::mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::runtime_error("mmap failed");
  return new (p) Shared{};
}

template <class F>
pid_t spawn(int cpu, F&& f) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    hb::pin_to_cpu(cpu);  // the child has one thread
    f();
    ::_exit(0);
  }
  return pid;
}

void wait_child(pid_t pid) { ::waitpid(pid, nullptr, 0); }

std::string unique(const char* what) {
  static int n = 0;
  return fmt::format("bench.shm.{}.{}.{}", what, ::getpid(), n++);
}

// The true floor's two bounces (cache_floor.hpp) between this process and a child, through a
// MAP_SHARED page.
std::vector<double> floor_rounds(std::uint64_t rounds, int cpu, const hb::TscClock& tsc, hb::FloorMode mode) {
  void* p = ::mmap(nullptr, sizeof(hb::FloorLines), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::runtime_error("mmap failed");
  auto* lines = new (p) hb::FloorLines{};
  const pid_t child = spawn(cpu, [&] { hb::floor_echo(*lines, mode, rounds); });
  std::vector<double> out;
  out.reserve(rounds);
  for (std::uint64_t k = 0; k < rounds; ++k) {
    const auto t0 = hb::TscClock::now();
    hb::floor_ping(*lines, mode, k);
    out.push_back(tsc.to_ns(hb::TscClock::now() - t0) / 2.0);
  }
  wait_child(child);
  ::munmap(p, sizeof(hb::FloorLines));
  return out;
}

// Ping-pong of M through two shared-memory topics; make(k) builds message k, seq(m) reads it back.
template <class M, class Make, class Seq>
std::vector<double> topic_rounds(std::uint64_t rounds, int cpu, const hb::TscClock& tsc, Make make, Seq seq) {
  const std::string ping = unique("ping"), pong = unique("pong");
  Shared* s = map_shared();
  horus::Topic<M> pong_sub(pong);
  horus::Topic<M> ping_pub(ping);
  const pid_t child = spawn(cpu, [&] {
    horus::Topic<M> ping_sub(ping);
    horus::Topic<M> pong_pub(pong);
    s->ready.v.store(1, std::memory_order_release);
    for (std::uint64_t k = 0; k < rounds;) {
      if (auto m = ping_sub.recv()) {
        pong_pub.send(*m);
        ++k;
      } else {
        hb_relax();
      }
    }
  });
  while (s->ready.v.load(std::memory_order_acquire) == 0) hb_relax();
  std::vector<double> out;
  out.reserve(rounds);
  for (std::uint64_t k = 0; k < rounds; ++k) {
    const M msg = make(k);
    const auto t0 = hb::TscClock::now();
    ping_pub.send(msg);
    for (;;) {
      if (auto m = pong_sub.recv()) {
        if (seq(*m) == k) break;
      } else {
        hb_relax();
      }
    }
    out.push_back(tsc.to_ns(hb::TscClock::now() - t0) / 2.0);
  }
  wait_child(child);
  ::munmap(s, sizeof(Shared));
  return out;
}

// Ping-pong of a 1920x1080 RGB image through the pool. Zero-copy: each side loans a slot and
// writes only the sequence number (in the first 8 bytes and the timestamp), as the iceoryx
// baseline does. Copy: each side sends an existing image, copied into a slot.
std::vector<double> image_rounds(std::uint64_t rounds, int cpu, const hb::TscClock& tsc, bool loan) {
  using horus::msg::Image;
  const std::string ping = unique("iping"), pong = unique("ipong");
  const auto desc = *Image::describe(1080, 1920, horus::msg::ImageEncoding::Rgb8);
  Shared* s = map_shared();
  horus::Topic<Image> pong_sub(pong);
  horus::Topic<Image> ping_pub(ping);
  auto stamp = [](Image& img, std::uint64_t k) {
    std::memcpy(img.data_mut().data(), &k, sizeof k);
    img.set_timestamp_ns(k);
  };
  auto send = [&](horus::Topic<Image>& t, std::uint64_t k, const Image& frame) {
    if (loan) {
      auto l = t.loan(desc);
      if (!l) throw std::runtime_error(l.error().message());
      stamp(**l, k);
      t.send(std::move(*l));
    } else {
      t.send(frame);
    }
  };
  const pid_t child = spawn(cpu, [&] {
    horus::Topic<Image> ping_sub(ping);
    horus::Topic<Image> pong_pub(pong);
    s->ready.v.store(1, std::memory_order_release);
    for (std::uint64_t k = 0; k < rounds;) {
      if (auto m = ping_sub.recv()) {
        send(pong_pub, m->timestamp_ns(), *m);
        ++k;
      } else {
        hb_relax();
      }
    }
  });
  while (s->ready.v.load(std::memory_order_acquire) == 0) hb_relax();
  Image frame(1080, 1920, horus::msg::ImageEncoding::Rgb8);
  std::vector<double> out;
  out.reserve(rounds);
  for (std::uint64_t k = 0; k < rounds; ++k) {
    if (!loan) stamp(frame, k);
    const auto t0 = hb::TscClock::now();
    send(ping_pub, k, frame);
    for (;;) {
      if (auto m = pong_sub.recv()) {
        if (m->timestamp_ns() == k) break;
      } else {
        hb_relax();
      }
    }
    out.push_back(tsc.to_ns(hb::TscClock::now() - t0) / 2.0);
  }
  wait_child(child);
  ::munmap(s, sizeof(Shared));
  return out;
}

double throughput_cmdvel(std::uint64_t count, int cpu) {
  const std::string name = unique("tput");
  Shared* s = map_shared();
  horus::Topic<horus::msg::CmdVel> pub(name);
  const pid_t child = spawn(cpu, [&] {
    horus::Topic<horus::msg::CmdVel> sub(name);
    s->ready.v.store(1, std::memory_order_release);
    std::uint64_t got = 0;
    while (got < count)
      if (sub.recv()) ++got;
    s->done.v.store(1, std::memory_order_release);
  });
  while (s->ready.v.load(std::memory_order_acquire) == 0) hb_relax();
  auto msg = horus::msg::CmdVel::make(1.0f, 0.5f);
  const auto t0 = std::chrono::steady_clock::now();
  for (std::uint64_t i = 0; i < count; ++i) {
    msg.stamp_nanos = i;
    while (!pub.try_send(msg)) hb_relax();
  }
  while (s->done.v.load(std::memory_order_acquire) == 0) hb_relax();
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  wait_child(child);
  ::munmap(s, sizeof(Shared));
  return static_cast<double>(count) / secs;
}

double p50(std::vector<double> v) { return hb::percentiles(v).p50; }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Options {
  std::uint64_t rounds = 100000;
  int blocks = 10;
  std::uint64_t image_rounds_n = 2000;
  std::uint64_t tput = 2'000'000;
  std::vector<int> cpus{0, 1};
  bool quick = false;
  std::string json_path;
  bool no_iceoryx = false;
};

// Reads the command line into `o` (--quick shrinks the counts); the exit code when the program
// stops there (--help, a bad option).
std::optional<int> parse_options(Options& o, int argc, char** argv) {
  CLI::App app{"horus cross-process latency (shared memory) with the floor measured in the same run"};
  app.add_option("--rounds", o.rounds, "round trips per kind (split into blocks)");
  app.add_option("--blocks", o.blocks, "interleaved blocks")->check(CLI::Range(1, 100));
  app.add_option("--image-rounds", o.image_rounds_n, "round trips of the 1920x1080 image");
  app.add_option("--throughput", o.tput, "messages for the throughput run");
  app.add_option("--cpus", o.cpus, "parent and child CPU")->expected(2);
  app.add_flag("--quick", o.quick, "a short smoke run");
  app.add_option("--json", o.json_path, "also write the rows as JSON");
  app.add_flag("--no-iceoryx", o.no_iceoryx, "skip the iceoryx baseline");
  CLI11_PARSE(app, argc, argv);
  if (o.quick) {
    o.rounds = 4000;
    o.blocks = 2;
    o.image_rounds_n = 100;
    o.tput = 100000;
  }
  return std::nullopt;
}

// Every sample of the run (in ns) and the per-block ratios: p50 / the block's true floor, and
// iceoryx / horus.
struct Samples {
  std::vector<double> floor1_all, floor2_all, cmd_all, kb_all, iox16_all, iox1k_all;
  std::vector<double> one_ratio, two_ratio, cmd_ratio, kb_ratio, iox16_ratio, iox1k_ratio;
  std::vector<double> img, img_copy, iox_img;
  double rate = 0;  // CmdVel messages per second
};

// The whole measurement: the interleaved blocks of floor, horus and iceoryx rounds, then the
// images and the throughput. iox_block(bytes, rounds): the iceoryx samples, none when left out.
template <class IoxBlock>
void measure(const Options& o, std::uint64_t per_block, const hb::TscClock& tsc, IoxBlock& iox_block, Samples& s) {
  const int child_cpu = o.cpus[1];
  for (int b = 0; b < o.blocks; ++b) {
    auto f1 = floor_rounds(per_block, child_cpu, tsc, hb::FloorMode::OneLine);
    auto f2 = floor_rounds(per_block, child_cpu, tsc, hb::FloorMode::TwoLines);
    auto c = topic_rounds<horus::msg::CmdVel>(
        per_block, child_cpu, tsc,
        [](std::uint64_t k) {
          auto m = horus::msg::CmdVel::make(1.0f, 0.5f);
          m.stamp_nanos = k;
          return m;
        },
        [](const horus::msg::CmdVel& m) { return m.stamp_nanos; });
    auto k = topic_rounds<horus_bench::Kilobyte>(
        per_block, child_cpu, tsc,
        [](std::uint64_t i) {
          horus_bench::Kilobyte m;
          m.seq = i;
          return m;
        },
        [](const horus_bench::Kilobyte& m) { return m.seq; });
    auto i16 = iox_block(16, per_block);
    auto i1k = iox_block(1024, per_block);
    const double fb = std::min(p50(f1), p50(f2));  // the true floor of this block
    s.one_ratio.push_back(p50(f1) / fb);
    s.two_ratio.push_back(p50(f2) / fb);
    s.cmd_ratio.push_back(p50(c) / fb);
    s.kb_ratio.push_back(p50(k) / fb);
    if (!i16.empty() && !i1k.empty()) {
      s.iox16_ratio.push_back(p50(i16) / p50(c));
      s.iox1k_ratio.push_back(p50(i1k) / p50(k));
      s.iox16_all.insert(s.iox16_all.end(), i16.begin(), i16.end());
      s.iox1k_all.insert(s.iox1k_all.end(), i1k.begin(), i1k.end());
    }
    s.floor1_all.insert(s.floor1_all.end(), f1.begin(), f1.end());
    s.floor2_all.insert(s.floor2_all.end(), f2.begin(), f2.end());
    s.cmd_all.insert(s.cmd_all.end(), c.begin(), c.end());
    s.kb_all.insert(s.kb_all.end(), k.begin(), k.end());
  }
  s.img = image_rounds(o.image_rounds_n, child_cpu, tsc, /*loan=*/true);
  s.img_copy = image_rounds(std::clamp<std::uint64_t>(o.image_rounds_n / 4, 10, 300), child_cpu, tsc, /*loan=*/false);
  s.iox_img = iox_block(1920 * 1080 * 3, o.image_rounds_n);
  s.rate = throughput_cmdvel(o.tput, child_cpu);
}

// The percentiles of each row. Taking them sorts the samples, as the JSON's CDF points want.
struct Figures {
  hb::Percentiles f1, f2, cmd, kib, img, img_copy;
  bool have_iox = false;
  hb::Percentiles i16, i1k, iim;  // when have_iox
  double img_vs_iox = 0;
  // The true floor's samples: the better of the two bounces.
  const hb::Percentiles& floor() const { return f1.p50 <= f2.p50 ? f1 : f2; }
};

Figures figures_of(Samples& s) {
  Figures f;
  f.f1 = hb::percentiles(s.floor1_all);
  f.f2 = hb::percentiles(s.floor2_all);
  f.cmd = hb::percentiles(s.cmd_all);
  f.kib = hb::percentiles(s.kb_all);
  f.img = hb::percentiles(s.img);
  f.img_copy = hb::percentiles(s.img_copy);
  f.have_iox = !s.iox16_all.empty() && !s.iox_img.empty();
  if (f.have_iox) {
    f.i16 = hb::percentiles(s.iox16_all);
    f.i1k = hb::percentiles(s.iox1k_all);
    f.iim = hb::percentiles(s.iox_img);
    f.img_vs_iox = f.iim.p50 / f.img.p50;
  }
  return f;
}

void print_table(const Options& o, std::uint64_t per_block, const Samples& s, const Figures& f,
                 const std::string& iox_why) {
  const auto &pf1 = f.f1, &pf2 = f.f2, &pc = f.cmd, &pk = f.kib, &pi = f.img, &pic = f.img_copy;
  fmt::print("horus cross-process latency, shared memory (CPUs {} and {}, {} round trips in {} blocks)\n\n", o.cpus[0],
             o.cpus[1], per_block * static_cast<std::uint64_t>(o.blocks), o.blocks);
  fmt::print("{:<44} {:>10} {:>10} {:>10} {:>10}\n", "one-way (RTT/2)", "p50 ns", "p99 ns", "p99.9 ns", "p50/floor*");
  fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>9.2f}x\n", "floor: one line", pf1.p50, pf1.p99, pf1.p999,
             median(s.one_ratio));
  fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>9.2f}x\n", "floor: two lines 256 B apart", pf2.p50, pf2.p99,
             pf2.p999, median(s.two_ratio));
  fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>9.2f}x\n", "horus Topic<CmdVel> (16 B)", pc.p50, pc.p99, pc.p999,
             median(s.cmd_ratio));
  fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>9.2f}x\n", "horus 1 KiB message", pk.p50, pk.p99, pk.p999,
             median(s.kb_ratio));
  fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>10}\n", "horus Image 1920x1080 RGB, loan (zero-copy)", pi.p50,
             pi.p99, pi.p999, "");
  fmt::print("{:<44} {:>10.0f} {:>10.0f} {:>10.0f} {:>10}\n", "horus Image 1920x1080 RGB, send() (one copy)", pic.p50,
             pic.p99, pic.p999, "");
  if (f.have_iox) {
    const auto &i16 = f.i16, &i1k = f.i1k, &iim = f.iim;
    fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>10}\n", "iceoryx 2.0 16 B (loan)", i16.p50, i16.p99, i16.p999, "");
    fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>10}\n", "iceoryx 2.0 1 KiB (loan)", i1k.p50, i1k.p99, i1k.p999, "");
    fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>10}\n", "iceoryx 2.0 6 MB image chunk (loan)", iim.p50, iim.p99,
               iim.p999, "");
    fmt::print("\nvs iceoryx (p50 iceoryx / p50 horus, median over blocks): CmdVel {:.1f}x, 1 KiB {:.1f}x, image "
               "{:.1f}x lower with horus\n",
               median(s.iox16_ratio), median(s.iox1k_ratio), f.img_vs_iox);
  } else {
    fmt::print("\niceoryx baseline: {}\n", iox_why);
  }
  fmt::print("\nthroughput, lossless: {:.1f} M CmdVel/s\n", s.rate / 1e6);
  fmt::print("* median over {} blocks of (p50 / the true floor's p50 in the same block: the better of its one-line\n"
             "  and two-line bounces, every spin with pause; horus/detail/cache_floor.hpp)\n",
             o.blocks);
  const bool iox_met = f.have_iox && median(s.iox16_ratio) >= 3 && median(s.iox1k_ratio) >= 3 && f.img_vs_iox >= 3;
  fmt::print("targets: CmdVel p50 <= 1.2x true floor ({}), p99 <= 3x floor p99 ({}); image p50 < 2 us ({}); "
             "throughput >= 100 M/s ({}); p50 >= 3x lower than iceoryx ({})\n",
             median(s.cmd_ratio) <= 1.2 ? "met" : "missed", pc.p99 <= 3.0 * f.floor().p99 ? "met" : "missed",
             pi.p50 < 2000.0 ? "met" : "missed", s.rate >= 100e6 ? "met" : "missed",
             !f.have_iox ? "not measured" : iox_met ? "met" : "missed");
}

// Every row with its percentiles and CDF points (the samples are sorted by figures_of()).
void write_json(const std::string& path, const Samples& s, const Figures& f) {
  nlohmann::json j;
  auto row = [&](const char* key, const hb::Percentiles& p, const std::vector<double>& sorted, double ratio) {
    j[key] = {{"p50", p.p50}, {"p99", p.p99}, {"p999", p.p999}, {"cdf", hb::cdf_points(sorted)}};
    if (ratio > 0) j[key]["ratio"] = ratio;
  };
  row("floor_one_line", f.f1, s.floor1_all, median(s.one_ratio));
  row("floor_two_lines", f.f2, s.floor2_all, median(s.two_ratio));
  j["floor"] = {{"p50", f.floor().p50}, {"p99", f.floor().p99}, {"p999", f.floor().p999}};
  row("cmdvel", f.cmd, s.cmd_all, median(s.cmd_ratio));
  row("kib", f.kib, s.kb_all, median(s.kb_ratio));
  row("image", f.img, s.img, 0);
  row("image_copy", f.img_copy, s.img_copy, 0);
  if (f.have_iox) {
    row("iceoryx_16b", f.i16, s.iox16_all, 0);
    row("iceoryx_1kib", f.i1k, s.iox1k_all, 0);
    row("iceoryx_image", f.iim, s.iox_img, 0);
    j["vs_iceoryx"] = {{"cmdvel", median(s.iox16_ratio)}, {"kib", median(s.iox1k_ratio)}, {"image", f.img_vs_iox}};
  }
  j["throughput_msgs_per_s"] = s.rate;
  std::ofstream(path) << j.dump() << "\n";
}

}  // namespace

int main(int argc, char** argv) {
#ifdef HORUS_BENCH_ICEORYX
  if (auto rc = hb::iox::child_main(argc, argv)) return *rc;  // the iceoryx ping and pong helpers
#endif
  Options o;
  if (auto rc = parse_options(o, argc, argv)) return *rc;
  hb::pin_to_cpu(o.cpus[0]);
  const hb::TscClock tsc;
  const std::uint64_t per_block = std::max<std::uint64_t>(500, o.rounds / static_cast<std::uint64_t>(o.blocks));

  std::string iox_why = "not built (iceoryx_posh not found by CMake)";
#ifdef HORUS_BENCH_ICEORYX
  const int child_cpu = o.cpus[1];
  const std::optional<hb::iox::Roudi> roudi =
      o.no_iceoryx ? std::nullopt : hb::iox::Roudi::start(&iox_why);  // stopped when main returns
  bool iox = roudi.has_value();
  if (o.no_iceoryx) iox_why = "skipped (--no-iceoryx)";
  char self_buf[4096];
  const ssize_t self_len = ::readlink("/proc/self/exe", self_buf, sizeof(self_buf) - 1);
  const std::string self_exe = self_len > 0 ? std::string(self_buf, static_cast<std::size_t>(self_len)) : argv[0];
  auto iox_block = [&](std::size_t bytes, std::uint64_t n) {
    std::vector<double> v;
    if (iox) {
      v = hb::iox::pingpong(bytes, n, child_cpu, tsc, self_exe, &iox_why);
      if (v.empty()) iox = false;  // reported below
    }
    return v;
  };
#else
  auto iox_block = [](std::size_t, std::uint64_t) { return std::vector<double>{}; };
#endif
  Samples s;
  measure(o, per_block, tsc, iox_block, s);
  const Figures f = figures_of(s);
  print_table(o, per_block, s, f, iox_why);
  if (!o.json_path.empty()) write_json(o.json_path, s, f);
  return 0;
}

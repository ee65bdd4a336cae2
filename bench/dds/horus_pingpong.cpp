// horus-dds-pingpong: the horus side of the DDS latency benchmark (bench/dds/run_dds_bench.sh),
// with the command line of the raw baselines (raw-cyclone-pingpong, raw-fastdds-pingpong):
//
//   horus-dds-pingpong pong <domain> <type> <seconds>
//   horus-dds-pingpong ping <domain> <type> <round_trips> <warmup>
//   horus-dds-pingpong sink <domain> <type> <seconds>      throughput: counts what arrives on
//   horus-dds-pingpong source <domain> <type> <seconds>    bench.<type>.tput, sent back to back (send_blocking)
//     type: cmdvel | kilobyte | image (1920x1080 RGB8)
//
// BENCH_ROS2=1 maps the topics onto ROS 2 (TopicOptions::ros2: CmdVel as geometry_msgs/msg/TwistStamped,
// the image as sensor_msgs/msg/Image, the kilobyte as its horus_msgs type), impl horus-<backend>-ros2.
// The backend comes from HORUS_BACKEND (cyclonedds, fastdds or lcm); BENCH_LOCALHOST=1 keeps DDS
// on loopback (HORUS_DDS_LOCALHOST=1); LCM uses HORUS_LCM_URL (bench/lcm/run_lcm_bench.sh), the
// channels being the topic names, as for the raw baseline raw-lcm-pingpong. LCM has no
// discovery: ping sends probes until the pong answers, and source starts at once. Topics bench.<type>.ping / bench.<type>.pong are the DDS
// topics horus/bench/<type>/ping|pong of the baselines, with the same QoS (reliable, volatile,
// KEEP_LAST 16; 4 for the image). ping prints one line:
//   RESULT impl=horus-<backend> type=<type> n=<n> p50_ns=.. p99_ns=.. p999_ns=.. mean_ns=.. [lost=k]
// with one-way latency = RTT / 2; sink prints
//   RESULT impl=.. type=.. mode=tput received=<n> seconds=<s> rate=<msgs/s> mbps=<MB/s>
// counting from the first message to the stop marker the source sends after <seconds>. A receiving
// handle blocks in recv_for (it sleeps until the backend's receive thread writes a message into
// its ring), as the raw baselines block in a waitset or poll(); BENCH_POLL=1 makes it poll recv()
// (yielding between polls), as the raw programs then poll too.
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "bench_types.hpp"
#include "horus/msg/all.hpp"
#include "horus/topic.hpp"

namespace {

using Clock = std::chrono::steady_clock;
// The stop marker: a sequence number no run reaches, and a stamp ROS 2's Time holds (its seconds
// are an int32: 2e18 ns is 2e9 s), so that it survives a topic mapped onto ROS 2.
constexpr std::uint64_t kStop = 2'000'000'000'000'000'000ULL;

std::uint64_t seq_of(const horus::msg::CmdVel& m) { return m.stamp_nanos; }
std::uint64_t seq_of(const horus_bench::Kilobyte& m) { return m.seq; }
std::uint64_t seq_of(const horus::msg::Image& m) { return m.timestamp_ns(); }
void set_seq(horus::msg::CmdVel& m, std::uint64_t s) { m.stamp_nanos = s; }
void set_seq(horus_bench::Kilobyte& m, std::uint64_t s) { m.seq = s; }
void set_seq(horus::msg::Image& m, std::uint64_t s) { m.set_timestamp_ns(s); }

template <class T>
T make_sample() {
  if constexpr (std::is_same_v<T, horus::msg::Image>) {
    horus::msg::Image img(1080, 1920, horus::msg::ImageEncoding::Rgb8);
    auto bytes = img.data_mut();
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i);
    return img;
  } else if constexpr (std::is_same_v<T, horus_bench::Kilobyte>) {
    horus_bench::Kilobyte k;
    for (std::size_t i = 0; i < k.payload.size(); ++i) k.payload[i] = static_cast<std::uint8_t>(i);
    return k;
  } else {
    return horus::msg::CmdVel{0, 0.5f, 0.25f};
  }
}

// LCM reports no matched endpoints (pub_count / sub_count count this process only).
bool no_discovery() {
  const char* b = std::getenv("HORUS_BACKEND");
  return b != nullptr && std::string_view(b) == "lcm";
}

template <class T>
horus::Result<horus::Topic<T>> open(const std::string& name, std::uint32_t capacity = 0) {
  horus::TopicOptions o;
  o.capacity = capacity != 0 ? capacity : std::is_same_v<T, horus::msg::Image> ? 4u : 16u;
  o.reliability = horus::net::Reliability::Reliable;
  o.durability = horus::net::Durability::Volatile;
  // BENCH_ROS2=1: the topics as a ROS 2 node's (rt/bench/<type>/ping, the ROS 2 type, converted;
  // docs/ROS2.md), against horus's own naming and bytes in the same run.
  static const bool ros2 = [] {
    const char* v = std::getenv("BENCH_ROS2");
    return v != nullptr && std::string(v) == "1";
  }();
  if (ros2) {
    o.ros2 = horus::Ros2Mapping{};
    // The sequence number travels in the stamp: a CmdVel as a TwistStamped (a Twist has none).
    if constexpr (std::is_same_v<T, horus::msg::CmdVel>) o.ros2->type = "geometry_msgs/msg/TwistStamped";
  }
  return horus::Topic<T>::open(name, o);
}

// The next message within `timeout`: recv_for, or with BENCH_POLL=1 recv() in a loop yielding
// between empty polls (as the raw programs poll with BENCH_POLL=1).
template <class Handle>
auto receive(Handle& in, Clock::duration timeout) {
  static const bool poll = [] {
    const char* v = std::getenv("BENCH_POLL");
    return v != nullptr && std::string(v) == "1";
  }();
  if (!poll) return in.recv_for(timeout);
  const auto until = Clock::now() + timeout;
  for (;;) {
    if (auto m = in.recv()) return m;
    if (Clock::now() >= until) return decltype(in.recv()){};
    std::this_thread::yield();
  }
}

bool stdin_closed() {
  pollfd p{0, POLLIN, 0};
  char c;
  return ::poll(&p, 1, 0) > 0 && ::read(0, &c, 1) <= 0;
}

template <class T>
int pong(const std::string& type, double seconds) {
  auto in = open<T>("bench." + type + ".ping");
  auto out = open<T>("bench." + type + ".pong");
  if (!in || !out) {
    std::fprintf(stderr, "horus-dds-pingpong: %s\n", (!in ? in.error() : out.error()).message().c_str());
    return 3;
  }
  std::printf("ready\n");
  std::fflush(stdout);
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (Clock::now() < end) {
    if (auto m = receive(*in, std::chrono::milliseconds(100))) {
      if (seq_of(*m) == kStop) return 0;
      out->send(*m);
      continue;
    }
    if (stdin_closed()) return 0;
  }
  return 0;
}

// Waits (30 s at most) until the pong is matched both ways: its reader and writer, or with LCM
// (no discovery) until it answers a probe. False, said on stderr, when it is not.
template <class T>
bool await_pong(horus::Topic<T>& out, horus::Topic<T>& in) {
  const auto match_deadline = Clock::now() + std::chrono::seconds(30);
  if (no_discovery()) {
    constexpr std::uint64_t kProbe = std::uint64_t{1} << 62;
    T probe = make_sample<T>();
    for (std::uint64_t k = 1;; ++k) {
      if (Clock::now() > match_deadline) {
        std::fprintf(stderr, "horus-dds-pingpong: no pong answered in 30 s\n");
        return false;
      }
      set_seq(probe, kProbe + k);
      out.send(probe);
      bool answered = false;
      const auto until = Clock::now() + std::chrono::milliseconds(200);
      while (!answered) {
        auto m = receive(in, until - Clock::now());
        if (!m) break;
        answered = seq_of(*m) == kProbe + k;
      }
      if (answered) break;
    }
  }
  while (!no_discovery() && (out.sub_count() < 2 || in.pub_count() < 1)) {  // our own reader counts in sub_count
    if (Clock::now() > match_deadline) {
      std::fprintf(stderr, "horus-dds-pingpong: no pong matched in 30 s\n");
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

// Prints ping's RESULT line from the one-way latencies (sorted here); 1 when none came back.
int print_result(const std::string& type, const std::string& impl, std::vector<std::int64_t>& one_way, long lost) {
  if (one_way.empty()) {
    std::printf("RESULT impl=%s type=%s n=0 lost=%ld\n", impl.c_str(), type.c_str(), lost);
    return 1;
  }
  std::sort(one_way.begin(), one_way.end());
  auto rank = [&](double q) {
    auto k = static_cast<std::size_t>(q * static_cast<double>(one_way.size()));
    return one_way[std::min(k, one_way.size() - 1)];
  };
  double mean = 0;
  for (auto v : one_way) mean += static_cast<double>(v);
  mean /= static_cast<double>(one_way.size());
  std::printf("RESULT impl=%s type=%s n=%zu p50_ns=%lld p99_ns=%lld p999_ns=%lld mean_ns=%.0f", impl.c_str(), type.c_str(),
              one_way.size(), static_cast<long long>(rank(0.5)), static_cast<long long>(rank(0.99)),
              static_cast<long long>(rank(0.999)), mean);
  if (lost != 0) std::printf(" lost=%ld", lost);
  std::printf("\n");
  return 0;
}

template <class T>
int ping(const std::string& type, const std::string& impl, long n, long warmup) {
  auto out = open<T>("bench." + type + ".ping");
  auto in = open<T>("bench." + type + ".pong");
  if (!out || !in) {
    std::fprintf(stderr, "horus-dds-pingpong: %s\n", (!out ? out.error() : in.error()).message().c_str());
    return 3;
  }
  if (!await_pong(*out, *in)) return 3;
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  T msg = make_sample<T>();
  std::vector<std::int64_t> one_way;
  one_way.reserve(static_cast<std::size_t>(n));
  long lost = 0;
  for (long i = 0; i < warmup + n; ++i) {
    const std::uint64_t seq = static_cast<std::uint64_t>(i) + 1;
    set_seq(msg, seq);
    const auto t0 = Clock::now();
    out->send(msg);
    bool got = false;
    const auto give_up = t0 + std::chrono::seconds(2);
    while (!got) {
      auto m = receive(*in, give_up - Clock::now());
      if (!m) break;
      got = seq_of(*m) == seq;  // skip stale ones
    }
    const auto t1 = Clock::now();
    if (i < warmup) continue;
    if (!got) {
      ++lost;
      continue;
    }
    one_way.push_back(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count() / 2);
  }
  set_seq(msg, kStop);
  out->send(msg);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  return print_result(type, impl, one_way, lost);
}

template <class T>
int sink(const std::string& type, const std::string& impl, double seconds) {
  // Equal terms: the raw DDS readers hold up to 4096 samples (KEEP_ALL, run_dds_bench.sh) and the
  // raw LCM sink's queue is unlimited; the horus sink's ring is as deep (images: 32 slots).
  auto in = open<T>("bench." + type + ".tput", std::is_same_v<T, horus::msg::Image> ? 32u : 4096u);
  if (!in) {
    std::fprintf(stderr, "horus-dds-pingpong: %s\n", in.error().message().c_str());
    return 3;
  }
  std::printf("ready\n");
  std::fflush(stdout);
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::uint64_t received = 0, bytes = 0;
  Clock::time_point first{}, last{};
  while (Clock::now() < end) {
    auto m = receive(*in, std::chrono::milliseconds(100));
    if (!m) continue;
    if (seq_of(*m) == kStop) break;
    last = Clock::now();
    if (received++ == 0) first = last;
    if constexpr (std::is_same_v<T, horus::msg::Image>) bytes += m->buffer().size();
    else bytes += sizeof(T);
  }
  const double s = std::chrono::duration<double>(last - first).count();
  // dropped: what the topic counted lost (ring overwrites; LCM: datagrams the kernel dropped).
  std::printf("RESULT impl=%s type=%s mode=tput received=%llu seconds=%.3f rate=%.0f mbps=%.1f dropped=%llu\n",
              impl.c_str(), type.c_str(), static_cast<unsigned long long>(received), s,
              s > 0 ? static_cast<double>(received) / s : 0.0, s > 0 ? static_cast<double>(bytes) / s / 1e6 : 0.0,
              static_cast<unsigned long long>(in->dropped_count()));
  return received > 0 ? 0 : 1;
}

template <class T>
int source(const std::string& type, double seconds) {
  // LCM: the raw source runs ahead of the network as far as the kernel's socket buffer lets it;
  // the horus source gets a deep ring to run ahead of its bridge. DDS: a ring of 16 before the
  // bridge's reliable writer, which holds 256 samples as the raw KEEP_ALL writer does.
  auto out = no_discovery() ? open<T>("bench." + type + ".tput", std::is_same_v<T, horus::msg::Image> ? 32u : 4096u)
                            : open<T>("bench." + type + ".tput");
  if (!out) {
    std::fprintf(stderr, "horus-dds-pingpong: %s\n", out.error().message().c_str());
    return 3;
  }
  const auto match_deadline = Clock::now() + std::chrono::seconds(30);
  while (!no_discovery() && out->sub_count() < 2) {
    if (Clock::now() > match_deadline) {
      std::fprintf(stderr, "horus-dds-pingpong: no sink matched in 30 s\n");
      return 3;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  T msg = make_sample<T>();
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  // send_blocking: the host's bridge is a subscriber of the topic, so the source goes as fast as
  // the bridge hands messages to the transport, as a raw writer goes as fast as its write()
  // returns; send() would overwrite what the bridge has not exported yet (counted as dropped).
  std::uint64_t refused = 0;
  for (std::uint64_t seq = 1; Clock::now() < end; ++seq) {
    set_seq(msg, seq);
    if (!out->send_blocking(msg, std::chrono::seconds(1))) ++refused;
  }
  if (refused != 0) std::fprintf(stderr, "horus-dds-pingpong: %llu sends timed out\n", static_cast<unsigned long long>(refused));
  const auto sent_for = std::chrono::duration<double>(Clock::now() - (end - std::chrono::duration_cast<Clock::duration>(
                                                                               std::chrono::duration<double>(seconds))))
                            .count();
  const std::uint64_t sent = seq_of(msg);
  set_seq(msg, kStop);
  for (int i = 0; i < 3; ++i) {
    out->send(msg);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const char* backend = std::getenv("HORUS_BACKEND");
  std::printf("SENT impl=horus-%s type=%s sent=%llu seconds=%.3f rate=%.0f send_failures=%llu\n",
              backend != nullptr ? backend : "?", type.c_str(), static_cast<unsigned long long>(sent), sent_for,
              sent_for > 0 ? static_cast<double>(sent) / sent_for : 0.0,
              static_cast<unsigned long long>(out->metrics().send_failures()));
  return 0;
}

template <class T>
int run(const std::string& role, const std::string& type, char** argv) {
  const char* backend = std::getenv("HORUS_BACKEND");
  const char* ros2 = std::getenv("BENCH_ROS2");
  const std::string impl = std::string("horus-") + (backend != nullptr ? backend : "?") +
                           (ros2 != nullptr && std::string(ros2) == "1" ? "-ros2" : "");
  if (role == "pong") return pong<T>(type, std::atof(argv[4]));
  if (role == "sink") return sink<T>(type, impl, std::atof(argv[4]));
  if (role == "source") return source<T>(type, std::atof(argv[4]));
  return ping<T>(type, impl, std::atol(argv[4]), std::atol(argv[5]));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5 || (std::string(argv[1]) == "ping" && argc < 6)) {
    std::fprintf(stderr,
                 "usage: horus-dds-pingpong pong <domain> <type> <seconds> | ping <domain> <type> <round_trips> <warmup>\n");
    return 2;
  }
  const std::string role = argv[1];
  ::setenv("HORUS_DOMAIN_ID", argv[2], 1);
  const char* local = std::getenv("BENCH_LOCALHOST");
  ::setenv("HORUS_DDS_LOCALHOST", local != nullptr && std::string(local) == "1" ? "1" : "0", 1);
  const std::string type = argv[3];
  if (role != "ping" && role != "pong" && role != "sink" && role != "source") return 2;
  if (type == "cmdvel") return run<horus::msg::CmdVel>(role, type, argv);
  if (type == "kilobyte") return run<horus_bench::Kilobyte>(role, type, argv);
  if (type == "image") return run<horus::msg::Image>(role, type, argv);
  std::fprintf(stderr, "horus-dds-pingpong: unknown type '%s'; expected cmdvel, kilobyte or image\n", type.c_str());
  return 2;
}

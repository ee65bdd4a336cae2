// horus-slow-link-image: one side of bench/fleet/slow_link.sh and priority_link.sh. A camera
// publishes an image topic (side x side mono8, 1024 by default: 1 MiB; best effort as sensor
// data is) at a rate, or a node publishes Pose2D at a rate (stamped); the other host receives
// and reports the age of each message it got (its receive time minus the message's stamp: both
// hosts are namespaces of one machine, one clock), so a link slower than the traffic shows
// whether messages queue up (ages grow) or the newest are kept (ages stay bounded).
//
//   horus-slow-link-image pub <topic> <hz> <seconds> [side]
//   horus-slow-link-image sub <topic> <seconds>          prints "frames N age_ms p50 P p99 Q max M dropped D"
//   horus-slow-link-image pose-pub <topic> <hz> <seconds>
//   horus-slow-link-image pose-sub <topic> <seconds>     the same line for Pose2D
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "horus/msg/geometry.hpp"
#include "horus/msg/image.hpp"
#include "horus/topic.hpp"

namespace {
using namespace std::chrono;

std::uint64_t unix_ns() {
  return static_cast<std::uint64_t>(
      duration_cast<nanoseconds>(system_clock::now().time_since_epoch()).count());
}

template <class T>
std::optional<horus::Topic<T>> open(const std::string& topic, std::uint32_t capacity) {
  horus::TopicOptions o;
  o.capacity = capacity;
  auto t = horus::Topic<T>::open(topic, o);
  if (!t) {
    std::fprintf(stderr, "%s\n", t.error().message().c_str());
    return std::nullopt;
  }
  return std::move(*t);
}

// Sends make(stamp) at `hz` for `secs` seconds.
template <class T, class Make>
int publish(const std::string& topic, std::uint32_t capacity, double hz, int secs, Make make) {
  auto t = open<T>(topic, capacity);
  if (!t) return 3;
  const auto end = steady_clock::now() + seconds(secs);
  const auto period = duration_cast<steady_clock::duration>(duration<double>(1.0 / hz));
  auto next = steady_clock::now();
  std::uint64_t sent = 0;
  while (steady_clock::now() < end) {
    t->send(make(unix_ns()));
    ++sent;
    next += period;
    std::this_thread::sleep_until(next);
  }
  std::printf("sent %llu\n", static_cast<unsigned long long>(sent));
  return 0;
}

template <class T, class Stamp>
int receive(const std::string& topic, std::uint32_t capacity, int secs, Stamp stamp) {
  auto t = open<T>(topic, capacity);
  if (!t) return 3;
  const auto end = steady_clock::now() + seconds(secs);
  std::vector<double> ages;
  while (steady_clock::now() < end) {
    if (auto m = t->recv_for(milliseconds(50))) ages.push_back(static_cast<double>(unix_ns() - stamp(*m)) / 1e6);
  }
  std::sort(ages.begin(), ages.end());
  auto q = [&](double p) {
    return ages.empty() ? -1.0
                        : ages[std::min(ages.size() - 1, static_cast<std::size_t>(p * static_cast<double>(ages.size())))];
  };
  std::printf("frames %zu age_ms p50 %.1f p99 %.1f max %.1f dropped %llu\n", ages.size(), q(0.5), q(0.99),
              ages.empty() ? -1.0 : ages.back(), static_cast<unsigned long long>(t->dropped_count()));
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  const std::string role = argc > 1 ? argv[1] : "";
  const bool pub = role == "pub" || role == "pose-pub";
  if ((pub && argc != 5 && !(role == "pub" && argc == 6)) || (!pub && argc != 4) ||
      (role != "pub" && role != "sub" && role != "pose-pub" && role != "pose-sub")) {
    std::fprintf(stderr,
                 "usage: %s pub <topic> <hz> <seconds> [side] | sub <topic> <seconds> | pose-pub <topic> <hz> <seconds> | "
                 "pose-sub <topic> <seconds>\n",
                 argv[0]);
    return 2;
  }
  const std::string topic = argv[2];
  if (role == "pub") {
    const auto side = static_cast<std::uint32_t>(argc == 6 ? std::atoi(argv[5]) : 1024);
    return publish<horus::msg::Image>(topic, 4, std::atof(argv[3]), std::atoi(argv[4]), [side](std::uint64_t now) {
      horus::msg::Image img(side, side, horus::msg::ImageEncoding::Mono8);
      img.set_timestamp_ns(now);
      return img;
    });
  }
  if (role == "pose-pub")
    return publish<horus::msg::Pose2D>(topic, 64, std::atof(argv[3]), std::atoi(argv[4]), [](std::uint64_t now) {
      return horus::msg::Pose2D{1.0, 2.0, 0.5, now};
    });
  if (role == "sub")
    return receive<horus::msg::Image>(topic, 4, std::atoi(argv[3]), [](const horus::msg::Image& m) { return m.timestamp_ns(); });
  return receive<horus::msg::Pose2D>(topic, 64, std::atoi(argv[3]), [](const horus::msg::Pose2D& m) { return m.timestamp_ns; });
}

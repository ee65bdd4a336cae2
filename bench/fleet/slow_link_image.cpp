// horus-slow-link-image: one side of bench/fleet/slow_link.sh. A camera publishes a 1 MiB
// image topic (1024 x 1024 mono8, best effort as sensor data is) at a rate; the other host
// receives it and reports the age of each frame it got (its receive time minus the frame's
// stamp: both hosts are namespaces of one machine, one clock), so a link slower than the
// camera shows whether frames queue up (ages grow) or the newest are kept (ages stay bounded).
//
//   horus-slow-link-image pub <topic> <hz> <seconds>
//   horus-slow-link-image sub <topic> <seconds>     prints "frames N age_ms p50 P p99 Q max M dropped D"
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "horus/msg/image.hpp"
#include "horus/topic.hpp"

namespace {
std::uint64_t unix_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}
}  // namespace

int main(int argc, char** argv) {
  using namespace std::chrono;
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s pub <topic> <hz> <seconds> | sub <topic> <seconds>\n", argv[0]);
    return 2;
  }
  const std::string role = argv[1], topic = argv[2];
  horus::TopicOptions o;
  o.capacity = 4;
  auto t = horus::Topic<horus::msg::Image>::open(topic, o);
  if (!t) {
    std::fprintf(stderr, "%s\n", t.error().message().c_str());
    return 3;
  }
  if (role == "pub" && argc == 5) {
    const double hz = std::atof(argv[3]);
    const auto end = steady_clock::now() + seconds(std::atoi(argv[4]));
    const auto period = duration_cast<steady_clock::duration>(duration<double>(1.0 / hz));
    auto next = steady_clock::now();
    std::uint64_t sent = 0;
    while (steady_clock::now() < end) {
      horus::msg::Image img(1024, 1024, horus::msg::ImageEncoding::Mono8);
      img.set_timestamp_ns(unix_ns());
      t->send(img);
      ++sent;
      next += period;
      std::this_thread::sleep_until(next);
    }
    std::printf("sent %llu\n", static_cast<unsigned long long>(sent));
    return 0;
  }
  if (role != "sub") return 2;
  const auto end = steady_clock::now() + seconds(std::atoi(argv[3]));
  std::vector<double> ages;
  while (steady_clock::now() < end) {
    if (auto m = t->recv_for(milliseconds(50))) {
      ages.push_back(static_cast<double>(unix_ns() - m->timestamp_ns()) / 1e6);
    }
  }
  std::sort(ages.begin(), ages.end());
  auto q = [&](double p) { return ages.empty() ? -1.0 : ages[std::min(ages.size() - 1, static_cast<std::size_t>(p * static_cast<double>(ages.size())))]; };
  std::printf("frames %zu age_ms p50 %.1f p99 %.1f max %.1f dropped %llu\n", ages.size(), q(0.5), q(0.99),
              ages.empty() ? -1.0 : ages.back(), static_cast<unsigned long long>(t->dropped_count()));
  return 0;
}

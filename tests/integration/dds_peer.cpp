// horus_dds_peer: the other process of the DDS and LCM tests (and of the multi-host tests). The
// backend comes from HORUS_BACKEND, the domain from HORUS_DOMAIN_ID, the LCM URL from HORUS_LCM_URL. It runs until its deadline or
// until stdin closes (the test that started it ended), so it never outlives a test for long.
//
//   horus_dds_peer echo <prefix> <seconds>
//       for every standard message T: receives on <prefix>.<T> and sends it back on <prefix>.<T>.echo
//   horus_dds_peer publish-pose <topic> <seconds>
//       publishes a Pose2D (x = sequence number) every 20 ms
//   horus_dds_peer expect-mismatch <topic> <seconds>
//       opens <topic> as CmdVel; exits 0 as soon as the backend reports an incompatible remote
//       endpoint (DDS) or a message of another type fails to decode (LCM: another fingerprint),
//       e.g. from a Pose2D publisher on another host, 1 if none is reported in time, or 4 if a
//       message arrives (a Pose2D must never be delivered as a CmdVel)
//   horus_dds_peer burst <topic> <count> <seconds>
//       opens <topic> as a reliable Pose2D, says "ready", waits for a 'g' on stdin, then sends
//       <count> of them (x = sequence number) with send_blocking, as fast as the reliable
//       path takes them, and prints "sent <n>" (how many send_blocking accepted)
//   horus_dds_peer ros2-scan <dds-topic> <type hash> <seconds>
//       a ROS 2 node's LaserScan writer (sensor_msgs::msg::dds_::LaserScan_, USER_DATA
//       "typehash=<type hash>;"): every 20 ms a scan of 720 beams (more than horus's LaserScan
//       holds), then one of 100 beams (stamp 1700000000 s + 5 ns, frame "laser")
//   horus_dds_peer raw <dds-topic or lcm-channel> <dds-type> <seconds>
//       a raw writer (the byte-level transport, no horus codec): every 20 ms, a malformed
//       sample, then a valid Pose2D with x = 42 (tests that bad samples are counted and later
//       good ones still arrive). On LCM the malformed ones are garbage, a truncated Pose2D,
//       a CmdVel (another fingerprint) and a Pose2D with bytes left over.
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "horus/ros2/dynamic.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/wire/xcdr1.hpp"
#include "horus/dds/transports.hpp"
#include "horus/transport_registry.hpp"
#include "horus/wire/lcm.hpp"
#ifdef HORUS_HAVE_LCM
#include "horus/lcm/transport.hpp"
#endif
#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "message_trips.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// True when stdin was closed (or says "quit").
bool parent_gone() {
  pollfd p{0, POLLIN, 0};
  if (::poll(&p, 1, 0) <= 0) return false;
  char c;
  return ::read(0, &c, 1) <= 0 || c == 'q';
}

int publish_pose(const std::string& topic, Clock::time_point deadline) {
  auto pub = horus::Topic<horus::msg::Pose2D>::open(topic);
  if (!pub) {
    std::fprintf(stderr, "horus_dds_peer: %s\n", pub.error().message().c_str());
    return 3;
  }
  std::printf("ready\n");
  std::fflush(stdout);
  for (std::uint64_t i = 0; Clock::now() < deadline && !parent_gone(); ++i) {
    pub->send(horus::msg::Pose2D{static_cast<double>(i), 0.0, 0.0, i});
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return 0;
}

int burst(const std::string& topic, std::uint64_t count, Clock::time_point deadline) {
  horus::TopicOptions reliable;
  reliable.reliability = horus::net::Reliability::Reliable;
  auto pub = horus::Topic<horus::msg::Pose2D>::open(topic, reliable);
  if (!pub) {
    std::fprintf(stderr, "horus_dds_peer: %s\n", pub.error().message().c_str());
    return 3;
  }
  pub->publish_only();
  std::printf("ready\n");
  std::fflush(stdout);
  for (;;) {  // 'g' starts, a closed stdin or 'q' ends
    if (Clock::now() >= deadline) return 1;
    pollfd p{0, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    char c;
    if (::read(0, &c, 1) <= 0 || c == 'q') return 0;
    if (c == 'g') break;
  }
  std::uint64_t sent = 0;
  for (std::uint64_t i = 0; i < count && Clock::now() < deadline; ++i)
    if (pub->send_blocking(horus::msg::Pose2D{static_cast<double>(i), 0.0, 0.0, i}, std::chrono::seconds(5))) ++sent;
  std::printf("sent %llu\n", static_cast<unsigned long long>(sent));
  std::fflush(stdout);
  while (Clock::now() < deadline && !parent_gone()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  return 0;
}

int expect_mismatch(const std::string& topic, Clock::time_point deadline) {
  auto sub = horus::Topic<horus::msg::CmdVel>::open(topic);
  if (!sub) {
    std::fprintf(stderr, "horus_dds_peer: %s\n", sub.error().message().c_str());
    return 3;
  }
  std::printf("ready\n");
  std::fflush(stdout);
  while (Clock::now() < deadline) {
    if (sub->recv()) return 4;
    if (sub->network_errors() > 0 || sub->metrics().decode_failures() > 0) {
      std::printf("mismatch reported\n");
      return 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return 1;
}

struct NoListener final : horus::net::Listener {
  void on_sample(const horus::net::Sample&) override {}
  void on_error(std::string_view) override {}
};

int raw_writer(const std::string& wire_topic, const std::string& type, Clock::time_point deadline) {
  horus::Result<std::shared_ptr<horus::net::Transport>> t = horus::fail(horus::Errc::Config, "no DDS backend");
  const char* backend = std::getenv("HORUS_BACKEND");
  auto config = horus::network_config_from_environment();
  if (!config) return 3;
  // The DDS transports through the registry (with libhorus.so they are plug-ins it loads).
  if (backend != nullptr && (std::string_view(backend) == "cyclonedds" || std::string_view(backend) == "fastdds")) {
    if (const horus::net::TransportInfo* info = horus::net::find_transport(backend)) t = info->open(*config);
  }
  const bool lcm = backend != nullptr && std::string_view(backend) == "lcm";
#ifdef HORUS_HAVE_LCM
  if (lcm) {
    auto url = horus::lcm::url_from(*config);
    if (!url) return 3;
    t = horus::lcm::lcm_transport(*url);
  }
#endif
  if (!t) {
    std::fprintf(stderr, "horus_dds_peer: %s\n", t.error().message().c_str());
    return 3;
  }
  NoListener listener;
  horus::net::EndpointSpec spec{"raw", wire_topic, type, 0, {}};
  auto ep = (*t)->open(spec, listener);
  if (!ep) {
    std::fprintf(stderr, "horus_dds_peer: %s\n", ep.error().message().c_str());
    return 3;
  }
  std::printf("ready\n");
  std::fflush(stdout);
  const horus::msg::Pose2D pose{42.0, 1.0, 2.0, 7};
  const auto good = lcm ? horus::lcm::encode(pose) : horus::cdr::encode(pose);
  std::vector<std::vector<std::byte>> bad = {
      {},                                                  // empty
      std::vector<std::byte>(good.begin(), good.begin() + 5),  // truncated
      std::vector<std::byte>(200, std::byte{0xab}),        // too long / garbage
  };
  if (lcm) {
    bad.push_back(horus::lcm::encode(horus::msg::CmdVel{}));  // another fingerprint
    bad.push_back(std::vector<std::byte>(good.begin(), good.end() - 1));  // one byte short
    auto longer = good;
    longer.push_back(std::byte{0});
    bad.push_back(longer);  // a byte left over
  }
  auto fill = [](void* ctx, std::span<std::byte> body) {
    const auto* v = static_cast<const std::vector<std::byte>*>(ctx);
    if (!v->empty()) std::memcpy(body.data(), v->data(), v->size());
  };
  for (std::size_t i = 0; Clock::now() < deadline && !parent_gone(); ++i) {
    const auto& b = bad[i % bad.size()];
    (void)(*ep)->write(b.size(), horus::net::BodyWriter{fill, const_cast<std::vector<std::byte>*>(&b)});
    (void)(*ep)->write(good.size(), horus::net::BodyWriter{fill, const_cast<std::vector<std::byte>*>(&good)});
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return 0;
}

// A ROS 2 LaserScan of n beams, made by the dynamic codec from its .msg (not by horus's conversion).
std::vector<std::byte> ros2_scan(std::size_t n) {
  nlohmann::json j;
  j["header"] = {{"stamp", {{"sec", 1700000000}, {"nanosec", 5}}}, {"frame_id", "laser"}};
  j["angle_min"] = -1.0;
  j["angle_increment"] = 0.01;
  j["angle_max"] = -1.0 + 0.01 * static_cast<double>(n - 1);
  j["range_min"] = 0.1;
  j["range_max"] = 30.0;
  j["ranges"] = std::vector<double>(n, 2.5);
  return horus::ros2::encode_json(horus::ros2::Interfaces::standard(), "sensor_msgs/msg/LaserScan", j).value();
}

int ros2_scan_writer(const std::string& wire_topic, const std::string& type_hash, Clock::time_point deadline) {
  const char* backend = std::getenv("HORUS_BACKEND");
  auto config = horus::network_config_from_environment();
  const horus::net::TransportInfo* info = backend != nullptr ? horus::net::find_transport(backend) : nullptr;
  if (!config || info == nullptr) return 3;
  auto t = info->open(*config);
  if (!t) return 3;
  NoListener listener;
  horus::net::EndpointSpec spec{"ros2", wire_topic, "sensor_msgs::msg::dds_::LaserScan_", 0, {}};
  spec.qos.reliability = horus::net::Reliability::Reliable;
  spec.user_data = "typehash=" + type_hash + ";";
  auto ep = (*t)->open(spec, listener);
  if (!ep) {
    std::fprintf(stderr, "horus_dds_peer: %s\n", ep.error().message().c_str());
    return 3;
  }
  std::printf("ready\n");
  std::fflush(stdout);
  const auto too_long = ros2_scan(720), fits = ros2_scan(100);
  auto fill = [](void* ctx, std::span<std::byte> body) {
    const auto* v = static_cast<const std::vector<std::byte>*>(ctx);
    std::memcpy(body.data(), v->data(), v->size());
  };
  while (Clock::now() < deadline && !parent_gone()) {
    (void)(*ep)->write(too_long.size(), horus::net::BodyWriter{fill, const_cast<std::vector<std::byte>*>(&too_long)});
    (void)(*ep)->write(fits.size(), horus::net::BodyWriter{fill, const_cast<std::vector<std::byte>*>(&fits)});
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: horus_dds_peer echo <prefix> <s> | publish-pose <topic> <s> | raw <topic> <type> <s>\n");
    return 2;
  }
  const std::string mode = argv[1];
  const auto deadline = Clock::now() + std::chrono::seconds(std::atoi(argv[argc - 1]));
  if (mode == "echo") return horus_test::echo_all(argv[2], horus_test::standard_types(), deadline, &parent_gone);
  if (mode == "publish-pose") return publish_pose(argv[2], deadline);
  if (mode == "expect-mismatch") return expect_mismatch(argv[2], deadline);
  if (mode == "burst" && argc == 5) return burst(argv[2], std::strtoull(argv[3], nullptr, 10), deadline);
  if (mode == "raw" && argc == 5) return raw_writer(argv[2], argv[3], deadline);
  if (mode == "ros2-scan" && argc == 5) return ros2_scan_writer(argv[2], argv[3], deadline);
  std::fprintf(stderr, "horus_dds_peer: unknown mode '%s'\n", mode.c_str());
  return 2;
}

// The fleet demo: robots publish their heartbeat, pose and transform; a monitor prints a
// live table of the fleet. Today robots are threads of one process on in-process topics;
// the same code runs unchanged on shared memory and DDS/LCM as those backends land.
//
//   fleet_demo --robots 3 --duration 5
//
// Topics, per robot i: fleet.robot_<i>.heartbeat (Heartbeat, 2 Hz), fleet.robot_<i>.pose
// (Pose2D, --pose-rate Hz), fleet.robot_<i>.tf (TransformStamped, half the pose rate).
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "horus/horus.hpp"

namespace msg = horus::msg;
using clock_type = std::chrono::steady_clock;

namespace {

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

std::string topic_of(int robot, const char* what) { return fmt::format("fleet.robot_{}.{}", robot, what); }

// One robot: drives a circle and publishes at fixed rates until `stop`.
void run_robot(int id, double pose_rate_hz, const std::atomic<bool>& stop) {
  horus::Topic<msg::Heartbeat> heartbeat(topic_of(id, "heartbeat"));
  horus::Topic<msg::Pose2D> pose(topic_of(id, "pose"));
  horus::Topic<msg::TransformStamped> tf(topic_of(id, "tf"));

  msg::Heartbeat hb{};
  (void)hb.set_node_name(fmt::format("robot_{}", id));
  hb.node_id = static_cast<std::uint32_t>(id);

  const auto start = clock_type::now();
  const auto period = std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(1.0 / pose_rate_hz));
  const int ticks_per_heartbeat = std::max(1, static_cast<int>(pose_rate_hz / 2.0));
  const double radius = 1.0 + id;
  const double omega = 0.3 / radius;  // ~0.3 m/s along the circle
  auto next = start;
  for (int tick = 0; !stop.load(std::memory_order_relaxed); ++tick) {
    const double t = std::chrono::duration<double>(clock_type::now() - start).count();
    const double angle = omega * t + id * std::numbers::pi / 3.0;
    auto p = msg::Pose2D::make(radius * std::cos(angle), radius * std::sin(angle), angle + std::numbers::pi / 2.0);
    p.normalize_angle();
    p.timestamp_ns = now_ns();
    pose.send(p);
    if (tick % 2 == 0) {
      auto transform = msg::TransformStamped::from_pose_2d(p);
      transform.timestamp_ns = p.timestamp_ns;
      tf.send(transform);
    }
    if (tick % ticks_per_heartbeat == 0) {
      hb.update(t);
      hb.timestamp_ns = p.timestamp_ns;
      heartbeat.send(hb);
    }
    next += period;
    std::this_thread::sleep_until(next);
  }
}

// What the monitor knows of one robot.
struct RobotView {
  int id = 0;
  horus::Topic<msg::Heartbeat> heartbeat;
  horus::Topic<msg::Pose2D> pose;
  horus::Topic<msg::TransformStamped> tf;
  msg::Heartbeat last_hb{};
  msg::Pose2D last_pose{};
  std::uint64_t hb_count = 0, pose_count = 0, tf_count = 0;
  std::uint64_t hb_prev = 0, pose_prev = 0, tf_prev = 0;

  explicit RobotView(int i)
      : id(i), heartbeat(topic_of(i, "heartbeat")), pose(topic_of(i, "pose")), tf(topic_of(i, "tf")) {}

  void drain() {
    while (auto m = heartbeat.recv()) {
      last_hb = *m;
      ++hb_count;
    }
    while (auto m = pose.recv()) {
      last_pose = *m;
      ++pose_count;
    }
    while (tf.recv()) ++tf_count;
  }
};

void print_table(std::vector<RobotView>& fleet, double elapsed_s, double interval_s) {
  fmt::print("\nt = {:5.1f} s\n", elapsed_s);
  fmt::print("{:<9} {:>5} {:>6} {:>8} {:>8} {:>9} {:>8} {:>7} {:>7} {:>6}\n", "robot", "alive", "hb seq", "x [m]",
             "y [m]", "th [rad]", "pose Hz", "tf Hz", "hb Hz", "drops");
  for (auto& r : fleet) {
    const auto rate = [&](std::uint64_t now, std::uint64_t& prev) {
      const double hz = static_cast<double>(now - prev) / interval_s;
      prev = now;
      return hz;
    };
    const double pose_hz = rate(r.pose_count, r.pose_prev);
    const double tf_hz = rate(r.tf_count, r.tf_prev);
    const double hb_hz = rate(r.hb_count, r.hb_prev);
    const std::uint64_t drops = r.heartbeat.dropped_count() + r.pose.dropped_count() + r.tf.dropped_count();
    fmt::print("{:<9} {:>5} {:>6} {:>8.2f} {:>8.2f} {:>9.2f} {:>8.1f} {:>7.1f} {:>7.1f} {:>6}\n",
               r.hb_count ? std::string(r.last_hb.node_name_str()) : fmt::format("robot_{}", r.id),
               r.last_hb.alive ? "yes" : "no", r.last_hb.sequence, r.last_pose.x, r.last_pose.y,
               r.last_pose.theta, pose_hz, tf_hz, hb_hz, drops);
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  int robots = 3;
  double duration_s = 5.0;
  double pose_rate_hz = 20.0;
  double print_interval_s = 1.0;
  CLI::App app{"horus fleet demo: robots publish heartbeat, pose and transform; a monitor prints the fleet"};
  app.add_option("--robots", robots, "number of robots")->check(CLI::Range(1, 64));
  app.add_option("--duration", duration_s, "seconds to run")->check(CLI::Range(0.5, 86400.0));
  app.add_option("--pose-rate", pose_rate_hz, "pose messages per second per robot")->check(CLI::Range(1.0, 10000.0));
  app.add_option("--interval", print_interval_s, "seconds between tables")->check(CLI::Range(0.1, 60.0));
  CLI11_PARSE(app, argc, argv);

  try {
    // The monitor subscribes first, so it sees every message from the robots' first one on.
    std::vector<RobotView> fleet;
    fleet.reserve(static_cast<std::size_t>(robots));
    for (int i = 1; i <= robots; ++i) fleet.emplace_back(i);

    fmt::print("horus fleet demo: {} robots, {} backend, {:.0f} s\n", robots,
               horus::to_string(fleet.front().pose.backend()), duration_s);
    std::atomic<bool> stop{false};
    std::vector<std::thread> threads;
    for (int i = 1; i <= robots; ++i) threads.emplace_back(run_robot, i, pose_rate_hz, std::cref(stop));

    const auto start = clock_type::now();
    const auto interval = std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(print_interval_s));
    auto next_print = start + interval;
    const auto end = start + std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(duration_s));
    while (clock_type::now() < end) {
      for (auto& r : fleet) r.drain();
      if (clock_type::now() >= next_print) {
        print_table(fleet, std::chrono::duration<double>(clock_type::now() - start).count(), print_interval_s);
        next_print += interval;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    stop = true;
    for (auto& t : threads) t.join();
    for (auto& r : fleet) r.drain();

    int silent = 0;
    std::uint64_t total = 0;
    for (const auto& r : fleet) {
      total += r.hb_count + r.pose_count + r.tf_count;
      if (r.pose_count == 0 || r.hb_count == 0) ++silent;
    }
    fmt::print("\nreceived {} messages from {} robots; {} silent\n", total, robots, silent);
    return silent == 0 ? 0 : 1;
  } catch (const horus::Exception& e) {
    fmt::print(stderr, "fleet_demo: {}\n", e.what());
    return 2;
  }
}

// The spec's production example, on an Executor: a fusion node subscribes to Imu and Odometry
// and publishes a fused Pose3D. Nothing polls: the node sleeps until a message arrives.
//
//   fusion_node                 the node alone: imu + odom in, pose out (Ctrl-C stops it)
//   fusion_node --demo 2        plus simulated sensors (IMU 200 Hz, odometry 50 Hz) and a
//                               listener on "pose", for 2 seconds, then a summary
//
// The fusion is deliberately simple: position and heading from odometry, roll and pitch from the
// IMU (a real node would run a filter here).
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <thread>

#include "horus/horus.hpp"

namespace msg = horus::msg;
using namespace std::chrono_literals;

namespace {

horus::Executor* g_executor = nullptr;
extern "C" void on_signal(int) {
  if (g_executor != nullptr) g_executor->stop();
}

msg::Pose3D fuse(const msg::Imu& imu, const msg::Odometry& odom) {
  const msg::Quaternion q{imu.orientation[0], imu.orientation[1], imu.orientation[2], imu.orientation[3]};
  const auto [roll, pitch, yaw] = q.to_euler();
  (void)yaw;  // the heading comes from odometry
  auto pose = msg::Pose3D::make(msg::Point3{odom.pose.x, odom.pose.y, 0.0},
                                msg::Quaternion::from_euler(roll, pitch, odom.pose.theta));
  pose.timestamp_ns = std::max(imu.timestamp_ns, odom.timestamp_ns);
  return pose;
}

// Simulated sensors: the robot drives a circle; the IMU sees a small roll.
void simulate(std::chrono::nanoseconds duration) {
  horus::Topic<msg::Imu> imu("imu");
  horus::Topic<msg::Odometry> odom("odom");
  horus::Executor ex;
  std::uint64_t t = 0;
  ex.every(5ms, [&] {  // IMU, 200 Hz
    auto m = msg::Imu::make();
    m.set_orientation_from_euler(0.02 * std::sin(1e-9 * static_cast<double>(t)), 0.0, 0.0);
    m.timestamp_ns = t += 5'000'000;
    imu.send(m);
  });
  ex.every(20ms, [&] {  // odometry, 50 Hz
    auto m = msg::Odometry::make();
    const double s = 1e-9 * static_cast<double>(t);
    m.pose = msg::Pose2D::make(std::cos(0.3 * s), std::sin(0.3 * s), 0.3 * s + 1.5707963);
    m.timestamp_ns = t;
    odom.send(m);
  });
  ex.spin_for(duration);
}

}  // namespace

int main(int argc, char** argv) {
  double demo_s = 0;
  CLI::App app{"fusion_node: Imu + Odometry in, fused Pose3D out, on a horus::Executor"};
  app.add_option("--demo", demo_s, "also run simulated sensors and a listener for this many seconds")
      ->check(CLI::Range(0.1, 3600.0));
  CLI11_PARSE(app, argc, argv);

  try {
    horus::Topic<msg::Pose3D> pose_pub("pose");
    std::optional<msg::Imu> last_imu;
    std::optional<msg::Odometry> last_odom;
    std::uint64_t fused = 0;

    horus::Executor node;
    node.subscribe<msg::Imu>("imu", [&](const msg::Imu& m) { last_imu = m; });
    node.subscribe<msg::Odometry>("odom", [&](const msg::Odometry& m) {
      last_odom = m;
      if (last_imu) {
        pose_pub.send(fuse(*last_imu, *last_odom));
        ++fused;
      }
    });

    // The demo's listener: another node (its own Executor) on "pose".
    horus::Executor listener;
    std::atomic<std::uint64_t> heard{0};
    msg::Pose3D last_pose{};
    listener.subscribe<msg::Pose3D>("pose", [&](const msg::Pose3D& p) {
      last_pose = p;
      heard.fetch_add(1);
    });

    g_executor = &node;
    ::signal(SIGINT, on_signal);
    ::signal(SIGTERM, on_signal);
    if (demo_s <= 0) {
      fmt::print("fusion_node: imu + odom -> pose (Ctrl-C to stop)\n");
      node.spin();
      return 0;
    }
    const auto duration = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(demo_s));
    std::thread sensors([&] { simulate(duration); });
    std::thread listening([&] { listener.spin_for(duration + 200ms); });
    node.spin_for(duration + 100ms);
    sensors.join();
    listening.join();
    g_executor = nullptr;
    fmt::print("fused {} poses; the listener heard {}; last pose ({:.2f}, {:.2f}); {} callback errors\n", fused,
               heard.load(), last_pose.position.x, last_pose.position.y, node.callback_errors());
    return fused > 0 && heard.load() == fused ? 0 : 1;
  } catch (const horus::Exception& e) {
    fmt::print(stderr, "fusion_node: {}\n", e.what());
    return 2;
  }
}

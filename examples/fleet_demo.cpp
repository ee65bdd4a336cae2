// The fleet demo: robots publish their heartbeat, pose and transform; a monitor prints a
// live table of the fleet. Every robot is its own process; they meet the monitor through
// shared-memory topics, with no broker. With HORUS_BACKEND=cyclonedds or fastdds the same code
// runs across hosts (robots on some, the monitor on another).
//
//   fleet_demo --robots 3 --duration 5            launch: robot processes + the monitor
//   fleet_demo --role monitor --robots 3           only the monitor (start it before or after)
//   fleet_demo --role robot --id 2                 only robot 2 (e.g. after killing it)
//   fleet_demo --restart 2                         launch, and halfway kill robot 2 and start it again
//   fleet_demo --role robot --id 1 --camera 10     robot 1 also publishes a 640x480 image at 10 Hz
//   fleet_demo --role planner --id 1               reads robot 1's pose and camera on its host
//
// Which topics stay on the host and which go to the fleet is not in this code: scripts/
// fleet-demo.sh runs it on three namespace hosts with HORUS_CONFIG=examples/fleet.yaml (pose,
// heartbeat and transform on fleet scope, the camera on host scope).
//
// Topics, per robot i: fleet.robot_<i>.heartbeat (Heartbeat, 2 Hz), fleet.robot_<i>.pose
// (Pose2D, --pose-rate Hz), fleet.robot_<i>.tf (TransformStamped, half the pose rate).
// Robots and the monitor run on a horus::Executor: timers and message callbacks, no sleep loop.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <thread>
#include <algorithm>
#include <functional>
#include <memory>
#include <vector>

#include "horus/fleet.hpp"
#include "horus/horus.hpp"

extern char** environ;

namespace msg = horus::msg;
using clock_type = std::chrono::steady_clock;

namespace {

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

std::string topic_of(int robot, const char* what) { return fmt::format("fleet.robot_{}.{}", robot, what); }

horus::Executor* g_executor = nullptr;  // what SIGINT/SIGTERM stop
extern "C" void on_signal(int) {
  if (g_executor != nullptr) g_executor->stop();  // async-signal-safe
}

std::string camera_of(int robot) { return fmt::format("robot_{}.camera", robot); }

// One robot: drives a circle and publishes at fixed rates (an Executor timer) for `duration`;
// with camera_hz > 0 also a 640x480 RGB image (written in place in a loaned pool slot).
void run_robot(int id, double pose_rate_hz, double camera_hz, std::chrono::nanoseconds duration) {
  horus::Topic<msg::Heartbeat> heartbeat(topic_of(id, "heartbeat"));
  horus::Topic<msg::Pose2D> pose(topic_of(id, "pose"));
  horus::Topic<msg::TransformStamped> tf(topic_of(id, "tf"));
  std::optional<horus::Topic<msg::Image>> camera;
  if (camera_hz > 0) camera.emplace(camera_of(id));

  msg::Heartbeat hb{};
  (void)hb.set_node_name(fmt::format("robot_{}", id));
  hb.node_id = static_cast<std::uint32_t>(id);

  const auto start = clock_type::now();
  const int ticks_per_heartbeat = std::max(1, static_cast<int>(pose_rate_hz / 2.0));
  const double radius = 1.0 + id;
  const double omega = 0.3 / radius;  // ~0.3 m/s along the circle
  int tick = 0;
  horus::Executor ex;
  ex.every(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(1.0 / pose_rate_hz)), [&] {
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
    ++tick;
  });
  std::uint8_t shade = 0;
  if (camera)
    ex.every(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(1.0 / camera_hz)), [&] {
      auto loan = camera->loan(*msg::Image::describe(480, 640, msg::ImageEncoding::Rgb8));
      if (!loan) return;
      std::fill((*loan)->data_mut().begin(), (*loan)->data_mut().end(), ++shade);
      (*loan)->set_timestamp_ns(now_ns());
      camera->send(std::move(*loan));
    });
  g_executor = &ex;
  ex.spin_for(duration);
  g_executor = nullptr;
}

// A planner beside robot `id` on its host: reads its pose and its camera, prints their rates
// and where each topic goes (its scope) every second; exits 0 when both arrived.
int run_planner(int id, std::chrono::nanoseconds duration) {
  horus::Executor ex;
  std::uint64_t poses = 0, images = 0, poses_prev = 0, images_prev = 0;
  std::uint32_t width = 0, height = 0;
  const auto where = [](std::string_view topic) {  // what HORUS_CONFIG (or the default) chose
    auto o = horus::resolve_topic_options(topic, {});
    return o && o->backend ? std::string(horus::to_string(*o->backend)) : std::string("shm");
  };
  const std::string pose_where = where(topic_of(id, "pose"));
  const std::string camera_where = where(camera_of(id));
  ex.subscribe<msg::Pose2D>(topic_of(id, "pose"), [&](const msg::Pose2D&) { ++poses; });
  ex.subscribe<msg::Image>(camera_of(id), [&](const msg::Image& img) {
    ++images;
    width = img.width();
    height = img.height();
  });
  ex.every(std::chrono::seconds(1), [&] {
    fmt::print("planner robot_{}: pose {} Hz ({}), camera {} Hz {}x{} ({})\n", id, poses - poses_prev,
               pose_where, images - images_prev, width, height, camera_where);
    std::fflush(stdout);
    poses_prev = poses;
    images_prev = images;
  });
  g_executor = &ex;
  ex.spin_for(duration);
  g_executor = nullptr;
  fmt::print("planner robot_{}: {} poses, {} images\n", id, poses, images);
  return poses > 0 && images > 0 ? 0 : 1;
}

// What the monitor knows of one robot (its callbacks on the monitor's Executor fill it in).
struct RobotView {
  int id = 0;
  horus::Executor::Id heartbeat = 0, pose = 0, tf = 0;  // the subscriptions
  msg::Heartbeat last_hb{};
  msg::Pose2D last_pose{};
  std::uint64_t hb_count = 0, pose_count = 0, tf_count = 0;
  std::uint64_t hb_prev = 0, pose_prev = 0, tf_prev = 0;

  RobotView(int i, horus::Executor& ex) : id(i) {
    heartbeat = ex.subscribe<msg::Heartbeat>(topic_of(i, "heartbeat"), [this](const msg::Heartbeat& m) {
      last_hb = m;
      ++hb_count;
    });
    pose = ex.subscribe<msg::Pose2D>(topic_of(i, "pose"), [this](const msg::Pose2D& m) {
      last_pose = m;
      ++pose_count;
    });
    tf = ex.subscribe<msg::TransformStamped>(topic_of(i, "tf"), [this](const msg::TransformStamped&) { ++tf_count; });
  }
  RobotView(const RobotView&) = delete;
};

void print_table(const horus::Executor& ex, std::vector<std::unique_ptr<RobotView>>& fleet, double elapsed_s,
                 double interval_s) {
  fmt::print("\nt = {:5.1f} s\n", elapsed_s);
  fmt::print("{:<9} {:>5} {:>6} {:>8} {:>8} {:>9} {:>8} {:>7} {:>7} {:>6}\n", "robot", "alive", "hb seq", "x [m]",
             "y [m]", "th [rad]", "pose Hz", "tf Hz", "hb Hz", "drops");
  for (auto& rp : fleet) {
    auto& r = *rp;
    const auto rate = [&](std::uint64_t now, std::uint64_t& prev) {
      const double hz = static_cast<double>(now - prev) / interval_s;
      prev = now;
      return hz;
    };
    const double pose_hz = rate(r.pose_count, r.pose_prev);
    const double tf_hz = rate(r.tf_count, r.tf_prev);
    const double hb_hz = rate(r.hb_count, r.hb_prev);
    std::uint64_t drops = 0;
    for (const auto id : {r.heartbeat, r.pose, r.tf})
      if (auto m = ex.metrics(id)) drops += m->messages_dropped();
    fmt::print("{:<9} {:>5} {:>6} {:>8.2f} {:>8.2f} {:>9.2f} {:>8.1f} {:>7.1f} {:>7.1f} {:>6}\n",
               r.hb_count ? std::string(r.last_hb.node_name_str()) : fmt::format("robot_{}", r.id),
               r.last_hb.alive ? "yes" : "no", r.last_hb.sequence, r.last_pose.x, r.last_pose.y,
               r.last_pose.theta, pose_hz, tf_hz, hb_hz, drops);
  }
  std::fflush(stdout);
}

// One line: each host of the fleet with its state, heartbeat age and link RTT.
void print_hosts(const horus::Fleet& f) {
  std::string line;
  for (const auto& h : f.hosts()) {
    line += fmt::format("{}{} {}", line.empty() ? "" : ", ", h.name, horus::to_string(h.state));
    if (h.rejoins > 0) line += fmt::format(" {}x", h.rejoins);
    if (h.self) line += " (here)";
    else line += fmt::format(" ({} ms ago{})", h.heartbeat_age.count(),
                             h.rtt ? fmt::format(", rtt {:.2f} ms", static_cast<double>(h.rtt->count()) / 1000.0) : "");
  }
  fmt::print("hosts: {}\n", line.empty() ? "none heard yet" : line);
  std::fflush(stdout);
}

// Starts `fleet_demo --role robot --id <id> ...` as a child process.
pid_t spawn_robot(int id, double pose_rate_hz, double duration_s) {
  const std::string self = "/proc/self/exe";
  std::vector<std::string> args = {"fleet_demo", "--role", "robot", "--id", std::to_string(id),
                                   "--pose-rate", fmt::format("{}", pose_rate_hz), "--duration",
                                   fmt::format("{}", duration_s + 5.0)};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (::posix_spawn(&pid, self.c_str(), nullptr, nullptr, argv.data(), environ) != 0) return -1;
  return pid;
}

int run_monitor(int robots, double duration_s, double print_interval_s, const std::function<void(double)>& tick) {
  // The monitor subscribes before the robots start (in launch mode), so it sees their first
  // messages. It runs on an Executor: callbacks per message, timers for the table and the
  // launcher's checks; it sleeps between messages instead of polling.
  horus::Executor ex;
  std::vector<std::unique_ptr<RobotView>> fleet;
  for (int i = 1; i <= robots; ++i) fleet.push_back(std::make_unique<RobotView>(i, ex));
  const auto chosen = horus::resolve_topic_options(topic_of(1, "pose"), {});
  fmt::print("horus fleet demo: {} robots, poses on {}, {:.0f} s\n", robots,
             chosen && chosen->backend ? horus::to_string(*chosen->backend) : std::string_view("shm"), duration_s);
  // The hosts of the fleet (horus::Fleet): who is alive, lost, back; on the same Executor.
  const auto start = clock_type::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(clock_type::now() - start).count(); };
  std::unique_ptr<horus::Fleet> hosts;
  if (auto f = horus::Fleet::open(ex)) {
    hosts = std::move(*f);
    hosts->on_change([&](const horus::FleetEvent& e) {
      if (e.kind == horus::FleetEvent::Kind::Changed) return;
      fmt::print("fleet: host {} {} at t = {:.1f} s{}\n", e.host.name, horus::to_string(e.kind), elapsed(),
                 e.kind == horus::FleetEvent::Kind::Lost
                     ? fmt::format(" (no heartbeat for {} ms)", e.host.heartbeat_age.count())
                     : std::string());
      std::fflush(stdout);
    });
  }
  if (tick) tick(-1.0);  // start the robots now
  const auto seconds = [](double s) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s));
  };
  ex.every(seconds(print_interval_s), [&] {
    print_table(ex, fleet, elapsed(), print_interval_s);
    if (hosts) print_hosts(*hosts);
  });
  if (tick) ex.every(std::chrono::milliseconds(50), [&] { tick(std::chrono::duration<double>(clock_type::now() - start).count()); });
  g_executor = &ex;
  ex.spin_for(seconds(duration_s));
  g_executor = nullptr;
  while (ex.spin_once(std::chrono::nanoseconds::zero()) != 0) {
  }  // what is still waiting
  int silent = 0;
  std::uint64_t total = 0;
  for (const auto& r : fleet) {
    total += r->hb_count + r->pose_count + r->tf_count;
    if (r->pose_count == 0 || r->hb_count == 0 || r->tf_count == 0) ++silent;
  }
  if (hosts) print_hosts(*hosts);
  fmt::print("\nreceived {} messages from {} robots; {} silent\n", total, robots, silent);
  return silent == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  int robots = 3;
  int id = 1;
  int restart = 0;
  double duration_s = 5.0;
  double pose_rate_hz = 20.0;
  double print_interval_s = 1.0;
  double camera_hz = 0.0;
  std::string role = "launch";
  CLI::App app{"horus fleet demo: robot processes publish heartbeat, pose and transform; a monitor prints the fleet"};
  app.add_option("--role", role, "launch (robots + monitor), monitor, robot, or planner")
      ->check(CLI::IsMember({"launch", "monitor", "robot", "planner"}));
  app.add_option("--camera", camera_hz, "robot: also publish a 640x480 image at this rate")->check(CLI::Range(0.0, 100.0));
  app.add_option("--robots", robots, "number of robots")->check(CLI::Range(1, 30));
  app.add_option("--id", id, "robot id (--role robot)")->check(CLI::Range(1, 30));
  app.add_option("--duration", duration_s, "seconds to run")->check(CLI::Range(0.5, 86400.0));
  app.add_option("--pose-rate", pose_rate_hz, "pose messages per second per robot")->check(CLI::Range(1.0, 10000.0));
  app.add_option("--interval", print_interval_s, "seconds between tables")->check(CLI::Range(0.1, 60.0));
  app.add_option("--restart", restart, "launch: kill this robot halfway (SIGKILL) and start it again")
      ->check(CLI::Range(0, 30));
  CLI11_PARSE(app, argc, argv);
  ::signal(SIGTERM, on_signal);
  ::signal(SIGINT, on_signal);

  try {
    const auto duration = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(duration_s));
    if (role == "robot") {
      run_robot(id, pose_rate_hz, camera_hz, duration);
      return 0;
    }
    if (role == "planner") return run_planner(id, duration);
    if (role == "monitor") return run_monitor(robots, duration_s, print_interval_s, {});

    // launch: the monitor here, each robot a process of its own.
    std::vector<pid_t> pids(static_cast<std::size_t>(robots) + 1, -1);
    bool restarted = false;
    const int rc = run_monitor(robots, duration_s, print_interval_s, [&](double t) {
      if (t < 0) {
        for (int i = 1; i <= robots; ++i) pids[static_cast<std::size_t>(i)] = spawn_robot(i, pose_rate_hz, duration_s);
      } else if (restart != 0 && restart <= robots && !restarted && t >= duration_s / 2) {
        restarted = true;
        const pid_t old = pids[static_cast<std::size_t>(restart)];
        ::kill(old, SIGKILL);
        ::waitpid(old, nullptr, 0);
        fmt::print("\nkilled robot_{} (pid {}) with SIGKILL; starting it again\n", restart, old);
        pids[static_cast<std::size_t>(restart)] = spawn_robot(restart, pose_rate_hz, duration_s);
      }
    });
    for (int i = 1; i <= robots; ++i) {
      const pid_t pid = pids[static_cast<std::size_t>(i)];
      if (pid > 0) {
        ::kill(pid, SIGTERM);
        ::waitpid(pid, nullptr, 0);
      }
    }
    return rc;
  } catch (const horus::Exception& e) {
    fmt::print(stderr, "fleet_demo: {}\n", e.what());
    return 2;
  }
}

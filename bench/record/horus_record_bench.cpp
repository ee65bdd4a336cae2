// horus-record-bench: recording on one host without loss. A 1080p RGB image topic at 30 Hz and
// ten 1 kHz Imu topics (the traffic of a robot's camera and IMU-rate sensors), recorded for N
// seconds by:
//   - `horus record` from shared memory (MCAP, zstd and lz4 chunks);
//   - on the same traffic sent over LCM (fleet topics, udpm on loopback, ttl=0): `lcm-logger`
//     (the baseline), `horus record --format lcm` and `horus record` (MCAP).
// For each: messages sent, recorded and lost per stream, the recorder's CPU (its utime+stime
// over the traffic, from /proc), and the MB/s it wrote. Several rounds show the spread.
//
//   horus-record-bench [--seconds 10] [--rounds 3] [--quick]
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "horus/horus.hpp"
#include "horus/msg/all.hpp"
#include "horus/record/lcm_log.hpp"
#include "horus/record/player.hpp"

extern char** environ;

namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

struct Config {
  double seconds = 10;
  int rounds = 3;
  std::uint32_t width = 1920, height = 1080;
  double fps = 30;
  int small_topics = 10;
  double small_hz = 1000;
  std::string cli = HORUS_CLI;
  std::string prefix;
  std::string lcm_url;
};

double cpu_seconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const auto close = text.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream rest(text.substr(close + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) utime = std::stod(field);
    if (i == 15) stime = std::stod(field);
  }
  return (utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

class Child {
 public:
  explicit Child(std::vector<std::string> args) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, "/tmp/horus-record-bench.stderr", O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (::posix_spawn(&pid_, argv[0], &fa, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&fa);
  }
  ~Child() { stop(); }
  pid_t pid() const { return pid_; }
  int stop() {
    if (pid_ <= 0) return -1;
    ::kill(pid_, SIGINT);
    int st = 0;
    const auto deadline = Clock::now() + 30s;
    while (::waitpid(pid_, &st, WNOHANG) == 0) {
      if (Clock::now() > deadline) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, &st, 0);
        break;
      }
      std::this_thread::sleep_for(10ms);
    }
    pid_ = -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  }

 private:
  pid_t pid_ = -1;
};

struct Traffic {
  std::uint64_t images = 0, small = 0;  // sent
};

// The robot: images at fps and small_topics Imu topics at small_hz, for `seconds`.
class Robot {
 public:
  Robot(const Config& c, std::optional<horus::Backend> backend) : c_(c) {
    horus::TopicOptions o;
    o.backend = backend;
    auto cam = horus::Topic<horus::msg::Image>::open(c.prefix + ".camera", o);
    if (!cam) throw std::runtime_error(cam.error().message());
    camera_.emplace(std::move(*cam));
    camera_->publish_only();
    for (int i = 0; i < c.small_topics; ++i) {
      auto t = horus::Topic<horus::msg::Imu>::open(fmt::format("{}.imu{}", c.prefix, i), o);
      if (!t) throw std::runtime_error(t.error().message());
      imus_.push_back(std::move(*t));
      imus_.back().publish_only();
    }
    // Four frames of noise (camera images barely compress), rotated; the frame number in front.
    std::mt19937 rng(42);
    for (int f = 0; f < 4; ++f) {
      horus::msg::Image img(c.height, c.width, horus::msg::ImageEncoding::Rgb8);
      auto px = img.data_mut();
      for (std::size_t i = 0; i + 4 <= px.size(); i += 4) {
        const auto r = rng();
        std::memcpy(px.data() + i, &r, 4);
      }
      frames_.push_back(std::move(img));
    }
  }
  // Waits until every topic has a subscriber (the recorder), at most 20 s.
  bool wait_for_recorder() {
    const auto deadline = Clock::now() + 20s;
    while (Clock::now() < deadline) {
      bool all = camera_->sub_count() > 0;
      for (auto& t : imus_) all = all && t.sub_count() > 0;
      if (all) return true;
      std::this_thread::sleep_for(20ms);
    }
    return false;
  }
  Traffic run() {
    Traffic sent;
    std::atomic<bool> done{false};
    std::thread cam([&] {
      const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / c_.fps));
      auto next = Clock::now();
      std::uint64_t n = 0;
      while (!done.load()) {
        auto& img = frames_[n % frames_.size()];
        img.set_timestamp_ns(n);
        if (camera_->send_blocking(img, 100ms)) ++sent.images;
        ++n;
        next += period;
        std::this_thread::sleep_until(next);
      }
    });
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / c_.small_hz));
    const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(c_.seconds));
    auto next = Clock::now();
    std::uint64_t n = 0;
    while (Clock::now() < end) {
      horus::msg::Imu m{};
      m.timestamp_ns = n;
      for (auto& t : imus_) {
        t.send(m);
        ++sent.small;
      }
      ++n;
      next += period;
      std::this_thread::sleep_until(next);
    }
    done.store(true);
    cam.join();
    return sent;
  }

 private:
  const Config& c_;
  std::optional<horus::Topic<horus::msg::Image>> camera_;
  std::vector<horus::Topic<horus::msg::Imu>> imus_;
  std::vector<horus::msg::Image> frames_;
};

struct Result {
  std::string name;
  Traffic sent;
  std::uint64_t images = 0, small = 0;  // recorded
  double cpu = 0;                       // recorder CPU, % of one core
  double mb_s = 0;                      // file bytes per second of traffic
  std::string error;
};

void count_recorded(const std::string& file, const Config& c, Result& r) {
  if (horus::lcmlog::looks_like_log(file)) {
    auto log = horus::lcmlog::Reader::open(file);
    if (!log) {
      r.error = log.error().message();
      return;
    }
    auto ok = (*log)->read([&](const horus::lcmlog::Event& e) {
      if (e.channel == c.prefix + ".camera") ++r.images;
      else if (e.channel.starts_with(c.prefix + ".imu")) ++r.small;
      return true;
    });
    if (!ok) r.error = ok.error().message();
    return;
  }
  auto p = horus::Player::open(file, true);
  if (!p) {
    r.error = p.error().message();
    return;
  }
  for (const auto& ch : (*p)->channels()) {
    if (ch.topic == c.prefix + ".camera") r.images += ch.messages;
    else if (ch.topic.starts_with(c.prefix + ".imu")) r.small += ch.messages;
  }
}

Result run_one(const Config& c, const std::string& name, std::optional<horus::Backend> backend,
               std::vector<std::string> recorder, const std::string& file, bool lcm_logger) {
  Result r;
  r.name = name;
  std::remove(file.c_str());
  try {
    Robot robot(c, backend);
    Child rec(std::move(recorder));
    if (rec.pid() <= 0) {
      r.error = "could not start the recorder";
      return r;
    }
    if (lcm_logger) std::this_thread::sleep_for(1500ms);  // lcm-logger says nothing when it is ready
    else if (!robot.wait_for_recorder()) {
      r.error = "the recorder did not subscribe to every topic in 20 s";
      return r;
    }
    const double cpu0 = cpu_seconds(rec.pid());
    const auto t0 = Clock::now();
    r.sent = robot.run();
    std::this_thread::sleep_for(500ms);  // what is in flight
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    r.cpu = 100.0 * (cpu_seconds(rec.pid()) - cpu0) / wall;
    rec.stop();
  } catch (const std::exception& e) {
    r.error = e.what();
    return r;
  }
  std::ifstream f(file, std::ios::binary | std::ios::ate);
  r.mb_s = f ? static_cast<double>(f.tellg()) / 1e6 / c.seconds : 0;
  count_recorded(file, c, r);
  std::remove(file.c_str());
  return r;
}

std::string tool(const char* name) {
  for (const char* dir : {"/usr/bin/", "/usr/local/bin/"}) {
    const std::string p = std::string(dir) + name;
    if (::access(p.c_str(), X_OK) == 0) return p;
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  bool quick = false;
  CLI::App app{"horus-record-bench: recording a camera and ten 1 kHz topics without loss, against lcm-logger"};
  app.add_option("--seconds", c.seconds, "seconds of traffic per run")->check(CLI::Range(0.5, 3600.0));
  app.add_option("--rounds", c.rounds, "rounds (the spread)")->check(CLI::Range(1, 100));
  app.add_option("--fps", c.fps, "image rate")->check(CLI::Range(1.0, 240.0));
  app.add_option("--small-hz", c.small_hz, "rate of each small topic")->check(CLI::Range(1.0, 20000.0));
  app.add_flag("--quick", quick, "one short round (a smoke test)");
  CLI11_PARSE(app, argc, argv);
  if (quick) {
    c.seconds = 1;
    c.rounds = 1;
  }
  const std::string dir = "/tmp";
  const int port = 20000 + (::getpid() * 7 + 5) % 20000;
  c.lcm_url = fmt::format("udpm://239.255.76.67:{}?ttl=0&recv_buf_size=8388608", port);
  ::setenv("HORUS_LCM_URL", c.lcm_url.c_str(), 1);
  const std::string logger = tool("lcm-logger");
  fmt::print("horus-record-bench: a {}x{} rgb8 image topic at {} Hz ({:.0f} MB/s) + {} Imu topics at {} Hz, {} s per "
             "run, {} round(s), {} CPUs\n",
             c.width, c.height, c.fps, c.width * c.height * 3.0 * c.fps / 1e6, c.small_topics, c.small_hz, c.seconds,
             c.rounds, std::thread::hardware_concurrency());
  fmt::print("{:<44} {:>14} {:>16} {:>8} {:>9} {:>8}\n", "recorder", "images rec/sent", "small rec/sent", "lost",
             "CPU %", "MB/s");
  std::map<std::string, std::vector<Result>> all;
  for (int round = 0; round < c.rounds; ++round) {
    c.prefix = fmt::format("recbench{}r{}", ::getpid(), round);
    const std::string mcap = fmt::format("{}/{}.mcap", dir, c.prefix), log = fmt::format("{}/{}.lcmlog", dir, c.prefix);
    const std::string topics = c.prefix + ".**";
    std::vector<Result> results;
    results.push_back(run_one(c, "shm -> horus record (MCAP, zstd)", std::nullopt,
                              {c.cli, "record", "-o", mcap, "--topics", topics}, mcap, false));
    results.push_back(run_one(c, "shm -> horus record (MCAP, lz4)", std::nullopt,
                              {c.cli, "record", "-o", mcap, "--topics", topics, "--compression", "lz4"}, mcap, false));
    if (horus::backend_available(horus::Backend::Lcm)) {
      if (!logger.empty()) {
        std::string regex;
        for (char ch : c.prefix) regex += (ch == '.' ? "\\." : std::string(1, ch));
        results.push_back(run_one(c, "LCM -> lcm-logger (baseline)", horus::Backend::Lcm,
                                  {logger, "--lcm-url=" + c.lcm_url, "-c", regex + "\\..*", "-f", "-q", log}, log, true));
      }
      results.push_back(run_one(c, "LCM -> horus record --format lcm", horus::Backend::Lcm,
                                {c.cli, "record", "-o", log, "--topics", topics, "--format", "lcm"}, log, false));
      results.push_back(run_one(c, "LCM -> horus record (MCAP, zstd)", horus::Backend::Lcm,
                                {c.cli, "record", "-o", mcap, "--topics", topics}, mcap, false));
    }
    for (const auto& r : results) {
      if (!r.error.empty()) {
        fmt::print("{:<44} error: {}\n", r.name, r.error);
        continue;
      }
      const auto lost = (r.sent.images - std::min(r.images, r.sent.images)) + (r.sent.small - std::min(r.small, r.sent.small));
      fmt::print("{:<44} {:>6}/{:<7} {:>7}/{:<8} {:>8} {:>9.1f} {:>8.1f}\n", r.name, r.images, r.sent.images, r.small,
                 r.sent.small, lost, r.cpu, r.mb_s);
      all[r.name].push_back(r);
    }
    std::fflush(stdout);
  }
  if (c.rounds > 1) {
    fmt::print("\nover {} rounds: recorder CPU % median (min-max), lost messages total\n", c.rounds);
    for (auto& [name, rs] : all) {
      std::vector<double> cpu;
      std::uint64_t lost = 0;
      for (const auto& r : rs) {
        cpu.push_back(r.cpu);
        lost += (r.sent.images - std::min(r.images, r.sent.images)) + (r.sent.small - std::min(r.small, r.sent.small));
      }
      std::sort(cpu.begin(), cpu.end());
      fmt::print("{:<44} {:>6.1f} ({:.1f}-{:.1f}) {:>10} lost\n", name, cpu[cpu.size() / 2], cpu.front(), cpu.back(), lost);
    }
  }
  return 0;
}

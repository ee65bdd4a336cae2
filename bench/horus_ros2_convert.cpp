// horus-ros2-convert: what a topic mapped onto ROS 2 (docs/ROS2.md) pays per message for its
// conversion, against horus's own XCDR1 encoding of the same message in the same run: a CmdVel
// (geometry_msgs/msg/Twist), a 360-beam LaserScan (sensor_msgs/msg/LaserScan) and a 640x480 RGB8
// Image (sensor_msgs/msg/Image), each encoded (size + bytes: what the bridge does before the
// transport sends) and decoded (bytes -> the horus message: what the bridge does on receipt).
//
//   horus-ros2-convert [--rounds 5] [--samples 4000] [--json FILE]
//
// One sample times a batch of calls (64 for the small messages, 1 for the image) and divides, so
// the clock's own cost stays out; each round prints p50/p99/p99.9 per message, and the end the
// median p50 over the rounds with its spread (min-max) and the ratio to horus's own. Lines
//   RESULT op=<encode|decode> type=<cmdvel|scan|image> codec=<horus|ros2> round=<r> p50_ns=.. p99_ns=.. p999_ns=..
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "horus/horus.hpp"
#include "horus/ros2/convert.hpp"
#include "horus/wire/xcdr1.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using namespace horus::msg;

struct Percentiles {
  double p50, p99, p999;
};

Percentiles percentiles(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  auto at = [&](double q) { return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))]; };
  return {at(0.50), at(0.99), at(0.999)};
}

// ns per call of f, `samples` samples of `batch` calls each.
template <class F>
std::vector<double> time_calls(std::size_t samples, std::size_t batch, F&& f) {
  std::vector<double> out;
  out.reserve(samples);
  for (std::size_t s = 0; s < samples; ++s) {
    const auto t0 = Clock::now();
    for (std::size_t i = 0; i < batch; ++i) f();
    out.push_back(static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count()) /
                  static_cast<double>(batch));
  }
  return out;
}

LaserScan make_scan() {
  LaserScan s = LaserScan::make();
  for (std::size_t i = 0; i < LaserScan::kMaxRanges; ++i) s.ranges[i] = 1.0f + 0.01f * static_cast<float>(i);
  s.timestamp_ns = 1'700'000'000'000'000'000ULL;
  return s;
}

Image make_image() {
  Image img(480, 640, ImageEncoding::Rgb8);
  auto px = img.data_mut();
  for (std::size_t i = 0; i < px.size(); ++i) px[i] = static_cast<std::uint8_t>(i * 31);
  img.set_frame_id("camera");
  return img;
}

// One message type's four measurements in one round: horus's and the conversion's encode and decode.
template <class T>
std::map<std::string, Percentiles> measure(const T& msg, std::size_t samples, std::size_t batch) {
  const auto* conv = horus::ros2::find_conversion(horus::type_hash<T>, "");
  const horus::ros2::Context ctx{"base_link", ""};
  std::vector<std::byte> own(horus::cdr::encoded_size(msg)), ros(conv->encoded_size(&msg, ctx));
  volatile std::size_t sink = 0;
  std::map<std::string, Percentiles> out;
  out["encode/horus"] = percentiles(time_calls(samples, batch, [&] {
    own.resize(horus::cdr::encoded_size(msg));
    sink = horus::cdr::encode(msg, std::span<std::byte>(own));
  }));
  out["encode/ros2"] = percentiles(time_calls(samples, batch, [&] {
    ros.resize(conv->encoded_size(&msg, ctx));
    conv->encode(&msg, ctx, ros);
  }));
  out["decode/horus"] = percentiles(time_calls(samples, batch, [&] {
    auto m = horus::cdr::decode<T>(own);
    sink = m.has_value();
  }));
  out["decode/ros2"] = percentiles(time_calls(samples, batch, [&] {
    T m{};
    sink = conv->decode(ros, true, &m, nullptr).has_value();
  }));
  (void)sink;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"horus-ros2-convert: the conversion a topic mapped onto ROS 2 pays per message"};
  int rounds = 5;
  std::size_t samples = 4000;
  std::string json;
  app.add_option("--rounds", rounds, "rounds (the spread is over them)")->check(CLI::Range(1, 100));
  app.add_option("--samples", samples, "samples per measurement and round")->check(CLI::Range(100, 1000000));
  app.add_option("--json", json, "write the medians here");
  CLI11_PARSE(app, argc, argv);

  const CmdVel cmd = CmdVel::with_timestamp(0.5f, 0.25f, 1'700'000'000'000'000'000ULL);
  const LaserScan scan = make_scan();
  const Image image = make_image();
  // type -> "op/codec" -> p50 of each round
  std::map<std::string, std::map<std::string, std::vector<double>>> p50s;
  for (int r = 1; r <= rounds; ++r) {
    const std::map<std::string, std::map<std::string, Percentiles>> round = {
        {"cmdvel", measure(cmd, samples, 64)},
        {"scan", measure(scan, samples, 16)},
        {"image", measure(image, std::max<std::size_t>(samples / 20, 100), 1)}};
    for (const auto& [type, ops] : round)
      for (const auto& [key, p] : ops) {
        const auto slash = key.find('/');
        std::printf("RESULT op=%s type=%s codec=%s round=%d p50_ns=%.1f p99_ns=%.1f p999_ns=%.1f\n",
                    key.substr(0, slash).c_str(), type.c_str(), key.substr(slash + 1).c_str(), r, p.p50, p.p99, p.p999);
        p50s[type][key].push_back(p.p50);
      }
  }
  std::printf("\nper message, p50 ns: median (min-max) over %d rounds\n", rounds);
  std::printf("%-7s %-7s %26s %26s %9s\n", "type", "op", "horus's own (XCDR1)", "ROS 2 conversion", "ros2/own");
  std::string out = "{";
  for (const char* type : {"cmdvel", "scan", "image"}) {
    for (const char* op : {"encode", "decode"}) {
      auto stat = [&](const std::string& codec) {
        auto v = p50s[type][std::string(op) + "/" + codec];
        std::sort(v.begin(), v.end());
        return std::array<double, 3>{v[v.size() / 2], v.front(), v.back()};
      };
      const auto own = stat("horus"), ros = stat("ros2");
      std::printf("%-7s %-7s %26s %26s %8.2fx\n", type, op, fmt::format("{:.1f} ({:.1f}-{:.1f})", own[0], own[1], own[2]).c_str(),
                  fmt::format("{:.1f} ({:.1f}-{:.1f})", ros[0], ros[1], ros[2]).c_str(), ros[0] / own[0]);
      out += fmt::format("{}\"{}/{}\": {{\"horus_p50_ns\": {:.1f}, \"ros2_p50_ns\": {:.1f}}}", out.size() > 1 ? ", " : "",
                         type, op, own[0], ros[0]);
    }
  }
  if (!json.empty()) std::ofstream(json) << out << "}\n";
  return 0;
}

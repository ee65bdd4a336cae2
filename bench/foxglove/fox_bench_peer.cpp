// The horus side of the `horus foxglove` benchmark (bench_foxglove.py): a publisher of a Pose2D
// stream and a 1080p RGB camera, each message stamped with the wall clock when it is sent; and
// a plain horus subscriber of one of them, the baseline, which prints the latency from that
// stamp to its receive (p50/p99/p99.9) as the Foxglove client does to its frame.
//
// And a minimal C++ Foxglove client (Boost.Beast), to tell what the server adds from what
// Node.js and Foxglove's client library add: it subscribes to one channel and times each frame
// on arrival, as client.mjs's latency command does.
//
//   horus-fox-bench-peer pub PREFIX [POSE_HZ] [IMAGE_HZ] [SECONDS]
//   horus-fox-bench-peer sub PREFIX pose|camera SECONDS
//   horus-fox-bench-peer ws PORT PREFIX pose|camera SECONDS
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "horus/transport/encapsulation.hpp"
#include "horus/wire/xcdr1.hpp"

namespace {

using Clock = std::chrono::steady_clock;

std::uint64_t unix_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

int pub(const std::string& prefix, double pose_hz, double image_hz, double seconds) {
  auto pose = horus::Topic<horus::msg::Pose2D>::open(prefix + ".pose");
  auto cam = horus::Topic<horus::msg::Image>::open(prefix + ".camera");
  if (!pose || !cam) {
    std::fprintf(stderr, "pub: %s\n", (!pose ? pose.error() : cam.error()).message().c_str());
    return 1;
  }
  pose->publish_only();
  cam->publish_only();
  std::thread images([&] {
    const auto period = std::chrono::duration<double>(1.0 / image_hz);
    auto next = Clock::now();
    const auto end = next + std::chrono::duration<double>(seconds);
    std::uint8_t shade = 0;
    while (Clock::now() < end) {
      auto loan = cam->loan(*horus::msg::Image::describe(1080, 1920, horus::msg::ImageEncoding::Rgb8));
      if (loan) {
        auto bytes = (*loan)->data_mut();
        std::fill(bytes.begin(), bytes.end(), ++shade);
        (*loan)->set_timestamp_ns(unix_ns());
        cam->send(std::move(*loan));
      }
      next += std::chrono::duration_cast<Clock::duration>(period);
      std::this_thread::sleep_until(next);
    }
  });
  const auto period = std::chrono::duration<double>(1.0 / pose_hz);
  auto next = Clock::now();
  const auto end = next + std::chrono::duration<double>(seconds);
  double x = 0;
  while (Clock::now() < end) {
    auto p = horus::msg::Pose2D::make(x += 0.001, 2.0, 0.5);
    p.timestamp_ns = unix_ns();
    pose->send(p);
    next += std::chrono::duration_cast<Clock::duration>(period);
    std::this_thread::sleep_until(next);
  }
  images.join();
  return 0;
}

void print_percentiles(std::vector<double>& us) {
  std::sort(us.begin(), us.end());
  const auto pct = [&](double p) {
    return us.empty() ? 0.0
                      : us[std::min(us.size() - 1, static_cast<std::size_t>(p / 100 * static_cast<double>(us.size())))];
  };
  std::printf("{\"n\": %zu, \"p50_us\": %.1f, \"p99_us\": %.1f, \"p999_us\": %.1f, \"max_us\": %.1f}\n", us.size(),
              pct(50), pct(99), pct(99.9), us.empty() ? 0.0 : us.back());
}

// A Foxglove client in C++: subscribes to `topic` and times each message data frame on arrival.
template <class T>
int ws_client(const std::string& port, const std::string& topic, double seconds) {
  namespace beast = boost::beast;
  namespace asio = boost::asio;
  asio::io_context ioc;
  asio::ip::tcp::resolver resolver(ioc);
  beast::websocket::stream<asio::ip::tcp::socket> ws(ioc);
  asio::connect(ws.next_layer(), resolver.resolve("127.0.0.1", port));
  ws.next_layer().set_option(asio::ip::tcp::no_delay(true));
  ws.set_option(beast::websocket::stream_base::decorator([](beast::websocket::request_type& req) {
    req.set(beast::http::field::sec_websocket_protocol, "foxglove.websocket.v1");
  }));
  ws.handshake("127.0.0.1", "/");
  std::vector<double> us;
  bool subscribed = false;
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  beast::flat_buffer buf;
  while (Clock::now() < end || !subscribed) {
    buf.clear();
    ws.read(buf);
    const std::uint64_t now = unix_ns();
    const auto data = buf.cdata();
    const auto* p = static_cast<const std::byte*>(data.data());
    if (ws.got_text()) {
      auto j = nlohmann::json::parse(std::string_view(static_cast<const char*>(data.data()), data.size()));
      if (j["op"] == "advertise" && !subscribed)
        for (const auto& c : j["channels"])
          if (c["topic"] == topic) {
            nlohmann::json sub{{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", c["id"]}}}}};
            ws.text(true);
            ws.write(asio::buffer(sub.dump()));
            subscribed = true;
          }
      continue;
    }
    if (data.size() < 13 || p[0] != std::byte{1}) continue;
    auto sample = horus::net::encapsulation::parse(std::span<const std::byte>(p + 13, data.size() - 13));
    const auto* s = std::get_if<horus::net::Sample>(&sample);
    if (s == nullptr) continue;
    auto m = horus::cdr::decode<T>(s->body, s->little_endian);
    if (!m) continue;
    std::uint64_t stamp = 0;
    if constexpr (std::is_same_v<T, horus::msg::Image>) stamp = m->timestamp_ns();
    else stamp = m->timestamp_ns;
    if (stamp != 0 && now > stamp) us.push_back(static_cast<double>(now - stamp) / 1e3);
  }
  ws.close(beast::websocket::close_code::normal);
  print_percentiles(us);
  return 0;
}

template <class T>
int sub(const std::string& topic, double seconds) {
  auto t = horus::Topic<T>::open(topic);
  if (!t) {
    std::fprintf(stderr, "sub: %s\n", t.error().message().c_str());
    return 1;
  }
  std::vector<double> us;
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < end) {
    auto m = t->recv_for(std::chrono::milliseconds(100));
    if (!m) continue;
    const std::uint64_t now = unix_ns();
    std::uint64_t stamp = 0;
    if constexpr (std::is_same_v<T, horus::msg::Image>)
      stamp = m->timestamp_ns();
    else
      stamp = m->timestamp_ns;
    if (stamp != 0 && now > stamp) us.push_back(static_cast<double>(now - stamp) / 1e3);
  }
  print_percentiles(us);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> a(argv + 1, argv + argc);
  if (a.size() >= 2 && a[0] == "pub")
    return pub(a[1], a.size() > 2 ? std::atof(a[2].c_str()) : 1000, a.size() > 3 ? std::atof(a[3].c_str()) : 30,
               a.size() > 4 ? std::atof(a[4].c_str()) : 3600);
  if (a.size() == 4 && a[0] == "sub" && (a[2] == "pose" || a[2] == "camera")) {
    const double s = std::atof(a[3].c_str());
    return a[2] == "pose" ? sub<horus::msg::Pose2D>(a[1] + ".pose", s) : sub<horus::msg::Image>(a[1] + ".camera", s);
  }
  if (a.size() == 5 && a[0] == "ws" && (a[3] == "pose" || a[3] == "camera")) {
    const double s = std::atof(a[4].c_str());
    return a[3] == "pose" ? ws_client<horus::msg::Pose2D>(a[1], a[2] + ".pose", s)
                          : ws_client<horus::msg::Image>(a[1], a[2] + ".camera", s);
  }
  std::fprintf(stderr,
               "usage: horus-fox-bench-peer pub PREFIX [POSE_HZ] [IMAGE_HZ] [SECONDS]\n"
               "       horus-fox-bench-peer sub PREFIX pose|camera SECONDS\n"
               "       horus-fox-bench-peer ws PORT PREFIX pose|camera SECONDS\n");
  return 2;
}

// horus foxglove against Foxglove's own client libraries (tests/interop/foxglove_js, npm): @foxglove/ws-protocol
// connects, lists the channels and subscribes; @foxglove/omgidl-serialization decodes every standard type with the
// advertised schema, compared field by field with what was sent, and the converted channels with @foxglove/schemas' own
// IDL; a CmdVel a client publishes reaches a horus subscriber; the connection graph names the publishing process; a
// client that stops reading loses frames (counted, it is told) while the publisher goes on at its rate; bad input is
// closed with a code and a reason and the server stays up; the status page answers. Between namespace hosts: a fleet
// topic of another host is served, and the status page in Debian's chromium (puppeteer-core) lists both hosts, with a
// screenshot.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "foxglove_compare.hpp"
#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "horus/wire/dynamic.hpp"
#include "message_trips.hpp"
#include "netns.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

namespace {

using namespace std::chrono_literals;
using nlohmann::json;

std::string node_path() {
  for (const char* p : {"/usr/bin/node", "/usr/local/bin/node"})
    if (::access(p, X_OK) == 0) return p;
  return {};
}

// Skips unless node and the npm packages are installed (scripts/install-deps.sh does both).
#define REQUIRE_FOXGLOVE_CLIENTS()                                                  \
  do {                                                                              \
    if (node_path().empty())                                                        \
      GTEST_SKIP() << "node is not installed (scripts/install-deps.sh "             \
                      "installs nodejs)";                                           \
    if (::access(FOXGLOVE_JS_DIR "/node_modules/@foxglove/ws-protocol", F_OK) != 0) \
      GTEST_SKIP() << "the npm packages are not installed in " FOXGLOVE_JS_DIR      \
                      " (scripts/install-deps.sh runs npm ci there)";               \
  } while (0)

std::vector<json> json_lines(const std::string& out) {
  std::vector<json> lines;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);)
    if (line.starts_with('{')) {
      auto j = json::parse(line, nullptr, false);
      if (!j.is_discarded()) lines.push_back(std::move(j));
    }
  return lines;
}

// `horus foxglove` on a free port of this host, serving `pattern`.
class Server {
 public:
  explicit Server(const std::string& pattern, const std::vector<std::string>& more = {})
      : proc_(horus_test::start_logged(args(pattern, more), "/tmp/" + horus_test::unique_name("fox") + ".log")) {
    if (!proc_.wait_for_output("status page", 20s)) return;
    // "ws://127.0.0.1:PORT (...": the port after the address
    const auto out = proc_.output();
    const auto at = out.find("ws://");
    const auto colon = at == std::string::npos ? std::string::npos : out.find(':', at + 5);
    if (colon != std::string::npos) port_ = std::atoi(out.c_str() + colon + 1);
  }
  int port() const { return port_; }
  std::string url() const { return "ws://127.0.0.1:" + std::to_string(port_); }
  std::string output() const { return proc_.output(); }
  horus_test::HostProcess& process() { return proc_; }

 private:
  static std::vector<std::string> args(const std::string& pattern, const std::vector<std::string>& more) {
    std::vector<std::string> a = {HORUS_CLI, "foxglove", "--port", "0", "--topics", pattern, "--duration", "120"};
    a.insert(a.end(), more.begin(), more.end());
    return a;
  }
  horus_test::HostProcess proc_;
  int port_ = 0;
};

// The node client (client.mjs) with `args`; its output, and its exit status in `rc`.
std::string client(const std::vector<std::string>& args, int& rc, std::chrono::seconds timeout = 60s) {
  std::vector<std::string> full = {node_path(), FOXGLOVE_JS_DIR "/client.mjs"};
  full.insert(full.end(), args.begin(), args.end());
  auto p = horus_test::start_logged(full, "/tmp/" + horus_test::unique_name("foxjs") + ".log");
  rc = p.wait(timeout);
  return p.output();
}

// GET `path` from 127.0.0.1:port: the status line and the body.
std::pair<std::string, std::string> http_get(int port, const std::string& path) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::string text;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
    const std::string req = "GET " + path + " HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n";
    (void)!::write(fd, req.data(), req.size());
    char buf[65536];
    for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  const auto eol = text.find("\r\n"), body = text.find("\r\n\r\n");
  return {text.substr(0, eol), body == std::string::npos ? "" : text.substr(body + 4)};
}

TEST(Foxglove, FoxglovesClientDecodesEveryStandardTypeAndEachConvertedChannelDrawsWhatWasSent) {
  REQUIRE_FOXGLOVE_CLIENTS();
  const std::string prefix = horus_test::unique_name("fxall");
  const auto& types = horus_test::standard_types();
  std::vector<std::unique_ptr<horus_test::Trip>> trips;
  for (const auto& t : types) {
    trips.push_back(t.trip());
    ASSERT_EQ(trips.back()->open(horus::Backend::SharedMemory, prefix), "") << t.name;
  }
  horus_test::Publishing publishing(100ms, [&](int) {
    for (auto& t : trips) t->send();
  });
  Server server(prefix + ".**");
  ASSERT_GT(server.port(), 0) << server.output();

  std::vector<std::string> args = {"decode", server.url(), "--foxglove-idl"};
  std::map<std::string, const horus_test::MessageType*> by_topic;
  for (const auto& t : types) {
    const std::string topic = prefix + "." + std::string(t.name);
    by_topic[topic] = &t;
    args.push_back(topic);
  }
  const std::vector<std::pair<std::string, std::string>> converted = {{"Image", "foxglove::RawImage"},
                                                                      {"DepthImage", "foxglove::RawImage"},
                                                                      {"CompressedImage", "foxglove::CompressedImage"},
                                                                      {"PointCloud", "foxglove::PointCloud"},
                                                                      {"LaserScan", "foxglove::LaserScan"},
                                                                      {"Pose2D", "foxglove::PoseInFrame"},
                                                                      {"Pose3D", "foxglove::PoseInFrame"},
                                                                      {"Odometry", "foxglove::PoseInFrame"},
                                                                      {"TransformStamped", "foxglove::FrameTransform"}};
  for (const auto& [type, schema] : converted) args.push_back(prefix + "." + type + "/foxglove");
  int rc = 0;
  const auto out = client(args, rc, 90s);
  ASSERT_EQ(rc, 0) << out.substr(0, 3000) << "\nserver:\n" << server.output();

  std::map<std::string, json> got;
  json info;
  for (const auto& j : json_lines(out)) {
    if (j.contains("serverInfo")) info = j["serverInfo"];
    if (j.contains("topic")) got[j["topic"]] = j;
  }
  EXPECT_EQ(info["capabilities"], json({"clientPublish", "time", "connectionGraph"})) << info.dump();
  for (const auto& [topic, type] : by_topic) {
    ASSERT_TRUE(got.contains(topic)) << topic;
    auto dyn = horus::wire::parse_signature(type->signature());
    ASSERT_TRUE(dyn) << dyn.error();
    EXPECT_EQ(got[topic]["schema"], dyn->name);
    EXPECT_EQ(horus_test::compare(*dyn, json::parse(type->sample_json()), got[topic]["value"], topic), "");
  }
  // The converted channels: decoded with Foxglove's own IDL (client.mjs --foxglove-idl).
  const auto sample = [&](const std::string& type) {
    return json::parse(by_topic.at(prefix + "." + type)->sample_json());
  };
  const auto conv = [&](const std::string& type) { return got[prefix + "." + type + "/foxglove"]["value"]; };
  for (const auto& [type, schema] : converted)
    EXPECT_EQ(got[prefix + "." + type + "/foxglove"]["schema"], schema) << type;
  {
    const auto s = sample("Pose2D"), v = conv("Pose2D");
    EXPECT_EQ(v["pose"]["position"]["x"], s["x"]);
    EXPECT_EQ(v["pose"]["position"]["y"], s["y"]);
    EXPECT_NEAR(v["pose"]["orientation"]["z"].get<double>(), std::sin(s["theta"].get<double>() / 2), 1e-12);
    EXPECT_EQ(v["frame_id"], "world");
  }
  {
    const auto s = sample("TransformStamped"), v = conv("TransformStamped");
    EXPECT_EQ(v["translation"]["x"], s["translation"][0]);
    EXPECT_EQ(v["rotation"]["w"], s["rotation"][3]);
    EXPECT_EQ(v["child_frame_id"], prefix + ".TransformStamped");
    EXPECT_EQ(v["parent_frame_id"], "world");
  }
  {
    const auto s = sample("Image"), v = conv("Image");
    EXPECT_EQ(v["width"], s["width"]);
    EXPECT_EQ(v["height"], s["height"]);
    EXPECT_EQ(v["data"].size(), v["step"].get<std::size_t>() * v["height"].get<std::size_t>()) << v.dump();
    EXPECT_FALSE(v["encoding"].get<std::string>().empty());
  }
  {
    const auto s = sample("CompressedImage"), v = conv("CompressedImage");
    EXPECT_EQ(v["format"], s["format"]);
    EXPECT_EQ(v["data"], s["data"]);
  }
  {
    const auto v = conv("LaserScan");
    EXPECT_EQ(v["ranges"].size(), horus::msg::LaserScan::kMaxRanges);
    EXPECT_EQ(v["intensities"].size(), 0u);
  }
  {
    const auto s = sample("PointCloud"), v = conv("PointCloud");
    EXPECT_EQ(v["fields"].size(), std::min<std::size_t>(s["fields_per_point"].get<std::size_t>(), 7)) << v.dump();
    EXPECT_EQ(v["fields"][0]["name"], "x");
    EXPECT_EQ(v["data"].size(), s["data"].size());
  }
}

TEST(Foxglove, ACmdVelAClientPublishesReachesAHorusSubscriber) {
  REQUIRE_FOXGLOVE_CLIENTS();
  const std::string prefix = horus_test::unique_name("fxpub");
  auto teleop = horus::Topic<horus::msg::CmdVel>::open(prefix + ".teleop");
  ASSERT_TRUE(teleop) << teleop.error().message();
  auto cmd = horus::Topic<horus::msg::CmdVel>::open(prefix + ".cmd");  // its schema is what the client encodes with
  ASSERT_TRUE(cmd) << cmd.error().message();
  cmd->publish_only();
  std::optional<horus_test::Publishing> beat;
  beat.emplace(100ms, [&](int) { cmd->send(horus::msg::CmdVel::make(0.1f, 0.2f)); });
  Server server(prefix + ".**");
  ASSERT_GT(server.port(), 0) << server.output();
  int rc = 0;
  const auto out = client({"publish", server.url(), prefix + ".cmd", prefix + ".teleop",
                           R"({"stamp_nanos": 42, "linear": 0.5, "angular": -0.25})", "20"},
                          rc);
  beat.reset();
  EXPECT_EQ(rc, 0) << out << server.output();
  auto m = teleop->recv_for(2s);
  ASSERT_TRUE(m.has_value()) << out;
  EXPECT_EQ(m->stamp_nanos, 42u);
  EXPECT_EQ(m->linear, 0.5f);
  EXPECT_EQ(m->angular, -0.25f);
  std::size_t n = 1;
  while (teleop->recv_for(200ms)) ++n;
  EXPECT_GE(n, 15u) << "20 were published";
  // The same as JSON (what Foxglove's Publish panel sends to a server that takes json).
  const auto json_out = client({"publish-json", server.url(), prefix + ".teleop", "horus::msg::CmdVel",
                                R"({"stamp_nanos": 43, "linear": 0.75, "angular": 0.5})", "5"},
                               rc);
  EXPECT_EQ(rc, 0) << json_out;
  auto j = teleop->recv_for(2s);
  ASSERT_TRUE(j.has_value()) << json_out;
  EXPECT_EQ(j->stamp_nanos, 43u);
  EXPECT_EQ(j->linear, 0.75f);
  // A type that is no standard message is refused, naming it.
  const auto bad = client({"publish-json", server.url(), prefix + ".x", "my::Thing", "{}", "1"}, rc);
  EXPECT_NE(bad.find("'my::Thing' is not a standard horus message"), std::string::npos) << bad;
}

// `horus foxglove --ros2`: a ROS 2 topic of the DDS domain (here a horus topic mapped onto ROS 2,
// which is on the wire what a ROS 2 driver publishes) is a channel under its ROS 2 name in its
// ROS 2 schema, which Foxglove's ROS 2 readers decode.
TEST(Foxglove, ARos2TopicOfTheDomainIsServedInItsRos2Schema) {
  REQUIRE_FOXGLOVE_CLIENTS();
  if (::access(FOXGLOVE_JS_DIR "/node_modules/@foxglove/rosmsg2-serialization", F_OK) != 0)
    GTEST_SKIP() << "the npm packages are not installed in " FOXGLOVE_JS_DIR;
  if (!horus::backend_available(horus::Backend::CycloneDds)) GTEST_SKIP() << "this build has no Cyclone DDS backend";
  ::setenv("HORUS_DDS_LOCALHOST", "1", 1);
  ::setenv("HORUS_DOMAIN_ID", std::to_string(1 + (::getpid() + 31) % 200).c_str(), 1);
  const std::string prefix = "fxros" + std::to_string(::getpid());
  horus::TopicOptions o;
  o.backend = horus::Backend::CycloneDds;
  horus::Ros2Mapping mapping;
  mapping.name = "/" + prefix + "/scan";
  mapping.frame_id = "laser";
  o.ros2 = mapping;
  auto scan = horus::Topic<horus::msg::LaserScan>::open(prefix + ".scan", o);
  ASSERT_TRUE(scan) << scan.error().message();
  horus::msg::LaserScan s{};
  s.angle_increment = 0.01f;
  s.angle_max = 0.01f * 99;
  s.range_min = 0.1f;
  s.range_max = 20.0f;
  s.ranges[0] = 3.5f;
  s.timestamp_ns = 1'700'000'000'250'000'000ULL;
  horus_test::Publishing beat(100ms, [&](int) { scan->send(s); });
  Server server(prefix + ".**", {"--ros2"});
  ASSERT_GT(server.port(), 0) << server.output();
  int rc = 0;
  const auto out = client({"decode", server.url(), "/" + prefix + "/scan"}, rc);
  ASSERT_EQ(rc, 0) << out << server.output();
  bool decoded = false;
  for (const auto& j : json_lines(out)) {
    if (!j.contains("topic")) continue;
    decoded = true;
    EXPECT_EQ(j["schema"], "sensor_msgs/msg/LaserScan");
    EXPECT_EQ(j["schema_encoding"], "ros2msg");
    EXPECT_EQ(j["value"]["header"]["frame_id"], "laser");
    EXPECT_EQ(j["value"]["header"]["stamp"]["sec"], 1'700'000'000);
    EXPECT_EQ(j["value"]["header"]["stamp"]["nanosec"], 250'000'000);
    ASSERT_EQ(j["value"]["ranges"].size(), 100u) << j.dump();
    EXPECT_FLOAT_EQ(j["value"]["ranges"][0].get<float>(), 3.5f);
  }
  EXPECT_TRUE(decoded) << out;
  EXPECT_NE(server.output().find("ROS 2 topics of the domain"), std::string::npos) << server.output();
}

TEST(Foxglove, TheConnectionGraphNamesThisProcessAsThePublisher) {
  REQUIRE_FOXGLOVE_CLIENTS();
  const std::string prefix = horus_test::unique_name("fxgraph");
  auto pose = horus::Topic<horus::msg::Pose2D>::open(prefix + ".pose");
  ASSERT_TRUE(pose) << pose.error().message();
  pose->publish_only();
  pose->send(horus::msg::Pose2D::make(1, 2, 3));  // a publisher's lane is taken at its first send
  Server server(prefix + ".**");
  ASSERT_GT(server.port(), 0) << server.output();
  int rc = 0;
  const auto out = client({"graph", server.url(), prefix + ".pose", "pid " + std::to_string(::getpid())}, rc);
  EXPECT_EQ(rc, 0) << out << server.output();
}

TEST(Foxglove, ATopicIsAdvertisedWhenItAppearsAndUnadvertisedWhenItsLastProcessEnds) {
  REQUIRE_FOXGLOVE_CLIENTS();
  const std::string prefix = horus_test::unique_name("fxwatch");
  Server server(prefix + ".**");
  ASSERT_GT(server.port(), 0) << server.output();
  auto watcher =
      horus_test::start_logged({node_path(), FOXGLOVE_JS_DIR "/client.mjs", "watch", server.url(), prefix + ".appears"},
                               "/tmp/" + prefix + ".watch.log");
  // A publisher that comes, sends for a while and ends (it waits up to 2 s for a subscriber first).
  std::string out;
  EXPECT_EQ(horus_test::run_command(
                std::string(HORUS_CLI) + " topic pub " + prefix + ".appears Pose2D '{\"x\": 1}' -r 20 -n 20", out),
            0)
      << out;
  ASSERT_EQ(watcher.wait(40s), 0) << watcher.output() << server.output();
  const auto lines = json_lines(watcher.output());
  ASSERT_EQ(lines.size(), 2u) << watcher.output();
  EXPECT_EQ(lines[0]["advertised"], lines[1]["unadvertised"]);
}

TEST(Foxglove, ASlowClientLosesItsOldestFramesAndIsToldWhileThePublisherKeepsItsRate) {
  REQUIRE_FOXGLOVE_CLIENTS();
  const std::string prefix = horus_test::unique_name("fxslow");
  auto cam = horus::Topic<horus::msg::Image>::open(prefix + ".cam");
  ASSERT_TRUE(cam) << cam.error().message();
  cam->publish_only();
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> sent{0};
  std::atomic<std::int64_t> worst_us{0};
  std::thread pub([&] {  // 640x480 RGB at 200 Hz: about 180 MB/s, more than a paused client takes
    auto next = std::chrono::steady_clock::now();
    while (!stop) {
      const auto t0 = std::chrono::steady_clock::now();
      horus::msg::Image img(480, 640, horus::msg::ImageEncoding::Rgb8);
      cam->send(std::move(img));  // never waits for a subscriber: a full ring overwrites
      ++sent;
      const auto us =
          std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0).count();
      if (us > worst_us) worst_us = us;
      next += 5ms;
      std::this_thread::sleep_until(next);
    }
  });
  Server server(prefix + ".**");
  ASSERT_GT(server.port(), 0) << server.output();
  const auto start = std::chrono::steady_clock::now();
  int rc = 0;
  const auto out = client({"slow", server.url(), prefix + ".cam", "4"}, rc);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto [status_line, body] = http_get(server.port(), "/status.json");
  stop = true;
  pub.join();
  ASSERT_EQ(rc, 0) << out << server.output();
  json resumed;
  for (const auto& j : json_lines(out))
    if (j.contains("resumed")) resumed = j;
  ASSERT_FALSE(resumed.empty()) << out;
  EXPECT_GT(resumed["received_after"].get<int>(), 0) << "frames flow again after the pause: " << out;
  bool told = false;
  for (const auto& w : resumed["warnings"]) told = told || w.get<std::string>().find("dropped") != std::string::npos;
  EXPECT_TRUE(told) << "the client is told that it lost messages: " << out;
  // The publisher never waited on the client: its rate held (200 Hz, some slack for a loaded CI).
  EXPECT_LT(worst_us.load(), 200'000) << "a send took " << worst_us.load() << " us";
  EXPECT_GT(static_cast<double>(sent.load()) / seconds, 120.0) << sent.load() << " in " << seconds << " s";
  // The server's memory stayed bounded (64 MiB of queue per client, plus the program); not under
  // a sanitizer, whose shadow memory and quarantine are most of the figure.
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  std::ifstream st("/proc/" + std::to_string(server.process().pid()) + "/status");
  for (std::string line; std::getline(st, line);) {
    if (line.starts_with("VmHWM:")) {
      EXPECT_LT(std::stol(line.substr(6)), 400L * 1024) << line;
    }
  }
#endif
  EXPECT_NE(status_line.find("200"), std::string::npos) << status_line;
}

TEST(Foxglove, BadClientInputIsClosedWithACodeAndAReasonAndTheServerStaysUp) {
  REQUIRE_FOXGLOVE_CLIENTS();
  const std::string prefix = horus_test::unique_name("fxbad");
  Server server(prefix + ".**");
  ASSERT_GT(server.port(), 0) << server.output();
  int rc = 0;
  const auto out = client({"bad", server.url()}, rc, 90s);
  ASSERT_EQ(rc, 0) << out << server.output();
  const std::map<std::string, int> want = {{"not JSON", 1007},     {"unknown op", 1007},
                                           {"bad field", 1007},    {"unknown binary opcode", 1003},
                                           {"short binary", 1003}, {"huge frame", 1009}};
  std::size_t seen = 0;
  bool alive = false;
  for (const auto& j : json_lines(out)) {
    if (j.contains("alive")) alive = true;
    if (!j.contains("case")) continue;
    ++seen;
    EXPECT_EQ(j["code"], want.at(j["case"])) << j.dump();
    EXPECT_FALSE(j["reason"].get<std::string>().empty()) << j.dump();
  }
  EXPECT_EQ(seen, want.size()) << out;
  EXPECT_TRUE(alive) << out;
  EXPECT_FALSE(server.process().ended()) << server.output();
}

// A WebSocket upgrade offering `subprotocols`: the response's status line and headers.
std::string ws_upgrade(int port, const std::string& subprotocols) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::string text;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
    const std::string req = "GET / HTTP/1.1\r\nHost: localhost\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
                            "Sec-WebSocket-Protocol: " + subprotocols + "\r\n\r\n";
    (void)!::write(fd, req.data(), req.size());
    char buf[4096];
    for (ssize_t n; text.find("\r\n\r\n") == std::string::npos && (n = ::read(fd, buf, sizeof buf)) > 0;)
      text.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return text;
}

// Foxglove's SDK servers answer foxglove.sdk.v1, and its newer clients offer it: horus foxglove
// takes it beside foxglove.websocket.v1 (the first of the offer it speaks), and names both when
// an offer has neither.
TEST(Foxglove, TheSdkSubprotocolIsAcceptedBesideTheWebsocketOne) {
  const std::string prefix = horus_test::unique_name("fxsdk");
  Server server(prefix + ".**");
  ASSERT_GT(server.port(), 0) << server.output();
  const std::string sdk = ws_upgrade(server.port(), "foxglove.sdk.v1");
  EXPECT_NE(sdk.find("101"), std::string::npos) << sdk;
  EXPECT_NE(sdk.find("Sec-WebSocket-Protocol: foxglove.sdk.v1"), std::string::npos) << sdk;
  const std::string both = ws_upgrade(server.port(), "foxglove.websocket.v1, foxglove.sdk.v1");
  EXPECT_NE(both.find("Sec-WebSocket-Protocol: foxglove.websocket.v1"), std::string::npos) << both;
  const std::string other = ws_upgrade(server.port(), "mqtt");
  EXPECT_NE(other.find("400"), std::string::npos) << other;
  EXPECT_NE(other.find("foxglove.websocket.v1 or foxglove.sdk.v1"), std::string::npos) << other;
}

TEST(Foxglove, TheStatusPageAndItsFiguresAreServedAndAnUnknownPathIsNamed) {
  const std::string prefix = horus_test::unique_name("fxhttp");
  auto pose = horus::Topic<horus::msg::Pose2D>::open(prefix + ".pose");
  ASSERT_TRUE(pose) << pose.error().message();
  Server server(prefix + ".**");
  ASSERT_GT(server.port(), 0) << server.output();
  const auto [line, page] = http_get(server.port(), "/");
  EXPECT_NE(line.find("200"), std::string::npos) << line;
  EXPECT_NE(page.find("<title>horus fleet</title>"), std::string::npos);
  EXPECT_EQ(page.find("http://"), std::string::npos) << "the page fetches nothing from elsewhere";
  EXPECT_EQ(page.find("https://"), std::string::npos) << "the page fetches nothing from elsewhere";
  // The figures: the topic with its type (the scan runs every 500 ms).
  json status;
  for (int i = 0; i < 40; ++i) {
    status = json::parse(http_get(server.port(), "/status.json").second, nullptr, false);
    if (!status.is_discarded() && status.contains("topics") && !status["topics"].empty()) break;
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_FALSE(status.is_discarded());
  ASSERT_EQ(status["topics"].size(), 1u) << status.dump();
  EXPECT_EQ(status["topics"][0]["name"], prefix + ".pose");
  EXPECT_EQ(status["topics"][0]["type"], "horus::msg::Pose2D");
  EXPECT_EQ(status["channels"].size(), 2u) << "the topic and its foxglove::PoseInFrame: " << status.dump();
  const auto [missing, why] = http_get(server.port(), "/nope");
  EXPECT_NE(missing.find("404"), std::string::npos) << missing;
  EXPECT_NE(why.find("/status.json"), std::string::npos) << why;
}

// horus record --foxglove: beside the topic, TOPIC/foxglove in Foxglove's schema, which Foxglove's MCAP reader
// (tests/interop/mcap_js) decodes.
TEST(Foxglove, RecordWithFoxgloveAddsTheConvertedChannelsBesideTheTopics) {
  if (node_path().empty() || ::access(MCAP_JS_DIR "/node_modules/@mcap/core", F_OK) != 0)
    GTEST_SKIP() << "node or the npm packages of " MCAP_JS_DIR " are not installed (scripts/install-deps.sh)";
  const std::string prefix = horus_test::unique_name("fxrec");
  auto pose = horus::Topic<horus::msg::Pose2D>::open(prefix + ".pose");
  ASSERT_TRUE(pose) << pose.error().message();
  const std::string file = "/tmp/" + prefix + ".mcap";
  auto rec = horus_test::start_logged(
      {HORUS_CLI, "record", "-o", file, "--topics", prefix + ".**", "--foxglove", "--frame", "map", "--duration", "3"},
      file + ".log");
  ASSERT_TRUE(rec.wait_for_output("+ " + prefix + ".pose/foxglove (foxglove::PoseInFrame", 10s)) << rec.output();
  for (int i = 0; i < 10; ++i) {
    pose->send(horus::msg::Pose2D::make(1.5, -2.0, 0.0));
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_EQ(rec.wait(30s), 0) << rec.output();
  std::string out;
  ASSERT_EQ(horus_test::run_command(node_path() + " " MCAP_JS_DIR "/read_mcap.mjs " + file, out), 0) << out;
  std::size_t plain = 0, converted = 0;
  for (const auto& j : json_lines(out)) {
    if (!j.contains("topic")) continue;
    if (j["topic"] == prefix + ".pose") ++plain;
    if (j["topic"] != prefix + ".pose/foxglove") continue;
    ++converted;
    EXPECT_EQ(j["schema"], "foxglove::PoseInFrame");
    EXPECT_EQ(j["value"]["frame_id"], "map");
    EXPECT_EQ(j["value"]["pose"]["position"]["x"], 1.5);
    EXPECT_EQ(j["value"]["pose"]["position"]["y"], -2.0);
    EXPECT_EQ(j["value"]["pose"]["orientation"]["w"], 1.0);
  }
  EXPECT_EQ(plain, 10u) << out.substr(0, 2000);
  EXPECT_EQ(converted, 10u) << out.substr(0, 2000);
  std::remove(file.c_str());
  // LCM logs cannot hold Foxglove's schemas: refused, naming why.
  EXPECT_EQ(
      horus_test::run_command(std::string(HORUS_CLI) + " record -o /tmp/x.lcmlog --format lcm --foxglove --all", out),
      2)
      << out;
  EXPECT_NE(out.find("only MCAP holds"), std::string::npos) << out;
}

TEST(Foxglove, ABadPortOrPatternIsRefusedNamingIt) {
  std::string out;
  EXPECT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " foxglove --port 70000", out), 2) << out;
  EXPECT_NE(out.find("--port 70000 is not a TCP port"), std::string::npos) << out;
  EXPECT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " foxglove --topics 'a..b'", out), 2) << out;
  EXPECT_NE(out.find("--topics 'a..b'"), std::string::npos) << out;
  EXPECT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " foxglove --address nowhere --port 0 --duration 1", out),
            1)
      << out;
  EXPECT_NE(out.find("--address 'nowhere' is not an IP address"), std::string::npos) << out;
}

// Two namespace hosts on Cyclone DDS: host 1 publishes a fleet topic; host 2 serves Foxglove.
TEST(FoxgloveFleet, AFleetTopicOfAnotherHostIsServedAndTheStatusPageListsBothHosts) {
  REQUIRE_FOXGLOVE_CLIENTS();
  if (!horus::backend_available(horus::Backend::CycloneDds)) GTEST_SKIP() << "this build has no cyclonedds backend";
  horus_test::NetnsLan lan(2, "f");
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const std::vector<std::string> env = {"HORUS_BACKEND=cyclonedds",
                                        "HORUS_DOMAIN_ID=" + std::to_string(1 + (::getpid() + 37) % 200),
                                        "HORUS_DDS_LOCALHOST=0", "HORUS_CONFIG="};
  auto pub = lan.spawn(0,
                       {HORUS_CLI, "topic", "pub", "robot1.pose", "Pose2D", R"({"x": 3, "y": 4, "theta": 1})", "-r",
                        "20", "-n", "100000"},
                       env);
  // A type the CLI was not built with (watch::Battery: a string, an enum, an array of structs, a
  // sequence, a char array): served through the signature host 1 announces.
  auto user = lan.spawn(0, {FLEET_WATCH, "60", "--user-type", "robot1.battery"}, env);
  auto server = lan.spawn(1, {HORUS_CLI, "foxglove", "--port", "8765", "--duration", "120"}, env);
  ASSERT_TRUE(server.wait_for_output("status page", 20s)) << server.output();
  const auto node = [&](std::vector<std::string> args, std::chrono::seconds timeout) {
    args.insert(args.begin(), {node_path(), FOXGLOVE_JS_DIR "/client.mjs"});
    auto p = lan.spawn(1, args, {});
    const int rc = p.wait(timeout);
    return std::make_pair(rc, p.output());
  };
  const auto [rc, out] =
      node({"decode", "ws://127.0.0.1:8765", "robot1.pose", "robot1.pose/foxglove", "robot1.battery"}, 60s);
  ASSERT_EQ(rc, 0) << out << "\nserver:\n" << server.output() << "\npub:\n" << pub.output();
  std::size_t checked = 0;
  for (const auto& j : json_lines(out)) {
    if (j.contains("topic") && j["topic"] == "robot1.pose") {
      EXPECT_EQ(j["value"]["x"], 3);
      EXPECT_EQ(j["value"]["y"], 4);
      ++checked;
    }
    if (j.contains("topic") && j["topic"] == "robot1.battery") {
      EXPECT_EQ(j["schema"], "watch::Battery");
      EXPECT_TRUE(j["value"]["label"].get<std::string>().starts_with("pack-")) << j.dump();
      EXPECT_EQ(j["value"]["cells"][1]["temp_dc"], -12) << j.dump();
      EXPECT_EQ(j["value"]["history"], json({100, 99, 65535})) << j.dump();
      EXPECT_EQ(j["value"]["charge"], 0.875) << j.dump();
      ++checked;
    }
  }
  EXPECT_EQ(checked, 2u) << out;
  const auto [grc, gout] = node({"graph", "ws://127.0.0.1:8765", "robot1.pose", lan.host(0)}, 60s);
  EXPECT_EQ(grc, 0) << gout;
  if (::access("/usr/bin/chromium", X_OK) != 0) {
    std::printf("chromium is not installed (scripts/install-deps.sh installs it): the status page is not shown\n");
    return;
  }
  const std::string png = std::filesystem::current_path().string() + "/foxglove-status.png";
  std::remove(png.c_str());
  const auto [brc, bout] = node({"browser", "http://127.0.0.1:8765/", png, "2"}, 90s);
  ASSERT_EQ(brc, 0) << bout;
  json shown;
  for (const auto& j : json_lines(bout))
    if (j.contains("hosts")) shown = j;
  std::string hosts = shown["hosts"].dump();
  EXPECT_NE(hosts.find(lan.host(0)), std::string::npos) << bout;
  EXPECT_NE(hosts.find(lan.host(1)), std::string::npos) << bout;
  EXPECT_NE(shown["topics"].dump().find("robot1.pose"), std::string::npos) << bout;
  EXPECT_GT(std::filesystem::file_size(png), 10'000u) << "the screenshot " << png;
  std::printf("the status page's screenshot: %s\n", png.c_str());
}

}  // namespace

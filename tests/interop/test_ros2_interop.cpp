// horus topics mapped onto ROS 2 (TopicOptions::ros2) against what a ROS 2 node puts on the DDS
// wire, without ROS 2: peers built at test time by idlc and fastddsgen from IDL written from
// common_interfaces' field lists (tests/interop/ros2/), on rt/<name> with ROS 2's type names and
// USER_DATA. Both horus backends against both peers, on loopback. The peer reports, field by
// field, what it read (units, stamps, frame ids, arrays) and the USER_DATA it saw; it echoes each
// sample back, and horus checks what the conversion made of the peer's bytes. The peer reads
// ros_discovery_info as ROS 2's graph does and finds horus's node with the writers it matched.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dds_support.hpp"
#include "netns.hpp"
#include "horus/ros2/interface.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

namespace {

using horus::Backend;
using namespace horus::msg;

constexpr std::uint64_t kStamp = 1'700'000'000'123'456'789ULL;  // 1700000000 s, 123456789 ns
constexpr const char* kNode = "horus_interop_node";              // HORUS_ROS2_NODE

// The peer's entries, in its order: the horus name under the prefix and the ROS 2 type.
const std::vector<std::pair<std::string, std::string>> kEntries = {
    {"cmd_vel", "geometry_msgs/msg/Twist"},    {"scan", "sensor_msgs/msg/LaserScan"},
    {"image", "sensor_msgs/msg/Image"},        {"joints", "sensor_msgs/msg/JointState"},
    {"odom", "nav_msgs/msg/Odometry"},         {"tf", "tf2_msgs/msg/TFMessage"},
};

struct Case {
  Backend horus;
  const char* peer;  // ros2_peer_cyclone or ros2_peer_fastdds
};

// The peer's report: its lines by first word.
std::multimap<std::string, std::vector<std::string>> read_report(const std::string& path) {
  std::multimap<std::string, std::vector<std::string>> out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string x; words >> x;) w.push_back(x);
    if (!w.empty()) out.emplace(w[0], std::vector<std::string>(w.begin() + 1, w.end()));
  }
  return out;
}

// The GUIDs of the writers on `prefix`'s topics the peer matched (its "userdata" lines).
std::vector<std::string> matched_writers(const std::multimap<std::string, std::vector<std::string>>& r,
                                         const std::string& prefix) {
  std::vector<std::string> out;
  for (const auto& [name, type] : kEntries)
    for (auto [it, end] = r.equal_range("userdata"); it != end; ++it)
      if (it->second.size() == 3 && it->second[0] == "rt/" + prefix + "/" + name) out.push_back(it->second[1]);
  return out;
}

// Whether a "graph" line of the report (ros_discovery_info) has horus's node at "/" listing every
// writer of `gids` under its participant's GID (a writer's GUID prefix), and a reader per entry.
bool graph_lists(const std::multimap<std::string, std::vector<std::string>>& r, const std::vector<std::string>& gids) {
  if (gids.size() < kEntries.size()) return false;
  for (auto [it, end] = r.equal_range("graph"); it != end; ++it) {
    const auto& g = it->second;  // gid ns name "writers" w... "readers" r...
    if (g.size() < 4 || g[2] != kNode || g[1] != "/") continue;
    const auto readers_at = std::find(g.begin(), g.end(), "readers");
    const std::set<std::string> writers(g.begin() + 4, readers_at);
    bool lists_all = static_cast<std::size_t>(g.end() - readers_at) - 1 >= kEntries.size();
    for (const auto& w : gids) lists_all = lists_all && writers.contains(w) && w.substr(0, 24) == g[0].substr(0, 24);
    if (lists_all) return true;
  }
  return false;
}

double num(const std::string& s) { return std::strtod(s.c_str(), nullptr); }

template <class T>
horus::Topic<T> open_mapped(const std::string& name, Backend b, horus::Ros2Mapping m) {
  horus::TopicOptions o;
  o.backend = b;
  o.ros2 = std::move(m);
  auto t = horus::Topic<T>::open(name, o);
  if (!t) throw std::runtime_error(name + ": " + t.error().message());
  return std::move(*t);
}

horus::Ros2Mapping mapping(std::string type = {}, std::string frame = {}, std::string child = {},
                           horus::Ros2Mapping::Qos qos = horus::Ros2Mapping::Qos::Topic) {
  horus::Ros2Mapping m;
  m.qos = qos;
  m.type = std::move(type);
  m.frame_id = std::move(frame);
  m.child_frame_id = std::move(child);
  return m;
}

// What horus sends on each topic.
struct Sent {
  CmdVel cmd = CmdVel::with_timestamp(0.5f, -0.25f, kStamp);
  LaserScan scan = [] {
    LaserScan s = LaserScan::make();
    s.angle_min = -1.0f;
    s.angle_increment = 0.01f;
    s.angle_max = -1.0f + 0.01f * 99;  // 100 beams
    s.range_min = 0.1f;
    s.range_max = 30.0f;
    for (std::size_t i = 0; i < 100; ++i) s.ranges[i] = 1.0f + 0.125f * static_cast<float>(i);
    s.timestamp_ns = kStamp;
    return s;
  }();
  Image image = [] {
    Image img(6, 8, ImageEncoding::Rgb8);
    auto px = img.data_mut();
    for (std::size_t i = 0; i < px.size(); ++i) px[i] = static_cast<std::uint8_t>(i * 7 + 3);
    img.set_frame_id("camera");
    img.set_timestamp_ns(kStamp);
    return img;
  }();
  JointState joints = [] {
    JointState j{};
    j.add_joint("shoulder", 0.5, 1.25, -3.0);
    j.add_joint("elbow", -1.5, 0.0, 2.0);
    j.add_joint("wrist_roll", 3.0, -0.5, 0.25);
    j.timestamp_ns = kStamp;
    return j;
  }();
  Odometry odom = [] {
    Odometry o = Odometry::make();
    o.pose = Pose2D::make(1.5, -2.25, 0.5);
    o.twist = Twist::new_2d(0.75, 0.1);
    o.pose_covariance[0] = 0.01;
    o.pose_covariance[35] = 0.35;
    o.twist_covariance[7] = 0.07;
    o.set_frames("odom", "base_link");
    o.timestamp_ns = kStamp;
    return o;
  }();
  TransformStamped tf = [] {
    TransformStamped t = TransformStamped::make({1.0, 2.0, 3.0}, {0.0, 0.0, 0.6, 0.8});
    t.timestamp_ns = kStamp;
    return t;
  }();
};

class Ros2Interop : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    ::setenv("HORUS_DDS_LOCALHOST", "1", 1);
    domain_ = std::to_string(1 + ::getpid() % 200);
    ::setenv("HORUS_DOMAIN_ID", domain_.c_str(), 1);
    ::setenv("HORUS_ROS2_NODE", kNode, 1);
  }
  std::string domain_;
};

// Both ways, every mapped type: the ROS 2 peer reads horus's samples field by field (ROS 2's
// units, stamps as builtin_interfaces/Time, frame ids from the fields or the rule) and sees
// ROS 2's USER_DATA; horus reads the peer's echo back into its own types.
TEST_P(Ros2Interop, ARos2PeerReadsHorusFieldByFieldAndHorusReadsItsEcho) {
  const auto [backend, peer_name] = GetParam();
  if (!horus::backend_available(backend)) GTEST_SKIP() << "this build has no " << horus::to_string(backend) << " backend";
  const std::string program = std::string(INTEROP_WORK_DIR) + "/" + peer_name;
  if (::access(program.c_str(), X_OK) != 0) GTEST_SKIP() << peer_name << " was not built (see interop.BuildThirdPartyPeers)";
  static int n = 0;
  const std::string prefix = "r2t" + std::to_string(::getpid()) + "_" + std::to_string(++n);
  const std::string report = (std::filesystem::temp_directory_path() / (prefix + ".txt")).string();
  std::vector<std::string> args{domain_, prefix, "60", report};
  std::map<std::string, std::string> hashes;
  for (const auto& [name, type] : kEntries) {
    hashes[name] = horus::ros2::Interfaces::standard().type_hash(type).value();
    args.push_back(hashes[name]);
  }
  horus_test::Peer peer(program, backend, args);
  ASSERT_TRUE(peer.ready()) << peer_name << " did not start";

  const Sent sent;
  const std::string p = prefix + ".";
  auto cmd = open_mapped<CmdVel>(p + "cmd_vel", backend, mapping());
  auto cmd_back = open_mapped<CmdVel>(p + "cmd_vel_echo", backend, mapping());
  // horus's sensor types are best effort; the peer subscribes as a ROS 2 node does by default
  // (reliable): the mapping's `qos: default` gives these topics ROS 2's default profile.
  constexpr auto kRosDefault = horus::Ros2Mapping::Qos::Default;
  auto scan = open_mapped<LaserScan>(p + "scan", backend, mapping("", "laser", "", kRosDefault));
  auto scan_back = open_mapped<LaserScan>(p + "scan_echo", backend, mapping("", "laser", "", kRosDefault));
  auto image = open_mapped<Image>(p + "image", backend, mapping("", "", "", kRosDefault));
  auto image_back = open_mapped<Image>(p + "image_echo", backend, mapping("", "", "", kRosDefault));
  auto joints = open_mapped<JointState>(p + "joints", backend, mapping("", "arm"));
  auto joints_back = open_mapped<JointState>(p + "joints_echo", backend, mapping("", "arm"));
  auto odom = open_mapped<Odometry>(p + "odom", backend, mapping());
  auto odom_back = open_mapped<Odometry>(p + "odom_echo", backend, mapping());
  auto tf = open_mapped<TransformStamped>(p + "tf", backend, mapping("tf2_msgs/msg/TFMessage", "map", "odom"));
  auto tf_back = open_mapped<TransformStamped>(p + "tf_echo", backend, mapping("tf2_msgs/msg/TFMessage", "map", "odom"));

  std::optional<CmdVel> got_cmd;
  std::optional<LaserScan> got_scan;
  std::optional<Image> got_image;
  std::optional<JointState> got_joints;
  std::optional<Odometry> got_odom;
  std::optional<TransformStamped> got_tf;
  auto resend_at = std::chrono::steady_clock::now();
  const bool all = horus_test::eventually(
      [&] {
        // Sent again every 50 ms until echoed: the peer's reader matches ours at its own pace.
        if (std::chrono::steady_clock::now() >= resend_at) {
          resend_at += std::chrono::milliseconds(50);
          if (!got_cmd) cmd.send(sent.cmd);
          if (!got_scan) scan.send(sent.scan);
          if (!got_image) image.send(sent.image);
          if (!got_joints) joints.send(sent.joints);
          if (!got_odom) odom.send(sent.odom);
          if (!got_tf) tf.send(sent.tf);
        }
        if (auto m = cmd_back.recv()) got_cmd = *m;
        if (auto m = scan_back.recv()) got_scan = *m;
        if (auto m = image_back.recv()) got_image = std::move(*m);
        if (auto m = joints_back.recv()) got_joints = *m;
        if (auto m = odom_back.recv()) got_odom = *m;
        if (auto m = tf_back.recv()) got_tf = *m;
        return got_cmd && got_scan && got_image && got_joints && got_odom && got_tf;
      },
      std::chrono::seconds(30), std::chrono::milliseconds(2));
  // The peer reads ros_discovery_info at its own pace: its report lists horus's node once it has.
  const bool graphed = all && horus_test::eventually(
                                  [&] {
                                    const auto now = read_report(report);
                                    return graph_lists(now, matched_writers(now, prefix));
                                  },
                                  std::chrono::seconds(10), std::chrono::milliseconds(20));
  EXPECT_EQ(peer.stop(), 0);
  EXPECT_TRUE(graphed) << "the peer's report never listed horus's node with the writers it matched";
  ASSERT_TRUE(all) << "echoes: cmd_vel " << got_cmd.has_value() << " scan " << got_scan.has_value() << " image "
                   << got_image.has_value() << " joints " << got_joints.has_value() << " odom " << got_odom.has_value()
                   << " tf " << got_tf.has_value();

  // -- what the ROS 2 peer read -------------------------------------------------------------
  const auto r = read_report(report);
  std::filesystem::remove(report);
  bool enclave = false;
  for (auto [it, end] = r.equal_range("participant"); it != end; ++it) enclave |= it->second == std::vector<std::string>{"enclave=/;"};
  EXPECT_TRUE(enclave) << "no participant with USER_DATA enclave=/;";
  std::vector<std::string> writer_gids;  // the GUIDs of horus's writers the peer matched
  for (const auto& [name, type] : kEntries) {
    const std::string topic = "rt/" + prefix + "/" + name;
    bool found = false;
    for (auto [it, end] = r.equal_range("userdata"); it != end; ++it)
      if (it->second.size() == 3 && it->second[0] == topic) {
        found = true;
        writer_gids.push_back(it->second[1]);
        EXPECT_EQ(it->second[2], "typehash=" + hashes[name] + ";") << topic;
      }
    EXPECT_TRUE(found) << "the peer matched no writer on " << topic;
  }
  // ros_discovery_info: horus's participant is one node, named by HORUS_ROS2_NODE, whose writers
  // are the ones the peer matched (and whose readers the echo topics'), under its participant's GID.
  EXPECT_TRUE(graph_lists(r, writer_gids)) << "no ros_discovery_info of node '" << kNode << "' at / listing the writers the peer matched";
  auto line = [&](const std::string& kind) {
    auto it = r.find(kind);
    return it == r.end() ? std::vector<std::string>{} : it->second;
  };
  EXPECT_EQ(line("twist"), (std::vector<std::string>{"0.5", "0", "0", "0", "0", "-0.25"}));
  const auto s = line("scan");
  ASSERT_EQ(s.size(), 12u);
  EXPECT_EQ(s[0], "1700000000");
  EXPECT_EQ(s[1], "123456789");
  EXPECT_EQ(s[2], "laser");  // the rule's frame_id: horus's LaserScan has no frame field
  EXPECT_FLOAT_EQ(static_cast<float>(num(s[3])), -1.0f);
  EXPECT_FLOAT_EQ(static_cast<float>(num(s[5])), 0.01f);
  EXPECT_FLOAT_EQ(static_cast<float>(num(s[6])), 0.1f);
  EXPECT_FLOAT_EQ(static_cast<float>(num(s[7])), 30.0f);
  EXPECT_EQ(s[8], "100");  // the beams of angle_min..angle_max, not the 360 of the array
  EXPECT_FLOAT_EQ(static_cast<float>(num(s[9])), 1.0f);
  EXPECT_FLOAT_EQ(static_cast<float>(num(s[10])), 1.125f);
  EXPECT_FLOAT_EQ(static_cast<float>(num(s[11])), 1.0f + 0.125f * 99);
  const auto im = line("image");
  ASSERT_EQ(im.size(), 10u);
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < sent.image.data().size(); ++i) sum += sent.image.data()[i] * static_cast<std::uint32_t>(i % 251 + 1);
  EXPECT_EQ(im, (std::vector<std::string>{"1700000000", "123456789", "camera", "6", "8", "rgb8", "0", "24", "144",
                                          std::to_string(sum)}));
  EXPECT_EQ(line("joints"), (std::vector<std::string>{"1700000000", "123456789", "arm", "3", "shoulder", "0.5", "1.25",
                                                      "-3", "wrist_roll", "3"}));
  const auto o = line("odom");
  ASSERT_EQ(o.size(), 16u);
  EXPECT_EQ(std::vector<std::string>(o.begin(), o.begin() + 4),
            (std::vector<std::string>{"1700000000", "123456789", "odom", "base_link"}));
  EXPECT_DOUBLE_EQ(num(o[4]), 1.5);
  EXPECT_DOUBLE_EQ(num(o[5]), -2.25);
  EXPECT_DOUBLE_EQ(num(o[6]), 0.0);
  EXPECT_NEAR(num(o[9]), std::sin(0.25), 1e-12);  // yaw 0.5 as a quaternion (z, w)
  EXPECT_NEAR(num(o[10]), std::cos(0.25), 1e-12);
  EXPECT_DOUBLE_EQ(num(o[11]), 0.75);
  EXPECT_DOUBLE_EQ(num(o[12]), 0.1);
  EXPECT_DOUBLE_EQ(num(o[13]), 0.01);
  EXPECT_DOUBLE_EQ(num(o[14]), 0.35);
  EXPECT_DOUBLE_EQ(num(o[15]), 0.07);
  EXPECT_EQ(line("tf"), (std::vector<std::string>{"1", "1700000000", "123456789", "map", "odom", "1", "2", "3", "0", "0",
                                                  "0.59999999999999998", "0.80000000000000004"}));

  // -- what horus read of the peer's bytes --------------------------------------------------
  EXPECT_EQ(got_cmd->linear, 0.5f);
  EXPECT_EQ(got_cmd->angular, -0.25f);
  EXPECT_GT(got_cmd->stamp_nanos, kStamp);  // Twist has no stamp: the time of receipt
  EXPECT_EQ(got_scan->timestamp_ns, kStamp);
  EXPECT_EQ(got_scan->angle_min, sent.scan.angle_min);
  EXPECT_EQ(got_scan->angle_max, sent.scan.angle_max);
  EXPECT_EQ(got_scan->ranges, sent.scan.ranges);
  EXPECT_EQ(got_image->timestamp_ns(), kStamp);
  EXPECT_EQ(got_image->frame_id(), "camera");
  EXPECT_EQ(got_image->width(), 8u);
  EXPECT_EQ(got_image->encoding(), ImageEncoding::Rgb8);
  EXPECT_TRUE(std::ranges::equal(got_image->data(), sent.image.data()));
  EXPECT_EQ(got_joints->timestamp_ns, kStamp);
  EXPECT_EQ(got_joints->joint_count, 3);
  EXPECT_EQ(got_joints->names, sent.joints.names);
  EXPECT_EQ(got_joints->positions, sent.joints.positions);
  EXPECT_EQ(got_joints->velocities, sent.joints.velocities);
  EXPECT_EQ(got_joints->efforts, sent.joints.efforts);
  EXPECT_EQ(got_odom->frame_id_str(), "odom");
  EXPECT_EQ(got_odom->child_frame_id_str(), "base_link");
  EXPECT_DOUBLE_EQ(got_odom->pose.x, 1.5);
  EXPECT_NEAR(got_odom->pose.theta, 0.5, 1e-12);
  EXPECT_EQ(got_odom->pose_covariance, sent.odom.pose_covariance);
  EXPECT_EQ(got_odom->twist.linear, sent.odom.twist.linear);
  EXPECT_EQ(got_tf->translation, sent.tf.translation);
  EXPECT_EQ(got_tf->rotation, sent.tf.rotation);
  EXPECT_EQ(got_tf->timestamp_ns, kStamp);
}

// Between hosts (network namespaces, each with its own /dev/shm): on host 0 a horus topic mapped
// onto ROS 2 by the configuration file, published by one process and read by another through
// shared memory; on host 1 the ROS 2 peer. The peer reads every message once (one bridge on
// host 0 however many of its processes use the topic), with ROS 2's values, type hash and graph
// node; host 0 reads the peer's echo by its ROS 2 name (`horus topic echo /...`).
class Ros2Hosts : public ::testing::TestWithParam<Case> {};

TEST_P(Ros2Hosts, ARos2NodeOnAnotherHostReadsEachMessageOnceWhileTheHostsSubscribersUseSharedMemory) {
  const auto [backend, peer_name] = GetParam();
  if (!horus::backend_available(backend)) GTEST_SKIP() << "this build has no " << horus::to_string(backend) << " backend";
  const std::string program = std::string(INTEROP_WORK_DIR) + "/" + peer_name;
  if (::access(program.c_str(), X_OK) != 0) GTEST_SKIP() << peer_name << " was not built (see interop.BuildThirdPartyPeers)";
  horus_test::NetnsLan lan(2, "r");
  if (!lan.ok()) GTEST_SKIP() << lan.why();
  const std::string prefix = "r2h" + std::to_string(::getpid());
  const std::string domain = std::to_string(1 + ::getpid() % 200);
  const std::string report = "/tmp/" + prefix + ".txt", config = "/tmp/" + prefix + ".yaml";
  std::ofstream(config) << "topics:\n  - match: " << prefix << ".cmd_vel\n    ros2: true\n";
  const std::string dds(horus::to_string(backend));
  const std::vector<std::string> env{"HORUS_BACKEND=" + dds, "HORUS_DOMAIN_ID=" + domain, "HORUS_DDS_LOCALHOST=0",
                                     "HORUS_CONFIG=" + config, "HORUS_ROS2_NODE=robot1_horus"};
  std::vector<std::string> peer_args{program, domain, prefix, "60", report};
  for (const auto& [name, type] : kEntries) peer_args.push_back(horus::ros2::Interfaces::standard().type_hash(type).value());
  auto peer = lan.spawn(1, peer_args, {"ROS2_PEER_LAN=1"});
  ASSERT_TRUE(peer.wait_for_output("ready", std::chrono::seconds(20))) << peer.output();

  constexpr int kSent = 200;  // 10 s at 20 Hz
  const std::string cli = HORUS_CLI;
  auto local = lan.spawn(0, {cli, "topic", "echo", prefix + ".cmd_vel", "--json", "-n", "3", "--timeout", "40"}, env);
  auto pub = lan.spawn(0, {cli, "topic", "pub", prefix + ".cmd_vel", "CmdVel", R"({"linear": 1.25, "angular": -0.5})",
                           "-r", "20", "-n", std::to_string(kSent)}, env);
  auto back = lan.spawn(0, {cli, "topic", "echo", "/" + prefix + "/cmd_vel_echo", "--json", "-n", "1", "--wait", "30000"},
                        env);
  const int back_rc = back.wait(std::chrono::seconds(45));
  if (back_rc != 0) {  // what host 0 sees of the domain, to say why
    auto list = lan.spawn(0, {cli, "topic", "list", "--ros2", "--wait", "3000"}, env);
    (void)list.wait(std::chrono::seconds(20));
    ADD_FAILURE() << "the echo of the peer's echo ended " << back_rc << ":\n" << back.output() << "\nhost 0 lists:\n"
                  << list.output();
  }
  EXPECT_EQ(local.wait(std::chrono::seconds(45)), 0) << local.output();
  EXPECT_EQ(pub.wait(std::chrono::seconds(30)), 0) << pub.output();
  peer.close_stdin();
  EXPECT_EQ(peer.wait(std::chrono::seconds(10)), 0) << peer.output();

  // Host 0's own subscriber and the peer's echo read on host 0: the values horus sent.
  for (auto* out : {&local, &back}) {
    const std::string text = out->output();
    const auto at = std::min(text.find('{'), text.size());
    const auto j = nlohmann::json::parse(text.substr(at, text.find('\n', at) - at), nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << text;
    EXPECT_FLOAT_EQ(j["linear"].is_object() ? j["linear"]["x"].get<float>() : j["linear"].get<float>(), 1.25f) << text;
  }
  const auto r = read_report(report);
  std::filesystem::remove(report);
  std::filesystem::remove(config);
  // Each message once, as ROS 2's Twist: no more than were sent (two bridges would double them).
  const auto twists = r.count("twist");
  EXPECT_GT(twists, 0u);
  EXPECT_LE(twists, static_cast<std::size_t>(kSent)) << "a message reached the ROS 2 node more than once";
  for (auto [it, end] = r.equal_range("twist"); it != end; ++it)
    EXPECT_EQ(it->second, (std::vector<std::string>{"1.25", "0", "0", "0", "0", "-0.5"}));
  const std::string topic = "rt/" + prefix + "/cmd_vel";
  std::string writer;
  for (auto [it, end] = r.equal_range("userdata"); it != end; ++it)
    if (it->second.size() == 3 && it->second[0] == topic) {
      EXPECT_TRUE(writer.empty()) << "more than one writer of " << topic << " (one bridge per host)";
      writer = it->second[1];
      EXPECT_EQ(it->second[2],
                "typehash=" + horus::ros2::Interfaces::standard().type_hash("geometry_msgs/msg/Twist").value() + ";");
    }
  ASSERT_FALSE(writer.empty()) << "the peer matched no writer of " << topic;
  bool graphed = false;
  for (auto [it, end] = r.equal_range("graph"); it != end; ++it)
    graphed |= it->second.size() >= 4 && it->second[1] == "/" && it->second[2] == "robot1_horus" &&
               std::find(it->second.begin(), it->second.end(), writer) != it->second.end();
  EXPECT_TRUE(graphed) << "ros_discovery_info never listed robot1_horus with the bridge's writer " << writer;
}

INSTANTIATE_TEST_SUITE_P(Hosts, Ros2Hosts,
                         ::testing::Values(Case{Backend::CycloneDds, "ros2_peer_cyclone"},
                                           Case{Backend::FastDds, "ros2_peer_fastdds"}),
                         [](const auto& param_info) {
                           return std::string(horus::to_string(param_info.param.horus)) + "_with_" +
                                  param_info.param.peer;
                         });

INSTANTIATE_TEST_SUITE_P(Peers, Ros2Interop,
                         ::testing::Values(Case{Backend::CycloneDds, "ros2_peer_cyclone"},
                                           Case{Backend::CycloneDds, "ros2_peer_fastdds"},
                                           Case{Backend::FastDds, "ros2_peer_cyclone"},
                                           Case{Backend::FastDds, "ros2_peer_fastdds"}),
                         [](const auto& param_info) {
                           return std::string(horus::to_string(param_info.param.horus)) + "_with_" +
                                  param_info.param.peer;
                         });

}  // namespace

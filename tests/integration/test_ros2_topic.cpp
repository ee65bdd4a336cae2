// Topics mapped onto ROS 2 (TopicOptions::ros2, the `ros2:` key; docs/ROS2.md) on both DDS
// backends: what the ROS 2 type holds and horus's cannot is dropped and counted, a ROS 2 writer
// of the same type with another type hash is reported, and a mapping that cannot be made fails
// its open with an error naming why. (Field by field against ROS 2 peers built by idlc and
// fastddsgen: tests/interop/test_ros2_interop.cpp.)
#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "dds_support.hpp"
#include "horus/idlgen/emit.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/wire/dynamic.hpp"
#include "horus/record/recorder.hpp"
#include "netns.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

namespace {

using horus::Backend;
using namespace horus::msg;

class Ros2Topic : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    if (!horus::backend_available(GetParam())) GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
    ::setenv("HORUS_DDS_LOCALHOST", "1", 1);
    domain_ = std::to_string(1 + (::getpid() + 77) % 200);
    ::setenv("HORUS_DOMAIN_ID", domain_.c_str(), 1);
    static int n = 0;
    prefix_ = "r2topic" + std::to_string(::getpid()) + "_" + std::to_string(++n);
  }
  template <class T>
  horus::Result<horus::Topic<T>> open(const std::string& name, horus::Ros2Mapping m) {
    horus::TopicOptions o;
    o.backend = GetParam();
    o.ros2 = std::move(m);
    return horus::Topic<T>::open(name, o);
  }
  std::string domain_, prefix_;
};

TEST_P(Ros2Topic, AScanOfMoreBeamsThanHorusHoldsIsDroppedAndCountedAndAnotherTypeHashIsReported) {
  const std::string other_hash = "RIHS01_" + std::string(64, '0');
  horus_test::Peer peer(GetParam(), {"ros2-scan", "rt/" + prefix_ + "/scan", other_hash, "30"});
  ASSERT_TRUE(peer.ready()) << "horus_dds_peer ros2-scan did not start";
  horus::Ros2Mapping m;
  m.qos = horus::Ros2Mapping::Qos::Default;
  auto scan = open<LaserScan>(prefix_ + ".scan", m);
  ASSERT_TRUE(scan) << scan.error().message();
  std::optional<LaserScan> got;
  ASSERT_TRUE(horus_test::eventually(
      [&] {
        if (auto s = scan->recv()) got = *s;
        return got && scan->dropped_count() > 0 && scan->network_errors() > 0;
      },
      std::chrono::seconds(20)))
      << "received " << got.has_value() << ", dropped " << scan->dropped_count() << ", errors " << scan->network_errors();
  // The 100-beam scans arrive whole; each 720-beam one is dropped and counted, never cut to 360.
  EXPECT_EQ(got->ranges[0], 2.5f);
  EXPECT_EQ(got->ranges[99], 2.5f);
  EXPECT_EQ(got->ranges[100], 0.0f);
  EXPECT_EQ(got->timestamp_ns, 1'700'000'000'000'000'005ULL);
  while (auto s = scan->recv()) EXPECT_EQ(s->ranges[100], 0.0f) << "a 720-beam scan was delivered cut";
  EXPECT_EQ(peer.stop(), 0);
}

TEST_P(Ros2Topic, AMappingThatCannotBeMadeFailsItsOpenNamingWhy) {
  horus::Ros2Mapping twist;
  twist.type = "geometry_msgs/msg/Twist";
  auto pose = open<Pose2D>(prefix_ + ".pose", twist);
  ASSERT_FALSE(pose);
  EXPECT_NE(pose.error().message().find("horus::msg::Pose2D does not convert to geometry_msgs/msg/Twist"), std::string::npos)
      << pose.error().message();
  EXPECT_NE(pose.error().message().find("it converts to geometry_msgs/msg/Pose2D"), std::string::npos)
      << pose.error().message();
  auto dashed = open<Pose2D>(prefix_ + ".front-left", {});
  ASSERT_FALSE(dashed);
  EXPECT_NE(dashed.error().message().find("ROS 2"), std::string::npos) << dashed.error().message();
  horus::Ros2Mapping standard_other;
  standard_other.type = "sensor_msgs/msg/Imu";
  auto hb = open<Heartbeat>(prefix_ + ".heartbeat", standard_other);
  ASSERT_FALSE(hb);
  EXPECT_NE(hb.error().message().find("it has no ROS 2 equivalent"), std::string::npos) << hb.error().message();
  // A type of its own package name: refused when the name is not its own.
  horus::Ros2Mapping wrong_name;
  wrong_name.type = "my_robot_msgs/msg/Beat";
  auto beat = open<Heartbeat>(prefix_ + ".beat", wrong_name);
  ASSERT_FALSE(beat);
  EXPECT_NE(beat.error().message().find("is my_robot_msgs/msg/Heartbeat"), std::string::npos) << beat.error().message();
}

// A message with no ROS 2 equivalent is its own type of the horus_msgs package: it opens, and the
// type hash it announces is the one `horus idl --ros2` prints for the generated .msg.
TEST_P(Ros2Topic, AMessageWithoutAnEquivalentGoesAsItsHorusMsgsType) {
  auto hb = open<Heartbeat>(prefix_ + ".heartbeat", {});
  ASSERT_TRUE(hb) << hb.error().message();
  auto dyn = horus::wire::parse_signature(horus::reflect::type_signature<Heartbeat>());
  ASSERT_TRUE(dyn) << dyn.error();
  auto t = horus::idlgen::ros2_type_of(*dyn);
  ASSERT_TRUE(t) << t.error().message();
  EXPECT_EQ(t->name, "horus_msgs/msg/Heartbeat");
  EXPECT_TRUE(t->type_hash.starts_with("RIHS01_")) << t->type_hash;
  horus::idlgen::Ros2Options mine;
  mine.package = "my_robot_msgs";
  auto other = horus::idlgen::ros2_type_of(*dyn, mine);
  ASSERT_TRUE(other);
  EXPECT_EQ(other->name, "my_robot_msgs/msg/Heartbeat");
  // The package name is part of what is hashed (the type's name is in its description).
  EXPECT_NE(other->type_hash, t->type_hash);
}

// The CLI on the ROS 2 graph, without a configuration file: `horus topic list --ros2` lists a
// mapped topic with its ROS 2 type, its publisher and the node ros_discovery_info names;
// `horus topic echo` and `hz` read it by its ROS 2 name.
TEST_P(Ros2Topic, TheCliListsEchoesAndRatesATopicByItsRos2Name) {
  const std::string node = "cli_check_" + std::to_string(::getpid());
  ::setenv("HORUS_ROS2_NODE", node.c_str(), 1);
  auto cmd = open<CmdVel>(prefix_ + ".cmd_vel", {});
  ASSERT_TRUE(cmd) << cmd.error().message();
  std::optional<horus_test::Publishing> sender;  // 20 Hz while the CLI reads
  sender.emplace(std::chrono::milliseconds(50), [&](int) { cmd->send(CmdVel{0, 1.25f, -0.5f}); });
  const std::string ros_name = "/" + prefix_ + "/cmd_vel";
  const std::string cli = std::string(HORUS_CLI) + " topic ";
  const std::string backend = " --backend " + std::string(horus::to_string(GetParam()));
  std::string out;
  EXPECT_EQ(horus_test::run_command(cli + "list --ros2 --json --wait 3000" + backend, out), 0) << out;
  const auto list = nlohmann::json::parse(out.substr(std::min(out.find('{'), out.size())), nullptr, false);
  bool listed = false;
  for (const auto& t : list.is_discarded() ? nlohmann::json::array() : list["topics"])
    if (t["name"] == ros_name) {
      listed = true;
      EXPECT_EQ(t["type"], "geometry_msgs/msg/Twist");
      EXPECT_EQ(t["type_hash"], horus::ros2::Interfaces::standard().type_hash("geometry_msgs/msg/Twist").value());
      EXPECT_GE(t["publishers"].get<int>(), 1);
      EXPECT_EQ(t["publishing_nodes"], nlohmann::json::array({"/" + node})) << t.dump();
    }
  EXPECT_TRUE(listed) << ros_name << " not in\n" << out;
  EXPECT_EQ(horus_test::run_command(cli + "echo " + ros_name + " -n 2 --json --wait 5000" + backend, out), 0) << out;
  const auto brace = std::min(out.find('{'), out.size());
  const auto first = nlohmann::json::parse(out.substr(brace, out.find('\n', brace) - brace), nullptr, false);
  EXPECT_EQ(out.find("INCOMPATIBLE"), std::string::npos) << "the echo is an observer, no writer:\n" << out;
  EXPECT_FALSE(first.is_discarded()) << out;
  if (!first.is_discarded()) {
    EXPECT_FLOAT_EQ(first["linear"]["x"].get<float>(), 1.25f) << out;
    EXPECT_FLOAT_EQ(first["angular"]["z"].get<float>(), -0.5f) << out;
  }
  EXPECT_EQ(horus_test::run_command(cli + "hz " + ros_name + " --duration 2 --wait 5000" + backend, out), 0) << out;
  EXPECT_NE(out.find("average rate"), std::string::npos) << out;
  // A ROS 2 name nobody publishes: named, with what the domain has.
  EXPECT_EQ(horus_test::run_command(cli + "echo /" + prefix_ + "/nothing -n 1 --wait 500" + backend, out), 1) << out;
  EXPECT_NE(out.find("no ROS 2 publisher"), std::string::npos) << out;
  sender.reset();
}

// `horus play --ros2`: a ROS 2 bag's topic played onto the ROS 2 wire (its recorded name and
// type), where a reader of the ROS 2 name (`horus topic echo /...`) gets the recorded values.
TEST_P(Ros2Topic, PlayWithRos2PutsABagsTopicsOnTheRos2Wire) {
  const std::string bag = "/tmp/" + prefix_ + ".mcap";
  {
    auto rec = horus::Recorder::open(bag, {.profile = horus::RecordProfile::Ros2});
    ASSERT_TRUE(rec) << rec.error().message();
    ASSERT_TRUE((*rec)->add<CmdVel>(prefix_ + ".cmd"));
    auto cmd = horus::Topic<CmdVel>::open(prefix_ + ".cmd");
    ASSERT_TRUE(cmd);
    for (int i = 0; i < 5; ++i) cmd->send(CmdVel{0, 0.75f, 0.125f});
    ASSERT_TRUE((*rec)->close());
  }
  const std::string backend(horus::to_string(GetParam()));
  ::setenv("HORUS_BACKEND", backend.c_str(), 1);  // the player's mapped topics on this backend
  auto play = horus_test::start_logged({HORUS_CLI, "play", bag, "--ros2", "--loop", "--rate", "10"},
                                       "/tmp/" + prefix_ + "-play.log");
  std::string out;
  EXPECT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " topic echo /" + prefix_ + "/cmd -n 1 --json --wait 10000" +
                                        " --backend " + backend,
                                    out),
            0)
      << out << play.output();
  const auto brace = std::min(out.find('{'), out.size());
  const auto j = nlohmann::json::parse(out.substr(brace, out.find('\n', brace) - brace), nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << out;
  EXPECT_FLOAT_EQ(j["linear"]["x"].get<float>(), 0.75f);
  EXPECT_FLOAT_EQ(j["angular"]["z"].get<float>(), 0.125f);
  play.terminate();
  EXPECT_EQ(play.wait(std::chrono::seconds(10)), 0) << play.output();
  std::filesystem::remove(bag);
}

INSTANTIATE_TEST_SUITE_P(Backends, Ros2Topic, ::testing::Values(Backend::CycloneDds, Backend::FastDds),
                         [](const auto& param_info) { return std::string(horus::to_string(param_info.param)); });

}  // namespace

// ROS 2 bags (RecordProfile::Ros2, `horus record --profile ros2`, `horus play` of a ROS 2 bag),
// read by Foxglove's own ROS 2 libraries (tests/interop/mcap_js/read_ros2_bag.mjs: @mcap/core,
// @foxglove/rosmsg, @foxglove/rosmsg2-serialization):
//  - every standard message recorded as its ROS 2 type: each message decodes in Foxglove's reader
//    as in the library's own ROS 2 decoder; names, types, hashes, QoS and the rosbag2 metadata
//    record are what rosbag2 writes;
//  - a bag plays back into horus topics through the conversions (`horus play`), also a bag that
//    a ROS 2 program wrote (no horus metadata); a ROS 2 type horus has no conversion for is named;
//  - the horus_msgs package (`horus idl --ros2`) parses in @foxglove/rosmsg, and the RIHS01 hash
//    computed in JavaScript from that parse is the library's for every type.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "horus/msg/all.hpp"
#include "horus/record/mcap.hpp"
#include "horus/record/player.hpp"
#include "horus/record/recorder.hpp"
#include "horus/record/standard.hpp"
#include "horus/ros2/dynamic.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/topic.hpp"
#include "horus/transport/encapsulation.hpp"
#include "message_trips.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

namespace {

using namespace std::chrono_literals;
using nlohmann::json;

// node and the npm packages, or the reason to skip.
std::string js_missing() {
  if (::access("/usr/bin/node", X_OK) != 0) return "node is not installed (scripts/install-deps.sh installs nodejs)";
  if (::access(MCAP_JS_DIR "/node_modules/@foxglove/rosmsg2-serialization", F_OK) != 0)
    return "the npm packages are not installed in " MCAP_JS_DIR " (scripts/install-deps.sh runs npm ci there)";
  return {};
}

std::vector<json> run_js(const std::string& args, std::string& out) {
  const int rc = horus_test::run_command("/usr/bin/node " MCAP_JS_DIR "/read_ros2_bag.mjs " + args, out);
  EXPECT_EQ(rc, 0) << out.substr(0, 4000);
  std::vector<json> lines;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);)
    if (line.starts_with('{')) lines.push_back(json::parse(line));
  return lines;
}

// Foxglove's value against the library's decoding of the same bytes: equal, with 64-bit integers
// as decimal strings on Foxglove's side and non-finite floats as null. The first difference.
std::string differs(const json& mine, const json& theirs, const std::string& at) {
  if (mine.is_object()) {
    if (!theirs.is_object() || theirs.size() != mine.size()) return at + ": not the same fields";
    for (const auto& [k, v] : mine.items()) {
      if (!theirs.contains(k)) return at + "." + k + ": missing";
      if (auto d = differs(v, theirs[k], at + "." + k); !d.empty()) return d;
    }
    return {};
  }
  if (mine.is_array()) {
    if (!theirs.is_array() || theirs.size() != mine.size()) return at + ": not the same length";
    for (std::size_t i = 0; i < mine.size(); ++i)
      if (auto d = differs(mine[i], theirs[i], at + "[" + std::to_string(i) + "]"); !d.empty()) return d;
    return {};
  }
  if (theirs.is_string() && mine.is_number_integer()) return theirs == mine.dump() ? "" : at + ": " + mine.dump();
  if (mine.is_number_float() && !std::isfinite(mine.get<double>())) return theirs.is_null() ? "" : at + ": not null";
  if (mine.is_number() && theirs.is_number())
    return std::abs(mine.get<double>() - theirs.get<double>()) <= 1e-9 * std::max(1.0, std::abs(mine.get<double>()))
               ? ""
               : at + ": " + mine.dump() + " vs " + theirs.dump();
  if (mine.is_null() && theirs.is_null()) return {};
  return mine == theirs ? "" : at + ": " + mine.dump() + " vs " + theirs.dump();
}

// A unique topic prefix that is also a ROS 2 name (no token starts with a digit).
std::string ros_prefix(const std::string& base) {
  static std::atomic<int> n{0};
  return "test." + base + ".p" + std::to_string(::getpid()) + "_" + std::to_string(n.fetch_add(1));
}

std::uint64_t wall_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

TEST(RecordRos2, EveryStandardTypeIsABagThatFoxglovesRos2ReadersDecode) {
  if (auto why = js_missing(); !why.empty()) GTEST_SKIP() << why;
  const std::string prefix = ros_prefix("bag");
  const std::string file = "/tmp/horus-" + prefix + ".mcap";
  const auto& types = horus_test::standard_types();
  auto rec = horus::Recorder::open(file, {.profile = horus::RecordProfile::Ros2});
  ASSERT_TRUE(rec) << rec.error().message();
  std::vector<std::unique_ptr<horus_test::Trip>> trips;
  for (const auto& t : types) {
    trips.push_back(t.trip());
    ASSERT_EQ(trips.back()->open(horus::Backend::SharedMemory, prefix), "") << t.name;
    auto source = horus::open_standard_source(t.name, prefix + "." + std::string(t.name));
    ASSERT_TRUE(source) << source.error().message();
    ASSERT_TRUE((*rec)->add(std::move(*source))) << t.name;
  }
  for (auto& t : trips) t->send();
  ASSERT_TRUE((*rec)->close());
  const auto stats = (*rec)->stats();
  for (const auto& t : stats.topics) EXPECT_EQ(t.messages, 1u) << t.topic << " as " << t.ros2_topic;

  // The library's reading: each message through its schema's ROS 2 type.
  auto reader = horus::mcap::Reader::open(file);
  ASSERT_TRUE(reader) << reader.error().message();
  EXPECT_EQ((*reader)->profile(), "ros2");
  std::map<std::string, json> decoded;  // by ROS 2 topic
  std::map<std::string, std::string> hashes;
  auto ok = (*reader)->read_messages([&](const horus::mcap::Channel& ch, const horus::mcap::Schema* s,
                                         const horus::mcap::Message& m) {
    EXPECT_TRUE(s != nullptr && s->encoding == "ros2msg") << ch.topic;
    if (s == nullptr) return true;
    horus::ros2::Interfaces types_of_bag;  // the schema's own text: the definition and its dependencies
    const std::string text(reinterpret_cast<const char*>(s->data.data()), s->data.size());
    std::size_t at = 0;
    for (std::string name = s->name; !name.empty();) {
      const std::size_t sep = text.find("\n\n" + std::string(80, '='), at);
      EXPECT_TRUE(types_of_bag.add(name, text.substr(at, sep == std::string::npos ? std::string::npos : sep + 1 - at)))
          << name;
      if (sep == std::string::npos) break;
      const std::size_t line = text.find("MSG: ", sep) + 5, end = text.find('\n', line);
      const auto n = horus::ros2::parse_type_name(text.substr(line, end - line));
      name = n ? n->full() : "";
      at = end + 1;
    }
    const auto& standard = horus::ros2::Interfaces::standard();
    const auto& interfaces = standard.find(s->name) != nullptr ? standard : types_of_bag;
    EXPECT_EQ(types_of_bag.type_hash(s->name).value_or("?"), ch.metadata.at("topic_type_hash"))
        << ch.topic << ": the schema's text hashes as the channel says";
    hashes[ch.topic] = ch.metadata.at("topic_type_hash");
    const auto sample = std::get<horus::net::Sample>(horus::net::encapsulation::parse(m.data));
    auto j = horus::ros2::decode_json(interfaces, s->name, sample.body);
    EXPECT_TRUE(j) << ch.topic << ": " << (j ? "" : j.error().message());
    if (j) decoded[ch.topic] = *j;
    return true;
  });
  ASSERT_TRUE(ok) << ok.error().message();
  ASSERT_EQ(decoded.size(), types.size());

  // Foxglove's reading of the same bag.
  std::string out;
  const auto lines = run_js(file, out);
  std::size_t messages = 0;
  json metadata;
  for (const auto& j : lines) {
    if (j.contains("profile")) {
      EXPECT_EQ(j["profile"], "ros2");
    }
    if (j.contains("metadata") && j["metadata"].is_string() && j["metadata"] == "rosbag2") metadata = j["values"];
    if (!j.contains("topic")) continue;
    ++messages;
    const std::string topic = j["topic"];
    ASSERT_TRUE(decoded.contains(topic)) << topic;
    EXPECT_EQ(differs(decoded[topic], j["value"], topic), "");
    const YAML::Node qos = YAML::Load(j["metadata"]["offered_qos_profiles"].get<std::string>());
    EXPECT_TRUE(qos.IsSequence() && qos[0]["reliability"].as<std::string>() == "reliable" &&
                qos[0]["history"].as<std::string>() == "keep_last")
        << topic;
  }
  EXPECT_EQ(messages, types.size());
  // Spot checks of the conversions: the values horus sent, in ROS 2's fields.
  std::string root = "/" + prefix + "/";
  std::replace(root.begin(), root.end(), '.', '/');
  const json cmd = json::parse(horus_test::types_named({"CmdVel"})[0].sample_json());
  EXPECT_FLOAT_EQ(decoded[root + "CmdVel"]["linear"]["x"].get<float>(), cmd["linear"].get<float>());
  EXPECT_FLOAT_EQ(decoded[root + "CmdVel"]["angular"]["z"].get<float>(), cmd["angular"].get<float>());
  const json scan = json::parse(horus_test::types_named({"LaserScan"})[0].sample_json());
  EXPECT_EQ(decoded[root + "LaserScan"]["header"]["stamp"]["nanosec"].get<std::uint64_t>(),
            scan["timestamp_ns"].get<std::uint64_t>() % 1'000'000'000u);
  EXPECT_EQ(hashes[root + "CmdVel"], horus::ros2::Interfaces::standard().type_hash("geometry_msgs/msg/Twist").value());
  EXPECT_TRUE(hashes.contains(root + "Heartbeat"));

  // The rosbag2 record: metadata version 9, every topic with its type, hash and count.
  ASSERT_TRUE(metadata.contains("serialized_metadata")) << out.substr(0, 2000);
  const YAML::Node md = YAML::Load(metadata["serialized_metadata"].get<std::string>());
  EXPECT_EQ(md["version"].as<int>(), 9);
  EXPECT_EQ(md["storage_identifier"].as<std::string>(), "mcap");
  EXPECT_EQ(md["message_count"].as<std::size_t>(), types.size());
  ASSERT_EQ(md["topics_with_message_count"].size(), types.size());
  for (const auto& t : md["topics_with_message_count"]) {
    const auto name = t["topic_metadata"]["name"].as<std::string>();
    EXPECT_EQ(t["message_count"].as<int>(), 1) << name;
    EXPECT_EQ(t["topic_metadata"]["type_description_hash"].as<std::string>(), hashes[name]) << name;
    EXPECT_EQ(t["topic_metadata"]["offered_qos_profiles"][0]["durability"].as<std::string>(), "volatile") << name;
  }
  EXPECT_EQ(md["files"][0]["path"].as<std::string>(), std::filesystem::path(file).filename().string());
  std::filesystem::remove(file);
}

// A bag of ROS 2 types, as a ROS 2 program writes it: no horus metadata, only the schema.
void write_foreign_bag(const std::string& file) {
  const auto& standard = horus::ros2::Interfaces::standard();
  auto w = horus::mcap::Writer::create(file, {.profile = "ros2"});
  ASSERT_TRUE(w);
  auto add = [&](const std::string& topic, const std::string& type) {
    const std::string def = standard.message_definition(type).value();
    auto schema = (*w)->add_schema(type, "ros2msg", std::as_bytes(std::span(def.data(), def.size())));
    return (*w)->add_channel(schema.value(), topic, "cdr").value();
  };
  const auto twist = add("/robot9/cmd_vel", "geometry_msgs/msg/Twist");
  const auto text = add("/robot9/chatter", "std_msgs/msg/String");
  auto put = [&](std::uint16_t channel, const std::string& type, const json& value) {
    auto body = horus::ros2::encode_json(standard, type, value).value();
    std::vector<std::byte> data(horus::net::encapsulation::serialized_size(body.size()));
    std::copy(body.begin(), body.end(), data.begin() + horus::net::encapsulation::kHeaderSize);
    horus::net::encapsulation::write_header_and_padding(data, body.size());
    const auto now = wall_ns();
    ASSERT_TRUE((*w)->write({channel, 0, now, now, data}));
  };
  put(twist, "geometry_msgs/msg/Twist", {{"linear", {{"x", 0.75}}}, {"angular", {{"z", -0.5}}}});
  put(text, "std_msgs/msg/String", {{"data", "hello"}});
  ASSERT_TRUE((*w)->close());
}

TEST(RecordRos2, ABagPlaysBackIntoHorusTopicsThroughTheConversions) {
  const std::string prefix = ros_prefix("play");
  const std::string file = "/tmp/horus-" + prefix + ".mcap";
  {
    auto rec = horus::Recorder::open(file, {.profile = horus::RecordProfile::Ros2});
    ASSERT_TRUE(rec) << rec.error().message();
    ASSERT_TRUE((*rec)->add<horus::msg::CmdVel>(prefix + ".cmd_vel"));
    ASSERT_TRUE((*rec)->add<horus::msg::LaserScan>(prefix + ".scan"));
    auto cmd = horus::Topic<horus::msg::CmdVel>::open(prefix + ".cmd_vel");
    auto scan = horus::Topic<horus::msg::LaserScan>::open(prefix + ".scan");
    ASSERT_TRUE(cmd && scan);
    const std::uint64_t stamp = wall_ns() - 1'000'000'000u;
    cmd->send(horus::msg::CmdVel{stamp, 1.25f, -0.5f});
    horus::msg::LaserScan s{};
    s.ranges[0] = 2.5f;
    s.ranges[359] = 7.0f;
    s.angle_increment = 0.0174533f;
    s.angle_max = s.angle_increment * 359;  // 360 beams (the conversion counts them from the angles)
    s.range_min = 0.1f;  // a range outside [range_min, range_max] is invalid, 0 in horus
    s.range_max = 10.0f;
    s.timestamp_ns = stamp;
    scan->send(s);
    ASSERT_TRUE((*rec)->close());
    const auto stats = (*rec)->stats();
    ASSERT_EQ(stats.topics.size(), 2u);
    std::string ros_name = "/" + prefix + "/cmd_vel";
    std::replace(ros_name.begin(), ros_name.end(), '.', '/');
    EXPECT_EQ(stats.topics[0].ros2_topic, ros_name);
    EXPECT_EQ(stats.topics[1].ros2_type, "sensor_msgs/msg/LaserScan");
  }
  // horus play: the ROS 2 names back into the horus topics, through the conversions.
  auto cmd = horus::Topic<horus::msg::CmdVel>::open(prefix + ".cmd_vel");
  auto scan = horus::Topic<horus::msg::LaserScan>::open(prefix + ".scan");
  ASSERT_TRUE(cmd && scan);
  std::string out;
  ASSERT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " play " + file + " --rate 0", out), 0) << out;
  EXPECT_NE(out.find("published 2 messages"), std::string::npos) << out;
  auto c = cmd->recv_for(5s);
  ASSERT_TRUE(c) << out;
  EXPECT_FLOAT_EQ(c->linear, 1.25f);
  EXPECT_FLOAT_EQ(c->angular, -0.5f);
  auto l = scan->recv_for(5s);
  ASSERT_TRUE(l) << out;
  EXPECT_FLOAT_EQ(l->ranges[0], 2.5f);
  EXPECT_FLOAT_EQ(l->ranges[359], 7.0f);
  EXPECT_GT(l->timestamp_ns, 0u);

  // A ROS 2 program's bag: Twist plays as the standard message whose preferred type it is, into
  // robot9.cmd_vel; a String is named as a type horus does not convert.
  const std::string foreign = "/tmp/horus-" + prefix + "-ros2.mcap";
  ASSERT_NO_FATAL_FAILURE(write_foreign_bag(foreign));
  auto player = horus::Player::open(foreign);
  ASSERT_TRUE(player) << player.error().message();
  const auto* twist = (*player)->channel("/robot9/cmd_vel");
  ASSERT_NE(twist, nullptr);
  EXPECT_EQ(twist->horus_topic, "robot9.cmd_vel");
  EXPECT_EQ(twist->ros2_type, "geometry_msgs/msg/Twist");
  ASSERT_NE(twist->conversion, nullptr);
  EXPECT_TRUE(twist->conversion->preferred);
  const auto* chatter = (*player)->channel("/robot9/chatter");
  ASSERT_NE(chatter, nullptr);
  auto refused = horus::Player::playable(*chatter);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message().find("std_msgs/msg/String"), std::string::npos) << refused.error().message();
  if (twist->type == "horus::msg::CmdVel") {
    const std::string into = prefix + ".foreign";
    auto sub = horus::Topic<horus::msg::CmdVel>::open(into);
    ASSERT_TRUE(sub);
    ASSERT_TRUE((*player)->bind<horus::msg::CmdVel>("/robot9/cmd_vel", into));
    horus::PlayOptions fast;
    fast.rate = 0;
    auto played = (*player)->play(fast);
    ASSERT_TRUE(played) << played.error().message();
    auto m = sub->recv_for(5s);
    ASSERT_TRUE(m);
    EXPECT_FLOAT_EQ(m->linear, 0.75f);
    EXPECT_FLOAT_EQ(m->angular, -0.5f);
  }
  ASSERT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " play " + foreign + " --rate 0", out), 0) << out;
  EXPECT_NE(out.find("skipping '/robot9/chatter'"), std::string::npos) << out;
  for (const auto& f : {file, foreign}) std::filesystem::remove(f);
}

TEST(RecordRos2, WhatABagCannotHoldIsRefusedNamingWhy) {
  auto lcm = horus::Recorder::open("/tmp/horus-ros2-refused.lcm",
                                   {.format = horus::RecordFormat::Lcm, .profile = horus::RecordProfile::Ros2});
  ASSERT_FALSE(lcm);
  EXPECT_NE(lcm.error().message().find("ros2 profile"), std::string::npos) << lcm.error().message();
  const std::string file = "/tmp/" + horus_test::unique_name("refused") + ".mcap";
  auto rec = horus::Recorder::open(file, {.profile = horus::RecordProfile::Ros2});
  ASSERT_TRUE(rec);
  auto digit = (*rec)->add<horus::msg::CmdVel>(horus_test::unique_name("r") + ".2d");
  ASSERT_FALSE(digit);
  EXPECT_NE(digit.error().message().find("ROS 2 name"), std::string::npos) << digit.error().message();
  ASSERT_TRUE((*rec)->close());
  std::filesystem::remove(file);
}

TEST(RecordRos2, TheHorusMsgsPackageParsesInFoxglovesRosmsgAndHashesAsTheLibrarySays) {
  if (auto why = js_missing(); !why.empty()) GTEST_SKIP() << why;
  const std::string dir = "/tmp/" + horus_test::unique_name("pkg") + "/horus_msgs";
  std::string out;
  // Standard output alone (to a file): the CLI's progress on standard error would interleave.
  const std::string listing = std::filesystem::path(dir).parent_path().string() + ".txt";
  ASSERT_EQ(horus_test::run_command("(" + std::string(HORUS_CLI) + " idl --ros2 " + dir + " 2>/dev/null) > " + listing, out), 0) << out;
  std::map<std::string, std::string> library;
  std::ifstream in(listing);
  for (std::string name, hash; in >> name >> hash;)
    if (name.starts_with("horus_msgs/msg/")) library[name] = hash;
  ASSERT_GE(library.size(), 80u) << out.substr(0, 2000);
  std::string js;
  std::size_t same = 0;
  for (const auto& j : run_js("--hash " + dir, js)) {
    ASSERT_TRUE(j.contains("type")) << j.dump();
    const auto it = library.find(j["type"]);
    if (it == library.end()) continue;  // a type the CLI lists elsewhere
    EXPECT_EQ(j["hash"], it->second) << it->first;
    ++same;
  }
  EXPECT_EQ(same, library.size());
  std::filesystem::remove_all(std::filesystem::path(dir).parent_path());
  std::filesystem::remove(listing);
}

}  // namespace

// Verbose topics (TopicOptions::verbose, `log:` rules, HORUS_LOG_TOPICS): the line each send and
// receive of a verbose handle logs, and none for other topics; the per-topic rate limit and
// what it held back; the message's own summary (a free overload, a member, large data); the
// precedence of code, environment and file, and the errors of bad settings. The library's
// logger is read through a sink added for the test. ctest runs each test in its own process.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <vector>

#include "horus/config.hpp"
#include "horus/format.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/msg/image.hpp"
#include "horus/topic.hpp"
#include "log_capture.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

// Messages of a user's own, with their own summaries.
namespace arm {
HORUS_MESSAGE(Joints, (float, shoulder), (float, elbow))
// A free overload beside the type: found by argument-dependent lookup.
std::string log_summary(const Joints& j) { return fmt::format("Joints(shoulder {:.2f} rad, elbow {:.2f} rad)", j.shoulder, j.elbow); }

struct Gripper {
  float width{};
  std::string log_summary() const { return fmt::format("Gripper({:.3f} m)", width); }
};
HORUS_REFLECT(Gripper, width)

HORUS_MESSAGE(Plain, (std::int32_t, a), (std::int32_t, b))
HORUS_MESSAGE(Note, (std::string, text))
}  // namespace arm

namespace {

using horus::TopicOptions;
using horus_test::LogCapture;
using horus_test::unique_name;

TopicOptions verbose(double rate_hz = 0) {
  TopicOptions o;
  o.backend = horus::Backend::InProcess;
  o.verbose = true;
  o.log_rate_hz = rate_hz;
  return o;
}

class TopicLogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ::unsetenv("HORUS_LOG_TOPICS");
    ::unsetenv("HORUS_CONFIG");
    ::unsetenv("HORUS_BACKEND");
    horus::detail::log().set_level(spdlog::level::info);
  }
};

TEST_F(TopicLogTest, AVerboseHandleLogsEachSendAndReceiveAndAnotherTopicNothing) {
  LogCapture log;
  const std::string name = unique_name("log.pose");
  const std::string quiet = unique_name("log.quiet");
  auto pub = horus::Topic<horus::msg::Pose2D>::open(name, verbose());
  auto sub = horus::Topic<horus::msg::Pose2D>::open(name, verbose());
  ASSERT_TRUE(pub && sub);
  auto other_pub = horus::Topic<horus::msg::Pose2D>::open(quiet, TopicOptions{horus::Backend::InProcess, {}, {}});
  auto other_sub = horus::Topic<horus::msg::Pose2D>::open(quiet, TopicOptions{horus::Backend::InProcess, {}, {}});
  ASSERT_TRUE(other_pub && other_sub);
  for (int i = 1; i <= 3; ++i) {
    pub->send(horus::msg::Pose2D{1.0 * i, 2.0, 0.5, 0});
    other_pub->send(horus::msg::Pose2D{});
  }
  for (int i = 1; i <= 3; ++i) {
    ASSERT_TRUE(sub->recv());
    ASSERT_TRUE(other_sub->recv());
  }
  const auto opened = log.lines("this handle logs its sends and receives");
  ASSERT_EQ(opened.size(), 2u) << log.text();
  EXPECT_NE(opened[0].find("topic '" + name + "' (horus::msg::Pose2D)"), std::string::npos) << opened[0];
  EXPECT_NE(opened[0].find("every message"), std::string::npos) << opened[0];
  EXPECT_NE(opened[0].find("from code (TopicOptions::verbose)"), std::string::npos) << opened[0];
  const auto sends = log.lines("topic '" + name + "' send #");
  ASSERT_EQ(sends.size(), 3u) << log.text();
  EXPECT_EQ(sends[0], "info topic '" + name + "' send #1: Pose2D { x: 1, y: 2, theta: 0.5, timestamp_ns: 0 }");
  EXPECT_EQ(sends[2], "info topic '" + name + "' send #3: Pose2D { x: 3, y: 2, theta: 0.5, timestamp_ns: 0 }");
  const auto recvs = log.lines("topic '" + name + "' recv #");
  ASSERT_EQ(recvs.size(), 3u) << log.text();
  EXPECT_EQ(recvs[1], "info topic '" + name + "' recv #2: Pose2D { x: 2, y: 2, theta: 0.5, timestamp_ns: 0 }");
  EXPECT_TRUE(log.lines(quiet).empty()) << log.text();
}

// A receiver that lost messages says so; a refused send is a line of its own.
TEST_F(TopicLogTest, ReceivesReportDropsAndRefusedSendsAreLogged) {
  LogCapture log;
  const std::string name = unique_name("log.drops");
  TopicOptions o = verbose();
  o.capacity = 4;
  auto pub = horus::Topic<horus::msg::Pose2D>::open(name, o);
  auto sub = horus::Topic<horus::msg::Pose2D>::open(name, o);
  ASSERT_TRUE(pub && sub);
  for (int i = 0; i < 10; ++i) pub->send(horus::msg::Pose2D{});
  ASSERT_TRUE(sub->recv());
  const auto recvs = log.lines("' recv #1");
  ASSERT_EQ(recvs.size(), 1u) << log.text();
  EXPECT_NE(recvs[0].find("(6 dropped so far)"), std::string::npos) << recvs[0];

  TopicOptions small = verbose();
  small.slot_size = 64;
  auto notes = horus::Topic<arm::Note>::open(unique_name("log.notes"), small);
  ASSERT_TRUE(notes);
  notes->send(arm::Note{"short"});
  notes->send(arm::Note{std::string(200, 'n')});  // over the slot: refused
  EXPECT_EQ(log.lines("' send #1: Note { text: \"short\" }").size(), 1u) << log.text();
  EXPECT_EQ(log.lines("' send refused (1 so far): Note { text: \"nnnn").size(), 1u) << log.text();
  EXPECT_EQ(notes->metrics().send_failures(), 1u);
}

TEST_F(TopicLogTest, TheRateLimitHoldsAndCountsWhatItHeldBack) {
  LogCapture log;
  const std::string name = unique_name("log.fast");
  constexpr int kSends = 3000;
  constexpr double kRate = 4;
  const auto start = std::chrono::steady_clock::now();
  {
    auto pub = horus::Topic<horus::msg::CmdVel>::open(name, verbose(kRate));
    ASSERT_TRUE(pub);
    EXPECT_NE(log.lines("at most 4 lines a second for the topic").size(), 0u) << log.text();
    for (int i = 0; i < kSends; ++i) pub->send(horus::msg::CmdVel::make(0.1f * static_cast<float>(i % 10), 0.0f));
  }  // the topic closes: what was held back after the last line is reported
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto c = horus_test::count_traffic(log, name);
  // A full bucket (one second's lines) at first, then kRate a second.
  EXPECT_GE(c.sends, static_cast<std::uint64_t>(kRate)) << log.text();
  EXPECT_LE(static_cast<double>(c.sends), kRate + seconds * kRate + 1) << log.text();
  // Every send is either a line or counted as held back: in the next line, or at the close.
  EXPECT_EQ(c.closes, 1u) << log.text();
  EXPECT_EQ(c.sends + c.held_in_lines + c.held_at_close, static_cast<std::uint64_t>(kSends)) << log.text();
  EXPECT_EQ(c.held_in_lines + c.held_at_close, c.held_in_all);
}

TEST_F(TopicLogTest, MessagesOfTheirOwnUseTheirOwnSummary) {
  EXPECT_EQ(horus::log_summary(arm::Joints{0.5f, 1.25f}), "Joints(shoulder 0.50 rad, elbow 1.25 rad)");
  EXPECT_EQ(horus::log_summary(arm::Gripper{0.04f}), "Gripper(0.040 m)");
  EXPECT_EQ(horus::log_summary(arm::Plain{1, 2}), "Plain { a: 1, b: 2 }");
  LogCapture log;
  auto joints = horus::Topic<arm::Joints>::open(unique_name("log.joints"), verbose());
  auto gripper = horus::Topic<arm::Gripper>::open(unique_name("log.gripper"), verbose());
  auto plain = horus::Topic<arm::Plain>::open(unique_name("log.plain"), verbose());
  ASSERT_TRUE(joints && gripper && plain);
  joints->send(arm::Joints{0.5f, 1.25f});
  gripper->send(arm::Gripper{0.04f});
  plain->send(arm::Plain{1, 2});
  EXPECT_EQ(log.lines("send #1: Joints(shoulder 0.50 rad, elbow 1.25 rad)").size(), 1u) << log.text();
  EXPECT_EQ(log.lines("send #1: Gripper(0.040 m)").size(), 1u) << log.text();
  EXPECT_EQ(log.lines("send #1: Plain { a: 1, b: 2 }").size(), 1u) << log.text();
}

TEST_F(TopicLogTest, LargeDataLogsItsDescriptionNeverItsBytes) {
  LogCapture log;
  const std::string name = unique_name("log.camera");
  TopicOptions o = verbose();
  o.backend = horus::Backend::SharedMemory;
  auto pub = horus::Topic<horus::msg::Image>::open(name, o);
  auto sub = horus::Topic<horus::msg::Image>::open(name, o);
  ASSERT_TRUE(pub && sub);
  horus::msg::Image img(480, 640, horus::msg::ImageEncoding::Rgb8);
  pub->send(img);
  auto loan = pub->loan(*horus::msg::Image::describe(480, 640, horus::msg::ImageEncoding::Rgb8));
  ASSERT_TRUE(loan);
  pub->send(std::move(*loan));
  ASSERT_TRUE(sub->recv());
  ASSERT_TRUE(sub->recv());
  auto lines = log.lines(name + "' send #");
  const auto recvs = log.lines(name + "' recv #");
  lines.insert(lines.end(), recvs.begin(), recvs.end());
  ASSERT_EQ(lines.size(), 4u) << log.text();
  for (const auto& l : lines) {
    EXPECT_NE(l.find(": Image(640x480 Rgb8"), std::string::npos) << l;
    EXPECT_LT(l.size(), 200u) << l;
  }
  EXPECT_EQ(log.lines("' send #2: Image(").size(), 1u) << log.text();  // the loan
}

TEST_F(TopicLogTest, ReadLatestLogsEachNewerMessageOnce) {
  LogCapture log;
  const std::string name = unique_name("log.latest");
  auto pub = horus::Topic<horus::msg::Pose2D>::open(name, TopicOptions{horus::Backend::InProcess, {}, {}});
  auto reader = horus::Topic<horus::msg::Pose2D>::open(name, verbose());
  ASSERT_TRUE(pub && reader);
  pub->send(horus::msg::Pose2D{1, 0, 0, 0});
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(reader->read_latest());
  pub->send(horus::msg::Pose2D{2, 0, 0, 0});
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(reader->read_latest());
  const auto lines = log.lines("' read_latest: ");
  ASSERT_EQ(lines.size(), 2u) << log.text();
  EXPECT_NE(lines[1].find("Pose2D { x: 2"), std::string::npos) << lines[1];
}

// Lines below the logger's level cost no summary and are not counted as held back; the handle
// says at its opening that they will not show.
TEST_F(TopicLogTest, ALevelTheLoggerHidesIsSaidAtOpeningAndCountsNothing) {
  LogCapture log;
  const std::string name = unique_name("log.hidden");
  TopicOptions o = verbose(1);
  o.log_level = horus::LogLevel::Debug;
  {
    auto pub = horus::Topic<horus::msg::Pose2D>::open(name, o);
    ASSERT_TRUE(pub);
    for (int i = 0; i < 100; ++i) pub->send(horus::msg::Pose2D{});
    const auto warned = log.lines("set HORUS_LOG_LEVEL=debug to see them");
    ASSERT_EQ(warned.size(), 1u) << log.text();
    EXPECT_EQ(warned[0].rfind("warning ", 0), 0u) << warned[0];
  }
  EXPECT_TRUE(log.lines("' send #").empty()) << log.text();
  EXPECT_TRUE(log.lines("held back").empty()) << log.text();

  horus::detail::log().set_level(spdlog::level::debug);
  o.log_level = horus::LogLevel::Warn;
  auto pub = horus::Topic<horus::msg::Pose2D>::open(name, o);
  ASSERT_TRUE(pub);
  pub->send(horus::msg::Pose2D{});
  const auto sends = log.lines("' send #1");
  ASSERT_EQ(sends.size(), 1u) << log.text();
  EXPECT_EQ(sends[0].rfind("warning topic", 0), 0u) << sends[0];
}

TEST_F(TopicLogTest, TheEnvironmentBeatsTheFileAndCodeBeatsBoth) {
  horus_test::TempFile file(
      "topics:\n"
      "  - match: \"robot.**\"\n    log: true\n    log_level: warn\n    log_rate_hz: 0\n"
      "  - match: \"**\"\n    log_rate_hz: 2.5\n");
  auto config = horus::Config::load(file.path);
  ASSERT_TRUE(config) << config.error().message();
  auto c = horus::choose("robot.cmd", {}, &*config);
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->verbose);
  EXPECT_EQ(c->verbose_from, horus::Source::File);
  EXPECT_EQ(horus::verbose_origin(*c), "file " + file.path + ", line 2: rule 'robot.**'");
  EXPECT_EQ(c->log_level, horus::LogLevel::Warn);
  EXPECT_EQ(c->log_rate_hz, 0.0);
  c = horus::choose("misc.thing", {}, &*config);
  ASSERT_TRUE(c);
  EXPECT_FALSE(c->verbose);
  EXPECT_EQ(horus::verbose_origin(*c), "default");
  EXPECT_EQ(c->log_rate_hz, 2.5);

  // The first entry of HORUS_LOG_TOPICS that matches decides, over the file.
  ::setenv("HORUS_LOG_TOPICS", "!robot.cmd, robot.**,misc.*", 1);
  c = horus::choose("robot.cmd", {}, &*config);
  ASSERT_TRUE(c);
  EXPECT_FALSE(c->verbose);
  EXPECT_EQ(horus::verbose_origin(*c), "environment (HORUS_LOG_TOPICS entry '!robot.cmd')");
  c = horus::choose("misc.thing", {}, &*config);
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->verbose);
  EXPECT_EQ(c->verbose_entry, "misc.*");
  c = horus::choose("robot.arm.joints", {}, &*config);
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->verbose);
  EXPECT_EQ(c->verbose_entry, "robot.**");
  EXPECT_EQ(c->log_level, horus::LogLevel::Warn);  // the file's, for what the environment does not say
  TopicOptions code;
  code.verbose = false;
  c = horus::choose("misc.thing", code, &*config);
  ASSERT_TRUE(c);
  EXPECT_FALSE(c->verbose);
  EXPECT_EQ(horus::verbose_origin(*c), "code (TopicOptions::verbose)");

  // A topic opened under them logs, and says why.
  LogCapture log;
  ::setenv("HORUS_CONFIG", file.path.c_str(), 1);
  const std::string name = "robot." + unique_name("env");
  auto pub = horus::Topic<horus::msg::Pose2D>::open(name, TopicOptions{horus::Backend::InProcess, {}, {}});
  ASSERT_TRUE(pub) << pub.error().message();
  pub->send(horus::msg::Pose2D{});
  EXPECT_EQ(log.lines("from environment (HORUS_LOG_TOPICS entry 'robot.**')").size(), 1u) << log.text();
  EXPECT_EQ(log.lines("warning topic '" + name + "' send #1: Pose2D").size(), 1u) << log.text();
}

TEST_F(TopicLogTest, BadSettingsAreRefusedNamingWhatIsWrong) {
  auto empty = horus::log_topics_match("cmd_vel,,odom", "cmd_vel");
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.error().message().find("HORUS_LOG_TOPICS='cmd_vel,,odom': entry 2 is empty"), std::string::npos)
      << empty.error().message();
  auto bad = horus::log_topics_match("cmd_vel,robot/arm", "cmd_vel");  // checked even after a match
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message().find("entry 2 'robot/arm'"), std::string::npos) << bad.error().message();
  EXPECT_NE(bad.error().message().find("expected topic-name patterns separated by commas"), std::string::npos);
  auto none = horus::log_topics_match("odom,!imu", "cmd_vel");
  ASSERT_TRUE(none);
  EXPECT_FALSE(*none);

  ::setenv("HORUS_LOG_TOPICS", "!", 1);
  auto refused = horus::Topic<horus::msg::Pose2D>::open(unique_name("log.env"));
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code(), horus::Errc::Config);
  EXPECT_NE(refused.error().message().find("HORUS_LOG_TOPICS='!': entry 1 is empty"), std::string::npos);
  ::unsetenv("HORUS_LOG_TOPICS");

  auto negative = horus::Topic<horus::msg::Pose2D>::open(unique_name("log.rate"), verbose(-1));
  ASSERT_FALSE(negative);
  EXPECT_EQ(negative.error().code(), horus::Errc::InvalidArgument);
  EXPECT_NE(negative.error().message().find("log_rate_hz -1 is not a rate"), std::string::npos)
      << negative.error().message();

  struct Case {
    const char* rule;
    const char* expected;
  };
  for (const Case& k : {Case{"log: yes", "line 3, key 'topics[0].log': 'yes' is not a boolean"},
                        Case{"log_level: loud", "line 3, key 'topics[0].log_level': unknown level 'loud'; expected trace"},
                        Case{"log_rate_hz: -1", "line 3, key 'topics[0].log_rate_hz': '-1' is not a rate"},
                        Case{"log_rate_hz: fast", "'fast' is not a rate; expected lines per second"}}) {
    auto c = horus::Config::parse(std::string("topics:\n  - match: cmd_vel\n    ") + k.rule + "\n", "robot.yaml");
    ASSERT_FALSE(c) << k.rule;
    EXPECT_NE(c.error().message().find(k.expected), std::string::npos) << c.error().message();
  }
}

TEST_F(TopicLogTest, TheCliExplainsWhetherATopicLogsAndWhy) {
  horus_test::TempFile file("topics:\n  - match: cmd_vel\n    log: true\n    log_level: debug\n    log_rate_hz: 20\n");
  std::string out;
  // `horus config explain TOPIC --file F` with these variables (the others unset); its exit status.
  auto explain = [&](const std::string& env, const std::string& topic) {
    return horus_test::run_command("env -u HORUS_LOG_TOPICS -u HORUS_LOG_LEVEL " + env + " " + HORUS_CLI +
                                       " config explain " + topic + " --file " + file.path,
                                   out);
  };
  ASSERT_EQ(explain("", "cmd_vel"), 0) << out;
  EXPECT_NE(out.find("log         on               file " + file.path + ", line 2: rule 'cmd_vel'"), std::string::npos)
      << out;
  EXPECT_NE(out.find("log_level   debug            file"), std::string::npos) << out;
  EXPECT_NE(out.find("log_rate_hz 20               file"), std::string::npos) << out;
  EXPECT_NE(out.find("(hidden: the library's log level (info, HORUS_LOG_LEVEL) hides debug lines"), std::string::npos)
      << out;  // info: the default
  ASSERT_EQ(explain("", "odom"), 0) << out;
  EXPECT_NE(out.find("log         off              default"), std::string::npos) << out;
  EXPECT_EQ(out.find("log_level"), std::string::npos) << out;
  ASSERT_EQ(explain("HORUS_LOG_LEVEL=info HORUS_LOG_TOPICS='!cmd_vel,odom'", "cmd_vel"), 0) << out;
  EXPECT_NE(out.find("log         off              environment (HORUS_LOG_TOPICS entry '!cmd_vel')"), std::string::npos)
      << out;
  ASSERT_EQ(explain("HORUS_LOG_LEVEL=info HORUS_LOG_TOPICS=odom", "odom"), 0) << out;
  EXPECT_NE(out.find("log         on               environment (HORUS_LOG_TOPICS entry 'odom')"), std::string::npos)
      << out;
  EXPECT_NE(out.find("log_rate_hz 5                default"), std::string::npos) << out;
  ASSERT_EQ(explain("HORUS_LOG_LEVEL=info HORUS_LOG_TOPICS=cmd_vel", "cmd_vel"), 0) << out;
  EXPECT_NE(out.find("(hidden: the library's log level (info, HORUS_LOG_LEVEL) hides debug lines: set "
                     "HORUS_LOG_LEVEL=debug to see them)"),
            std::string::npos)
      << out;
  ASSERT_EQ(explain("HORUS_LOG_LEVEL=debug HORUS_LOG_TOPICS=cmd_vel", "cmd_vel"), 0) << out;
  EXPECT_EQ(out.find("(hidden:"), std::string::npos) << out;
  ASSERT_EQ(horus_test::run_command("HORUS_LOG_TOPICS=cmd/vel " + std::string(HORUS_CLI) + " config explain cmd_vel", out),
            1)
      << out;
  EXPECT_NE(out.find("HORUS_LOG_TOPICS='cmd/vel': entry 1 'cmd/vel'"), std::string::npos) << out;
}

// Another process, told by the environment alone: `horus topic pub` logs what it sends.
TEST_F(TopicLogTest, AProcessLogsTheTopicsTheEnvironmentNames) {
  const std::string name = unique_name("log.cli");
  std::string out;
  ASSERT_EQ(horus_test::run_command("HORUS_BACKEND=inproc HORUS_LOG_TOPICS='test.**' HORUS_LOG_LEVEL=info " +
                                        std::string(HORUS_CLI) + " topic pub " + name +
                                        " CmdVel '{\"linear\": 0.5, \"angular\": 0.25}' --count 3 --rate 100 --wait 0 2>&1",
                                    out),
            0)
      << out;
  EXPECT_NE(out.find("from environment (HORUS_LOG_TOPICS entry 'test.**')"), std::string::npos) << out;
  EXPECT_NE(out.find("topic '" + name + "' send #1: CmdVel { stamp_nanos: 0, linear: 0.5, angular: 0.25 }"), std::string::npos) << out;
  EXPECT_NE(out.find("topic '" + name + "' send #3: CmdVel {"), std::string::npos) << out;
}

}  // namespace

// The egress budget in the configuration file (max_rate_hz, max_bandwidth) and its units;
// deadline and lifespan, and their durations.
#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "horus/config.hpp"

namespace {

TEST(BudgetConfig, BandwidthsParseWithTheirUnitsAndBadOnesSayWhatIsExpected) {
  auto bytes = [](std::string_view s) {
    const auto b = horus::parse_bandwidth(s);
    return std::holds_alternative<std::uint64_t>(b) ? std::get<std::uint64_t>(b) : std::uint64_t{0};
  };
  EXPECT_EQ(bytes("2000000"), 2'000'000u);
  EXPECT_EQ(bytes("2 MB/s"), 2'000'000u);
  EXPECT_EQ(bytes("2MB/s"), 2'000'000u);
  EXPECT_EQ(bytes("1.5 MiB/s"), 1'572'864u);
  EXPECT_EQ(bytes("20 Mbit/s"), 2'500'000u);
  EXPECT_EQ(bytes("512 kbit/s"), 64'000u);
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::string>>{
           {"fast", "is not a bandwidth"}, {"-2 MB/s", "is not a bandwidth"}, {"2 MB", "unknown unit 'MB'"},
           {"0", "is not a bandwidth"}, {"5000 GB/s", "out of range"}}) {
    const auto b = horus::parse_bandwidth(text);
    ASSERT_TRUE(std::holds_alternative<std::string>(b)) << text;
    EXPECT_NE(std::get<std::string>(b).find(expected), std::string::npos) << std::get<std::string>(b);
    EXPECT_NE(std::get<std::string>(b).find("Mbit/s"), std::string::npos) << std::get<std::string>(b);
  }
}

TEST(BudgetConfig, ARuleGivesAFleetTopicItsBudgetAndBadValuesNameTheLineAndKey) {
  auto c = horus::Config::parse(
      "topics:\n  - match: \"camera.**\"\n    scope: fleet\n    backend: lcm\n    max_rate_hz: 2.5\n"
      "    max_bandwidth: \"2 MB/s\"\n",
      "robot.yaml");
  if (!c) GTEST_SKIP() << c.error().message();  // a build without LCM
  auto choice = horus::choose("camera.front", {}, &*c);
  ASSERT_TRUE(choice.has_value()) << choice.error().message();
  EXPECT_EQ(choice->max_rate_hz, 2.5);
  EXPECT_EQ(choice->max_rate_hz_from, horus::Source::File);
  EXPECT_EQ(choice->max_bandwidth, 2'000'000u);
  horus::TopicOptions code;
  code.max_rate_hz = 10;
  auto from_code = horus::choose("camera.front", code, &*c);
  ASSERT_TRUE(from_code.has_value());
  EXPECT_EQ(from_code->max_rate_hz, 10.0);
  EXPECT_EQ(from_code->max_rate_hz_from, horus::Source::Code);
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::vector<std::string>>>{
           {"topics:\n  - match: a\n    scope: fleet\n    backend: lcm\n    max_rate_hz: 0\n",
            {"line 5", "topics[0].max_rate_hz", "a number above 0"}},
           {"topics:\n  - match: a\n    scope: fleet\n    backend: lcm\n    max_bandwidth: lots\n",
            {"line 5", "topics[0].max_bandwidth", "is not a bandwidth"}},
           {"topics:\n  - match: a\n    scope: host\n    max_rate_hz: 5\n",
            {"line 2", "topics[0]", "budgets of the network"}}}) {
    auto bad = horus::Config::parse(text, "robot.yaml");
    ASSERT_FALSE(bad.has_value()) << text;
    for (const auto& e : expected) EXPECT_NE(bad.error().message().find(e), std::string::npos) << bad.error().message();
  }
}

TEST(QosConfig, DurationsParseWithTheirUnitsAndBadOnesSayWhatIsExpected) {
  auto ns = [](std::string_view s) {
    const auto d = horus::parse_duration(s);
    return std::holds_alternative<std::chrono::nanoseconds>(d) ? std::get<std::chrono::nanoseconds>(d).count() : -1;
  };
  EXPECT_EQ(ns("100ms"), 100'000'000);
  EXPECT_EQ(ns("1.5 s"), 1'500'000'000);
  EXPECT_EQ(ns("250us"), 250'000);
  EXPECT_EQ(ns("2min"), 120'000'000'000);
  EXPECT_EQ(ns("1h"), 3'600'000'000'000);
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::string>>{
           {"soon", "is not a duration"}, {"100", "has no unit"}, {"5 d", "unknown unit 'd'"}, {"-1s", "is not a duration"}}) {
    const auto d = horus::parse_duration(text);
    ASSERT_TRUE(std::holds_alternative<std::string>(d)) << text;
    EXPECT_NE(std::get<std::string>(d).find(expected), std::string::npos) << std::get<std::string>(d);
    EXPECT_NE(std::get<std::string>(d).find("ms"), std::string::npos) << std::get<std::string>(d);
  }
}

TEST(QosConfig, ARuleGivesATopicItsDeadlineAndLifespanAndCodeWins) {
  auto c = horus::Config::parse("topics:\n  - match: \"cmd_vel\"\n    deadline: 100ms\n    lifespan: \"0.5 s\"\n",
                                "robot.yaml");
  ASSERT_TRUE(c.has_value()) << c.error().message();
  auto choice = horus::choose("cmd_vel", {}, &*c);
  ASSERT_TRUE(choice.has_value()) << choice.error().message();
  EXPECT_EQ(choice->deadline, std::chrono::milliseconds(100));
  EXPECT_EQ(choice->deadline_from, horus::Source::File);
  EXPECT_EQ(choice->lifespan, std::chrono::milliseconds(500));
  horus::TopicOptions code;
  code.deadline = std::chrono::milliseconds(20);
  choice = horus::choose("cmd_vel", code, &*c);
  ASSERT_TRUE(choice.has_value());
  EXPECT_EQ(choice->deadline, std::chrono::milliseconds(20));
  EXPECT_EQ(choice->deadline_from, horus::Source::Code);
  auto bad = horus::Config::parse("topics:\n  - match: \"cmd_vel\"\n    deadline: fast\n", "robot.yaml");
  ASSERT_FALSE(bad.has_value());
  const std::string why = bad.error().message();
  EXPECT_NE(why.find("robot.yaml, line 3"), std::string::npos) << why;
  EXPECT_NE(why.find("deadline"), std::string::npos) << why;
  EXPECT_NE(why.find("is not a duration"), std::string::npos) << why;
}

}  // namespace

// Unit tests of the diagnostics messages: the enums, NodeHeartbeat, Status / DiagnosticStatus,
// EmergencyStop, SafetyStatus, ResourceUsage, DiagnosticValue, DiagnosticReport (diagnostics.hpp).
#include "msg_diagnostics_test.hpp"

namespace {

// ===========================================================================
// Enums

TEST(DiagnosticEnums, ValuesAndNamesMatchHorus) {
  static_assert(static_cast<int>(StatusLevel::Ok) == 0 && static_cast<int>(StatusLevel::Fatal) == 3);
  static_assert(static_cast<int>(NodeState::Idle) == 0 && static_cast<int>(NodeState::Error) == 5);
  static_assert(static_cast<int>(HealthStatus::Healthy) == 0 && static_cast<int>(HealthStatus::Unknown) == 4);
  EXPECT_EQ(to_string(StatusLevel::Warn), "Warn");
  EXPECT_EQ(to_string(NodeState::Initializing), "Initializing");
  EXPECT_EQ(to_string(HealthStatus::Critical), "Critical");
  EXPECT_EQ(to_string(static_cast<StatusLevel>(9)), "");
}

// ===========================================================================
// NodeHeartbeat

TEST(NodeHeartbeat, FieldTypesFollowTheSpec) {
  static_assert(std::is_same_v<decltype(NodeHeartbeat::tick_count), std::uint32_t>);
  static_assert(std::is_same_v<decltype(NodeHeartbeat::target_rate), float>);
  static_assert(std::is_same_v<decltype(NodeHeartbeat::actual_rate), float>);
  static_assert(std::is_same_v<decltype(NodeHeartbeat::last_tick_timestamp), std::uint64_t>);
  EXPECT_EQ(sizeof(NodeHeartbeat), 40u);
}

TEST(NodeHeartbeat, MakeSetsStateHealthAndBothTimestamps) {
  const NodeHeartbeat hb = NodeHeartbeat::make(NodeState::Running, HealthStatus::Warning, 1'700'000'000);
  EXPECT_EQ(hb.state_enum(), NodeState::Running);
  EXPECT_EQ(hb.health_enum(), HealthStatus::Warning);
  EXPECT_EQ(hb.state, 2u);
  EXPECT_EQ(hb.health, 1u);
  EXPECT_EQ(hb.last_tick_timestamp, 1'700'000'000u);
  EXPECT_EQ(hb.heartbeat_timestamp, 1'700'000'000u);
  EXPECT_EQ(hb.tick_count, 0u);
  EXPECT_EQ(hb.error_count, 0u);
}

TEST(NodeHeartbeat, MakeWithoutATimeUsesEpochSecondsOfTheSystemClock) {
  const auto now = [] {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count());
  };
  const std::uint64_t before = now();
  const NodeHeartbeat hb = NodeHeartbeat::make(NodeState::Idle, HealthStatus::Unknown);
  const std::uint64_t after = now();
  EXPECT_GE(hb.heartbeat_timestamp, before);
  EXPECT_LE(hb.heartbeat_timestamp, after);
  EXPECT_TRUE(hb.is_fresh(5));
}

TEST(NodeHeartbeat, IsFreshUpToMaxAgeAndStaleAfter) {
  const NodeHeartbeat hb = NodeHeartbeat::make(NodeState::Running, HealthStatus::Healthy, 1000);
  EXPECT_TRUE(hb.is_fresh(5, 1000));
  EXPECT_TRUE(hb.is_fresh(5, 1005));
  EXPECT_FALSE(hb.is_fresh(5, 1006));
  EXPECT_FALSE(hb.is_fresh(0, 1001));
  // Stamped in the future (clock skew): fresh, not an unsigned wrap-around.
  EXPECT_TRUE(hb.is_fresh(0, 10));
}

TEST(NodeHeartbeat, UpdateTimestampMovesOnlyTheHeartbeatTime) {
  NodeHeartbeat hb = NodeHeartbeat::make(NodeState::Running, HealthStatus::Healthy, 100);
  hb.update_timestamp(250);
  EXPECT_EQ(hb.heartbeat_timestamp, 250u);
  EXPECT_EQ(hb.last_tick_timestamp, 100u);
  hb.set_state(NodeState::Stopped);
  hb.set_health(HealthStatus::Error);
  EXPECT_EQ(hb.state, 4u);
  EXPECT_EQ(hb.health, 2u);
}

// ===========================================================================
// Status / DiagnosticStatus

TEST(Status, FactoriesSetLevelCodeAndMessage) {
  const Status ok = Status::ok("all good");
  EXPECT_EQ(ok.level_enum(), StatusLevel::Ok);
  EXPECT_EQ(ok.code, 0u);
  EXPECT_EQ(ok.message_str(), "all good");
  EXPECT_EQ(ok.component_str(), "");
  EXPECT_EQ(Status::warn(12, "hot").level, Status::LEVEL_WARN);
  EXPECT_EQ(Status::warn(12, "hot").code, 12u);
  EXPECT_EQ(Status::error(13, "stalled").level, Status::LEVEL_ERROR);
  EXPECT_EQ(Status::fatal(14, "dead").level, Status::LEVEL_FATAL);
  EXPECT_EQ(Status::make(StatusLevel::Error, 7, "x"), *Status::create(StatusLevel::Error, 7, "x"));
}

TEST(Status, LevelConstantsMatchStatusLevel) {
  static_assert(Status::LEVEL_OK == static_cast<std::uint8_t>(StatusLevel::Ok));
  static_assert(Status::LEVEL_WARN == static_cast<std::uint8_t>(StatusLevel::Warn));
  static_assert(Status::LEVEL_ERROR == static_cast<std::uint8_t>(StatusLevel::Error));
  static_assert(Status::LEVEL_FATAL == static_cast<std::uint8_t>(StatusLevel::Fatal));
  Status s{};
  s.set_level(StatusLevel::Fatal);
  EXPECT_EQ(s.level, 3u);
}

TEST(Status, MessageOf127CharactersFitsAnd128IsRefused) {
  const std::string fits(127, 'm');
  const std::string too_long(128, 'm');
  EXPECT_EQ(Status::create(StatusLevel::Warn, 1, fits)->message_str(), fits);
  EXPECT_EQ(Status::create(StatusLevel::Warn, 1, too_long), std::nullopt);
  EXPECT_THROW((void)Status::warn(1, too_long), std::invalid_argument);
  EXPECT_THROW((void)Status::ok(std::string("a\0b", 3)), std::invalid_argument);
  try {
    (void)Status::error(1, too_long);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(std::string_view(e.what()).starts_with("Status message")) << e.what();
    EXPECT_TRUE(contains(e.what(), "128 characters")) << e.what();
    EXPECT_TRUE(contains(e.what(), "at most 127")) << e.what();
  }
  Status s = Status::ok("keep");
  EXPECT_FALSE(s.set_message(too_long));
  EXPECT_EQ(s.message_str(), "keep");
}

TEST(Status, WithComponentSetsTheNameAndRefusesOneThatDoesNotFit) {
  const Status s = Status::warn(3, "low battery").with_component("power");
  EXPECT_EQ(s.component_str(), "power");
  EXPECT_EQ(s.message_str(), "low battery");
  EXPECT_EQ(Status::ok("x").with_component(std::string(31, 'c')).component_str(), std::string(31, 'c'));
  EXPECT_THROW((void)Status::ok("x").with_component(std::string(32, 'c')), std::invalid_argument);
  Status t = s;
  EXPECT_FALSE(t.set_component(std::string(32, 'c')));
  EXPECT_EQ(t.component_str(), "power");
}

TEST(DiagnosticStatus, HasTheFieldsHelpersAndLayoutOfStatusUnderItsOwnName) {
  static_assert(!std::is_same_v<DiagnosticStatus, Status>);
  EXPECT_EQ(horus::type_name<DiagnosticStatus>(), "horus::msg::DiagnosticStatus");
  EXPECT_NE(horus::type_hash<DiagnosticStatus>, horus::type_hash<Status>);
  EXPECT_EQ(sizeof(DiagnosticStatus), sizeof(Status));
  EXPECT_EQ(offsetof(DiagnosticStatus, component), offsetof(Status, component));

  const DiagnosticStatus d = DiagnosticStatus::error(5, "overheat").with_component("motor");
  static_assert(std::is_same_v<decltype(d), const DiagnosticStatus>);
  EXPECT_EQ(d.level_enum(), StatusLevel::Error);
  EXPECT_EQ(d.code, 5u);
  EXPECT_EQ(d.message_str(), "overheat");
  EXPECT_EQ(d.component_str(), "motor");
  EXPECT_EQ(DiagnosticStatus::create(StatusLevel::Fatal, 1, std::string(128, 'x')), std::nullopt);
  // Same bytes as the Status built the same way.
  const Status s = Status::error(5, "overheat").with_component("motor");
  EXPECT_EQ(std::memcmp(&d, &s, sizeof s), 0);
  try {
    (void)DiagnosticStatus::ok(std::string(128, 'x'));
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(std::string_view(e.what()).starts_with("DiagnosticStatus message")) << e.what();
  }
}

TEST(Status, LayoutMatchesHorus) {
  static_assert(std::is_aggregate_v<Status> && std::is_aggregate_v<DiagnosticStatus>);
  EXPECT_EQ(sizeof(Status), 176u);
  EXPECT_EQ(offsetof(Status, code), 4u);
  EXPECT_EQ(offsetof(Status, message), 8u);
  EXPECT_EQ(offsetof(Status, component), 136u);
  EXPECT_EQ(offsetof(Status, timestamp_ns), 168u);
  static_assert(std::tuple_size_v<decltype(Status::message)> == 128);
  static_assert(std::tuple_size_v<decltype(Status::component)> == 32);
}

// ===========================================================================
// EmergencyStop

TEST(EmergencyStop, EngageSetsEngagedAndReason) {
  const EmergencyStop e = EmergencyStop::engage("obstacle in path");
  EXPECT_TRUE(e.is_engaged());
  EXPECT_EQ(e.engaged, 1u);
  EXPECT_EQ(e.reason_str(), "obstacle in path");
  EXPECT_EQ(e.auto_reset, 0u);
  EXPECT_EQ(e.source_str(), "");
  const EmergencyStop s = e.with_source("teleop");
  EXPECT_EQ(s.source_str(), "teleop");
  EXPECT_EQ(s.reason_str(), "obstacle in path");
  EXPECT_TRUE(s.is_engaged());
}

TEST(EmergencyStop, ReleaseClearsTheStop) {
  const EmergencyStop r = EmergencyStop::release();
  EXPECT_FALSE(r.is_engaged());
  EXPECT_EQ(r.engaged, 0u);
  EXPECT_EQ(r.reason_str(), "");
  EXPECT_EQ(r, EmergencyStop{});
}

TEST(EmergencyStop, EngageWithAReasonThatDoesNotFitStillEngagesAndMarksTheCut) {
  const std::string fits(63, 'r');
  EXPECT_EQ(EmergencyStop::engage(fits).reason_str(), fits);

  const std::string long_reason = "lidar reports an obstacle closer than the safety distance of 0.3 m on the left";
  ASSERT_GT(long_reason.size(), 63u);
  const EmergencyStop e = EmergencyStop::engage(long_reason);
  EXPECT_TRUE(e.is_engaged());
  const std::string_view r = e.reason_str();
  EXPECT_EQ(r.size(), 63u);
  EXPECT_EQ(r.substr(60), "...");
  EXPECT_EQ(r.substr(0, 60), std::string_view(long_reason).substr(0, 60));

  // A NUL ends the kept text; the cut is still marked.
  const EmergencyStop n = EmergencyStop::engage(std::string("stop\0now", 8));
  EXPECT_TRUE(n.is_engaged());
  EXPECT_EQ(n.reason_str(), "stop...");

  // Strict setter: refuses and leaves the reason alone.
  EmergencyStop strict = EmergencyStop::engage("short");
  EXPECT_FALSE(strict.set_reason(long_reason));
  EXPECT_EQ(strict.reason_str(), "short");
}

TEST(EmergencyStop, ShortenedTextNeverSplitsAUtf8Character) {
  // 59 ASCII bytes then 3-byte characters: byte 60 falls inside one.
  std::string reason(59, 'a');
  for (int i = 0; i < 5; ++i) reason += "\xE2\x82\xAC";  // U+20AC
  const EmergencyStop e = EmergencyStop::engage(reason);
  EXPECT_EQ(e.reason_str(), std::string(59, 'a') + "...");

  const EmergencyStop s = EmergencyStop::engage("x").with_source(std::string(40, 's'));
  EXPECT_EQ(s.source_str(), std::string(28, 's') + "...");
}

TEST(EmergencyStop, LayoutMatchesHorus) {
  EXPECT_EQ(sizeof(EmergencyStop), 112u);
  EXPECT_EQ(offsetof(EmergencyStop, reason), 1u);
  EXPECT_EQ(offsetof(EmergencyStop, source), 65u);
  EXPECT_EQ(offsetof(EmergencyStop, auto_reset), 97u);
  EXPECT_EQ(offsetof(EmergencyStop, timestamp_ns), 104u);
}

// ===========================================================================
// SafetyStatus

TEST(SafetyStatus, MakeIsSafeAndAllZerosIsNot) {
  const SafetyStatus s = SafetyStatus::make();
  EXPECT_TRUE(s.is_safe());
  EXPECT_EQ(s.mode, SafetyStatus::MODE_NORMAL);
  EXPECT_FALSE(SafetyStatus{}.is_safe());
  EXPECT_EQ(SafetyStatus::MODE_REDUCED, 1u);
  EXPECT_EQ(SafetyStatus::MODE_SAFE_STOP, 2u);
}

TEST(SafetyStatus, AnyBadFlagOrFaultMakesItUnsafe) {
  auto with = [](auto change) {
    SafetyStatus s = SafetyStatus::make();
    change(s);
    return s.is_safe();
  };
  EXPECT_FALSE(with([](SafetyStatus& s) { s.enabled = 0; }));
  EXPECT_FALSE(with([](SafetyStatus& s) { s.estop_engaged = 1; }));
  EXPECT_FALSE(with([](SafetyStatus& s) { s.watchdog_ok = 0; }));
  EXPECT_FALSE(with([](SafetyStatus& s) { s.limits_ok = 0; }));
  EXPECT_FALSE(with([](SafetyStatus& s) { s.comms_ok = 0; }));
  EXPECT_FALSE(with([](SafetyStatus& s) { s.fault_code = 42; }));
  EXPECT_TRUE(with([](SafetyStatus& s) { s.mode = SafetyStatus::MODE_REDUCED; }));
}

TEST(SafetyStatus, SetFaultSwitchesToSafeStopAndClearFaultsRestoresNormal) {
  SafetyStatus s = SafetyStatus::make();
  s.set_fault(17);
  EXPECT_EQ(s.fault_code, 17u);
  EXPECT_EQ(s.mode, SafetyStatus::MODE_SAFE_STOP);
  EXPECT_FALSE(s.is_safe());
  s.set_fault(0);  // clears the code but keeps the mode
  EXPECT_EQ(s.fault_code, 0u);
  EXPECT_EQ(s.mode, SafetyStatus::MODE_SAFE_STOP);
  s.set_fault(3);
  s.clear_faults();
  EXPECT_EQ(s.fault_code, 0u);
  EXPECT_EQ(s.mode, SafetyStatus::MODE_NORMAL);
  EXPECT_TRUE(s.is_safe());
  EXPECT_EQ(sizeof(SafetyStatus), 24u);
}

// ===========================================================================
// ResourceUsage

TEST(ResourceUsage, ThresholdsAreStrictAndNaNIsNeverHigh) {
  ResourceUsage r = ResourceUsage::make();
  EXPECT_EQ(r, ResourceUsage{});
  r.cpu_percent = 80.0f;
  r.memory_percent = 50.0f;
  r.temperature = 70.0f;
  EXPECT_TRUE(r.is_cpu_high(79.9f));
  EXPECT_FALSE(r.is_cpu_high(80.0f));
  EXPECT_TRUE(r.is_memory_high(49.0f));
  EXPECT_FALSE(r.is_memory_high(50.0f));
  EXPECT_TRUE(r.is_temperature_high(65.0f));
  EXPECT_FALSE(r.is_temperature_high(70.0f));
  r.cpu_percent = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(r.is_cpu_high(0.0f));
  EXPECT_EQ(sizeof(ResourceUsage), 72u);
}

// ===========================================================================
// DiagnosticValue

TEST(DiagnosticValue, TypedConstructorsWriteTextAndTypeTag) {
  const auto s = DiagnosticValue::from_string("mode", "auto");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->key_str(), "mode");
  EXPECT_EQ(s->value_str(), "auto");
  EXPECT_EQ(s->value_type, DiagnosticValue::TYPE_STRING);

  const auto i = DiagnosticValue::from_int("rpm", -1200);
  ASSERT_TRUE(i);
  EXPECT_EQ(i->value_str(), "-1200");
  EXPECT_EQ(i->value_type, DiagnosticValue::TYPE_INT);
  EXPECT_EQ(DiagnosticValue::from_int("min", std::numeric_limits<std::int64_t>::min())->value_str(),
            "-9223372036854775808");

  const auto f = DiagnosticValue::from_float("temp", 45.5);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->value_str(), "45.500");
  EXPECT_EQ(f->value_type, DiagnosticValue::TYPE_FLOAT);
  EXPECT_EQ(DiagnosticValue::from_float("t", 1.0 / 3.0)->value_str(), "0.333");
  EXPECT_EQ(DiagnosticValue::from_float("t", kNaN)->value_str(), "NaN");
  EXPECT_EQ(DiagnosticValue::from_float("t", kInf)->value_str(), "inf");
  EXPECT_EQ(DiagnosticValue::from_float("t", -kInf)->value_str(), "-inf");

  const auto b = DiagnosticValue::from_bool("ok", true);
  ASSERT_TRUE(b);
  EXPECT_EQ(b->value_str(), "true");
  EXPECT_EQ(b->value_type, DiagnosticValue::TYPE_BOOL);
  EXPECT_EQ(DiagnosticValue::from_bool("ok", false)->value_str(), "false");
}

TEST(DiagnosticValue, TextThatDoesNotFitIsRefused) {
  EXPECT_TRUE(DiagnosticValue::from_string(std::string(31, 'k'), "v"));
  EXPECT_FALSE(DiagnosticValue::from_string(std::string(32, 'k'), "v"));
  EXPECT_TRUE(DiagnosticValue::from_string("k", std::string(63, 'v')));
  EXPECT_FALSE(DiagnosticValue::from_string("k", std::string(64, 'v')));
  EXPECT_FALSE(DiagnosticValue::from_int(std::string(32, 'k'), 1));
  EXPECT_FALSE(DiagnosticValue::from_bool(std::string(32, 'k'), true));
  // 2^193 has 59 integer digits: 59 + ".000" = 63 characters fit; 2^196 has 60.
  EXPECT_EQ(DiagnosticValue::from_float("big", std::ldexp(1.0, 193))->value_str().size(), 63u);
  EXPECT_FALSE(DiagnosticValue::from_float("big", std::ldexp(1.0, 196)));
  EXPECT_FALSE(DiagnosticValue::from_float("big", -std::ldexp(1.0, 193)));
}

TEST(DiagnosticValue, TypedReadersParseOnlyTheirType) {
  EXPECT_EQ(DiagnosticValue::from_int("n", -42)->as_int(), -42);
  EXPECT_EQ(DiagnosticValue::from_int("n", -42)->as_float(), -42.0);
  EXPECT_EQ(DiagnosticValue::from_float("x", 2.25)->as_float(), 2.25);
  EXPECT_EQ(DiagnosticValue::from_float("x", 2.25)->as_int(), std::nullopt);
  EXPECT_TRUE(std::isnan(*DiagnosticValue::from_float("x", kNaN)->as_float()));
  EXPECT_EQ(DiagnosticValue::from_bool("b", true)->as_bool(), true);
  EXPECT_EQ(DiagnosticValue::from_bool("b", false)->as_bool(), false);
  EXPECT_EQ(DiagnosticValue::from_string("s", "true")->as_bool(), std::nullopt);
  EXPECT_EQ(DiagnosticValue::from_string("s", "12")->as_int(), std::nullopt);
  DiagnosticValue bad = *DiagnosticValue::from_int("n", 1);
  horus::set_fixed_str(bad.value, "12abc");
  EXPECT_EQ(bad.as_int(), std::nullopt);
}

TEST(DiagnosticValue, LayoutMatchesHorus) {
  EXPECT_EQ(sizeof(DiagnosticValue), 97u);
  EXPECT_EQ(alignof(DiagnosticValue), 1u);
  EXPECT_EQ(offsetof(DiagnosticValue, value), 32u);
  EXPECT_EQ(offsetof(DiagnosticValue, value_type), 96u);
}

// ===========================================================================
// DiagnosticReport

TEST(DiagnosticReport, MakeNamesTheComponentAndStartsEmptyAtLevelOk) {
  const DiagnosticReport r = DiagnosticReport::make("motor_left");
  EXPECT_EQ(r.component_str(), "motor_left");
  EXPECT_EQ(r.count(), 0u);
  EXPECT_EQ(r.level_enum(), StatusLevel::Ok);
  EXPECT_EQ(DiagnosticReport::create(std::string(32, 'c')), std::nullopt);
  EXPECT_THROW((void)DiagnosticReport::make(std::string(32, 'c')), std::invalid_argument);
  EXPECT_EQ(DiagnosticReport::create(std::string(31, 'c'))->component_str(), std::string(31, 'c'));
}

TEST(DiagnosticReport, TypedAddsAppendInOrderAndFindLooksUpByKey) {
  DiagnosticReport r = DiagnosticReport::make("driver");
  EXPECT_TRUE(r.add_string("mode", "auto"));
  EXPECT_TRUE(r.add_int("rpm", 1200));
  EXPECT_TRUE(r.add_float("temp_c", 45.5));
  EXPECT_TRUE(r.add_bool("enabled", true));
  EXPECT_EQ(r.count(), 4u);
  EXPECT_EQ(r.values[0].key_str(), "mode");
  EXPECT_EQ(r.values[3].value_str(), "true");
  ASSERT_NE(r.find("temp_c"), nullptr);
  EXPECT_EQ(r.find("temp_c")->as_float(), 45.5);
  EXPECT_EQ(r.find("missing"), nullptr);
  r.set_level(StatusLevel::Warn);
  EXPECT_EQ(r.level, Status::LEVEL_WARN);
}

TEST(DiagnosticReport, IsFullAtSixteenValues) {
  DiagnosticReport r = DiagnosticReport::make("c");
  for (int i = 0; i < 16; ++i) {
    EXPECT_FALSE(r.is_full());
    ASSERT_TRUE(r.add_int(fmt::format("k{}", i), i)) << i;
  }
  EXPECT_TRUE(r.is_full());
  EXPECT_EQ(r.value_count, 16u);
  const DiagnosticReport before = r;
  EXPECT_FALSE(r.add_value(*DiagnosticValue::from_bool("extra", true)));
  EXPECT_FALSE(r.add_string("extra", "x"));
  EXPECT_FALSE(r.add_int("extra", 1));
  EXPECT_FALSE(r.add_float("extra", 1.0));
  EXPECT_FALSE(r.add_bool("extra", true));
  EXPECT_EQ(r, before);
  EXPECT_EQ(r.find("extra"), nullptr);
  EXPECT_EQ(r.values[15].as_int(), 15);
}

TEST(DiagnosticReport, TextThatDoesNotFitIsRefusedWithoutUsingASlot) {
  DiagnosticReport r = DiagnosticReport::make("c");
  EXPECT_FALSE(r.add_string(std::string(32, 'k'), "v"));
  EXPECT_FALSE(r.add_string("k", std::string(64, 'v')));
  EXPECT_FALSE(r.add_float("k", 1e300));
  EXPECT_EQ(r.count(), 0u);
  EXPECT_EQ(r, DiagnosticReport::make("c"));
}

TEST(DiagnosticReport, CorruptValueCountIsClampedToSixteen) {
  DiagnosticReport r = DiagnosticReport::make("c");
  r.value_count = 200;
  EXPECT_EQ(r.count(), 16u);
  EXPECT_TRUE(r.is_full());
  EXPECT_FALSE(r.add_bool("x", true));
  EXPECT_EQ(r.find("x"), nullptr);
  EXPECT_LT(r.log_summary().size(), 200u);
}

TEST(DiagnosticReport, LogSummaryIsShortAndNamesLevelAndValues) {
  DiagnosticReport r = DiagnosticReport::make("motor_left");
  r.set_level(StatusLevel::Warn);
  r.add_float("temp_c", 45.5);
  r.add_int("rpm", 1200);
  r.add_bool("ok", true);
  EXPECT_EQ(r.log_summary(), "DiagnosticReport(motor_left, Warn, 3 values: temp_c=45.500, rpm=1200, ok=true)");
  EXPECT_EQ(DiagnosticReport::make("idle").log_summary(), "DiagnosticReport(idle, Ok, 0 values)");
  r.level = 9;
  EXPECT_TRUE(contains(r.log_summary(), "(motor_left, 9, ")) << r.log_summary();

  DiagnosticReport big = DiagnosticReport::make(std::string(31, 'c'));
  for (int i = 0; i < 16; ++i)
    ASSERT_TRUE(big.add_string(fmt::format("{:c}{}", 'a' + i, std::string(30, 'k')), std::string(63, 'v')));
  const std::string line = big.log_summary();
  EXPECT_LT(line.size(), 200u) << line;
  EXPECT_TRUE(contains(line, "more)")) << line;
}

TEST(DiagnosticReport, LogSummaryCutsLongValuesAtACharacterBoundary) {
  // "a" then 20 euro signs (3 bytes each): byte 24 falls inside the 8th one.
  std::string euros = "a";
  for (int i = 0; i < 20; ++i) euros += "\xE2\x82\xAC";
  // "ab" then 15 robots (4 bytes each): byte 24 falls inside the 6th one.
  std::string robots = "ab";
  for (int i = 0; i < 15; ++i) robots += "\xF0\x9F\xA4\x96";
  // Exactly 24 bytes of 2-byte characters: shown whole, no "...".
  std::string accents;
  for (int i = 0; i < 12; ++i) accents += "\xC3\xA9";

  DiagnosticReport r = DiagnosticReport::make("c");
  ASSERT_TRUE(r.add_string("euro", euros));
  ASSERT_TRUE(r.add_string("bot", robots));
  ASSERT_TRUE(r.add_string("e", accents));
  const std::string line = r.log_summary();
  EXPECT_EQ(detail::generic_utf8_error(line), std::string_view::npos) << "not valid UTF-8: " << line;
  std::string euros7 = "a";
  for (int i = 0; i < 7; ++i) euros7 += "\xE2\x82\xAC";
  std::string robots5 = "ab";
  for (int i = 0; i < 5; ++i) robots5 += "\xF0\x9F\xA4\x96";
  EXPECT_EQ(line, "DiagnosticReport(c, Ok, 3 values: euro=" + euros7 + "..., bot=" + robots5 + "..., e=" + accents + ")");
}

TEST(DiagnosticReport, Utf8PrefixNeverSplitsACharacter) {
  const std::string_view text = "x\xC3\xA9\xE2\x82\xAC";  // x, e-acute (2 bytes), euro (3 bytes)
  EXPECT_EQ(detail::diag_utf8_prefix(text, 100), text);
  EXPECT_EQ(detail::diag_utf8_prefix(text, 6), text);
  EXPECT_EQ(detail::diag_utf8_prefix(text, 5), "x\xC3\xA9");
  EXPECT_EQ(detail::diag_utf8_prefix(text, 4), "x\xC3\xA9");
  EXPECT_EQ(detail::diag_utf8_prefix(text, 3), "x\xC3\xA9");
  EXPECT_EQ(detail::diag_utf8_prefix(text, 2), "x");
  EXPECT_EQ(detail::diag_utf8_prefix(text, 1), "x");
  EXPECT_EQ(detail::diag_utf8_prefix(text, 0), "");
  EXPECT_EQ(detail::diag_utf8_prefix("", 0), "");
  EXPECT_EQ(detail::diag_utf8_prefix("plain ascii", 5), "plain");
}

TEST(DiagnosticReport, LayoutMatchesHorus) {
  EXPECT_EQ(sizeof(DiagnosticReport), 1600u);
  EXPECT_EQ(offsetof(DiagnosticReport, values), 32u);
  EXPECT_EQ(offsetof(DiagnosticReport, value_count), 1584u);
  EXPECT_EQ(offsetof(DiagnosticReport, level), 1585u);
  EXPECT_EQ(offsetof(DiagnosticReport, timestamp_ns), 1592u);
  static_assert(std::tuple_size_v<decltype(DiagnosticReport::values)> == 16);
}

}  // namespace

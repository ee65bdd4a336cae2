// A topic's settings, declared once.
//
// HORUS_TOPIC_SETTINGS is the one list of the per-topic settings. From it come TopicOptions (what
// code chooses), the configuration file's rule keys, their parsing and errors, the choice by
// precedence (horus/config.hpp: TopicRule, TopicChoice, choose, options_of), `horus config
// explain`, `horus config settings` (the table in README.md, checked by a test), Python's keyword
// arguments and horus.config.explain. A new setting of the usual kind (code > file > default) is
// one line here plus the code that acts on it.
//
// Each entry: X(member, Kind, Rule, file_key, example, default_value, unset_text, doc)
//   member         the name in TopicOptions, TopicRule and TopicChoice (TopicChoice::<member>_from)
//   Kind           how its value is written and read (horus::setting, below)
//   Rule           Plain: code > file > default, all made from the table;
//                  Special: its own precedence, written by hand in config.cpp (backend: code >
//                  HORUS_BACKEND > the rule's scope and backend; verbose: code > HORUS_LOG_TOPICS
//                  > the rule's `log:`); CodeOnly: code only, no file key
//   file_key       its key in a rule of the file's `topics:` list ("" for CodeOnly)
//   example        a value in the file's form (README's table; the test parses it)
//   default_value  what an unset value means, when that is one value (else std::nullopt)
//   unset_text     what `horus config explain` says of an unset value without one
//   doc            one line for README's table
//
// What some settings mean in full:
// - deadline: the period a topic's messages must keep. A receiving handle counts each full period
//   without a message (the requested deadline: a watchdog on cmd_vel), a sending one each full
//   period between its own sends (the offered deadline): deadline_missed_count(), and
//   Executor::on_deadline_missed calls back at once. Mapped to the DDS QoS of the same name.
// - lifespan: a message whose timestamp_ns (Unix ns, as the publisher set it) is older than this
//   on receipt is not delivered; counted in expired_count() and dropped_count(). Messages without
//   a timestamp_ns (or with 0) never expire.
// - max_rate_hz, max_bandwidth (fleet topics): the host's egress budget. The bridge sends at most
//   that many messages and bytes a second (a token bucket); when over budget the newest message
//   waits for its turn and older ones are not sent (counted per topic: `horus topic info`,
//   "budget dropped"). Local handles are not affected.
// - priority (fleet topics): the topic's share of the host's link budget (network.max_bandwidth
//   in the file, shared by every process of the host). High always goes (and uses the link);
//   Normal goes while what the host sent stays within 50 ms of the link's rate; Low within 10 ms,
//   so that it leaves the link's last bytes to the others. The fleet's own heartbeats and
//   announcements are High.
// - verbose (traffic logging, off by default): each send and receive of the handle logs a line
//   through the library's logger: the direction, the topic, the handle's count, the drops so far
//   and the message's horus::log_summary() (large data: its description, never its bytes). At
//   log_level, at most log_rate_hz lines a second for the topic in this process (0: every
//   message); the next line logged says how many were held back.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "horus/backend.hpp"
#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// A topic's mapping onto the ROS 2 graph (the `ros2:` key; docs/ROS2.md): on the network the
/// topic is what a ROS 2 node publishes, `rt/<name>` of the ROS 2 type, while its subscribers on
/// the host stay in shared memory. A fleet topic on Cyclone DDS or Fast DDS.
struct Ros2Mapping {
  /// The QoS a mapped topic gets: its own settings (reliability, durability, the type's
  /// defaults), ROS 2's default profile (reliable, volatile, keep last 10) or its sensor data
  /// profile (best effort, volatile, keep last 5). A reliability or durability set for the
  /// topic wins over a profile.
  enum class Qos : std::uint8_t { Topic, Default, SensorData };
  bool enabled = true;         // `ros2: false` turns a mapping of a broader rule off
  std::string name;            // "/cmd_vel"; empty: "/" + the horus name with '.' as '/'
  std::string type;            // "geometry_msgs/msg/Twist"; empty: the message type's preferred one
  std::string frame_id;        // header.frame_id for a message type without a frame id field
  std::string child_frame_id;  // child_frame_id likewise (TransformStamped, Odometry)
  Qos qos = Qos::Topic;
  friend bool operator==(const Ros2Mapping&, const Ros2Mapping&) = default;
};

/// The kinds of value a per-topic setting has: the C++ type, and how the file, Python and
/// `horus config explain` write it (horus/config.hpp: setting::parse, setting::format).
namespace setting {
struct BackendName { using type = Backend; };                   // a scope and a transport
struct PowerOfTwo { using type = std::uint32_t; };              // 1..shm::kMaxCapacity
struct ByteCount { using type = std::size_t; };                 // bytes
struct ReliabilityName { using type = net::Reliability; };      // best_effort | reliable
struct DurabilityName { using type = net::Durability; };        // volatile | transient_local
struct PositiveRate { using type = double; };                   // per second, above 0
struct RateOrZero { using type = double; };                     // per second, 0 allowed
struct Bandwidth { using type = std::uint64_t; };               // bytes per second ("2 MB/s")
struct PriorityName { using type = Priority; };                 // low | normal | high
struct Duration { using type = std::chrono::nanoseconds; };     // above 0 ("100ms", "1.5 s")
struct Boolean { using type = bool; };                          // true | false
struct LevelName { using type = LogLevel; };                    // trace | debug | info | warn | error
struct Ros2 { using type = Ros2Mapping; };                      // true | false | {name: ..., type: ...}
}  // namespace setting

// clang-format off
#define HORUS_TOPIC_SETTINGS(X)                                                                                       \
  X(backend, BackendName, Special, "backend", "lcm", std::nullopt, "shm",                                            \
    "the scope and, for fleet topics, the network transport: in code a Backend, in the environment HORUS_BACKEND, "   \
    "in the file `scope:` (process, host, fleet) and `backend:` (cyclonedds, fastdds, lcm); default shared memory")   \
  X(capacity, PowerOfTwo, Plain, "capacity", "64", std::nullopt, "type default",                                      \
    "slots per publisher, a power of two; default by message size (16-1024, 4 for messages of 1 MiB or more)")       \
  X(slot_size, ByteCount, CodeOnly, "", "", std::nullopt, "type default",                                             \
    "serialized messages: the largest encoded message; large data: the largest message's bytes (a pool slot)")       \
  X(reliability, ReliabilityName, Plain, "reliability", "reliable", std::nullopt, "type default",                     \
    "network backends: best_effort or reliable; default the message type's (horus/qos.hpp)")                         \
  X(durability, DurabilityName, Plain, "durability", "transient_local", std::nullopt, "type default",                 \
    "network backends: volatile or transient_local (late joiners get the last messages); default the type's")        \
  X(max_rate_hz, PositiveRate, Plain, "max_rate_hz", "5", std::nullopt, "none",                                      \
    "messages per second the host's bridge sends at most, a number above 0 (such as 5 or 0.5)")                      \
  X(max_bandwidth, Bandwidth, Plain, "max_bandwidth", "\"2 MB/s\"", std::nullopt, "none",                            \
    "fleet topics: bytes a second the host's bridge sends at most (B/s, kB/s, MB/s, MiB/s, Mbit/s, ...)")            \
  X(priority, PriorityName, Plain, "priority", "high", Priority::Normal, "",                                          \
    "fleet topics: the topic's share of the host's link budget (network.max_bandwidth): high, normal or low")        \
  X(deadline, Duration, Plain, "deadline", "100ms", std::nullopt, "none",                                             \
    "the period messages must keep: each one without a message counts (deadline_missed_count)")                      \
  X(lifespan, Duration, Plain, "lifespan", "300ms", std::nullopt, "none",                                             \
    "a message older than this on receipt (its timestamp_ns) is not delivered (expired_count)")                      \
  X(verbose, Boolean, Special, "log", "true", false, "",                                                               \
    "log each send and receive of the topic (in code `verbose`; HORUS_LOG_TOPICS=PATTERN,... in the environment)")  \
  X(log_level, LevelName, Plain, "log_level", "debug", LogLevel::Info, "",                                            \
    "the level of the topic's traffic lines: trace, debug, info, warn or error")                                     \
  X(log_rate_hz, RateOrZero, Plain, "log_rate_hz", "5", kDefaultLogRateHz, "",                                        \
    "lines per second the topic logs at most, a number such as 5 or 0.5 (0: every message)")                         \
  X(ros2, Ros2, Plain, "ros2", "{name: /cmd_vel, type: geometry_msgs/msg/Twist}", std::nullopt, "none",                \
    "the topic on the ROS 2 graph (a fleet topic on DDS): true, or a map of name, type, frame_id, child_frame_id and "  \
    "qos (default, sensor_data); docs/ROS2.md")
// clang-format on

// Helpers for code made from the table: HORUS_SETTING_IF_<Rule>(text) keeps `text` for one rule.
#define HORUS_SETTING_IF_PLAIN_Plain(...) __VA_ARGS__
#define HORUS_SETTING_IF_PLAIN_Special(...)
#define HORUS_SETTING_IF_PLAIN_CodeOnly(...)
#define HORUS_SETTING_IF_IN_FILE_Plain(...) __VA_ARGS__
#define HORUS_SETTING_IF_IN_FILE_Special(...) __VA_ARGS__
#define HORUS_SETTING_IF_IN_FILE_CodeOnly(...)

/// Per-topic choices made in code (they take precedence over the environment and the file); one
/// member per entry of HORUS_TOPIC_SETTINGS, in its order, each unset by default.
struct TopicOptions {
#define HORUS_TOPIC_OPTION(member, Kind, Rule, key, example, dflt, unset, doc) \
  std::optional<setting::Kind::type> member = std::nullopt;
  HORUS_TOPIC_SETTINGS(HORUS_TOPIC_OPTION)
#undef HORUS_TOPIC_OPTION
};

}  // namespace horus

HORUS_API_END

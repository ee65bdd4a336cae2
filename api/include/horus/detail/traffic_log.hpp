// A verbose topic's traffic log (TopicOptions::verbose; horus/topic.hpp): the line a send or a
// receive of a verbose handle writes through the library's logger, under the topic's limit on
// lines (TopicCore::traffic). A handle that is not verbose never calls any of this: its only
// cost is the test of Watch::active() that deadline and lifespan already make.
// Internal to horus: users include <horus/topic.hpp>.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "horus/detail/topic_core.hpp"
#include "horus/error.hpp"
#include "horus/format.hpp"  // horus::log_summary (messages of the user's own)
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {
struct TopicChoice;  // horus/config.hpp
}  // namespace horus

namespace horus::detail {

/// What a traffic line reports.
enum class Traffic : std::uint8_t {
  Send,     // a message sent (send #N: the handle's messages sent so far)
  Refused,  // a send that was refused (too large, no lane): counted in send_failures
  Recv,     // a message received (recv #N: the handle's messages received so far)
  Latest,   // read_latest() returned a message newer than the last one it logged
};

/// The settings a handle opening with `choice` logs with, once checked (a log_rate_hz below 0
/// or not a number is Errc::InvalidArgument); logs that the handle logs its traffic, at what
/// level and rate and why (verbose_origin), and warns when HORUS_LOG_LEVEL hides its lines.
Result<TrafficLogSettings> start_traffic_log(const TopicCore& core, const TopicChoice& choice);
/// Whether a line is written now: the logger takes the level and the topic's limit admits it.
/// Nothing when not (counted as held back when the limit refused it); else how many lines the
/// limit held back before this one.
std::optional<std::uint64_t> admit_traffic(TopicCore& core, const TrafficLogSettings& s) noexcept;
/// Writes a line: "topic 'NAME' send #N: SUMMARY", with what was dropped and held back.
void write_traffic(const TopicCore& core, const TrafficLogSettings& s, Traffic what, std::uint64_t count,
                   std::uint64_t dropped, std::uint64_t held, std::string_view summary) noexcept;
/// At the topic's close in this process: how many lines were held back after the last one.
void report_held_traffic(const TopicCore& core) noexcept;

/// horus::log_summary of the standard message with this type hash, compiled once in the library
/// (api/src/standard_types*.cpp: the StandardType tables); nothing for another hash.
std::optional<std::string> standard_summary(std::uint64_t type_hash, const void* msg);

/// The summary a traffic line shows: horus::log_summary(m) (the message's own overload or
/// log_summary() member, else its fields); the library's copy for a standard message, so that a
/// node's file does not instantiate the text of every message it uses.
template <class T>
std::string traffic_summary(const T& m) {
  if constexpr (reflect::StandardMessage<T>) {
    if (auto s = standard_summary(type_hash<T>, &m)) return std::move(*s);
    return std::string(type_name<T>());  // a library of another version than these headers
  } else {
    return horus::log_summary(m);
  }
}

}  // namespace horus::detail

HORUS_API_END

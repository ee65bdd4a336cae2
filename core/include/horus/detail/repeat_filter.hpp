// Diagnostics that repeat (a transport that fails to send every second while a link is down):
// the first line of a kind is logged, its repeats are counted, not printed, and the kind is
// logged again (with how many were held back) once it has been quiet for a while. Private to
// horus: the transports' log sinks use it (Cyclone DDS's log, Fast DDS's consumers, LCM).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

#include <spdlog/common.h>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::detail {

class RepeatFilter {
 public:
  using Clock = std::chrono::steady_clock;
  /// A kind that stays quiet this long is logged again when it comes back.
  explicit RepeatFilter(Clock::duration quiet = std::chrono::seconds(30), std::size_t max_kinds = 64) noexcept
      : quiet_(quiet), max_kinds_(max_kinds) {}

  /// The kind of a line: its text with every run of digits replaced by '#', so that ports,
  /// addresses, counts and times do not make a repeat look new.
  static std::string kind_of(std::string_view text);

  /// Whether a line of this kind is logged now: nothing for a repeat held back; otherwise how
  /// many lines of this kind were held back before it (0 the first time).
  std::optional<std::uint64_t> admit(std::string_view kind, Clock::time_point now = Clock::now());

 private:
  struct Seen {
    std::uint64_t held = 0;
    Clock::time_point last{};
  };
  std::mutex mutex_;
  std::unordered_map<std::string, Seen> seen_;
  Clock::duration quiet_;
  std::size_t max_kinds_;
};

/// Logs a transport library's own line through the library's logger ("[source] text", at
/// `level`), unless it repeats a line of the same kind (RepeatFilter, one per process). Lines
/// that come once the process has begun to exit are dropped: a transport's threads outlive the
/// library's statics (Fast DDS's participant factory logs from its log thread while the exit
/// handlers run, after the logger's sinks were destroyed).
void log_transport_line(spdlog::level::level_enum level, std::string_view source, std::string_view text);

/// Call before a transport library may call log_transport_line from its own threads (where it
/// installs its log routing): the logger is made, and the exit handler that closes
/// log_transport_line is registered after it, so it runs before the logger is destroyed.
void open_transport_log();

}  // namespace horus::detail

HORUS_API_END

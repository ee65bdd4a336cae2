// Verbose topics (horus/detail/traffic_log.hpp): HORUS_LOG_TOPICS, the per-topic limit on lines
// and the lines themselves, through the library's logger.
#include "horus/detail/traffic_log.hpp"

#include <fmt/format.h>

#include <time.h>

#include <algorithm>
#include <cmath>
#include <mutex>

#include "horus/config.hpp"
#include "horus/log.hpp"
#include "horus/names.hpp"

namespace horus {

Result<std::optional<LogTopicsEntry>> log_topics_match(std::string_view value, std::string_view topic) {
  constexpr std::string_view kExpected =
      "expected topic-name patterns separated by commas, such as \"cmd_vel,fleet.**\" ('*' is one segment, '**' any "
      "number; '!pattern' turns logging off)";
  std::optional<LogTopicsEntry> found;
  std::size_t index = 0;
  for (std::size_t start = 0; start <= value.size(); ++index) {
    std::size_t end = value.find(',', start);
    if (end == std::string_view::npos) end = value.size();
    std::string_view entry = value.substr(start, end - start);
    start = end + 1;
    while (!entry.empty() && entry.front() == ' ') entry.remove_prefix(1);
    while (!entry.empty() && entry.back() == ' ') entry.remove_suffix(1);
    const bool off = !entry.empty() && entry.front() == '!';
    const std::string_view pattern = off ? entry.substr(1) : entry;
    if (pattern.empty())
      return fail(Errc::Config, fmt::format("HORUS_LOG_TOPICS='{}': entry {} is empty; {}", value, index + 1, kExpected));
    if (auto ok = check_topic_pattern(pattern); !ok)
      return fail(Errc::Config, fmt::format("HORUS_LOG_TOPICS='{}': entry {} '{}': {}; {}", value, index + 1, entry,
                                            ok.error().message(), kExpected));
    // Every entry is checked, so that a typo is an error whatever the topic.
    if (!found && topic_pattern_matches(pattern, topic)) found = LogTopicsEntry{!off, std::string(entry)};
  }
  return found;
}

std::string verbose_origin(const TopicChoice& c) {
  switch (c.verbose_from) {
    case Source::Code: return "code (TopicOptions::verbose)";
    case Source::Environment: return fmt::format("environment (HORUS_LOG_TOPICS entry '{}')", c.verbose_entry);
    case Source::File:
      if (c.rule != nullptr && c.config != nullptr)
        return fmt::format("file {}, line {}: rule '{}'", c.config->file(), c.rule->line, c.rule->match);
      return "file";
    case Source::Default: break;
  }
  return "default";
}

namespace detail {

std::optional<std::uint64_t> TrafficLimiter::admit(const TrafficLogSettings& s, std::int64_t now_ns) noexcept {
  if (s.rate_hz > 0 && now_ns < empty_until_.load(std::memory_order_relaxed)) {
    held_.fetch_add(1, std::memory_order_relaxed);
    return std::nullopt;
  }
  std::lock_guard lock(mutex_);
  last_ = s;
  if (s.rate_hz > 0) {
    const double burst = std::max(1.0, s.rate_hz);  // one second's lines
    if (tokens_ < 0) tokens_ = burst;
    else if (now_ns > last_ns_) tokens_ = std::min(burst, tokens_ + static_cast<double>(now_ns - last_ns_) * 1e-9 * s.rate_hz);
    last_ns_ = std::max(last_ns_, now_ns);
    const bool admitted = tokens_ >= 1;
    if (admitted) tokens_ -= 1;
    // When the bucket has a line again: until then, lines are held back without the lock.
    const double wait_ns = tokens_ >= 1 ? 0 : std::min(1e15, (1 - tokens_) / s.rate_hz * 1e9);  // a tiny rate: 11 days
    empty_until_.store(last_ns_ + static_cast<std::int64_t>(wait_ns), std::memory_order_relaxed);
    if (!admitted) {
      held_.fetch_add(1, std::memory_order_relaxed);
      return std::nullopt;
    }
  }
  const std::uint64_t held = held_.exchange(0, std::memory_order_relaxed);
  held_reported_ += held;
  return held;
}

std::uint64_t TrafficLimiter::held_total() const noexcept {
  std::lock_guard lock(mutex_);
  return held_reported_ + held_.load(std::memory_order_relaxed);
}

TrafficLogSettings TrafficLimiter::last_settings() const noexcept {
  std::lock_guard lock(mutex_);
  return last_;
}

namespace {

spdlog::level::level_enum spd(LogLevel l) { return static_cast<spdlog::level::level_enum>(l); }

std::string rate_words(double hz) {
  return hz > 0 ? fmt::format("at most {:g} line{} a second for the topic", hz, hz == 1 ? "" : "s")
                : std::string("every message (log_rate_hz 0)");
}

}  // namespace

Result<TrafficLogSettings> start_traffic_log(const TopicCore& core, const TopicChoice& choice) {
  TrafficLogSettings s;
  if (choice.log_level) s.level = *choice.log_level;
  if (choice.log_rate_hz) {
    const double hz = *choice.log_rate_hz;
    if (!(hz >= 0) || !std::isfinite(hz))
      return fail(Errc::InvalidArgument,
                  fmt::format("topic '{}': log_rate_hz {} is not a rate; expected lines per second above 0, or 0 to log "
                              "every message",
                              core.name, hz));
    s.rate_hz = hz;
  }
  auto& log = detail::log();
  const std::string what = fmt::format("topic '{}' ({}): this handle logs its sends and receives at {}, {}; from {}",
                                       core.name, core.type_name, to_string(s.level), rate_words(s.rate_hz),
                                       verbose_origin(choice));
  if (const std::string hidden = hidden_lines(spd(s.level)); hidden.empty())
    log.log(std::max(spd(s.level), spdlog::level::info), "{}", what);
  else
    log.warn("{}; but {}", what, hidden);
  return s;
}

std::optional<std::uint64_t> admit_traffic(TopicCore& core, const TrafficLogSettings& s) noexcept {
  if (!log().should_log(spd(s.level))) return std::nullopt;
  // The coarse clock (a few ns instead of some 20; ticks of 1 to 4 ms) is enough for lines a
  // second: a held-back line then costs little more than its count.
  ::timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC_COARSE, &ts);
  return core.traffic.admit(s, static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec);
}

void write_traffic(const TopicCore& core, const TrafficLogSettings& s, Traffic what, std::uint64_t count,
                   std::uint64_t dropped, std::uint64_t held, std::string_view summary) noexcept {
  try {
    std::string line;
    switch (what) {
      case Traffic::Send: line = fmt::format("topic '{}' send #{}: {}", core.name, count, summary); break;
      case Traffic::Refused: line = fmt::format("topic '{}' send refused ({} so far): {}", core.name, count, summary); break;
      case Traffic::Recv: line = fmt::format("topic '{}' recv #{}: {}", core.name, count, summary); break;
      case Traffic::Latest: line = fmt::format("topic '{}' read_latest: {}", core.name, summary); break;
    }
    const bool drops = dropped != 0 && (what == Traffic::Recv || what == Traffic::Latest);
    if (drops || held != 0) {
      line += " (";
      if (drops) line += fmt::format("{} dropped so far", dropped);
      if (drops && held != 0) line += "; ";
      if (held != 0)
        line += fmt::format("{} line{} held back before this one by log_rate_hz {:g}", held, held == 1 ? "" : "s",
                            s.rate_hz);
      line += ")";
    }
    log().log(spd(s.level), "{}", line);
  } catch (...) {  // a summary or a line that cannot be made: the message itself went on
  }
}

void report_held_traffic(const TopicCore& core) noexcept {
  try {
    const std::uint64_t held = core.traffic.held();
    if (held == 0) return;
    const TrafficLogSettings s = core.traffic.last_settings();
    log().log(spd(s.level), "topic '{}': {} line{} of its traffic held back after the last one by log_rate_hz {:g} "
              "({} in all)",
              core.name, held, held == 1 ? "" : "s", s.rate_hz, core.traffic.held_total());
  } catch (...) {
  }
}

}  // namespace detail
}  // namespace horus

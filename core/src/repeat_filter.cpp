#include "horus/detail/repeat_filter.hpp"

#include <algorithm>
#include <utility>

#include "horus/log.hpp"

namespace horus::detail {

std::string RepeatFilter::kind_of(std::string_view text) {
  std::string kind;
  kind.reserve(text.size());
  bool digits = false;
  for (const char c : text) {
    const bool digit = c >= '0' && c <= '9';
    if (digit && !digits) kind.push_back('#');
    if (!digit) kind.push_back(c);
    digits = digit;
  }
  return kind;
}

std::optional<std::uint64_t> RepeatFilter::admit(std::string_view kind, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  auto it = seen_.find(std::string(kind));
  if (it == seen_.end()) {
    if (seen_.size() >= max_kinds_) {  // forget the kind quiet for the longest time
      auto oldest = std::min_element(seen_.begin(), seen_.end(),
                                     [](const auto& a, const auto& b) { return a.second.last < b.second.last; });
      seen_.erase(oldest);
    }
    seen_.emplace(std::string(kind), Seen{0, now});
    return 0;
  }
  Seen& s = it->second;
  const bool quiet = now - s.last >= quiet_;
  s.last = now;
  if (!quiet) {
    ++s.held;
    return std::nullopt;
  }
  return std::exchange(s.held, 0);
}

void log_transport_line(spdlog::level::level_enum level, std::string_view source, std::string_view text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.remove_suffix(1);
  if (text.empty() || !log().should_log(level)) return;
  static RepeatFilter filter;
  const auto held = filter.admit(RepeatFilter::kind_of(text));
  if (!held) return;
  if (*held == 0)
    log().log(level, "[{}] {} (repeats of this line are not shown)", source, text);
  else
    log().log(level, "[{}] {} ({} like it were held back since it was last shown)", source, text, *held);
}

}  // namespace horus::detail

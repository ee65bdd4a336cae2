#include "horus/detail/repeat_filter.hpp"

#include <algorithm>
#include <cstdlib>
#include <mutex>
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

namespace {
// What log_transport_line uses, never destroyed: a transport's thread may call it while the
// process's statics are destroyed. Closed (under its mutex) by an exit handler registered after
// the logger was made, so it runs before the logger goes.
struct TransportLog {
  std::mutex mutex;
  bool closed = false;
  RepeatFilter filter;
};
TransportLog& transport_log() {
  static TransportLog* const t = [] {
    (void)log();  // the logger first: the handler below runs before its destruction
    auto* made = new TransportLog;
    std::atexit([] {
      std::lock_guard lock(transport_log().mutex);
      transport_log().closed = true;
    });
    return made;
  }();
  return *t;
}
}  // namespace

void open_transport_log() { (void)transport_log(); }

void log_transport_line(spdlog::level::level_enum level, std::string_view source, std::string_view text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.remove_suffix(1);
  if (text.empty()) return;
  TransportLog& t = transport_log();
  std::lock_guard lock(t.mutex);  // the exit handler waits for a line in progress
  if (t.closed || !log().should_log(level)) return;
  const auto held = t.filter.admit(RepeatFilter::kind_of(text));
  if (!held) return;
  if (*held == 0)
    log().log(level, "[{}] {} (repeats of this line are not shown)", source, text);
  else
    log().log(level, "[{}] {} ({} like it were held back since it was last shown)", source, text, *held);
}

}  // namespace horus::detail

#include "horus/detail/repeat_filter.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <thread>
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
// process's statics are destroyed. Closed by an exit handler registered after the logger was
// made (so it runs before the logger goes), which then waits for the lines in progress. No lock
// is held across a write: a process that forks while a transport thread writes (spdlog's fork
// handler holds its console lock meanwhile) leaves the child a count, not a held mutex, and the
// child's exit waits for it kExitWait at most.
constexpr auto kExitWait = std::chrono::milliseconds(200);
struct TransportLog {
  std::atomic<bool> closed{false};
  std::atomic<std::uint32_t> writing{0};  // lines between their check of `closed` and their end
  RepeatFilter filter;
};
TransportLog& transport_log() {
  static TransportLog* const t = [] {
    (void)log();  // the logger first: the handler below runs before its destruction
    auto* made = new TransportLog;
    std::atexit([] {
      TransportLog& tl = transport_log();
      tl.closed.store(true, std::memory_order_seq_cst);
      const auto until = std::chrono::steady_clock::now() + kExitWait;
      while (tl.writing.load(std::memory_order_seq_cst) != 0 && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
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
  // Counted before closed is read (both sequentially consistent, as in the handler): either the
  // handler sees this line and waits for it, or this line sees closed and leaves.
  t.writing.fetch_add(1, std::memory_order_seq_cst);
  struct Done {
    TransportLog& t;
    ~Done() { t.writing.fetch_sub(1, std::memory_order_seq_cst); }
  } done{t};
  if (t.closed.load(std::memory_order_seq_cst) || !log().should_log(level)) return;
  const auto held = t.filter.admit(RepeatFilter::kind_of(text));
  if (!held) return;
  if (*held == 0)
    log().log(level, "[{}] {} (repeats of this line are not shown)", source, text);
  else
    log().log(level, "[{}] {} ({} like it were held back since it was last shown)", source, text, *held);
}

}  // namespace horus::detail

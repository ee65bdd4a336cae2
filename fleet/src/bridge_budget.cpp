// The egress budget of a fleet topic's bridge (TopicOptions::max_rate_hz, max_bandwidth): the
// budget itself and what it counts. Sending what it held back is Bridge::flush_latest
// (bridge.cpp), with the rest of the export.
#include <algorithm>
#include <string>

#include <fmt/format.h>

#include "bridge.hpp"
#include "engine.hpp"
#include "horus/config.hpp"
#include "horus/log.hpp"

namespace horus::fleet::detail {

using horus::detail::log;

void Bridge::set_budget(const TopicOptions& options, const Config* file) noexcept {
  if (options.max_rate_hz && *options.max_rate_hz > 0)
    budget_.min_interval_ns = static_cast<std::int64_t>(1e9 / *options.max_rate_hz);
  if (options.max_bandwidth && *options.max_bandwidth > 0)
    budget_.bytes_per_ns = static_cast<double>(*options.max_bandwidth) / 1e9;
  priority_ = options.priority.value_or(Priority::Normal);
  // The host's link budget: how long the link may stay busy with what the host's bridges sent
  // (beyond now) for this topic to go too. High always goes; Low keeps the last 40 ms for the
  // others.
  if (file != nullptr) {
    if (const auto& link = file->network().max_bandwidth; link && *link > 0) {
      link_ns_per_byte_ = 1e9 / static_cast<double>(*link);
      link_tolerance_ns_ = priority_ == Priority::High  ? INT64_MAX
                           : priority_ == Priority::Low ? kLinkLowTolerance.count()
                                                        : kLinkTolerance.count();
    }
  }
}

bool Bridge::admit(std::int64_t now, std::size_t bytes) noexcept {
  if (!budget_.allows(now, bytes)) return false;
  if (link_ns_per_byte_ > 0 && !engine_->admit_link(bytes, link_ns_per_byte_, link_tolerance_ns_)) return false;
  budget_.spend(now, bytes);
  return true;
}

// A token bucket of 100 ms of bandwidth (at least the message: a message larger than that goes
// when the bucket is full), and at most one message per min_interval.
bool Bridge::Budget::allows(std::int64_t now, std::size_t bytes) noexcept {
  if (min_interval_ns > 0 && any_sent && now - last_sent_ns < min_interval_ns) return false;
  if (bytes_per_ns > 0) {
    const double size = static_cast<double>(bytes);
    const double capacity = std::max(bytes_per_ns * 1e8, size);
    tokens = filled_ns == 0 ? capacity : std::min(capacity, tokens + static_cast<double>(now - filled_ns) * bytes_per_ns);
    filled_ns = now;
    if (tokens < size) return false;
  }
  return true;
}

void Bridge::Budget::spend(std::int64_t now, std::size_t bytes) noexcept {
  if (bytes_per_ns > 0) tokens -= static_cast<double>(bytes);
  last_sent_ns = now;
  any_sent = true;
}

void Bridge::budget_drop() noexcept {
  state().budget_dropped.fetch_add(1, std::memory_order_relaxed);
  if (budget_logged_) return;
  budget_logged_ = true;
  try {
    std::string what;
    auto add = [&](const std::string& s) { what += (what.empty() ? "" : ", ") + s; };
    if (budget_.min_interval_ns > 0)
      add(fmt::format("max_rate_hz {:.3g}", 1e9 / static_cast<double>(budget_.min_interval_ns)));
    if (budget_.bytes_per_ns > 0) add(fmt::format("max_bandwidth {:.0f} B/s", budget_.bytes_per_ns * 1e9));
    if (link_ns_per_byte_ > 0)
      add(fmt::format("the host's link budget {:.0f} B/s at priority {}", 1e9 / link_ns_per_byte_, to_string(priority_)));
    log().info("topic '{}': over its egress budget ({}): this host sends the newest message when the budget "
               "allows, the others are counted in `horus topic info` (budget dropped)",
               core_.name, what);
  } catch (...) {
  }
}

}  // namespace horus::fleet::detail

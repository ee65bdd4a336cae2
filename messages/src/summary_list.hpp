// The list that ends the log summary of a message with a variable number of entries (JointState,
// JointCommand, DiagnosticReport): ": a, b, c" while the line stays within kSummaryWidth
// characters, then ", +N more" for the entries left out, then ')'. Private to src/.
#pragma once

#include <fmt/format.h>

#include <cstddef>
#include <string>

namespace horus::msg::detail {

inline constexpr std::size_t kSummaryWidth = 170;

/// Appends entries entry(0) .. entry(count - 1) (each a std::string) to `out` as above.
template <class Entry>
void append_summary_list(std::string& out, std::size_t count, Entry entry) {
  std::size_t shown = 0;
  for (; shown < count; ++shown) {
    const std::string e = entry(shown);
    if (out.size() + e.size() + 2 > kSummaryWidth) break;
    out += shown == 0 ? ": " : ", ";
    out += e;
  }
  if (shown < count) out += fmt::format(", +{} more", count - shown);
  out += ')';
}

}  // namespace horus::msg::detail

// The functions of horus/msg/diagnostics.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/diagnostics.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <string>
#include <string_view>

namespace horus::msg {

std::optional<DiagnosticValue> DiagnosticValue::from_float(std::string_view k, double v) {
  if (std::isnan(v)) return with_type(k, "NaN", TYPE_FLOAT);
  return with_type(k, fmt::format("{:.3f}", v), TYPE_FLOAT);
}

std::string DiagnosticReport::log_summary() const {
  std::string out = fmt::format("DiagnosticReport({}, {}, {} values", component_str(),
                                detail::diag_enum_text(level_enum()), count());
  std::size_t shown = 0;
  for (; shown < count(); ++shown) {
    const std::string_view v = values[shown].value_str();
    const std::string_view head = detail::diag_utf8_prefix(v, 24);
    std::string entry = fmt::format("{}={}", values[shown].key_str(), head);
    if (head.size() < v.size()) entry += "...";
    if (out.size() + entry.size() + 2 > 170) break;
    out += shown == 0 ? ": " : ", ";
    out += entry;
  }
  if (shown < count()) out += fmt::format(", +{} more", count() - shown);
  out += ')';
  return out;
}

}  // namespace horus::msg

// The functions of horus/msg/diagnostics.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/diagnostics.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include "summary_list.hpp"

namespace horus::msg {

std::optional<DiagnosticValue> DiagnosticValue::from_float(std::string_view k, double v) {
  if (std::isnan(v)) return with_type(k, "NaN", TYPE_FLOAT);
  return with_type(k, fmt::format("{:.3f}", v), TYPE_FLOAT);
}

std::string DiagnosticReport::log_summary() const {
  std::string out = fmt::format("DiagnosticReport({}, {}, {} values", component_str(),
                                detail::diag_enum_text(level_enum()), count());
  detail::append_summary_list(out, count(), [&](std::size_t i) {
    const std::string_view v = values[i].value_str();
    const std::string_view head = detail::diag_utf8_prefix(v, 24);
    return fmt::format("{}={}{}", values[i].key_str(), head, head.size() < v.size() ? "..." : "");
  });
  return out;
}

}  // namespace horus::msg

// The functions of horus/msg/generic.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/generic.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "horus/msg/detail/msgpack_text.hpp"

namespace horus::msg {

std::expected<GenericMessage, std::string> GenericMessage::make(std::span<const std::uint8_t> bytes) {
  if (bytes.size() > kMaxPayload)
    return std::unexpected(
        fmt::format("GenericMessage payload is {} bytes; the maximum is {}", bytes.size(), kMaxPayload));
  GenericMessage m{};
  const std::size_t head = std::min(bytes.size(), kInlineCapacity);
  std::copy_n(bytes.begin(), head, m.inline_data_.begin());
  m.inline_len_ = static_cast<std::uint16_t>(head);
  if (bytes.size() > kInlineCapacity) {
    const std::size_t rest = bytes.size() - kInlineCapacity;
    std::copy_n(bytes.begin() + static_cast<std::ptrdiff_t>(kInlineCapacity), rest, m.overflow_data_.begin());
    m.overflow_len_ = static_cast<std::uint32_t>(rest);
  }
  return m;
}

std::string GenericMessage::log_summary() const {
  std::string out = fmt::format("GenericMessage({} B", size());
  std::string value;
  bool valid = false;
  if (!empty()) {
    valid = detail::MsgpackText::write(data(), value);
  }
  out += empty() ? ", empty" : valid ? " msgpack" : ", not MessagePack";
  if (const auto meta = metadata()) {
    const std::string_view shown = detail::generic_utf8_prefix(*meta, 60);
    out += fmt::format(", meta \"{}{}\"", shown, shown.size() < meta->size() ? "..." : "");
  } else if (const std::size_t n = metadata_bytes().size(); n > 0) {
    out += fmt::format(", meta not UTF-8 text ({} B)", n);
  }
  if (valid) {
    const std::string_view shown = detail::generic_utf8_prefix(value, 80);
    out += fmt::format(", value {}{}", shown, shown.size() < value.size() ? "..." : "");
  }
  out += ')';
  return out;
}

std::optional<std::string> GenericMessage::metadata_problem(std::string_view meta) {
  if (meta.size() > kMaxMetadata)
    return fmt::format("GenericMessage metadata is {} bytes; the maximum is {}", meta.size(), kMaxMetadata);
  if (const auto nul = meta.find('\0'); nul != std::string_view::npos)
    return fmt::format("GenericMessage metadata holds a NUL byte at offset {}", nul);
  if (const auto bad = detail::generic_utf8_error(meta); bad != std::string_view::npos)
    return fmt::format("GenericMessage metadata is not valid UTF-8 (at byte {})", bad);
  return std::nullopt;
}

}  // namespace horus::msg

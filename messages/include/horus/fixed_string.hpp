// Fixed-capacity, NUL-terminated text fields of messages (the spec's [u8; N]).
//
// Messages keep names in std::array<char, N> so they stay trivially copyable.
// Use these helpers instead of touching the bytes: set_fixed_str() refuses text
// that does not fit (N - 1 characters at most, no embedded NUL) and leaves the
// field unchanged, so a frame name is never silently cut.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <string_view>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// The text stored in a fixed field: the bytes up to the first NUL.
template <std::size_t N>
constexpr std::string_view fixed_str_view(const std::array<char, N>& field) noexcept {
  std::size_t len = 0;
  while (len < N && field[len] != '\0') ++len;
  return std::string_view(field.data(), len);
}

/// True when text fits a field of N bytes (at most N - 1 characters, no NUL).
template <std::size_t N>
constexpr bool fixed_str_fits(std::string_view text) noexcept {
  return text.size() < N && text.find('\0') == std::string_view::npos;
}

/// Stores text NUL-terminated and zero-padded. Returns false, leaving the field
/// unchanged, when the text does not fit (see fixed_str_fits).
template <std::size_t N>
constexpr bool set_fixed_str(std::array<char, N>& field, std::string_view text) noexcept {
  if (!fixed_str_fits<N>(text)) return false;
  field.fill('\0');
  std::copy(text.begin(), text.end(), field.begin());
  return true;
}

/// Builds a field from text known to fit at compile time or in tests.
template <std::size_t N>
constexpr std::array<char, N> make_fixed_str(std::string_view text) noexcept {
  std::array<char, N> field{};
  set_fixed_str(field, text.substr(0, std::min(text.size(), N - 1)));
  return field;
}

}  // namespace horus

HORUS_API_END

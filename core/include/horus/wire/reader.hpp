// The bounded reader every wire format decodes with (horus/wire/walk.hpp), and its error path.
//
// A Reader walks a span of bytes and never reads past it: every read says whether the bytes
// were there. Counts and lengths are checked against the bytes that remain before anything is
// allocated (fits()), so a corrupt length costs no more memory than the input could hold.
//
// Where a value sits ("horus::msg::OccupancyGrid.data[3]") is a chain of Path frames on the
// stack; it becomes text only when decoding fails (fail() and the helpers below), so a
// successful decode builds no strings.
#pragma once

#include <algorithm>
#include <bit>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

#include "horus/byte_buffer.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::wire {

/// Where a value sits in the message: a field name (or the type name at the root) or an
/// element index, under its parent. text() is called on failure only.
struct Path {
  const Path* parent = nullptr;
  std::string_view name;                // a field name, or the type name at the root
  std::size_t index = ~std::size_t{0};  // an element index instead of a name

  std::string text() const;  // core/src/wire/reader.cpp
};

/// v with its bytes in the other order (a number of 1, 2, 4 or 8 bytes).
template <class N>
constexpr N byteswap_number(N v) noexcept {
  if constexpr (sizeof(N) == 1) {
    return v;
  } else {
    using U = std::conditional_t<sizeof(N) == 2, std::uint16_t,
                                 std::conditional_t<sizeof(N) == 4, std::uint32_t, std::uint64_t>>;
    return std::bit_cast<N>(std::byteswap(std::bit_cast<U>(v)));
  }
}

namespace detail {
/// One part of an error text: text or an integer. Errors are built by append_parts, out of line,
/// so that each decoder's error paths cost a call, not an inlined string build per call site.
struct Part {
  enum class Kind : std::uint8_t { Text, Unsigned, Negative };
  std::string_view text;
  std::uint64_t magnitude = 0;
  Kind kind = Kind::Text;

  Part(const char* s) noexcept : text(s) {}
  Part(std::string_view s) noexcept : text(s) {}
  Part(const std::string& s) noexcept : text(s) {}
  template <class I>
    requires std::integral<I> && (!std::same_as<I, char>) && (!std::same_as<I, bool>)
  Part(I v) noexcept
      : magnitude(v < 0 ? 0 - static_cast<std::uint64_t>(v) : static_cast<std::uint64_t>(v)),
        kind(v < 0 ? Kind::Negative : Kind::Unsigned) {}
};
/// Appends the parts to out (integers in decimal).
void append_parts(std::string& out, std::initializer_list<Part> parts);  // core/src/wire/reader.cpp
}  // namespace detail

class Reader {
 public:
  explicit Reader(std::span<const std::byte> in, const ByteSink* byte_sink = nullptr, bool swap_bytes = false) noexcept
      : sink(byte_sink), swap(swap_bytes), base_(in.data()), size_(in.size()) {}

  std::size_t remaining() const noexcept { return size_ - pos_; }
  std::size_t position() const noexcept { return pos_; }
  const std::byte* here() const noexcept { return base_ + pos_; }
  /// Moves on n bytes the caller has checked are there.
  void skip(std::size_t n) noexcept { pos_ += n; }

  /// Skips padding up to a multiple of a (a power of two) from the first byte; false, without
  /// moving, when the padding itself runs past the end.
  bool align(std::size_t a) noexcept {
    const std::size_t to = (pos_ + a - 1) & ~(a - 1);
    if (to > size_) return false;
    pos_ = to;
    return true;
  }

  /// Copies n bytes out; false, without moving, when fewer remain.
  bool take(void* dst, std::size_t n) noexcept {
    if (n > remaining()) return false;
    if (n != 0) std::memcpy(dst, base_ + pos_, n);
    pos_ += n;
    return true;
  }

  /// One number, byte-swapped when `swapped`; false, without moving, when it is cut off.
  template <class N>
  bool number(N& v, bool swapped) noexcept {
    if (!take(&v, sizeof(N))) return false;
    if (swapped) v = byteswap_number(v);
    return true;
  }

  /// n numbers into out (n > 0), byte-swapped when `swapped`; false, without moving, when cut off.
  template <class N>
  bool numbers(N* out, std::size_t n, bool swapped) noexcept {
    if (n > remaining() / sizeof(N)) return false;
    std::memcpy(out, base_ + pos_, n * sizeof(N));
    if constexpr (sizeof(N) > 1)
      if (swapped)
        for (std::size_t i = 0; i < n; ++i) out[i] = byteswap_number(out[i]);
    pos_ += n * sizeof(N);
    return true;
  }

  /// True when `count` elements of at least min_bytes encoded bytes each can be in what remains:
  /// the bound every count or length passes before anything is allocated.
  bool fits(std::uint64_t count, std::size_t min_bytes) const noexcept {
    return count <= remaining() / std::max<std::size_t>(min_bytes, 1);
  }

  // -- the error path (never taken by a successful decode) ---------------------------------------

  /// Sets error to the path's text followed by the parts (text and integers); returns false.
  template <class... A>
  [[gnu::cold]] bool fail(const Path& path, const A&... parts) {
    error = path.text();
    detail::append_parts(error, {detail::Part(parts)...});
    return false;
  }

  /// "<path>: needs <n> bytes, <r> remain (truncated <noun>)".
  [[gnu::cold]] bool truncated(const Path& path, std::size_t need, std::string_view noun) {
    return fail(path, ": needs ", need, " bytes, ", remaining(), " remain (truncated ", noun, ")");
  }

  /// "<path>: <word> <count> needs at least <count * min> bytes, <r> remain (corrupt or truncated
  /// <noun>)": a count that fits() refused.
  [[gnu::cold]] bool too_many(const Path& path, std::string_view word, std::uint64_t count, std::size_t min_bytes,
                              std::string_view noun) {
    return fail(path, ": ", word, " ", count, " needs at least ", count * std::max<std::size_t>(min_bytes, 1),
                " bytes, ", remaining(), " remain (corrupt or truncated ", noun, ")");
  }

  /// "<path>: no buffer for <n> bytes (every pool slot is in use)": a ByteSink that had no room.
  [[gnu::cold]] bool no_buffer(const Path& path, std::size_t n) {
    return fail(path, ": no buffer for ", n, " bytes (every pool slot is in use)");
  }

  /// The first error (set once; decoding stops there).
  std::string error;
  /// Where the bytes of ByteBuffer fields go, when given.
  const ByteSink* sink;
  /// Whether multi-byte numbers arrive in the other byte order (XCDR1 from a big-endian writer).
  bool swap;

 private:
  const std::byte* base_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

/// A bool that must be the byte 0 or 1 (the local format and XCDR1).
inline bool get_strict_bool(Reader& r, bool& v, const Path& path, std::string_view noun) {
  std::uint8_t b = 0;
  if (!r.take(&b, 1)) return r.fail(path, ": needs 1 byte, 0 remain (truncated ", noun, ")");
  if (b > 1) return r.fail(path, ": bool byte ", b, ", expected 0 or 1 (corrupt ", noun, ")");
  v = b == 1;
  return true;
}

}  // namespace horus::wire

HORUS_API_END

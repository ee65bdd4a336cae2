// The one walk over a reflected type that every wire format shares (local, XCDR1, LCM).
//
// put<F>(stream, value) writes a value and get<F>(reader, value, path) reads it back; they
// visit the value the same way in every format:
//
//   bool, number, enum    F::put_scalar / F::get_scalar (width, byte order, alignment, checks)
//   std::string           F::put_string / F::get_string
//   std::vector<E>,       F::put_count / F::get_count, then the elements; a ByteBuffer's bytes
//   horus::ByteBuffer     may go to the reader's ByteSink (a pool slot) instead of the heap
//   std::array<E, N>      the N elements (nested arrays recurse; char arrays are arrays of char)
//   reflected struct      its fields in order
//
// A format chooses, per type, what goes in one piece instead: F::block<V> values are their
// in-memory bytes (the local format's POD values), and F::run<E> elements of an array or
// sequence are one run of numbers (F::put_run / F::get_run: one copy, then a byte swap if the
// format needs one). A run of 1-byte elements is read straight into the container.
//
// The format is a struct of static members (see local.hpp, xcdr1.hpp, lcm.hpp):
//
//   static constexpr std::string_view kNoun;               "message" or "sample", for errors
//   template <class V> static constexpr bool block;        V is written as its own bytes
//   template <class E> static constexpr bool run;          Es go as one run of numbers
//   template <class V> static constexpr std::size_t scalar_size;  wire bytes of a scalar
//   static constexpr std::size_t kMinString;               fewest bytes of an encoded string
//   static constexpr std::size_t kPadding;                 trailing bytes decode() accepts
//   static constexpr std::string_view kOutOfMemory, kLeftOver;  top-level error texts
//   put_scalar(s, v), put_count(s, n), put_string(s, str), put_run(s, p, n > 0)
//   get_scalar(r, v, path), get_count(r, n, min_bytes, path), get_string(r, str, path),
//   get_run(r, p, n > 0, path)
//
// The streams are Counter (encoded_size: counts, saturating) and Writer (encode: bounded
// output that throws std::length_error instead of writing past the end).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <expected>
#include <limits>
#include <new>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "horus/byte_buffer.hpp"
#include "horus/reflect.hpp"
#include "horus/wire/reader.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::wire {

using reflect::detail::is_std_array;
using reflect::detail::is_std_vector;

template <class V>
inline constexpr bool is_number = std::is_arithmetic_v<V> && !std::is_same_v<V, bool>;

/// A value the format writes on its own: bool, number or enum.
template <class V>
inline constexpr bool is_scalar = std::is_arithmetic_v<V> || std::is_enum_v<V>;

inline constexpr std::size_t kTooLarge = std::numeric_limits<std::size_t>::max();

constexpr std::size_t sat_add(std::size_t a, std::size_t b) noexcept { return b > kTooLarge - a ? kTooLarge : a + b; }

// ---------------------------------------------------------------------------------------------
// Streams.

/// Counts the bytes a walk would write; kTooLarge once saturated (a format may saturate it on
/// a count it cannot write, instead of throwing).
struct Counter {
  static constexpr bool kCounting = true;
  std::size_t pos = 0;

  void align(std::size_t a) noexcept {
    if (pos != kTooLarge) pos = (pos + a - 1) & ~(a - 1);
  }
  void bytes(const void*, std::size_t n) noexcept { pos = sat_add(pos, n); }
  template <class N>
  void swapped(const N*, std::size_t n) noexcept {
    pos = sat_add(pos, n * sizeof(N));
  }
  void saturate() noexcept { pos = kTooLarge; }
};

/// Writes into a buffer; throws std::length_error (with `overflow` as its text) before a write
/// that does not fit, so nothing is ever written past the end.
class Writer {
 public:
  static constexpr bool kCounting = false;
  Writer(std::byte* out, std::size_t size, const char* overflow) noexcept : base_(out), size_(size), overflow_(overflow) {}

  /// Zero padding up to a multiple of a (a power of two) from the first byte.
  void align(std::size_t a) {
    const std::size_t to = (pos + a - 1) & ~(a - 1);
    check(to - pos);
    std::memset(base_ + pos, 0, to - pos);
    pos = to;
  }
  void bytes(const void* src, std::size_t n) {
    check(n);
    if (n != 0) std::memcpy(base_ + pos, src, n);
    pos += n;
  }
  /// n numbers, each with its bytes in the other order.
  template <class N>
  void swapped(const N* src, std::size_t n) {
    check(n * sizeof(N));
    for (std::size_t i = 0; i < n; ++i) {
      const N v = byteswap_number(src[i]);
      std::memcpy(base_ + pos + i * sizeof(N), &v, sizeof(N));
    }
    pos += n * sizeof(N);
  }
  std::size_t pos = 0;

 private:
  void check(std::size_t n) const {
    if (n > size_ - pos) throw std::length_error(overflow_);
  }
  std::byte* base_;
  std::size_t size_;
  const char* overflow_;
};

// ---------------------------------------------------------------------------------------------
// Encoding.

template <class F, class S, class V>
void put(S& s, const V& v);

template <class F, class S, class E>
void put_elements(S& s, const E* p, std::size_t n) {
  if constexpr (F::template run<E>) {
    if (n != 0) F::put_run(s, p, n);
  } else {
    for (std::size_t i = 0; i < n; ++i) put<F>(s, p[i]);
  }
}

template <class F, class S, class V>
void put(S& s, const V& v) {
  if constexpr (F::template block<V>) {
    s.bytes(&v, sizeof(V));
  } else if constexpr (is_scalar<V>) {
    F::put_scalar(s, v);
  } else if constexpr (std::is_same_v<V, std::string>) {
    F::put_string(s, v);
  } else if constexpr (is_std_vector<V>::value) {
    F::put_count(s, v.size());
    put_elements<F>(s, v.data(), v.size());
  } else if constexpr (is_std_array<V>::value) {
    put_elements<F>(s, v.data(), v.size());
  } else {
    static_assert(Reflected<V>, "horus wire formats: not a reflected message or supported field type");
    reflect::for_each_field(v, [&](std::string_view, const auto& f) { put<F>(s, f); });
  }
}

// ---------------------------------------------------------------------------------------------
// Decoding.

/// Fewest bytes an encoded V can take (alignment aside): bounds a corrupt count before allocating.
template <class F, class V>
constexpr std::size_t min_size() {
  if constexpr (F::template block<V>) {
    return sizeof(V);
  } else if constexpr (is_scalar<V>) {
    return F::template scalar_size<V>;
  } else if constexpr (std::is_same_v<V, std::string>) {
    return F::kMinString;
  } else if constexpr (is_std_vector<V>::value) {
    return 4;
  } else if constexpr (is_std_array<V>::value) {
    return std::tuple_size_v<V> * min_size<F, typename V::value_type>();
  } else {
    static_assert(Reflected<V>, "horus wire formats: not a reflected message or supported field type");
    std::size_t n = 0;
    reflect::for_each_field_desc<V>(
        [&](const auto& fd) { n += min_size<F, typename std::remove_cvref_t<decltype(fd)>::type>(); });
    return n;
  }
}

template <class F, class V>
bool get(Reader& r, V& v, const Path& path);

// A sequence of n elements, n already checked against the bytes that remain.
template <class F, class V>
bool get_sequence(Reader& r, V& v, std::size_t n, const Path& path) {
  using E = typename V::value_type;
  if constexpr (F::template run<E> && sizeof(E) == 1) {
    // Bytes (images, grids, text): one copy, no zero-fill first; a ByteBuffer may take a pool slot.
    if constexpr (std::is_same_v<V, ByteBuffer>) {
      if (r.sink != nullptr && r.sink->place != nullptr && !r.sink->place(r.sink->context, n, v))
        return r.no_buffer(path, n);
    }
    const auto* p = reinterpret_cast<const E*>(r.here());
    v.assign(p, p + n);
    r.skip(n);
    return true;
  } else if constexpr (F::template run<E>) {
    if (n == 0) {
      v.clear();
      return true;
    }
    v.resize(n);
    return F::get_run(r, v.data(), n, path);
  } else {
    // Grow as elements decode: a corrupt count costs at most what the bytes can hold, however
    // much larger sizeof(E) is than its encoding (a std::string is 32 bytes, 4 encoded).
    v.clear();
    v.reserve(std::min<std::size_t>(n, 4096));
    for (std::size_t i = 0; i < n; ++i) {
      v.emplace_back();
      if (!get<F>(r, v.back(), Path{&path, {}, i})) return false;
    }
    return true;
  }
}

template <class F, class V>
bool get(Reader& r, V& v, const Path& path) {
  if constexpr (F::template block<V>) {
    if (!r.take(&v, sizeof(V))) return r.truncated(path, sizeof(V), F::kNoun);
    return true;
  } else if constexpr (is_scalar<V>) {
    return F::get_scalar(r, v, path);
  } else if constexpr (std::is_same_v<V, std::string>) {
    return F::get_string(r, v, path);
  } else if constexpr (is_std_vector<V>::value) {
    std::size_t n = 0;
    if (!F::get_count(r, n, min_size<F, typename V::value_type>(), path)) return false;
    return get_sequence<F>(r, v, n, path);
  } else if constexpr (is_std_array<V>::value) {
    if constexpr (F::template run<typename V::value_type>) {
      return v.size() == 0 || F::get_run(r, v.data(), v.size(), path);
    } else {
      for (std::size_t i = 0; i < v.size(); ++i)
        if (!get<F>(r, v[i], Path{&path, {}, i})) return false;
      return true;
    }
  } else {
    bool ok = true;
    reflect::for_each_field(v, [&](std::string_view name, auto& f) {
      if (ok) ok = get<F>(r, f, Path{&path, name});
    });
    return ok;
  }
}

/// "<type><parts>": an error about the whole message.
template <class... A>
[[gnu::cold]] std::string message_error(std::string_view type, const A&... parts) {
  std::string out(type);
  detail::append_parts(out, {detail::Part(parts)...});
  return out;
}

/// Reads a whole T from r (positioned at its first byte), then refuses more than F::kPadding
/// bytes left over. Errors start with T's name; `in_size` is the input's size for them.
template <class F, class T>
std::expected<T, std::string> decode_message(Reader& r, std::size_t in_size) {
  T msg{};
  try {
    if (!get<F>(r, msg, Path{nullptr, type_name<T>()})) return std::unexpected(std::move(r.error));
  } catch (const std::bad_alloc&) {
    return std::unexpected(message_error(type_name<T>(), F::kOutOfMemory, in_size, " bytes"));
  } catch (const std::length_error& e) {
    return std::unexpected(message_error(type_name<T>(), ": ", std::string_view(e.what())));
  }
  if (r.remaining() > F::kPadding)
    return std::unexpected(message_error(type_name<T>(), ": ", r.remaining(), F::kLeftOver));
  return msg;
}

}  // namespace horus::wire

HORUS_API_END

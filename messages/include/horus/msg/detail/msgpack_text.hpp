// A MessagePack value as text, for GenericMessage::log_summary(), without msgpack-cxx (whose
// headers would cost every file that includes <horus/horus.hpp> about two seconds of compile
// time). The text is what msgpack-cxx prints for a msgpack::object: JSON-like, maps as
// {"k":v,...}, arrays as [a,b], nil as null, binaries as "BIN(size:N)", extensions as
// "EXT(type:T,size:N)". Bounded: nothing is allocated from what a header claims (a container
// needs one byte per element), nesting stops at 64 levels, and the whole input must be one value.
// Internal to horus.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <sstream>
#include <string>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg::detail {

class MsgpackText {
 public:
  /// The text of the one value `bytes` holds, or false (the text is then partial) when they are
  /// not exactly one well-formed MessagePack value of at most 64 nesting levels.
  static bool write(std::span<const std::uint8_t> bytes, std::string& out) {
    MsgpackText t{bytes, out};
    return t.value(0) && t.at_ == bytes.size();
  }

 private:
  MsgpackText(std::span<const std::uint8_t> b, std::string& o) : in_(b), out_(o) {}

  bool take(std::size_t n, std::uint64_t& v) {  // a big-endian unsigned of n bytes
    if (in_.size() - at_ < n) return false;
    v = 0;
    for (std::size_t i = 0; i < n; ++i) v = (v << 8) | in_[at_ + i];
    at_ += n;
    return true;
  }
  template <class T>
  void number(T v) {
    std::ostringstream s;
    s << v;
    out_ += s.str();
  }
  bool str(std::size_t n) {
    if (in_.size() - at_ < n) return false;
    out_ += '"';
    for (std::size_t i = 0; i < n; ++i) {
      const auto c = static_cast<char>(in_[at_ + i]);
      switch (c) {
        case '\\': out_ += "\\\\"; break;
        case '"': out_ += "\\\""; break;
        case '/': out_ += "\\/"; break;
        case '\b': out_ += "\\b"; break;
        case '\f': out_ += "\\f"; break;
        case '\n': out_ += "\\n"; break;
        case '\r': out_ += "\\r"; break;
        case '\t': out_ += "\\t"; break;
        default: {
          const auto code = static_cast<unsigned char>(c);
          if (code < 0x20 || code == 0x7f) {
            static constexpr char kHex[] = "0123456789abcdef";
            out_ += "\\u00";
            out_ += kHex[code >> 4];
            out_ += kHex[code & 15];
          } else {
            out_ += c;
          }
        }
      }
    }
    out_ += '"';
    at_ += n;
    return true;
  }
  bool skip(std::size_t n) {
    if (in_.size() - at_ < n) return false;
    at_ += n;
    return true;
  }
  bool ext(std::size_t n) {  // n bytes of data after the type byte
    std::uint64_t type = 0;
    if (!take(1, type) || !skip(n)) return false;
    out_ += "\"EXT(type:" + std::to_string(static_cast<int>(static_cast<std::int8_t>(type))) +
            ",size:" + std::to_string(n) + ")\"";
    return true;
  }
  bool items(std::uint64_t n, bool map, int depth) {
    // Each element takes one byte at least: a count the rest cannot hold is refused at once.
    if (n > (in_.size() - at_) / (map ? 2 : 1)) return false;
    out_ += map ? '{' : '[';
    for (std::uint64_t i = 0; i < n; ++i) {
      if (i > 0) out_ += ',';
      if (!value(depth + 1)) return false;
      if (map) {
        out_ += ':';
        if (!value(depth + 1)) return false;
      }
    }
    out_ += map ? '}' : ']';
    return true;
  }
  bool value(int depth) {
    if (depth >= 64) return false;
    std::uint64_t b = 0, n = 0;
    if (!take(1, b)) return false;
    if (b <= 0x7f) return number(b), true;
    if (b >= 0xe0) return number(static_cast<std::int64_t>(static_cast<std::int8_t>(b))), true;
    if (b <= 0x8f) return items(b & 0x0f, true, depth);
    if (b <= 0x9f) return items(b & 0x0f, false, depth);
    if (b <= 0xbf) return str(b & 0x1f);
    switch (b) {
      case 0xc0: out_ += "null"; return true;
      case 0xc2: out_ += "false"; return true;
      case 0xc3: out_ += "true"; return true;
      case 0xc4: case 0xc5: case 0xc6:  // bin 8, 16, 32
        if (!take(std::size_t{1} << (b - 0xc4), n) || !skip(n)) return false;
        out_ += "\"BIN(size:" + std::to_string(n) + ")\"";
        return true;
      case 0xc7: case 0xc8: case 0xc9:  // ext 8, 16, 32
        return take(std::size_t{1} << (b - 0xc7), n) && ext(n);
      case 0xca:
        if (!take(4, n)) return false;
        return number(std::bit_cast<float>(static_cast<std::uint32_t>(n))), true;
      case 0xcb:
        if (!take(8, n)) return false;
        return number(std::bit_cast<double>(n)), true;
      case 0xcc: case 0xcd: case 0xce: case 0xcf:  // uint 8..64
        if (!take(std::size_t{1} << (b - 0xcc), n)) return false;
        return number(n), true;
      case 0xd0: case 0xd1: case 0xd2: case 0xd3: {  // int 8..64
        const std::size_t size = std::size_t{1} << (b - 0xd0);
        if (!take(size, n)) return false;
        const unsigned shift = static_cast<unsigned>(64 - 8 * size);  // sign-extend
        const auto v = static_cast<std::int64_t>(n << shift) >> shift;
        if (v >= 0) return number(static_cast<std::uint64_t>(v)), true;
        return number(v), true;
      }
      case 0xd4: case 0xd5: case 0xd6: case 0xd7: case 0xd8:  // fixext 1..16
        return ext(std::size_t{1} << (b - 0xd4));
      case 0xd9: case 0xda: case 0xdb:  // str 8, 16, 32
        return take(std::size_t{1} << (b - 0xd9), n) && str(n);
      case 0xdc: case 0xdd:  // array 16, 32
        return take(std::size_t{2} << (b - 0xdc), n) && items(n, false, depth);
      case 0xde: case 0xdf:  // map 16, 32
        return take(std::size_t{2} << (b - 0xde), n) && items(n, true, depth);
      default: return false;  // 0xc1: never used
    }
  }

  std::span<const std::uint8_t> in_;
  std::string& out_;
  std::size_t at_ = 0;
};

}  // namespace horus::msg::detail

HORUS_API_END

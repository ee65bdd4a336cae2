// Test messages that use every construct the interface generator and the wire codecs know:
// every primitive width, an IDL enum, an enum that stays an integer, char and number arrays,
// strings, sequences of numbers, structs and strings, nested structs, and names IDL reserves.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "horus/reflect.hpp"

namespace wiretest {

enum class Mode : std::uint8_t { Off, On, Auto };
HORUS_REFLECT_ENUM(Mode, Off, On, Auto)

enum class Raw : std::int16_t { A = 5, B = -2 };  // not 0..N-1: travels as its int16

struct Inner {
  std::uint8_t a{};
  double b{};
  bool operator==(const Inner&) const = default;
};
HORUS_REFLECT(Inner, a, b)

struct All {
  bool flag{};
  char c{};
  std::int8_t i8{};
  std::uint16_t u16{};
  std::int32_t i32{};
  std::uint64_t u64{};
  float f{};
  double d{};
  Mode mode{};
  Raw raw{};
  std::array<char, 4> name{};
  std::array<std::int16_t, 3> shorts{};
  std::string text;
  std::vector<double> values;
  std::vector<Inner> inners;
  std::vector<std::string> words;
  Inner inner;
  bool operator==(const All&) const = default;
};
HORUS_REFLECT(All, flag, c, i8, u16, i32, u64, f, d, mode, raw, name, shorts, text, values, inners, words, inner)

// Field names IDL reserves or forbids: a keyword, and a field named like its struct.
struct Keywords {
  std::int32_t map{};
  std::uint8_t keywords{};
  std::array<std::array<float, 2>, 3> grid{};
  std::vector<std::array<std::uint16_t, 2>> pairs;
  bool operator==(const Keywords&) const = default;
};
HORUS_REFLECT(Keywords, map, keywords, grid, pairs)

// The widths All lacks, and sequences of them.
struct Widths {
  std::int64_t i64{};
  std::uint32_t u32{};
  std::int16_t i16{};
  std::uint8_t u8{};
  std::vector<std::uint8_t> bytes;
  std::vector<std::int64_t> longs;
  std::array<bool, 3> flags{};
  bool operator==(const Widths&) const = default;
};
HORUS_REFLECT(Widths, i64, u32, i16, u8, bytes, longs, flags)

}  // namespace wiretest

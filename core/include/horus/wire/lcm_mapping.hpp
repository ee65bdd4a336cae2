// How horus messages map to LCM types: the rules the .lcm emitter (horus-idlgen) and the LCM
// codec (backend_lcm) share, so the emitted files and the bytes cannot disagree.
//
//   C++ field                        LCM member                       wire (big-endian)
//   bool                             boolean                          1 byte (0 or 1)
//   char, std::uint8_t               byte                             1 byte
//   std::int8_t                      int8_t                           1 byte
//   std::int16_t                     int16_t                          2 bytes
//   std::uint16_t                    int32_t (widened)                4 bytes
//   std::int32_t                     int32_t                          4 bytes
//   std::uint32_t                    int64_t (widened)                8 bytes
//   std::int64_t                     int64_t                          8 bytes
//   std::uint64_t                    int64_t (same bits: values above 2^63-1 read negative)
//   float / double                   float / double                   IEEE 754, 4 / 8 bytes
//   enum with HORUS_REFLECT_ENUM, values 0..N-1
//                                    int32_t; the enumerators are constants of a struct of
//                                    their own (`struct Mode { const int32_t Off = 0, ...; }`)
//   any other enum                   its underlying integer, as above
//   std::string                      string                           int32 length + 1, bytes, NUL
//   std::array<E, N> (nested: [N][M]) E name[N][M]                    the elements
//   std::vector<E>, horus::ByteBuffer int32_t num_name; E name[num_name];  the count is the
//                                    num_name member, written just before the elements
//   a reflected struct               pkg.Struct name                  its members (no fingerprint)
//
// LCM has no unsigned integers: uint16 and uint32 travel in the next wider signed type, so a
// C, C++ or Java program reads the true value; uint64 keeps its 64 bits in an int64_t. A
// received widened value outside the unsigned range is refused. LCM cannot express a
// variable-size array of variable-size arrays (vector<vector<E>>, array<vector<E>, N>):
// such types are refused by the emitter and by Topic<T> on the lcm backend.
//
// Package: the C++ namespaces joined by '_' (horus::msg::Pose2D is horus_msg.Pose2D; C type
// horus_msg_Pose2D, C++ horus_msg::Pose2D). Member names that are keywords of C, C++, Java or
// Python, or names of methods lcm-gen generates (encode, getHash, ...), get a trailing '_'.
//
// Fingerprint: lcm-gen's hash of the member names, primitive type names and dimensions
// (never the struct or package names), plus the fingerprints of the struct-typed members,
// rotated left by one. The functions below compute it exactly as lcm-gen does.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::idlgen::lcm {

// ---------------------------------------------------------------------------------------------
// lcm-gen's hash (lcmgen.c: hash_update / hash_string_update), in C int64 arithmetic:
// v = ((v << 8) ^ (v >> 55)) + c, with an arithmetic shift and c a signed char.

constexpr std::int64_t hash_update(std::int64_t v, char c) noexcept {
  const auto u = static_cast<std::uint64_t>(v);
  const auto shifted = static_cast<std::uint64_t>(v >> 55);
  const auto add = static_cast<std::uint64_t>(static_cast<std::int64_t>(static_cast<signed char>(c)));
  return static_cast<std::int64_t>(((u << 8) ^ shifted) + add);
}

/// A string: its length (as a char), then its bytes. Parts are hashed as one string.
constexpr std::int64_t hash_string(std::int64_t v, std::string_view a, std::string_view b = {},
                                   std::string_view c = {}) noexcept {
  v = hash_update(v, static_cast<char>(a.size() + b.size() + c.size()));
  for (char ch : a) v = hash_update(v, ch);
  for (char ch : b) v = hash_update(v, ch);
  for (char ch : c) v = hash_update(v, ch);
  return v;
}

inline constexpr std::int64_t kHashSeed = 0x12345678;

/// The fingerprint from a struct's base hash and the sum of its struct members' fingerprints
/// (one term per member, not per element): the sum rotated left by one.
constexpr std::uint64_t hash_finish(std::int64_t base, std::uint64_t nested_sum) noexcept {
  const std::uint64_t h = static_cast<std::uint64_t>(base) + nested_sum;
  return (h << 1) | (h >> 63);
}

/// A dimension's size as lcm-gen hashes it: the decimal text of a fixed size.
struct DecimalText {
  std::array<char, 20> digits{};
  std::size_t size = 0;
  constexpr std::string_view view() const noexcept { return {digits.data(), size}; }
};
constexpr DecimalText decimal(std::size_t n) noexcept {
  DecimalText out;
  std::array<char, 20> rev{};
  std::size_t k = 0;
  do {
    rev[k++] = static_cast<char>('0' + n % 10);
    n /= 10;
  } while (n != 0);
  for (std::size_t i = 0; i < k; ++i) out.digits[i] = rev[k - 1 - i];
  out.size = k;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Names.

/// Keywords of the languages lcm-gen writes (C, C++, Java, Python), and the members and methods
/// it generates: a field with one of these names gets a trailing '_' in the .lcm file.
inline constexpr std::string_view kReservedNames[] = {
    // C and C++
    "alignas", "alignof", "and", "and_eq", "asm", "auto", "bitand", "bitor", "bool", "break", "case", "catch",
    "char", "char8_t", "char16_t", "char32_t", "class", "compl", "concept", "const", "consteval", "constexpr",
    "constinit", "const_cast", "continue", "co_await", "co_return", "co_yield", "decltype", "default", "delete",
    "do", "double", "dynamic_cast", "else", "enum", "explicit", "export", "extern", "false", "float", "for",
    "friend", "goto", "if", "inline", "int", "long", "mutable", "namespace", "new", "noexcept", "not", "not_eq",
    "nullptr", "operator", "or", "or_eq", "private", "protected", "public", "register", "reinterpret_cast",
    "requires", "restrict", "return", "short", "signed", "sizeof", "static", "static_assert", "static_cast",
    "struct", "switch", "template", "this", "thread_local", "throw", "true", "try", "typedef", "typeid",
    "typename", "union", "unsigned", "using", "virtual", "void", "volatile", "wchar_t", "while", "xor", "xor_eq",
    // Java (beyond the above)
    "abstract", "assert", "boolean", "byte", "extends", "final", "finally", "implements", "import",
    "instanceof", "interface", "native", "package", "strictfp", "super", "synchronized", "throws", "transient",
    "null", "var", "record", "yield",
    // Python (beyond the above)
    "as", "async", "await", "def", "del", "elif", "except", "from", "global", "in", "is", "lambda", "nonlocal",
    "pass", "raise", "with", "None", "True", "False",
    // generated by lcm-gen
    "encode", "decode", "getHash", "getEncodedSize", "getTypeName", "_encodeNoHash", "_decodeNoHash",
    "_getEncodedSizeNoHash", "_computeHash", "LCM_FINGERPRINT", "LCM_FINGERPRINT_BASE", "copy"};

constexpr bool is_reserved(std::string_view name) noexcept {
  for (auto r : kReservedNames)
    if (r == name) return true;
  return false;
}

/// The member name of a field: the field name, with a trailing '_' when reserved.
struct MemberName {
  std::string_view field;
  bool escaped = false;
  constexpr std::string_view suffix() const noexcept { return escaped ? std::string_view("_") : std::string_view(); }
};
constexpr MemberName member_name(std::string_view field) noexcept { return {field, is_reserved(field)}; }

/// The prefix of the length member of a variable-size field: num_<field>.
inline constexpr std::string_view kLengthPrefix = "num_";

/// LCM primitive type names (the text lcm-gen hashes).
inline constexpr std::string_view kBoolean = "boolean";
inline constexpr std::string_view kByte = "byte";
inline constexpr std::string_view kInt8 = "int8_t";
inline constexpr std::string_view kInt16 = "int16_t";
inline constexpr std::string_view kInt32 = "int32_t";
inline constexpr std::string_view kInt64 = "int64_t";
inline constexpr std::string_view kFloat = "float";
inline constexpr std::string_view kDouble = "double";
inline constexpr std::string_view kString = "string";

/// The LCM type of an integer field of `size` bytes (see the table above).
constexpr std::string_view integer_type(std::size_t size, bool is_signed) noexcept {
  switch (size) {
    case 1: return is_signed ? kInt8 : kByte;
    case 2: return is_signed ? kInt16 : kInt32;
    case 4: return is_signed ? kInt32 : kInt64;
    default: return kInt64;
  }
}

/// Largest value a length member (int32_t) can hold.
inline constexpr std::size_t kMaxLength = 0x7fffffff;

}  // namespace horus::idlgen::lcm

HORUS_API_END

// Messages of a type this program was not compiled with: read from the type's signature.
//
// Every reflected type has a canonical layout text, reflect::type_signature<T>(), whose 64-bit
// FNV-1a hash is its type hash (horus/reflect.hpp):
//
//   horus::msg::Pose2D{f64 x;f64 y;f64 theta;u64 timestamp_ns;}
//
// The fleet layer announces that text with each topic, so a tool on another host (horus topic
// echo) can parse it into a DynType and decode samples of the topic from the wire (XCDR1 on
// DDS, lcm-gen's encoding on LCM) into the JSON that horus::to_json would give for the C++
// type: same keys, char arrays as strings, enums by name, non-finite floats as null.
//
//   auto type = horus::wire::parse_signature(text, hash);    // checks the hash too
//   auto json = horus::wire::decode_json(**type, net::WireFormat::Xcdr1, body, little_endian);
//
// Parsing and decoding are bounded and never throw on bad input: a signature that is not one,
// or whose hash is not the announced one, and a sample that does not decode give an error text
// naming where (the offset in the signature, the field path in the sample).
#pragma once

#include <cstddef>
#include <cstdint>
#include <expected>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::wire {

/// A parsed type signature: a tree of these.
struct DynType {
  enum class Kind : std::uint8_t { Bool, Char, Int, Float, Enum, String, Array, Sequence, Struct };
  Kind kind = Kind::Bool;
  std::uint8_t size = 0;   // Int, Float: bytes; Enum: bytes of its underlying integer
  bool is_signed = false;  // Int; Enum: its underlying integer
  std::string name;        // Enum, Struct: the qualified name
  // Enum: the enumerators (name, value) of a reflected enum; empty for a plain enum.
  std::vector<std::pair<std::string, std::int64_t>> enumerators;
  bool reflected = false;   // Enum: declared with HORUS_REFLECT_ENUM (it has enumerators)
  std::uint64_t length = 0; // Array
  // Array, Sequence: one element type. Struct: the field types, named by field_names.
  std::vector<DynType> children;
  std::vector<std::string> field_names;

  /// An IDL enum (horus/wire/mapping.hpp): reflected, enumerators 0..N-1 in order.
  bool idl_enum() const noexcept;
  /// A char array ([char;N]): JSON renders it as text.
  bool char_array() const noexcept { return kind == Kind::Array && children.size() == 1 && children[0].kind == Kind::Char; }
};

/// Parses a signature; when `expected_hash` is not 0, its FNV-1a hash must be that. The error
/// names the offset and what was expected there, or both hashes.
std::expected<DynType, std::string> parse_signature(std::string_view text, std::uint64_t expected_hash = 0);

/// The 64-bit FNV-1a hash of a signature (what horus::type_hash<T> is of T's).
std::uint64_t signature_hash(std::string_view text) noexcept;

/// How the bytes are encoded: XCDR1 (the sample body after the encapsulation header, in the
/// given byte order) or LCM (the 8-byte fingerprint first, big-endian). Mirrors
/// net::WireFormat without depending on it.
enum class DynFormat : std::uint8_t { Xcdr1, Lcm };

/// Why a type cannot travel in a format, or nothing (LCM: a sequence inside a sequence or an
/// array, an empty array).
std::expected<void, std::string> check_expressible(const DynType& type, DynFormat format);

/// Decodes one message into JSON (to_json's rendering). Errors name the field path.
std::expected<nlohmann::json, std::string> decode_json(const DynType& type, DynFormat format,
                                                       std::span<const std::byte> body, bool little_endian = true);

}  // namespace horus::wire

HORUS_API_END

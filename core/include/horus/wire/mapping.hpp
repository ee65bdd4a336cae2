// How C++ field types map to interface types (IDL, LCM) and wire encodings (CDR, LCM).
// One place decides, so the emitted files and the codecs cannot disagree:
//
//   C++ field                           IDL                          XCDR1
//   bool / char                         boolean / char               1 byte
//   std::int8_t / std::uint8_t          int8 / uint8                 1 byte
//   std::(u)int16/32/64_t               (unsigned) short/long/long long   2/4/8 bytes, aligned
//   float / double                      float / double               4/8 bytes, aligned
//   enum declared with HORUS_REFLECT_ENUM whose values are 0..N-1
//                                       enum (enumerators Name_Value) 4 bytes (u32)
//   any other enum                      its underlying integer       as that integer
//   std::array<E, N>                    E name[N] (nested: [N][M])   N elements, no count
//   std::vector<E>, horus::ByteBuffer   sequence<E>                  u32 count + elements
//   std::string                         string                       u32 length incl. NUL + bytes + NUL
//   a reflected struct                  @final struct                its fields in order
//
// Names: modules are the C++ namespaces, so DDS type names are the qualified C++ names
// (horus::msg::Pose2D). A field named like an IDL keyword is escaped (_map: generated code
// still says `map`); a field named like its own struct or like another type of its module,
// case ignored, gets a trailing '_' (Range.range and AccelStamped.accel are `range_` and
// `accel_` in IDL): IDL forbids the first, fastddsgen the second. Struct and enum types are
// always referred to by their qualified name. Field names never reach the XCDR1 wire.
#pragma once

#include <cstddef>
#include <type_traits>

#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::idlgen {

/// True when enum E maps to an IDL enum: reflected, with enumerators 0, 1, ..., N-1 in order.
template <class E>
constexpr bool is_idl_enum() {
  if constexpr (!reflect::ReflectedEnum<E>) {
    return false;
  } else {
    const auto values = reflect::enum_values<E>();
    if (values.size() == 0) return false;
    for (std::size_t i = 0; i < values.size(); ++i)
      if (static_cast<std::size_t>(static_cast<std::underlying_type_t<E>>(values[i].value)) != i) return false;
    return true;
  }
}

/// The number of enumerators of an IDL enum (valid wire values are 0..count-1).
template <class E>
constexpr std::size_t idl_enum_count() {
  return reflect::enum_values<E>().size();
}

}  // namespace horus::idlgen

HORUS_API_END

// GenericMessage::from_value and to_value: any value msgpack-cxx packs, in and out of a
// GenericMessage (horus/msg/generic.hpp). A separate header because msgpack-cxx costs about two
// seconds of compile time, which a file that only moves GenericMessages should not pay.
//
//   #include <horus/msg/generic_value.hpp>
//   auto msg = horus::msg::GenericMessage::from_value(std::map<std::string, double>{{"x", 1.0}});
//   auto back = msg->to_value<std::map<std::string, double>>();   // std::expected<T, std::string>
//
// msgpack-cxx is used header-only, without Boost (MSGPACK_NO_BOOST).
#pragma once

#ifndef MSGPACK_NO_BOOST
#define MSGPACK_NO_BOOST
#endif
#include <msgpack.hpp>

#include <cstddef>
#include <cstdint>
#include <exception>
#include <expected>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "horus/msg/generic.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg::detail {

inline std::string_view generic_msgpack_type_name(msgpack::type::object_type t) noexcept {
  switch (t) {
    case msgpack::type::NIL: return "nil";
    case msgpack::type::BOOLEAN: return "boolean";
    case msgpack::type::POSITIVE_INTEGER: return "positive integer";
    case msgpack::type::NEGATIVE_INTEGER: return "negative integer";
    case msgpack::type::FLOAT32: return "float32";
    case msgpack::type::FLOAT64: return "float64";
    case msgpack::type::STR: return "string";
    case msgpack::type::BIN: return "binary";
    case msgpack::type::ARRAY: return "array";
    case msgpack::type::MAP: return "map";
    case msgpack::type::EXT: return "ext";
  }
  return "unknown";
}

template <class T>
struct GenericValue {
  /// Packs value with MessagePack into a new message. An error when the encoding is over 4096
  /// bytes (the size is named) or packing fails.
  static std::expected<GenericMessage, std::string> pack(const T& value) {
    msgpack::sbuffer buf;
    try {
      msgpack::pack(buf, value);
    } catch (const std::exception& e) {
      return std::unexpected(fmt::format("GenericMessage::from_value<{}>: MessagePack encoding failed: {}",
                                         reflect::type_name<T>(), e.what()));
    }
    if (buf.size() > GenericMessage::kMaxPayload)
      return std::unexpected(fmt::format("GenericMessage::from_value<{}>: the MessagePack encoding is {} bytes; the "
                                         "maximum payload is {}",
                                         reflect::type_name<T>(), buf.size(), GenericMessage::kMaxPayload));
    return GenericMessage::make(
        std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(buf.data()), buf.size()));
  }

  /// Unpacks a payload into a T. An error, naming T and what was found, when the payload is
  /// empty, is not valid MessagePack, holds bytes after the first value, or the value does not
  /// convert to T.
  static std::expected<T, std::string> unpack(const std::vector<std::uint8_t>& bytes) {
    const auto fail = [](std::string_view what) {
      return std::unexpected(fmt::format("GenericMessage::to_value<{}>: {}", reflect::type_name<T>(), what));
    };
    if (bytes.empty()) return fail("the payload is empty (no MessagePack value)");
    msgpack::object_handle handle;
    std::size_t offset = 0;
    // A container holds at most one element per byte of the payload: a header that claims more
    // (a map of 2^32 entries in 5 bytes) is refused before msgpack allocates for it.
    const auto most = static_cast<std::size_t>(bytes.size());
    const msgpack::unpack_limit limit(most, most, most, most, most, 64);
    try {
      handle = msgpack::unpack(reinterpret_cast<const char*>(bytes.data()), bytes.size(), offset, nullptr, nullptr, limit);
    } catch (const msgpack::size_overflow& e) {
      return fail(fmt::format("the {}-byte payload is not valid MessagePack: a container or string claims more than "
                              "the payload holds ({})",
                              bytes.size(), e.what()));
    } catch (const std::exception& e) {
      return fail(fmt::format("the {}-byte payload is not valid MessagePack ({})", bytes.size(), e.what()));
    }
    if (offset != bytes.size())
      return fail(fmt::format("{} bytes follow the MessagePack value ({} of {} bytes used)", bytes.size() - offset,
                              offset, bytes.size()));
    try {
      return handle.get().as<T>();
    } catch (const std::exception& e) {
      return fail(fmt::format("cannot convert a MessagePack {} to {} ({})", generic_msgpack_type_name(handle.get().type),
                              reflect::type_name<T>(), e.what()));
    }
  }
};

}  // namespace horus::msg::detail

HORUS_API_END

// What kind of message a topic carries, which decides how its slots hold it:
//   fixed-size   trivially copyable T: the ring slot holds T itself (copied)
//   serialized   variable-size T (vectors, strings): the slot holds [length][encoded bytes]
//   pooled       large data (Image, PointCloud, DepthImage, Tensor): T's bytes live in a pool
//                slot beside the ring, and the ring slot holds T::Descriptor (zero-copy)
#pragma once

#include <concepts>
#include <cstddef>
#include <optional>
#include <type_traits>
#include <utility>

#include "horus/byte_buffer.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// A message type Topic<T> can carry: any reflected message. Trivially copyable ones travel
/// by copy; the others (vectors, strings, large-data classes) are serialized (horus/wire/local.hpp).
template <class T>
concept Message = Reflected<T> && std::is_default_constructible_v<T>;

/// Large-data messages (Image, PointCloud, DepthImage, Tensor): the topic keeps their bytes in
/// a pool of slots beside its ring, and the ring carries only T::Descriptor (zero-copy).
namespace detail {
template <class T>
concept PoolMessageParts = requires(const T& t, const typename T::Descriptor& d, ByteBuffer&& b) {
  requires std::is_trivially_copyable_v<typename T::Descriptor>;
  { t.descriptor() } -> std::same_as<typename T::Descriptor>;
  { t.buffer() } -> std::same_as<const ByteBuffer&>;
  { T::adopt(d, std::move(b)) } -> std::same_as<std::optional<T>>;
  d.pool_id;
  d.slot_id;
  d.generation;
  d.offset;
  d.data_size;
};
}  // namespace detail

template <class T>
concept PoolMessage = requires { typename T::Descriptor; } && detail::PoolMessageParts<T>;

namespace detail {
struct NoDescriptor {};
template <class T, bool = PoolMessage<T>>
struct DescriptorOf {
  using type = NoDescriptor;
};
template <class T>
struct DescriptorOf<T, true> {
  using type = typename T::Descriptor;
};
}  // namespace detail

/// True when Topic<T> keeps T's bytes in a shared-memory pool (PoolMessage).
template <class T>
inline constexpr bool is_pool_message = PoolMessage<T>;

/// True when Topic<T> serializes T rather than copying it.
template <class T>
inline constexpr bool is_serialized_message = !std::is_trivially_copyable_v<T> && !PoolMessage<T>;

namespace detail {
template <class T>
concept HasDefaultSlotBytes = requires { { T::kDefaultSlotBytes } -> std::convertible_to<std::size_t>; };
}  // namespace detail

/// Largest encoded message a serialized topic accepts unless the slot size is given:
/// T::kDefaultSlotBytes when T declares it (Image: a 1920x1080 RGBA frame), else 64 KiB.
template <class T>
inline constexpr std::size_t default_slot_bytes = [] {
  if constexpr (detail::HasDefaultSlotBytes<T>) {
    static_assert(T::kDefaultSlotBytes >= 1 && T::kDefaultSlotBytes <= (std::size_t{1} << 30) - 8,
                  "T::kDefaultSlotBytes must be 1 byte to 1 GiB - 8");
    return static_cast<std::size_t>(T::kDefaultSlotBytes);
  } else {
    return std::size_t{64 * 1024};
  }
}();

}  // namespace horus

HORUS_API_END

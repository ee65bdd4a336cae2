// What every large-data message (Image, PointCloud, DepthImage, Tensor) shares: the 2 GiB
// size limit, checked size arithmetic and its errors, byte-count formatting, and LargeData, the
// base of the four (from_descriptor, adopt, Descriptor, buffer). tensor.hpp includes it.
#pragma once

#include <dlpack/dlpack.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <memory>
#include <new>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "horus/byte_buffer.hpp"
#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

/// Largest data block of one large-data message (Image, PointCloud, DepthImage,
/// Tensor): 2^31 bytes (2 GiB). Exactly 2^31 is allowed, one byte more is not.
inline constexpr std::uint64_t kMaxLargeDataBytes = std::uint64_t{1} << 31;

/// The large-data API every such message shares, a base with no data: `M` is the message, `D`
/// its descriptor. M keeps its bytes in `data_` and checks a descriptor in its own
/// `static std::optional<M> build(const D&, Bytes&&)` (private: the base is M's friend), whose
/// comment says what it refuses.
template <class M, class D>
class LargeData {
 public:
  /// The fixed-size description that travels through a topic while the bytes stay in its pool.
  using Descriptor = D;

  /// Rebuilds a message from its descriptor and bytes (copied). nullopt unless the descriptor
  /// is one M's constructor could make (M::build says what is checked) and bytes.size() ==
  /// desc.data_size. The pool fields are not used (bytes are given).
  static std::optional<M> from_descriptor(const D& desc, std::span<const std::uint8_t> bytes) {
    return M::build(desc, bytes);
  }
  /// As from_descriptor, taking `bytes` over instead of copying them: how a topic hands out a
  /// message whose bytes stay in its shared-memory pool (zero-copy). nullopt under the same
  /// conditions.
  static std::optional<M> adopt(const D& desc, ByteBuffer&& bytes) { return M::build(desc, std::move(bytes)); }

  /// The bytes with their storage (owned, or borrowed from a pool slot).
  const ByteBuffer& buffer() const noexcept { return static_cast<const M&>(*this).data_; }

  friend bool operator==(const LargeData&, const LargeData&) = default;

 protected:
  LargeData() = default;
  /// The bytes build() keeps: taken over (a ByteBuffer) or copied (a span).
  template <class Bytes>
  static ByteBuffer keep(Bytes&& bytes) {
    if constexpr (std::is_same_v<std::remove_cvref_t<Bytes>, ByteBuffer>) {
      return std::move(bytes);
    } else {
      return ByteBuffer(std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
    }
  }
};

namespace detail {

/// out = a * b; false (out unchanged) when the product overflows 64 bits.
constexpr bool checked_mul(std::uint64_t a, std::uint64_t b, std::uint64_t& out) noexcept {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a) return false;
  out = a * b;
  return true;
}

/// Why a large-data size is refused (None = fine).
enum class SizeError : std::uint8_t { None, ZeroDimension, UnknownType, Overflow, TooLarge, BadShape };

std::string size_error_text(SizeError e, std::uint64_t bytes);

/// "512 B", "900 KiB", "11.7 KiB", "1.1 MiB" (one decimal, ".0" dropped).
std::string format_bytes(std::uint64_t n);

/// Where a descriptor's bytes are: "heap" (pool_id 0) or "pool 1 slot 42".
std::string pool_text(std::uint32_t pool_id, std::uint32_t slot_id);

/// "2, 3, 224" (the numbers of a shape, comma separated).
inline std::string join_dims(std::span<const std::uint64_t> dims) {
  std::string out;
  for (std::size_t i = 0; i < dims.size(); ++i) out += (i == 0 ? "" : ", ") + std::to_string(dims[i]);
  return out;
}

inline std::string ascii_lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// Reads / writes a T at a byte offset (memcpy: no alignment or aliasing assumptions).
template <class T>
T load_at(std::span<const std::uint8_t> bytes, std::size_t offset) noexcept {
  T v{};
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}
template <class T>
void store_at(std::span<std::uint8_t> bytes, std::size_t offset, const T& v) noexcept {
  std::memcpy(bytes.data() + offset, &v, sizeof(T));
}

/// True when the fixed text field has a NUL (a descriptor from another process may not).
template <std::size_t N>
constexpr bool has_terminator(const std::array<char, N>& field) noexcept {
  for (char c : field)
    if (c == '\0') return true;
  return false;
}

}  // namespace detail

}  // namespace horus::msg

HORUS_API_END

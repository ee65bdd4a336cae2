// Images: ImageEncoding, ImageDescriptor and the Image class.
//
// Image is a large-data message (see tensor.hpp): a class whose metadata and
// pixel bytes are private and always agree. Pixels are row-major, row y starts
// at byte y * step(), pixel x of a row at x * bytes_per_pixel(encoding()).
// Coordinates are (x, y) = (column, row); constructors take (height, width) as
// the spec's Image::new(480, 640, ...) does.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <new>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "horus/byte_buffer.hpp"
#include "horus/fixed_string.hpp"
#include "horus/msg/tensor.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// Pixel format of an image (values as HORUS's repr(u8) ImageEncoding).
enum class ImageEncoding : std::uint8_t {
  Mono8 = 0,       ///< 8-bit grey, 1 channel
  Mono16 = 1,      ///< 16-bit grey, 1 channel
  Rgb8 = 2,        ///< 8-bit RGB, 3 channels (HORUS's default)
  Bgr8 = 3,        ///< 8-bit BGR (OpenCV order), 3 channels
  Rgba8 = 4,       ///< 8-bit RGBA, 4 channels
  Bgra8 = 5,       ///< 8-bit BGRA, 4 channels
  Yuv422 = 6,      ///< YUV 4:2:2, 2 bytes per pixel, 2 channels
  Mono32F = 7,     ///< 32-bit float grey, 1 channel
  Rgb32F = 8,      ///< 32-bit float RGB, 3 channels
  BayerRggb8 = 9,  ///< raw Bayer RGGB sensor data, 1 byte per pixel
  Depth16 = 10,    ///< 16-bit depth in millimetres, 1 channel
};
HORUS_REFLECT_ENUM(ImageEncoding, Mono8, Mono16, Rgb8, Bgr8, Rgba8, Bgra8, Yuv422, Mono32F, Rgb32F, BayerRggb8,
                   Depth16)

/// Bytes per pixel of enc (Rgb32F: 12); 0 for a value that names no encoding.
constexpr std::uint32_t bytes_per_pixel(ImageEncoding enc) noexcept {
  switch (enc) {
    case ImageEncoding::Mono8:
    case ImageEncoding::BayerRggb8: return 1;
    case ImageEncoding::Mono16:
    case ImageEncoding::Yuv422:
    case ImageEncoding::Depth16: return 2;
    case ImageEncoding::Rgb8:
    case ImageEncoding::Bgr8: return 3;
    case ImageEncoding::Rgba8:
    case ImageEncoding::Bgra8:
    case ImageEncoding::Mono32F: return 4;
    case ImageEncoding::Rgb32F: return 12;
  }
  return 0;
}

/// Channels of enc (Yuv422: 2); 0 for a value that names no encoding.
constexpr std::uint32_t channels(ImageEncoding enc) noexcept {
  switch (enc) {
    case ImageEncoding::Mono8:
    case ImageEncoding::Mono16:
    case ImageEncoding::Mono32F:
    case ImageEncoding::BayerRggb8:
    case ImageEncoding::Depth16: return 1;
    case ImageEncoding::Yuv422: return 2;
    case ImageEncoding::Rgb8:
    case ImageEncoding::Bgr8:
    case ImageEncoding::Rgb32F: return 3;
    case ImageEncoding::Rgba8:
    case ImageEncoding::Bgra8: return 4;
  }
  return 0;
}

/// Element type of one channel of enc (U8, U16 or F32), as HORUS's
/// ImageEncoding::tensor_dtype; nullopt for an unknown value.
constexpr std::optional<TensorDtype> tensor_dtype(ImageEncoding enc) noexcept {
  switch (enc) {
    case ImageEncoding::Mono8:
    case ImageEncoding::Rgb8:
    case ImageEncoding::Bgr8:
    case ImageEncoding::Rgba8:
    case ImageEncoding::Bgra8:
    case ImageEncoding::Yuv422:
    case ImageEncoding::BayerRggb8: return TensorDtype::U8;
    case ImageEncoding::Mono16:
    case ImageEncoding::Depth16: return TensorDtype::U16;
    case ImageEncoding::Mono32F:
    case ImageEncoding::Rgb32F: return TensorDtype::F32;
  }
  return std::nullopt;
}

namespace detail {
std::string encoding_text(ImageEncoding e);
}  // namespace detail

// ---------------------------------------------------------------------------
/// Fixed-size description of an Image: what travels through a topic while the
/// pixels stay in the shared-memory pool (HORUS's 224-byte ImageDescriptor
/// holds the same information in a nested Tensor).
struct ImageDescriptor {
  std::uint32_t width{};   ///< pixels
  std::uint32_t height{};  ///< pixels
  ImageEncoding encoding{ImageEncoding::Rgb8};
  std::uint32_t step{};               ///< bytes per row (>= width * bytes_per_pixel)
  std::array<char, 32> frame_id{};    ///< camera frame, NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};       ///< ns since the epoch
  std::uint64_t data_size{};          ///< bytes of pixel data (step * height)
  // Location of the bytes: filled by the shared-memory pool (next issue); 0 = heap.
  std::uint32_t pool_id{};     ///< pool holding the bytes; 0 = heap (not in a pool)
  std::uint32_t slot_id{};     ///< slot within the pool
  std::uint64_t generation{};  ///< slot generation (guards against reuse of a freed slot)
  std::uint64_t offset{};      ///< byte offset of the data from the pool base

  bool set_frame_id(std::string_view text) noexcept { return set_fixed_str(frame_id, text); }
  std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }

  /// "ImageDescriptor(640x480 Rgb8, 900 KiB, heap)" or "..., pool 1 slot 42)".
  std::string log_summary() const;

  friend constexpr bool operator==(const ImageDescriptor&, const ImageDescriptor&) = default;
};
HORUS_REFLECT(ImageDescriptor, width, height, encoding, step, frame_id, timestamp_ns, data_size, pool_id, slot_id,
              generation, offset)
static_assert(horus::reflect::is_fixed_size<ImageDescriptor>,
              "ImageDescriptor must be trivially copyable and standard layout");

// ---------------------------------------------------------------------------
/// A camera image.
///
///   Image img(480, 640, ImageEncoding::Rgb8);          // height, width: zero-filled
///   img.set_pixel(100, 200, {255, 0, 0});              // x = 100, y = 200
///   auto px = img.pixel(100, 200);                     // optional<span<const uint8_t>>
///
/// A default-constructed Image is empty (0x0, Rgb8, no data). Copying an Image
/// copies its pixels.
class Image : public LargeData<Image, ImageDescriptor> {
 public:
  /// Largest encoded image a Topic<Image> carries unless told otherwise: a 1920x1080 RGBA8 frame.
  static constexpr std::size_t kDefaultSlotBytes = std::size_t{8} << 20;
  /// Empty image: 0x0, Rgb8, no data.
  Image() = default;

  /// A zero-filled height x width image, step = width * bytes_per_pixel.
  /// Throws std::invalid_argument naming the problem when a dimension is 0, the
  /// encoding is unknown, or the size overflows or exceeds kMaxLargeDataBytes (2 GiB).
  Image(std::uint32_t height, std::uint32_t width, ImageEncoding encoding);

  /// Non-throwing form of the constructor: nullopt for invalid arguments or
  /// when the memory cannot be allocated.
  static std::optional<Image> create(std::uint32_t height, std::uint32_t width, ImageEncoding encoding) noexcept {
    std::uint64_t bytes = 0;
    if (check(height, width, encoding, bytes) != detail::SizeError::None) return std::nullopt;
    try {
      Image img;
      img.init(height, width, encoding, bytes);
      return img;
    } catch (const std::bad_alloc&) {
      return std::nullopt;
    }
  }

  // --- metadata -----------------------------------------------------------
  std::uint32_t width() const noexcept { return width_; }    ///< pixels
  std::uint32_t height() const noexcept { return height_; }  ///< pixels
  ImageEncoding encoding() const noexcept { return encoding_; }
  std::uint32_t channels() const noexcept { return msg::channels(encoding_); }
  std::uint32_t bytes_per_pixel() const noexcept { return msg::bytes_per_pixel(encoding_); }
  std::uint32_t step() const noexcept { return step_; }  ///< bytes per row

  /// Camera frame name (at most 31 characters).
  std::string_view frame_id() const noexcept { return fixed_str_view(frame_id_); }
  /// Sets the frame name. False, changing nothing, when it does not fit
  /// (at most 31 characters, no NUL); HORUS would cut it to 31 bytes instead.
  bool set_frame_id(std::string_view id) noexcept { return set_fixed_str(frame_id_, id); }
  std::uint64_t timestamp_ns() const noexcept { return timestamp_ns_; }  ///< ns since the epoch
  Image& set_timestamp_ns(std::uint64_t ns) noexcept {
    timestamp_ns_ = ns;
    return *this;
  }

  // --- pixels -------------------------------------------------------------
  std::span<const std::uint8_t> data() const noexcept { return data_.view(); }
  /// Writable bytes; a received (borrowed, read-only) buffer is copied first (ByteBuffer).
  std::span<std::uint8_t> data_mut() { return data_.mutable_view(); }

  /// The bytes of pixel (x, y), or nullopt when x >= width() or y >= height().
  std::optional<std::span<const std::uint8_t>> pixel(std::uint32_t x, std::uint32_t y) const noexcept {
    const auto off = pixel_offset(x, y);
    if (!off) return std::nullopt;
    return std::span<const std::uint8_t>(data_).subspan(*off, bytes_per_pixel());
  }

  /// Writes pixel (x, y). False, changing nothing, when (x, y) is out of bounds
  /// or value.size() != bytes_per_pixel(). (HORUS returns &mut Self and
  /// silently ignores these cases; the bool lets a caller notice them.)
  bool set_pixel(std::uint32_t x, std::uint32_t y, std::span<const std::uint8_t> value) {
    const auto off = pixel_offset(x, y);
    if (!off || value.size() != bytes_per_pixel()) return false;
    std::memcpy(data_.data() + *off, value.data(), value.size());
    return true;
  }
  /// set_pixel(x, y, {255, 0, 0}).
  bool set_pixel(std::uint32_t x, std::uint32_t y, std::initializer_list<std::uint8_t> value) {
    return set_pixel(x, y, std::span<const std::uint8_t>(value.begin(), value.size()));
  }

  /// Copies a whole image's bytes (src.size() must equal data().size(), row
  /// padding included). False, copying nothing, otherwise (HORUS panics).
  bool copy_from(std::span<const std::uint8_t> src) {
    if (src.size() != data_.size()) return false;
    if (!src.empty()) std::memcpy(data_.data(), src.data(), src.size());
    return true;
  }

  /// Sets every pixel to value. Does nothing when value.size() != bytes_per_pixel()
  /// (as HORUS). Row padding bytes (step > width * bpp) are left alone.
  Image& fill(std::span<const std::uint8_t> value) {
    const std::size_t bpp = bytes_per_pixel();
    if (bpp == 0 || value.size() != bpp || !is_consistent()) return *this;
    for (std::uint32_t y = 0; y < height_; ++y) {
      std::uint8_t* row = data_.data() + static_cast<std::size_t>(y) * step_;
      for (std::uint32_t x = 0; x < width_; ++x)
        std::memcpy(row + static_cast<std::size_t>(x) * bpp, value.data(), bpp);
    }
    return *this;
  }
  /// fill({0, 0, 255}).
  Image& fill(std::initializer_list<std::uint8_t> value) {
    return fill(std::span<const std::uint8_t>(value.begin(), value.size()));
  }

  /// The pixels of the w x h rectangle at (x, y), rows concatenated without
  /// padding (w * h * bytes_per_pixel() bytes; empty when w or h is 0).
  /// nullopt when the rectangle crosses the right or bottom border
  /// (x + w > width() or y + h > height(), computed without overflow).
  std::optional<std::vector<std::uint8_t>> roi(std::uint32_t x, std::uint32_t y, std::uint32_t w,
                                               std::uint32_t h) const {
    if (std::uint64_t{x} + w > width_ || std::uint64_t{y} + h > height_ || !is_consistent()) return std::nullopt;
    const std::size_t bpp = bytes_per_pixel();
    const std::size_t row_bytes = static_cast<std::size_t>(w) * bpp;
    std::vector<std::uint8_t> out(row_bytes * h);
    for (std::uint32_t r = 0; r < h; ++r) {
      const std::size_t src = static_cast<std::size_t>(y + r) * step_ + static_cast<std::size_t>(x) * bpp;
      if (row_bytes != 0) std::memcpy(out.data() + r * row_bytes, data_.data() + src, row_bytes);
    }
    return out;
  }

  // --- descriptor ---------------------------------------------------------
  /// The fixed-size description of this image (pool fields 0: heap).
  ImageDescriptor descriptor() const noexcept {
    ImageDescriptor d{};
    d.width = width_;
    d.height = height_;
    d.encoding = encoding_;
    d.step = step_;
    d.frame_id = frame_id_;
    d.timestamp_ns = timestamp_ns_;
    d.data_size = data_.size();
    return d;
  }

  /// The descriptor of such a message without allocating its bytes: what Topic<Image>::loan
  /// takes to lend a pool slot. nullopt for the arguments the constructor refuses.
  static std::optional<ImageDescriptor> describe(std::uint32_t height, std::uint32_t width, ImageEncoding encoding) noexcept {
    std::uint64_t bytes = 0;
    if (check(height, width, encoding, bytes) != detail::SizeError::None) return std::nullopt;
    Image x;
    x.init_meta(height, width, encoding);
    ImageDescriptor d = x.descriptor();
    d.data_size = bytes;
    return d;
  }

 private:
  friend class LargeData<Image, ImageDescriptor>;
  /// What from_descriptor and adopt (LargeData) call.
  /// Rebuilds an image from its descriptor and pixel bytes (copied). nullopt
  /// unless width and height are > 0, the encoding is known, step >= width *
  /// bytes_per_pixel (a padded step is kept), data_size == step * height <=
  /// kMaxLargeDataBytes, bytes.size() == data_size and frame_id is
  /// NUL-terminated. The pool fields are not used (bytes are given).
  template <class Bytes>
  static std::optional<Image> build(const ImageDescriptor& desc, Bytes&& bytes) {
    std::uint64_t min_size = 0;
    if (check(desc.height, desc.width, desc.encoding, min_size) != detail::SizeError::None) return std::nullopt;
    const std::uint64_t row = std::uint64_t{desc.width} * msg::bytes_per_pixel(desc.encoding);
    std::uint64_t size = 0;
    if (desc.step < row || !detail::checked_mul(desc.step, desc.height, size)) return std::nullopt;
    if (size != desc.data_size || size > kMaxLargeDataBytes || bytes.size() != size) return std::nullopt;
    if (!detail::has_terminator(desc.frame_id)) return std::nullopt;
    std::optional<Image> img;
    img.emplace(Key{}, desc, keep(std::forward<Bytes>(bytes)));  // built in place: no default object overwritten
    return img;
  }

 public:
  /// Only Image itself can name a Key: the constructor below is for build().
  class Key {
    friend class Image;
    Key() = default;
  };
  Image(Key, const ImageDescriptor& desc, ByteBuffer&& bytes) noexcept
      : width_(desc.width),
        height_(desc.height),
        encoding_(desc.encoding),
        step_(desc.step),
        frame_id_(desc.frame_id),
        timestamp_ns_(desc.timestamp_ns),
        data_(std::move(bytes)) {}

 private:

 public:

  /// True when the metadata describes the bytes exactly (known encoding,
  /// step >= width * bpp, data().size() == step * height); false e.g. for an
  /// image read from hand-edited JSON. Always true for one made here (the
  /// empty image included). Pixel accessors check bounds either way.
  bool is_consistent() const noexcept {
    const std::uint32_t bpp = bytes_per_pixel();
    if (bpp == 0) return false;
    return std::uint64_t{step_} >= std::uint64_t{width_} * bpp &&
           data_.size() == std::uint64_t{step_} * std::uint64_t{height_};
  }

  /// "Image(640x480 Rgb8, 900 KiB)".
  std::string log_summary() const;

  friend bool operator==(const Image&, const Image&) = default;

 private:
  std::uint32_t width_{};
  std::uint32_t height_{};
  ImageEncoding encoding_{ImageEncoding::Rgb8};
  std::uint32_t step_{};
  std::array<char, 32> frame_id_{};
  std::uint64_t timestamp_ns_{};
  ByteBuffer data_;

  HORUS_REFLECT_FRIEND(Image)

  static detail::SizeError check(std::uint32_t height, std::uint32_t width, ImageEncoding encoding,
                                 std::uint64_t& bytes) noexcept {
    const std::uint32_t bpp = msg::bytes_per_pixel(encoding);
    if (bpp == 0) return detail::SizeError::UnknownType;
    if (width == 0 || height == 0) return detail::SizeError::ZeroDimension;
    // width * height * bpp < 2^32 * 2^32 * 2^4: can overflow 64 bits.
    std::uint64_t n = std::uint64_t{width} * height;
    if (!detail::checked_mul(n, bpp, n)) return detail::SizeError::Overflow;
    bytes = n;
    if (n > kMaxLargeDataBytes) return detail::SizeError::TooLarge;
    // A row must fit the u32 step (guaranteed by the 2 GiB limit).
    return detail::SizeError::None;
  }

  void init(std::uint32_t height, std::uint32_t width, ImageEncoding encoding, std::uint64_t bytes) {
    init_meta(height, width, encoding);
    data_.assign(static_cast<std::size_t>(bytes), std::uint8_t{0});
  }
  void init_meta(std::uint32_t height, std::uint32_t width, ImageEncoding encoding) noexcept {
    width_ = width;
    height_ = height;
    encoding_ = encoding;
    step_ = width * msg::bytes_per_pixel(encoding);  // <= 2^31 (checked)
  }

  // Byte offset of pixel (x, y) when it is inside the image and inside data_.
  std::optional<std::size_t> pixel_offset(std::uint32_t x, std::uint32_t y) const noexcept {
    if (x >= width_ || y >= height_) return std::nullopt;
    const std::uint64_t bpp = bytes_per_pixel();
    const std::uint64_t off = std::uint64_t{y} * step_ + std::uint64_t{x} * bpp;
    if (bpp == 0 || off + bpp > data_.size()) return std::nullopt;
    return static_cast<std::size_t>(off);
  }
};
HORUS_REFLECT_AS(Image, (width, width_), (height, height_), (encoding, encoding_), (step, step_),
                 (frame_id, frame_id_), (timestamp_ns, timestamp_ns_), (data, data_))

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(Image, ImageDescriptor)

}  // namespace horus::msg

HORUS_API_END

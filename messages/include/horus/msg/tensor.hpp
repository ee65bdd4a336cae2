// Tensors: TensorDtype, Device, TensorDescriptor and the Tensor class. The pieces every
// large-data message shares (the 2 GiB size limit, byte-count formatting) are in
// large_data.hpp. Image (image.hpp), PointCloud and DepthImage (perception.hpp)
// build on this header; perception.hpp includes it.
//
// Large-data messages are classes, not plain structs: their metadata and bytes
// are private so that the two always agree. The bytes live in a ByteBuffer: owned
// heap bytes, or a borrowed pool slot when the message came through a topic (only the
// fixed-size *Descriptor travels through the ring). The accessor API is
// storage-agnostic (data() is a std::span). from_descriptor(desc, bytes) rebuilds an object from
// a descriptor and its bytes, validating every size.
//
// Byte order of element data is the host's (little-endian on every supported
// target, as HORUS's from_le_bytes / to_le_bytes).
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
#include "horus/msg/large_data.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {


// ---------------------------------------------------------------------------
/// Element type of tensor data (values as HORUS's repr(u8) TensorDtype).
enum class TensorDtype : std::uint8_t {
  F32 = 0,   ///< 32-bit float (default)
  F64 = 1,   ///< 64-bit float
  F16 = 2,   ///< IEEE half precision
  BF16 = 3,  ///< bfloat16
  I8 = 4,
  I16 = 5,
  I32 = 6,
  I64 = 7,
  U8 = 8,  ///< common for images
  U16 = 9,
  U32 = 10,
  U64 = 11,
  Bool = 12,  ///< stored as one byte
};
HORUS_REFLECT_ENUM(TensorDtype, F32, F64, F16, BF16, I8, I16, I32, I64, U8, U16, U32, U64, Bool)

/// Bytes per element of dtype; 0 for a value that names no TensorDtype.
constexpr std::size_t element_size(TensorDtype dtype) noexcept {
  switch (dtype) {
    case TensorDtype::I8:
    case TensorDtype::U8:
    case TensorDtype::Bool: return 1;
    case TensorDtype::F16:
    case TensorDtype::BF16:
    case TensorDtype::I16:
    case TensorDtype::U16: return 2;
    case TensorDtype::F32:
    case TensorDtype::I32:
    case TensorDtype::U32: return 4;
    case TensorDtype::F64:
    case TensorDtype::I64:
    case TensorDtype::U64: return 8;
  }
  return 0;
}

namespace detail {
/// "F32", or "dtype99" for a value that names no TensorDtype.
std::string dtype_text(TensorDtype d);
}  // namespace detail

/// DLPack type code of booleans. The v0.6 header (Debian's libdlpack-dev) has
/// no kDLBool; DLPack 0.8 added it as 6, which HORUS uses too.
inline constexpr std::uint8_t kDLPackBoolCode = 6;

/// DLPack type of dtype (lanes = 1): F16/F32/F64 -> kDLFloat 16/32/64,
/// BF16 -> kDLBfloat 16, I8..I64 -> kDLInt 8..64, U8..U64 -> kDLUInt 8..64,
/// Bool -> code 6 (kDLBool of DLPack >= 0.8), 8 bits. nullopt for an unknown value.
constexpr std::optional<DLDataType> to_dlpack_dtype(TensorDtype dtype) noexcept {
  const auto bits = static_cast<std::uint8_t>(element_size(dtype) * 8);
  switch (dtype) {
    case TensorDtype::F16:
    case TensorDtype::F32:
    case TensorDtype::F64: return DLDataType{static_cast<std::uint8_t>(kDLFloat), bits, 1};
    case TensorDtype::BF16: return DLDataType{static_cast<std::uint8_t>(kDLBfloat), bits, 1};
    case TensorDtype::I8:
    case TensorDtype::I16:
    case TensorDtype::I32:
    case TensorDtype::I64: return DLDataType{static_cast<std::uint8_t>(kDLInt), bits, 1};
    case TensorDtype::U8:
    case TensorDtype::U16:
    case TensorDtype::U32:
    case TensorDtype::U64: return DLDataType{static_cast<std::uint8_t>(kDLUInt), bits, 1};
    case TensorDtype::Bool: return DLDataType{kDLPackBoolCode, 8, 1};
  }
  return std::nullopt;
}

/// The TensorDtype of a DLPack type (inverse of to_dlpack_dtype); nullopt for
/// vector types (lanes != 1), complex, opaque handles and unsupported widths.
constexpr std::optional<TensorDtype> dtype_from_dlpack(DLDataType t) noexcept {
  if (t.lanes != 1) return std::nullopt;
  switch (t.code) {
    case kDLFloat:
      if (t.bits == 16) return TensorDtype::F16;
      if (t.bits == 32) return TensorDtype::F32;
      if (t.bits == 64) return TensorDtype::F64;
      return std::nullopt;
    case kDLBfloat: return t.bits == 16 ? std::optional(TensorDtype::BF16) : std::nullopt;
    case kDLInt:
      if (t.bits == 8) return TensorDtype::I8;
      if (t.bits == 16) return TensorDtype::I16;
      if (t.bits == 32) return TensorDtype::I32;
      if (t.bits == 64) return TensorDtype::I64;
      return std::nullopt;
    case kDLUInt:
      if (t.bits == 8) return TensorDtype::U8;
      if (t.bits == 16) return TensorDtype::U16;
      if (t.bits == 32) return TensorDtype::U32;
      if (t.bits == 64) return TensorDtype::U64;
      return std::nullopt;
    case kDLPackBoolCode: return t.bits == 8 ? std::optional(TensorDtype::Bool) : std::nullopt;
    default: return std::nullopt;
  }
}

// ---------------------------------------------------------------------------
/// Kind of device tensor data lives on (HORUS's DEVICE_TYPE_CPU = 0, DEVICE_TYPE_CUDA = 1).
enum class DeviceType : std::uint8_t { Cpu = 0, Cuda = 1 };
HORUS_REFLECT_ENUM(DeviceType, Cpu, Cuda)

/// Where tensor data resides: the CPU, or CUDA GPU number device_id (any index).
/// 8 bytes, like HORUS's Device. (HORUS serialises it as the text "cuda:1";
/// here JSON shows the two fields, and log_summary() gives the text.)
struct Device {
  DeviceType device_type{DeviceType::Cpu};
  std::uint32_t device_id{};  ///< GPU index for Cuda, 0 for Cpu

  static constexpr Device cpu() noexcept { return Device{}; }
  static constexpr Device cuda(std::uint32_t index) noexcept { return Device{DeviceType::Cuda, index}; }

  constexpr bool is_cpu() const noexcept { return device_type == DeviceType::Cpu; }
  constexpr bool is_cuda() const noexcept { return device_type == DeviceType::Cuda; }

  /// Parses "cpu", "cuda" / "gpu" (= GPU 0), "cuda:N" / "gpu:N", any letter case.
  /// nullopt for anything else (including a missing or non-numeric index).
  static std::optional<Device> parse(std::string_view text) noexcept {
    std::array<char, 16> buf{};
    if (text.size() >= buf.size()) return std::nullopt;
    for (std::size_t i = 0; i < text.size(); ++i)
      buf[i] = static_cast<char>(std::tolower(static_cast<unsigned char>(text[i])));
    const std::string_view s(buf.data(), text.size());
    if (s == "cpu") return cpu();
    if (s == "cuda" || s == "gpu") return cuda(0);
    std::string_view index;
    if (s.starts_with("cuda:")) index = s.substr(5);
    else if (s.starts_with("gpu:")) index = s.substr(4);
    else return std::nullopt;
    std::uint32_t id{};
    const auto [end, ec] = std::from_chars(index.data(), index.data() + index.size(), id);
    if (index.empty() || ec != std::errc{} || end != index.data() + index.size()) return std::nullopt;
    return cuda(id);
  }

  /// "cpu" or "cuda:N" (an unknown device_type prints as "device<type>:N").
  std::string log_summary() const;

  friend constexpr bool operator==(const Device&, const Device&) = default;
};
HORUS_REFLECT(Device, device_type, device_id)

// ---------------------------------------------------------------------------
/// Fixed-size description of a Tensor: what travels through a topic while the
/// bytes stay in the shared-memory pool. Strides are in bytes, as in HORUS.
struct TensorDescriptor {
  static constexpr std::size_t kMaxDims = 8;

  std::array<std::uint64_t, kMaxDims> shape{};    ///< entries [0, ndim) in use
  std::array<std::uint64_t, kMaxDims> strides{};  ///< bytes between neighbours along each axis
  std::uint8_t ndim{};                            ///< 1..8 (0 = empty tensor)
  TensorDtype dtype{TensorDtype::F32};
  Device device{};
  std::uint64_t data_size{};  ///< bytes of the data block
  // Location of the bytes: filled by the shared-memory pool (next issue); 0 = heap.
  std::uint32_t pool_id{};     ///< pool holding the bytes; 0 = heap (not in a pool)
  std::uint32_t slot_id{};     ///< slot within the pool
  std::uint64_t generation{};  ///< slot generation (guards against reuse of a freed slot)
  std::uint64_t offset{};      ///< byte offset of the data from the pool base

  /// "TensorDescriptor([2, 3] F32 cpu, 24 B, heap)" or "..., pool 1 slot 42)".
  std::string log_summary() const;

  friend constexpr bool operator==(const TensorDescriptor&, const TensorDescriptor&) = default;
};
HORUS_REFLECT(TensorDescriptor, shape, strides, ndim, dtype, device, data_size, pool_id, slot_id, generation, offset)

static_assert(horus::reflect::is_fixed_size<Device>, "Device must be trivially copyable and standard layout");
static_assert(sizeof(Device) == 8, "Device is 8 bytes, as HORUS's");
static_assert(horus::reflect::is_fixed_size<TensorDescriptor>,
              "TensorDescriptor must be trivially copyable and standard layout");

// ---------------------------------------------------------------------------
/// An n-dimensional array (1 to 8 dimensions) of one TensorDtype, row-major.
///
///   Tensor t({2, 3, 224, 224}, TensorDtype::F32);   // zero-filled, 1.1 MiB
///   t.data_mut()[0] = 1;
///   DLManagedTensor* m = std::move(t).to_dlpack();   // hand over to PyTorch / NumPy
///
/// shape()[i] are the dimensions, strides()[i] the byte distance between
/// neighbouring elements along axis i (HORUS's convention; DLPack counts
/// elements, to_dlpack converts). A default-constructed Tensor is empty: ndim 0,
/// no data. Copying a Tensor copies its bytes.
class Tensor : public LargeData<Tensor, TensorDescriptor> {
 public:
  /// Largest encoded tensor a Topic<Tensor> carries unless told otherwise (8 MiB).
  static constexpr std::size_t kDefaultSlotBytes = std::size_t{8} << 20;
  static constexpr std::size_t kMaxDims = TensorDescriptor::kMaxDims;

  /// Empty tensor (ndim 0, numel 0, no data).
  Tensor() = default;

  /// Zero-filled, contiguous tensor. Throws std::invalid_argument naming the
  /// problem when shape has no or more than 8 dimensions, a dimension is 0,
  /// dtype is unknown, or the size overflows or exceeds kMaxLargeDataBytes.
  /// device is recorded as metadata: the bytes are host memory either way
  /// (until a device pool exists), so to_dlpack() refuses a non-CPU tensor.
  Tensor(std::span<const std::uint64_t> shape, TensorDtype dtype, Device device = Device::cpu());
  Tensor(std::initializer_list<std::uint64_t> shape, TensorDtype dtype, Device device = Device::cpu())
      : Tensor(std::span<const std::uint64_t>(shape.begin(), shape.size()), dtype, device) {}

  /// Non-throwing form of the constructor: nullopt for invalid arguments or
  /// when the memory cannot be allocated.
  static std::optional<Tensor> create(std::span<const std::uint64_t> shape, TensorDtype dtype,
                                      Device device = Device::cpu()) noexcept {
    std::uint64_t bytes = 0;
    if (check(shape, dtype, bytes) != detail::SizeError::None) return std::nullopt;
    try {
      Tensor t;
      t.init(shape, dtype, device, bytes);
      return t;
    } catch (const std::bad_alloc&) {
      return std::nullopt;
    }
  }
  static std::optional<Tensor> create(std::initializer_list<std::uint64_t> shape, TensorDtype dtype,
                                      Device device = Device::cpu()) noexcept {
    return create(std::span<const std::uint64_t>(shape.begin(), shape.size()), dtype, device);
  }

  // --- metadata -----------------------------------------------------------
  /// The dimensions (ndim() entries).
  std::span<const std::uint64_t> shape() const noexcept { return {shape_.data(), dims()}; }
  /// Byte strides (ndim() entries); row-major: last = element_size(dtype()).
  std::span<const std::uint64_t> strides() const noexcept { return {strides_.data(), dims()}; }
  std::uint8_t ndim() const noexcept { return ndim_; }
  TensorDtype dtype() const noexcept { return dtype_; }
  Device device() const noexcept { return device_; }
  bool is_cpu() const noexcept { return device_.is_cpu(); }
  bool is_cuda() const noexcept { return device_.is_cuda(); }
  /// Bytes per element.
  std::size_t element_size() const noexcept { return msg::element_size(dtype_); }

  /// Number of elements: the product of shape(); 0 for an empty tensor (HORUS
  /// gives 1 for ndim 0, but a HORUS tensor always has ndim >= 1).
  std::uint64_t numel() const noexcept {
    if (ndim_ == 0) return 0;
    std::uint64_t n = 1;
    for (std::uint64_t d : shape()) n *= d;
    return n;
  }

  /// Size of the data block in bytes.
  std::uint64_t nbytes() const noexcept { return data_.size(); }

  /// True when the strides are the row-major ones for shape() and dtype()
  /// (always, for a tensor made here; a descriptor may describe a view).
  bool is_contiguous() const noexcept {
    std::uint64_t expected = element_size();
    for (std::size_t i = dims(); i-- > 0;) {
      if (strides_[i] != expected) return false;
      expected *= shape_[i];
    }
    return true;
  }

  // --- data ---------------------------------------------------------------
  std::span<const std::uint8_t> data() const noexcept { return data_.view(); }
  /// Writable bytes; a received (borrowed, read-only) buffer is copied first (ByteBuffer).
  std::span<std::uint8_t> data_mut() { return data_.mutable_view(); }

  /// Copies src into the data block. False (nothing copied) when src.size() != nbytes().
  bool copy_from(std::span<const std::uint8_t> src) {
    if (src.size() != data_.size()) return false;
    if (!src.empty()) std::memcpy(data_.data(), src.data(), src.size());
    return true;
  }

  /// Gives the tensor a new shape with the same element count (row-major view
  /// of the same bytes, as HORUS's Tensor::view). False, changing nothing, when
  /// the element counts differ, new_shape has no or more than 8 dimensions or a
  /// zero dimension, or the tensor is not contiguous.
  bool reshape(std::span<const std::uint64_t> new_shape) noexcept {
    std::uint64_t bytes = 0;
    if (ndim_ == 0 || !is_contiguous() || check(new_shape, dtype_, bytes) != detail::SizeError::None) return false;
    if (bytes != data_.size()) return false;
    set_shape(new_shape);
    return true;
  }
  bool reshape(std::initializer_list<std::uint64_t> new_shape) noexcept {
    return reshape(std::span<const std::uint64_t>(new_shape.begin(), new_shape.size()));
  }

  // --- descriptor ---------------------------------------------------------
  /// The fixed-size description of this tensor (pool fields 0: heap).
  TensorDescriptor descriptor() const noexcept {
    TensorDescriptor d{};
    d.shape = shape_;
    d.strides = strides_;
    d.ndim = ndim_;
    d.dtype = dtype_;
    d.device = device_;
    d.data_size = data_.size();
    return d;
  }

  /// The descriptor of such a message without allocating its bytes: what Topic<Tensor>::loan
  /// takes to lend a pool slot. nullopt for the arguments the constructor refuses.
  static std::optional<TensorDescriptor> describe(std::span<const std::uint64_t> shape, TensorDtype dtype, Device device = Device::cpu()) noexcept {
    std::uint64_t bytes = 0;
    if (check(shape, dtype, bytes) != detail::SizeError::None) return std::nullopt;
    Tensor x;
    x.init_meta(shape, dtype, device);
    TensorDescriptor d = x.descriptor();
    d.data_size = bytes;
    return d;
  }

 private:
  friend class LargeData<Tensor, TensorDescriptor>;
  /// What from_descriptor and adopt (LargeData) call.
  /// Rebuilds a tensor from its descriptor and bytes (copied). nullopt unless
  /// ndim is 1..8, every dimension > 0, dtype known, every stride a multiple of
  /// the element size, the addressed extent within data_size, data_size and
  /// numel * element size <= kMaxLargeDataBytes, and bytes.size() == data_size.
  /// Non-row-major strides (a view, even a broadcast with stride 0) are kept.
  /// The pool fields are not used (bytes are given).
  template <class Bytes>
  static std::optional<Tensor> build(const TensorDescriptor& desc, Bytes&& bytes) {
    const std::size_t elem = msg::element_size(desc.dtype);
    if (desc.ndim == 0 || desc.ndim > kMaxDims || elem == 0) return std::nullopt;
    if (desc.data_size > kMaxLargeDataBytes || bytes.size() != desc.data_size) return std::nullopt;
    std::uint64_t extent = elem;   // last addressed byte + 1
    std::uint64_t logical = elem;  // numel * element size (a broadcast view may exceed data_size)
    for (std::size_t i = 0; i < desc.ndim; ++i) {
      if (desc.shape[i] == 0 || desc.strides[i] % elem != 0) return std::nullopt;
      if (!detail::checked_mul(logical, desc.shape[i], logical) || logical > kMaxLargeDataBytes) return std::nullopt;
      std::uint64_t span_bytes = 0;
      if (!detail::checked_mul(desc.shape[i] - 1, desc.strides[i], span_bytes)) return std::nullopt;
      if (span_bytes > kMaxLargeDataBytes) return std::nullopt;
      extent += span_bytes;
      if (extent > desc.data_size) return std::nullopt;
    }
    Tensor t;
    t.ndim_ = desc.ndim;
    for (std::size_t i = 0; i < desc.ndim; ++i) {
      t.shape_[i] = desc.shape[i];
      t.strides_[i] = desc.strides[i];
    }
    t.dtype_ = desc.dtype;
    t.device_ = desc.device;
    t.data_ = keep(std::forward<Bytes>(bytes));
    return t;
  }

 public:

  // --- DLPack (v0.6 ABI) --------------------------------------------------
  /// Exports a copy of the tensor as a DLManagedTensor owned by the caller, who
  /// must call m->deleter(m) once done (that frees the copy, shape and strides).
  /// dtype mapping: see to_dlpack_dtype(); strides are exported in elements,
  /// byte_offset 0, device kDLCPU. nullptr for an empty (or moved-from, or
  /// inconsistent) tensor or a non-CPU device (the bytes are host memory).
  /// Throws std::bad_alloc on allocation failure.
  DLManagedTensor* to_dlpack() const& {
    if (!exportable()) return nullptr;
    return export_dlpack(data_.to_vector());
  }

  /// Same, but hands the bytes over without copying (the exported data pointer
  /// is the old data().data()); *this is left empty. nullptr (and *this kept)
  /// in the cases above.
  DLManagedTensor* to_dlpack() && {
    if (!exportable()) return nullptr;
    DLManagedTensor* m = export_dlpack(std::move(data_).take_vector());
    *this = Tensor{};
    return m;
  }

  /// Copies a DLPack tensor (any strides, including nullptr = row-major, and
  /// byte_offset) into a new contiguous CPU tensor. ndim 0 (a scalar) becomes
  /// shape [1]. nullopt when the device is not kDLCPU, the type is unsupported
  /// (see dtype_from_dlpack), ndim > 8, a dimension is <= 0, data is null, or
  /// the size exceeds kMaxLargeDataBytes.
  static std::optional<Tensor> from_dlpack(const DLTensor& src) {
    if (src.device.device_type != kDLCPU) return std::nullopt;
    const auto dtype = dtype_from_dlpack(src.dtype);
    if (!dtype || src.ndim < 0 || src.ndim > static_cast<int>(kMaxDims) || src.data == nullptr) return std::nullopt;
    const auto nd = static_cast<std::size_t>(src.ndim);
    if (nd > 0 && src.shape == nullptr) return std::nullopt;
    std::array<std::uint64_t, kMaxDims> dims{};
    for (std::size_t i = 0; i < nd; ++i) {
      if (src.shape[i] <= 0) return std::nullopt;
      dims[i] = static_cast<std::uint64_t>(src.shape[i]);
    }
    const std::size_t out_nd = nd == 0 ? 1 : nd;
    if (nd == 0) dims[0] = 1;
    auto t = create(std::span<const std::uint64_t>(dims.data(), out_nd), *dtype);
    if (!t) return std::nullopt;

    const std::size_t elem = t->element_size();
    const auto* base = static_cast<const std::uint8_t*>(src.data) + src.byte_offset;
    bool contiguous = src.strides == nullptr;
    if (!contiguous) {
      contiguous = true;
      std::int64_t expected = 1;
      for (std::size_t i = nd; i-- > 0;) {
        if (src.shape[i] != 1 && src.strides[i] != expected) contiguous = false;
        expected *= src.shape[i];
      }
    }
    if (contiguous) {
      std::memcpy(t->data_.data(), base, t->data_.size());
      return t;
    }
    // General strides (possibly negative): walk a multi-index in row-major order.
    std::array<std::int64_t, kMaxDims> idx{};
    const std::uint64_t n = t->numel();
    for (std::uint64_t k = 0; k < n; ++k) {
      std::int64_t off = 0;
      for (std::size_t i = 0; i < nd; ++i) off += idx[i] * src.strides[i];
      std::memcpy(t->data_.data() + k * elem, base + off * static_cast<std::int64_t>(elem), elem);
      for (std::size_t i = nd; i-- > 0;) {
        if (++idx[i] < src.shape[i]) break;
        idx[i] = 0;
      }
    }
    return t;
  }

  /// True when the metadata describes the data block exactly (ndim <= 8, a
  /// known dtype, and the strided extent within nbytes()); false e.g. for a
  /// tensor read from hand-edited JSON. Always true for one made here.
  bool is_consistent() const noexcept {
    if (ndim_ == 0) return data_.empty();
    const std::size_t elem = element_size();
    if (ndim_ > kMaxDims || elem == 0) return false;
    std::uint64_t extent = elem;
    for (std::size_t i = 0; i < ndim_; ++i) {
      std::uint64_t s = 0;
      if (shape_[i] == 0 || !detail::checked_mul(shape_[i] - 1, strides_[i], s) || s > kMaxLargeDataBytes)
        return false;
      extent += s;
    }
    return extent <= data_.size();
  }

  /// "Tensor([2, 3, 224, 224] F32 cpu, 1.1 MiB)".
  std::string log_summary() const;

  friend bool operator==(const Tensor&, const Tensor&) = default;

 private:
  std::array<std::uint64_t, kMaxDims> shape_{};
  std::array<std::uint64_t, kMaxDims> strides_{};  // bytes
  std::uint8_t ndim_{};
  TensorDtype dtype_{TensorDtype::F32};
  Device device_{};
  ByteBuffer data_;

  HORUS_REFLECT_FRIEND(Tensor)

  std::size_t dims() const noexcept { return std::min<std::size_t>(ndim_, kMaxDims); }

  static detail::SizeError check(std::span<const std::uint64_t> shape, TensorDtype dtype,
                                 std::uint64_t& bytes) noexcept {
    if (shape.empty() || shape.size() > kMaxDims) return detail::SizeError::BadShape;
    const std::size_t elem = msg::element_size(dtype);
    if (elem == 0) return detail::SizeError::UnknownType;
    std::uint64_t n = elem;
    for (std::uint64_t d : shape)
      if (d == 0) return detail::SizeError::ZeroDimension;
    for (std::uint64_t d : shape)
      if (!detail::checked_mul(n, d, n)) return detail::SizeError::Overflow;
    bytes = n;
    return n > kMaxLargeDataBytes ? detail::SizeError::TooLarge : detail::SizeError::None;
  }

  void set_shape(std::span<const std::uint64_t> shape) noexcept {
    shape_.fill(0);
    strides_.fill(0);
    ndim_ = static_cast<std::uint8_t>(shape.size());
    std::uint64_t stride = element_size();
    for (std::size_t i = shape.size(); i-- > 0;) {
      shape_[i] = shape[i];
      strides_[i] = stride;
      stride *= shape[i];
    }
  }

  void init(std::span<const std::uint64_t> shape, TensorDtype dtype, Device device, std::uint64_t bytes) {
    init_meta(shape, dtype, device);
    data_.assign(static_cast<std::size_t>(bytes), std::uint8_t{0});
  }
  void init_meta(std::span<const std::uint64_t> shape, TensorDtype dtype, Device device) noexcept {
    dtype_ = dtype;
    device_ = device;
    set_shape(shape);
  }

  bool exportable() const noexcept {
    if (ndim_ == 0 || !device_.is_cpu() || !to_dlpack_dtype(dtype_) || !is_consistent()) return false;
    for (std::size_t i = 0; i < ndim_; ++i)
      if (strides_[i] % element_size() != 0) return false;
    return true;
  }

  // What a DLManagedTensor from to_dlpack() owns; freed by its deleter.
  struct DLPackContext {
    DLManagedTensor managed{};
    std::vector<std::uint8_t> bytes;
    std::array<std::int64_t, kMaxDims> shape{};
    std::array<std::int64_t, kMaxDims> strides{};
  };

  // Precondition: exportable().
  DLManagedTensor* export_dlpack(std::vector<std::uint8_t>&& bytes) const {
    auto ctx = std::make_unique<DLPackContext>();
    ctx->bytes = std::move(bytes);
    const auto elem = static_cast<std::uint64_t>(element_size());
    for (std::size_t i = 0; i < ndim_; ++i) {
      ctx->shape[i] = static_cast<std::int64_t>(shape_[i]);
      ctx->strides[i] = static_cast<std::int64_t>(strides_[i] / elem);
    }
    DLTensor& t = ctx->managed.dl_tensor;
    t.data = ctx->bytes.data();
    t.device = DLDevice{kDLCPU, 0};
    t.ndim = static_cast<int>(ndim_);
    t.dtype = *to_dlpack_dtype(dtype_);
    t.shape = ctx->shape.data();
    t.strides = ctx->strides.data();
    t.byte_offset = 0;
    ctx->managed.manager_ctx = ctx.get();
    ctx->managed.deleter = [](DLManagedTensor* self) {
      if (self != nullptr) delete static_cast<DLPackContext*>(self->manager_ctx);
    };
    return &ctx.release()->managed;
  }
};
HORUS_REFLECT_AS(Tensor, (shape, shape_), (strides, strides_), (ndim, ndim_), (dtype, dtype_), (device, device_),
                 (data, data_))

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(Tensor, Device, TensorDescriptor)

}  // namespace horus::msg

HORUS_API_END

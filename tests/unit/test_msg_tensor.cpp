// Unit tests of TensorDtype, Device and Tensor (tensor.hpp).
#include "msg_perception_test.hpp"

namespace {

// ===========================================================================
// TensorDtype and Device

TEST(TensorDtype, ElementSizesAndValuesAreHorusOnes) {
  const std::array<std::pair<TensorDtype, std::size_t>, 13> sizes{{{TensorDtype::F32, 4},
                                                                    {TensorDtype::F64, 8},
                                                                    {TensorDtype::F16, 2},
                                                                    {TensorDtype::BF16, 2},
                                                                    {TensorDtype::I8, 1},
                                                                    {TensorDtype::I16, 2},
                                                                    {TensorDtype::I32, 4},
                                                                    {TensorDtype::I64, 8},
                                                                    {TensorDtype::U8, 1},
                                                                    {TensorDtype::U16, 2},
                                                                    {TensorDtype::U32, 4},
                                                                    {TensorDtype::U64, 8},
                                                                    {TensorDtype::Bool, 1}}};
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    EXPECT_EQ(static_cast<std::size_t>(sizes[i].first), i);  // F32 = 0 ... Bool = 12
    EXPECT_EQ(element_size(sizes[i].first), sizes[i].second) << to_string(sizes[i].first);
  }
  EXPECT_EQ(element_size(static_cast<TensorDtype>(13)), 0u);
  EXPECT_EQ(horus::reflect::enum_values<TensorDtype>().size(), 13u);
}

TEST(TensorDtype, DlpackMappingRoundTripsEveryDtype) {
  for (const auto& v : horus::reflect::enum_values<TensorDtype>()) {
    const auto dl = to_dlpack_dtype(v.value);
    ASSERT_TRUE(dl.has_value()) << v.name;
    EXPECT_EQ(dl->lanes, 1u);
    EXPECT_EQ(dl->bits, element_size(v.value) * 8) << v.name;
    EXPECT_EQ(dtype_from_dlpack(*dl), v.value) << v.name;
  }
  const auto f32 = *to_dlpack_dtype(TensorDtype::F32);
  EXPECT_EQ(f32.code, kDLFloat);
  const auto bf16 = *to_dlpack_dtype(TensorDtype::BF16);
  EXPECT_EQ(bf16.code, kDLBfloat);
  EXPECT_EQ(to_dlpack_dtype(TensorDtype::I16)->code, kDLInt);
  EXPECT_EQ(to_dlpack_dtype(TensorDtype::U64)->code, kDLUInt);
  EXPECT_EQ(to_dlpack_dtype(TensorDtype::Bool)->code, 6);  // kDLBool of DLPack >= 0.8
  EXPECT_EQ(to_dlpack_dtype(static_cast<TensorDtype>(20)), std::nullopt);

  EXPECT_EQ(dtype_from_dlpack(DLDataType{kDLFloat, 32, 4}), std::nullopt);  // vector type
  EXPECT_EQ(dtype_from_dlpack(DLDataType{kDLComplex, 64, 1}), std::nullopt);
  EXPECT_EQ(dtype_from_dlpack(DLDataType{kDLFloat, 8, 1}), std::nullopt);
  EXPECT_EQ(dtype_from_dlpack(DLDataType{kDLBfloat, 32, 1}), std::nullopt);
  EXPECT_EQ(dtype_from_dlpack(DLDataType{kDLOpaqueHandle, 64, 1}), std::nullopt);
}

TEST(Device, CpuAndCudaWithAnyIndex) {
  static_assert(sizeof(Device) == 8 && horus::reflect::is_fixed_size<Device>);
  EXPECT_TRUE(Device::cpu().is_cpu());
  EXPECT_FALSE(Device::cpu().is_cuda());
  EXPECT_EQ(Device{}, Device::cpu());
  const Device g = Device::cuda(7);
  EXPECT_TRUE(g.is_cuda());
  EXPECT_EQ(g.device_id, 7u);
  EXPECT_NE(Device::cuda(0), Device::cpu());
  EXPECT_EQ(Device::cpu().log_summary(), "cpu");
  EXPECT_EQ(g.log_summary(), "cuda:7");
}

TEST(Device, ParseAcceptsHorusSpellings) {
  EXPECT_EQ(Device::parse("cpu"), Device::cpu());
  EXPECT_EQ(Device::parse("CPU"), Device::cpu());
  EXPECT_EQ(Device::parse("cuda"), Device::cuda(0));
  EXPECT_EQ(Device::parse("gpu"), Device::cuda(0));
  EXPECT_EQ(Device::parse("CUDA:3"), Device::cuda(3));
  EXPECT_EQ(Device::parse("gpu:15"), Device::cuda(15));
  EXPECT_EQ(Device::parse("cuda:"), std::nullopt);
  EXPECT_EQ(Device::parse("cuda:x"), std::nullopt);
  EXPECT_EQ(Device::parse("cuda:1x"), std::nullopt);
  EXPECT_EQ(Device::parse("cuda:-1"), std::nullopt);
  EXPECT_EQ(Device::parse("cuda:99999999999"), std::nullopt);
  EXPECT_EQ(Device::parse("tpu"), std::nullopt);
  EXPECT_EQ(Device::parse(""), std::nullopt);
}

TEST(Device, JsonRoundTripAndFormatting) {
  ExpectJsonRoundTrip(Device::cuda(3));
  EXPECT_EQ(horus::to_json(Device::cuda(3))["device_type"], "Cuda");
  EXPECT_EQ(fmt::format("{}", Device::cuda(3)), "Device { device_type: Cuda, device_id: 3 }");
}

// ===========================================================================
// Tensor

TEST(Tensor, ShapeStridesAndSizes) {
  const Tensor t({2, 3, 4}, TensorDtype::F32);
  EXPECT_EQ(t.ndim(), 3);
  EXPECT_EQ(std::vector<std::uint64_t>(t.shape().begin(), t.shape().end()), (std::vector<std::uint64_t>{2, 3, 4}));
  EXPECT_EQ(std::vector<std::uint64_t>(t.strides().begin(), t.strides().end()),
            (std::vector<std::uint64_t>{48, 16, 4}));  // bytes, as HORUS
  EXPECT_EQ(t.numel(), 24u);
  EXPECT_EQ(t.nbytes(), 96u);
  EXPECT_EQ(t.element_size(), 4u);
  EXPECT_TRUE(t.is_contiguous());
  EXPECT_TRUE(t.is_cpu());
  EXPECT_EQ(t.dtype(), TensorDtype::F32);
  EXPECT_EQ(to_bytes(t.data()), Bytes(96, 0));

  const std::vector<std::uint64_t> shape{1080, 1920, 3};
  const Tensor img(shape, TensorDtype::U8, Device::cuda(1));
  EXPECT_EQ(img.numel(), 1080u * 1920u * 3u);
  EXPECT_EQ(img.nbytes(), img.numel());
  EXPECT_EQ(img.device(), Device::cuda(1));
  EXPECT_TRUE(img.is_cuda());
}

TEST(Tensor, ConstructorThrowsNamingTheProblem) {
  EXPECT_TRUE(ThrowsNaming([] { Tensor(std::span<const std::uint64_t>{}, TensorDtype::F32); }, {"1 to 8"}));
  EXPECT_TRUE(ThrowsNaming([] { Tensor({1, 1, 1, 1, 1, 1, 1, 1, 1}, TensorDtype::F32); }, {"1 to 8"}));
  EXPECT_TRUE(ThrowsNaming([] { Tensor({2, 0, 3}, TensorDtype::F32); }, {"[2, 0, 3]", "greater than zero"}));
  EXPECT_TRUE(ThrowsNaming([] { Tensor({2}, static_cast<TensorDtype>(13)); }, {"unknown"}));
  EXPECT_TRUE(ThrowsNaming([] { Tensor({(1ULL << 31) + 1}, TensorDtype::U8); }, {"2147483649 bytes"}));
  EXPECT_TRUE(ThrowsNaming([] { Tensor({1ULL << 40, 1ULL << 40}, TensorDtype::F32); }, {"overflows"}));
  EXPECT_EQ(Tensor::create({2, 0}, TensorDtype::F32), std::nullopt);
  EXPECT_EQ(Tensor::create({(1ULL << 31) + 1}, TensorDtype::U8), std::nullopt);
  EXPECT_EQ(Tensor::create({2, 2}, TensorDtype::I16), std::optional(Tensor({2, 2}, TensorDtype::I16)));
}

TEST(Tensor, DefaultIsEmpty) {
  Tensor t;
  EXPECT_EQ(t.ndim(), 0);
  EXPECT_EQ(t.numel(), 0u);
  EXPECT_EQ(t.nbytes(), 0u);
  EXPECT_TRUE(t.shape().empty());
  EXPECT_TRUE(t.is_consistent());
  EXPECT_FALSE(t.reshape({1}));
  EXPECT_EQ(t.to_dlpack(), nullptr);
  EXPECT_EQ(std::move(t).to_dlpack(), nullptr);
}

TEST(Tensor, ReshapeKeepsTheBytesAndNeedsTheSameElementCount) {
  Tensor t({2, 3, 4}, TensorDtype::F32);
  t.data_mut()[5] = 99;
  EXPECT_TRUE(t.reshape({6, 4}));
  EXPECT_EQ(t.ndim(), 2);
  EXPECT_EQ(std::vector<std::uint64_t>(t.strides().begin(), t.strides().end()), (std::vector<std::uint64_t>{16, 4}));
  EXPECT_EQ(t.data()[5], 99);
  EXPECT_EQ(t.numel(), 24u);

  EXPECT_FALSE(t.reshape({5, 5}));
  EXPECT_FALSE(t.reshape({24, 0}));
  EXPECT_FALSE(t.reshape(std::span<const std::uint64_t>{}));
  EXPECT_FALSE(t.reshape({1, 1, 1, 1, 1, 1, 1, 1, 24}));
  EXPECT_EQ(t.shape()[0], 6u);  // unchanged
  EXPECT_TRUE(t.reshape({24}));
  EXPECT_EQ(t.strides()[0], 4u);
}

TEST(Tensor, CopyFromNeedsTheExactSize) {
  Tensor t({3}, TensorDtype::U16);
  const Bytes src{1, 0, 2, 0, 3, 0};
  EXPECT_FALSE(t.copy_from(std::span(src).first(5)));
  EXPECT_EQ(to_bytes(t.data()), Bytes(6, 0));
  EXPECT_TRUE(t.copy_from(src));
  EXPECT_EQ(to_bytes(t.data()), src);
}

// A 2 x 3 F32 tensor holding 0, 1, ..., 5.
Tensor counting_tensor() {
  Tensor t({2, 3}, TensorDtype::F32);
  for (std::uint32_t i = 0; i < 6; ++i) detail::store_at(t.data_mut(), i * 4u, static_cast<float>(i));
  return t;
}

std::vector<float> floats_of(const Tensor& t) {
  std::vector<float> out(t.nbytes() / 4);
  std::memcpy(out.data(), t.data().data(), t.nbytes());
  return out;
}

TEST(Tensor, DescriptorRoundTripKeepsAStridedView) {
  const Tensor t = counting_tensor();
  const TensorDescriptor d = t.descriptor();
  EXPECT_EQ(d.ndim, 2);
  EXPECT_EQ(d.shape[0], 2u);
  EXPECT_EQ(d.strides[1], 4u);
  EXPECT_EQ(d.data_size, 24u);
  EXPECT_EQ(d.pool_id, 0u);
  EXPECT_EQ(Tensor::from_descriptor(d, t.data()), std::optional(t));

  TensorDescriptor view = d;  // the transpose: shape [3, 2], byte strides [4, 12]
  view.shape = {3, 2};
  view.strides = {4, 12};
  const auto tr = Tensor::from_descriptor(view, t.data());
  ASSERT_TRUE(tr.has_value());
  EXPECT_FALSE(tr->is_contiguous());
  EXPECT_TRUE(tr->is_consistent());
  Tensor copy = *tr;
  EXPECT_FALSE(copy.reshape({6}));  // a view cannot be reshaped
}

TEST(Tensor, FromDescriptorAcceptsABroadcastButBoundsItsLogicalSize) {
  const Tensor row = counting_tensor();  // use the first 3 floats as one row
  TensorDescriptor b{};
  b.ndim = 2;
  b.shape = {4, 3};
  b.strides = {0, 4};  // every row is the same bytes
  b.dtype = TensorDtype::F32;
  b.data_size = 12;
  const auto t = Tensor::from_descriptor(b, row.data().first(12));
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(t->numel(), 12u);
  EXPECT_FALSE(t->is_contiguous());
  DLManagedTensor* m = t->to_dlpack();
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(floats_of(*Tensor::from_dlpack(m->dl_tensor)), (std::vector<float>{0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2}));
  m->deleter(m);

  b.shape = {1ULL << 40, 3};  // 12 TiB of logical data over 12 bytes
  EXPECT_EQ(Tensor::from_descriptor(b, row.data().first(12)), std::nullopt);
}

TEST(Tensor, FromDescriptorRejectsMismatchedSizes) {
  const Tensor t = counting_tensor();
  const TensorDescriptor d = t.descriptor();
  const Bytes bytes = to_bytes(t.data());
  EXPECT_EQ(Tensor::from_descriptor(d, std::span(bytes).first(23)), std::nullopt);
  TensorDescriptor bad = d;
  bad.data_size = 20;
  EXPECT_EQ(Tensor::from_descriptor(bad, std::span(bytes).first(20)), std::nullopt);  // extent 24 > 20
  bad = d;
  bad.shape[0] = 3;  // addresses 36 bytes
  EXPECT_EQ(Tensor::from_descriptor(bad, bytes), std::nullopt);
  bad = d;
  bad.strides[1] = 2;  // not a multiple of 4
  EXPECT_EQ(Tensor::from_descriptor(bad, bytes), std::nullopt);
  bad = d;
  bad.ndim = 0;
  EXPECT_EQ(Tensor::from_descriptor(bad, bytes), std::nullopt);
  bad = d;
  bad.ndim = 9;
  EXPECT_EQ(Tensor::from_descriptor(bad, bytes), std::nullopt);
  bad = d;
  bad.shape[1] = 0;
  EXPECT_EQ(Tensor::from_descriptor(bad, bytes), std::nullopt);
  bad = d;
  bad.dtype = static_cast<TensorDtype>(99);
  EXPECT_EQ(Tensor::from_descriptor(bad, bytes), std::nullopt);
}

// Wraps a DLManagedTensor's deleter to count calls (then runs the original).
struct DeleterProbe {
  static inline int calls = 0;
  static inline void (*original)(DLManagedTensor*) = nullptr;
  static void wrapped(DLManagedTensor* m) {
    ++calls;
    original(m);
  }
  static void release(DLManagedTensor* m) {
    original = m->deleter;
    m->deleter = &wrapped;
    m->deleter(m);
  }
};

TEST(Tensor, DlpackExportOfACopyThenImport) {
  const Tensor t = counting_tensor();
  DLManagedTensor* m = t.to_dlpack();
  ASSERT_NE(m, nullptr);
  const DLTensor& dl = m->dl_tensor;
  EXPECT_EQ(dl.ndim, 2);
  EXPECT_EQ(dl.shape[0], 2);
  EXPECT_EQ(dl.shape[1], 3);
  EXPECT_EQ(dl.strides[0], 3);  // elements, not bytes
  EXPECT_EQ(dl.strides[1], 1);
  EXPECT_EQ(dl.device.device_type, kDLCPU);
  EXPECT_EQ(dl.device.device_id, 0);
  EXPECT_EQ(dl.dtype.code, kDLFloat);
  EXPECT_EQ(dl.dtype.bits, 32);
  EXPECT_EQ(dl.dtype.lanes, 1);
  EXPECT_EQ(dl.byte_offset, 0u);
  EXPECT_NE(dl.data, static_cast<const void*>(t.data().data()));  // a copy
  EXPECT_EQ(t.nbytes(), 24u);                                       // the source is untouched

  const auto back = Tensor::from_dlpack(dl);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(*back, t);

  DeleterProbe::calls = 0;
  DeleterProbe::release(m);
  EXPECT_EQ(DeleterProbe::calls, 1);
}

TEST(Tensor, DlpackExportByMoveHandsOverTheBytes) {
  Tensor t = counting_tensor();
  const Tensor expected = t;
  const void* bytes = t.data().data();
  DLManagedTensor* m = std::move(t).to_dlpack();
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->dl_tensor.data, bytes);  // zero-copy
  EXPECT_EQ(t.ndim(), 0);               // NOLINT(bugprone-use-after-move): documented empty state
  EXPECT_EQ(t.nbytes(), 0u);
  const auto back = Tensor::from_dlpack(m->dl_tensor);
  EXPECT_EQ(back, std::optional(expected));
  DeleterProbe::calls = 0;
  DeleterProbe::release(m);
  EXPECT_EQ(DeleterProbe::calls, 1);
}

TEST(Tensor, DlpackExportRefusesANonCpuTensor) {
  Tensor t({4}, TensorDtype::F32, Device::cuda(0));
  EXPECT_EQ(t.to_dlpack(), nullptr);
  EXPECT_EQ(std::move(t).to_dlpack(), nullptr);
  EXPECT_EQ(t.nbytes(), 16u);  // NOLINT(bugprone-use-after-move): kept when refused
}

TEST(Tensor, DlpackExportsAViewWithElementStrides) {
  const Tensor t = counting_tensor();
  TensorDescriptor view = t.descriptor();
  view.shape = {3, 2};
  view.strides = {4, 12};
  const Tensor tr = *Tensor::from_descriptor(view, t.data());
  DLManagedTensor* m = tr.to_dlpack();
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->dl_tensor.strides[0], 1);
  EXPECT_EQ(m->dl_tensor.strides[1], 3);
  const auto back = Tensor::from_dlpack(m->dl_tensor);  // copied contiguous: the transpose
  ASSERT_TRUE(back.has_value());
  EXPECT_TRUE(back->is_contiguous());
  EXPECT_EQ(floats_of(*back), (std::vector<float>{0, 3, 1, 4, 2, 5}));
  m->deleter(m);
}

// A hand-made DLTensor over caller memory.
struct ManualDl {
  std::vector<float> values;
  std::vector<std::int64_t> shape;
  std::vector<std::int64_t> strides;
  DLTensor t{};
  ManualDl(std::vector<float> v, std::vector<std::int64_t> s, std::vector<std::int64_t> st = {})
      : values(std::move(v)), shape(std::move(s)), strides(std::move(st)) {
    t.data = values.data();
    t.device = DLDevice{kDLCPU, 0};
    t.ndim = static_cast<int>(shape.size());
    t.dtype = DLDataType{kDLFloat, 32, 1};
    t.shape = shape.data();
    t.strides = strides.empty() ? nullptr : strides.data();
    t.byte_offset = 0;
  }
};

TEST(Tensor, FromDlpackHandlesNullStridesOffsetsAndNegativeStrides) {
  ManualDl a({0, 1, 2, 3, 4, 5}, {2, 3});  // strides == nullptr: row-major
  auto t = Tensor::from_dlpack(a.t);
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(floats_of(*t), (std::vector<float>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(t->shape()[1], 3u);

  ManualDl b({0, 1, 2, 3, 4, 5}, {2, 2});
  b.t.byte_offset = 8;  // starts at element 2
  EXPECT_EQ(floats_of(*Tensor::from_dlpack(b.t)), (std::vector<float>{2, 3, 4, 5}));

  ManualDl c({0, 1, 2, 3}, {4}, {-1});  // reversed view starting at the last element
  c.t.byte_offset = 12;
  EXPECT_EQ(floats_of(*Tensor::from_dlpack(c.t)), (std::vector<float>{3, 2, 1, 0}));

  ManualDl d({0, 1, 2, 3, 4, 5}, {3, 1}, {2, 99});  // size-1 axis: its stride does not matter
  EXPECT_EQ(floats_of(*Tensor::from_dlpack(d.t)), (std::vector<float>{0, 2, 4}));

  ManualDl s({7}, {});  // a 0-d scalar becomes shape [1]
  auto scalar = Tensor::from_dlpack(s.t);
  ASSERT_TRUE(scalar.has_value());
  EXPECT_EQ(scalar->ndim(), 1);
  EXPECT_EQ(floats_of(*scalar), (std::vector<float>{7}));
}

TEST(Tensor, FromDlpackRejectsWhatItCannotCopy) {
  ManualDl a({0, 1, 2, 3}, {2, 2});
  a.t.device = DLDevice{kDLCUDA, 0};
  EXPECT_EQ(Tensor::from_dlpack(a.t), std::nullopt);
  a.t.device = DLDevice{kDLCPU, 0};
  a.t.dtype = DLDataType{kDLComplex, 64, 1};
  EXPECT_EQ(Tensor::from_dlpack(a.t), std::nullopt);
  a.t.dtype = DLDataType{kDLFloat, 32, 2};
  EXPECT_EQ(Tensor::from_dlpack(a.t), std::nullopt);
  a.t.dtype = DLDataType{kDLFloat, 32, 1};
  ASSERT_TRUE(Tensor::from_dlpack(a.t).has_value());
  a.shape[1] = 0;
  EXPECT_EQ(Tensor::from_dlpack(a.t), std::nullopt);
  a.shape[1] = -2;
  EXPECT_EQ(Tensor::from_dlpack(a.t), std::nullopt);
  a.shape[1] = 2;
  a.t.data = nullptr;
  EXPECT_EQ(Tensor::from_dlpack(a.t), std::nullopt);
  a.t.data = a.values.data();
  a.t.ndim = 9;
  EXPECT_EQ(Tensor::from_dlpack(a.t), std::nullopt);
}

TEST(Tensor, JsonRoundTripFormattingAndSummary) {
  Tensor t = counting_tensor();
  ExpectJsonRoundTrip(t);
  ExpectJsonRoundTrip(Tensor({2, 2}, TensorDtype::Bool, Device::cuda(2)));
  const std::string text = fmt::format("{}", t);
  EXPECT_NE(text.find("Tensor {"), std::string::npos) << text;
  EXPECT_NE(text.find("dtype: F32"), std::string::npos) << text;
  EXPECT_EQ(Tensor({2, 3, 224, 224}, TensorDtype::F32).log_summary(), "Tensor([2, 3, 224, 224] F32 cpu, 1.1 MiB)");
  EXPECT_EQ(Tensor({4}, TensorDtype::U8, Device::cuda(1)).log_summary(), "Tensor([4] U8 cuda:1, 4 B)");
  EXPECT_EQ(horus::log_summary(t), "Tensor([2, 3] F32 cpu, 24 B)");
}

TEST(TensorDescriptor, IsFixedSizePrintsAndRoundTrips) {
  static_assert(horus::reflect::is_fixed_size<TensorDescriptor>);
  TensorDescriptor d = Tensor({2, 3, 224, 224}, TensorDtype::F32).descriptor();
  EXPECT_EQ(d.log_summary(), "TensorDescriptor([2, 3, 224, 224] F32 cpu, 1.1 MiB, heap)");
  d.pool_id = 1;
  d.slot_id = 42;
  d.generation = 3;
  d.offset = 256;
  d.device = Device::cuda(1);
  EXPECT_EQ(d.log_summary(), "TensorDescriptor([2, 3, 224, 224] F32 cuda:1, 1.1 MiB, pool 1 slot 42)");
  ExpectJsonRoundTrip(d);
  EXPECT_NE(fmt::format("{}", d).find("TensorDescriptor {"), std::string::npos);
}

TEST(LargeData, ByteCountsPrintWithBinaryUnits) {
  EXPECT_EQ(detail::format_bytes(0), "0 B");
  EXPECT_EQ(detail::format_bytes(1023), "1023 B");
  EXPECT_EQ(detail::format_bytes(1024), "1 KiB");
  EXPECT_EQ(detail::format_bytes(1536), "1.5 KiB");
  EXPECT_EQ(detail::format_bytes(1024 * 1024), "1 MiB");
  EXPECT_EQ(detail::format_bytes(kMaxLargeDataBytes), "2 GiB");
  EXPECT_EQ(kMaxLargeDataBytes, 2147483648ULL);
}

}  // namespace

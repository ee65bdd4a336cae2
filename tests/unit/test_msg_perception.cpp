// Unit tests of the large-data messages (Image, PointCloud, DepthImage, Tensor),
// their descriptors, the point types, TensorDtype / Device and DLPack interop.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <ostream>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/messages.hpp"
#include "message_test_support.hpp"

namespace {

using namespace horus_test::values;

using namespace horus::msg;
using Bytes = std::vector<std::uint8_t>;

Bytes to_bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }
Bytes to_bytes(const std::optional<std::span<const std::uint8_t>>& s) {
  return s ? to_bytes(*s) : Bytes{0xDE, 0xAD};  // marker that no expectation uses
}

template <class T>
Bytes bytes_of(const T& v) {
  Bytes b(sizeof(T));
  std::memcpy(b.data(), &v, sizeof(T));
  return b;
}

// Expects fn() to throw std::invalid_argument whose text contains every fragment.
template <class F>
::testing::AssertionResult ThrowsNaming(F&& fn, std::initializer_list<std::string_view> fragments) {
  try {
    fn();
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    for (std::string_view f : fragments)
      if (what.find(f) == std::string::npos)
        return ::testing::AssertionFailure() << "message \"" << what << "\" lacks \"" << f << "\"";
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "no std::invalid_argument thrown";
}

template <class T>
void ExpectJsonRoundTrip(const T& m) {
  const auto j = horus::to_json(m);
  EXPECT_EQ(horus::from_json<T>(j), m) << j.dump();
}

// ===========================================================================
// ImageEncoding

TEST(ImageEncoding, BytesPerPixelOfEveryEncoding) {
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::Mono8), 1u);
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::Mono16), 2u);
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::Rgb8), 3u);
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::Bgr8), 3u);
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::Rgba8), 4u);
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::Bgra8), 4u);
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::Yuv422), 2u);
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::Mono32F), 4u);
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::Rgb32F), 12u);
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::BayerRggb8), 1u);
  EXPECT_EQ(bytes_per_pixel(ImageEncoding::Depth16), 2u);
  EXPECT_EQ(bytes_per_pixel(static_cast<ImageEncoding>(11)), 0u);
}

TEST(ImageEncoding, ChannelsOfEveryEncoding) {
  EXPECT_EQ(channels(ImageEncoding::Mono8), 1u);
  EXPECT_EQ(channels(ImageEncoding::Mono16), 1u);
  EXPECT_EQ(channels(ImageEncoding::Rgb8), 3u);
  EXPECT_EQ(channels(ImageEncoding::Bgr8), 3u);
  EXPECT_EQ(channels(ImageEncoding::Rgba8), 4u);
  EXPECT_EQ(channels(ImageEncoding::Bgra8), 4u);
  EXPECT_EQ(channels(ImageEncoding::Yuv422), 2u);
  EXPECT_EQ(channels(ImageEncoding::Mono32F), 1u);
  EXPECT_EQ(channels(ImageEncoding::Rgb32F), 3u);
  EXPECT_EQ(channels(ImageEncoding::BayerRggb8), 1u);
  EXPECT_EQ(channels(ImageEncoding::Depth16), 1u);
  EXPECT_EQ(channels(static_cast<ImageEncoding>(200)), 0u);
}

TEST(ImageEncoding, ValuesAndNamesAreHorusOnes) {
  const auto values = horus::reflect::enum_values<ImageEncoding>();
  ASSERT_EQ(values.size(), 11u);
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(static_cast<std::size_t>(values[i].value), i);
  EXPECT_EQ(values[0].name, "Mono8");
  EXPECT_EQ(values[10].name, "Depth16");
  EXPECT_EQ(to_string(ImageEncoding::BayerRggb8), "BayerRggb8");
}

TEST(ImageEncoding, TensorDtypeOfEachChannel) {
  EXPECT_EQ(tensor_dtype(ImageEncoding::Rgb8), TensorDtype::U8);
  EXPECT_EQ(tensor_dtype(ImageEncoding::Yuv422), TensorDtype::U8);
  EXPECT_EQ(tensor_dtype(ImageEncoding::Mono16), TensorDtype::U16);
  EXPECT_EQ(tensor_dtype(ImageEncoding::Depth16), TensorDtype::U16);
  EXPECT_EQ(tensor_dtype(ImageEncoding::Rgb32F), TensorDtype::F32);
  EXPECT_EQ(tensor_dtype(static_cast<ImageEncoding>(50)), std::nullopt);
}

// ===========================================================================
// Image

static_assert(!horus::reflect::is_fixed_size<Image>, "Image owns its pixels: not fixed-size");
static_assert(!horus::reflect::is_fixed_size<PointCloud>);
static_assert(!horus::reflect::is_fixed_size<DepthImage>);
static_assert(!horus::reflect::is_fixed_size<Tensor>);

TEST(Image, ConstructorTakesHeightThenWidthAndZeroFills) {
  const Image img(480, 640, ImageEncoding::Rgb8);
  EXPECT_EQ(img.width(), 640u);
  EXPECT_EQ(img.height(), 480u);
  EXPECT_EQ(img.encoding(), ImageEncoding::Rgb8);
  EXPECT_EQ(img.channels(), 3u);
  EXPECT_EQ(img.step(), 640u * 3u);
  ASSERT_EQ(img.data().size(), 640u * 480u * 3u);
  EXPECT_EQ(std::count(img.data().begin(), img.data().end(), 0), 640 * 480 * 3);
  EXPECT_TRUE(img.is_consistent());

  const Image f(2, 3, ImageEncoding::Rgb32F);
  EXPECT_EQ(f.step(), 36u);
  EXPECT_EQ(f.data().size(), 72u);
}

TEST(Image, ConstructorThrowsNamingTheProblem) {
  EXPECT_TRUE(ThrowsNaming([] { Image(0, 640, ImageEncoding::Rgb8); }, {"Image", "640x0", "greater than zero"}));
  EXPECT_TRUE(ThrowsNaming([] { Image(480, 0, ImageEncoding::Rgb8); }, {"0x480", "greater than zero"}));
  EXPECT_TRUE(ThrowsNaming([] { Image(4, 4, static_cast<ImageEncoding>(77)); }, {"unknown"}));
  // One byte more than 2^31 is refused (checked before anything is allocated).
  EXPECT_TRUE(ThrowsNaming([] { Image(1, (1u << 31) + 1, ImageEncoding::Mono8); }, {"2147483649 bytes", "2 GiB"}));
  EXPECT_TRUE(ThrowsNaming([] { Image(65536, 32769, ImageEncoding::Mono8); }, {"limit"}));
  EXPECT_TRUE(ThrowsNaming([] { Image(kU32Max, kU32Max, ImageEncoding::Rgb32F); }, {"overflows"}));
}

TEST(Image, CreateReturnsNulloptWhereTheConstructorThrows) {
  EXPECT_EQ(Image::create(0, 10, ImageEncoding::Mono8), std::nullopt);
  EXPECT_EQ(Image::create(10, 0, ImageEncoding::Mono8), std::nullopt);
  EXPECT_EQ(Image::create(1, (1u << 31) + 1, ImageEncoding::Mono8), std::nullopt);
  EXPECT_EQ(Image::create(kU32Max, kU32Max, ImageEncoding::Rgb32F), std::nullopt);
  EXPECT_EQ(Image::create(2, 2, static_cast<ImageEncoding>(11)), std::nullopt);
  const auto img = Image::create(2, 3, ImageEncoding::Mono16);
  ASSERT_TRUE(img.has_value());
  EXPECT_EQ(*img, Image(2, 3, ImageEncoding::Mono16));
  EXPECT_EQ(img->width(), 3u);
}

TEST(Image, DefaultIsEmpty) {
  const Image img;
  EXPECT_EQ(img.width(), 0u);
  EXPECT_EQ(img.height(), 0u);
  EXPECT_EQ(img.encoding(), ImageEncoding::Rgb8);
  EXPECT_TRUE(img.data().empty());
  EXPECT_EQ(img.pixel(0, 0), std::nullopt);
  EXPECT_TRUE(img.is_consistent());
  EXPECT_EQ(img.roi(0, 0, 0, 0), std::optional<Bytes>(Bytes{}));
  EXPECT_EQ(img.roi(0, 0, 1, 1), std::nullopt);
}

TEST(Image, PixelAtLastColumnAndRowButNotBeyond) {
  Image img(3, 4, ImageEncoding::Rgb8);  // 4 wide, 3 high
  EXPECT_TRUE(img.set_pixel(3, 2, {1, 2, 3}));
  EXPECT_EQ(to_bytes(img.pixel(3, 2)), (Bytes{1, 2, 3}));
  // Row 2 starts at 2 * step = 24, column 3 at 9 bytes.
  EXPECT_EQ(img.data()[33], 1);
  EXPECT_EQ(img.data()[35], 3);
  EXPECT_EQ(img.pixel(4, 0), std::nullopt);
  EXPECT_EQ(img.pixel(0, 3), std::nullopt);
  EXPECT_EQ(img.pixel(kU32Max, kU32Max), std::nullopt);

  const Bytes before = to_bytes(img.data());
  EXPECT_FALSE(img.set_pixel(4, 0, {9, 9, 9}));
  EXPECT_FALSE(img.set_pixel(0, 3, {9, 9, 9}));
  EXPECT_EQ(to_bytes(img.data()), before);
  EXPECT_EQ(to_bytes(img.pixel(0, 0)), (Bytes{0, 0, 0}));
}

TEST(Image, SetPixelRefusesTheWrongPixelSize) {
  Image img(2, 2, ImageEncoding::Rgb8);
  EXPECT_FALSE(img.set_pixel(0, 0, {1, 2}));
  EXPECT_FALSE(img.set_pixel(0, 0, {1, 2, 3, 4}));
  EXPECT_FALSE(img.set_pixel(0, 0, std::span<const std::uint8_t>{}));
  EXPECT_EQ(to_bytes(img.data()), Bytes(12, 0));
  const std::array<std::uint8_t, 3> px{7, 8, 9};
  EXPECT_TRUE(img.set_pixel(1, 1, px));
  EXPECT_EQ(to_bytes(img.pixel(1, 1)), (Bytes{7, 8, 9}));
}

TEST(Image, FillSetsEveryPixelAndIgnoresTheWrongSize) {
  Image img(2, 3, ImageEncoding::Rgba8);
  Image& same = img.fill({1, 2, 3, 4});
  EXPECT_EQ(&same, &img);
  for (std::uint32_t y = 0; y < 2; ++y)
    for (std::uint32_t x = 0; x < 3; ++x) EXPECT_EQ(to_bytes(img.pixel(x, y)), (Bytes{1, 2, 3, 4})) << x << "," << y;
  img.fill({9, 9, 9});  // Rgba8 needs 4 bytes: nothing happens
  EXPECT_EQ(to_bytes(img.pixel(2, 1)), (Bytes{1, 2, 3, 4}));
}

TEST(Image, CopyFromNeedsTheExactSize) {
  Image img(2, 2, ImageEncoding::Mono16);  // 8 bytes
  const Bytes src{1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_FALSE(img.copy_from(std::span(src).first(7)));
  const Bytes longer{1, 2, 3, 4, 5, 6, 7, 8, 9};
  EXPECT_FALSE(img.copy_from(longer));
  EXPECT_EQ(to_bytes(img.data()), Bytes(8, 0));
  EXPECT_TRUE(img.copy_from(src));
  EXPECT_EQ(to_bytes(img.data()), src);
  EXPECT_EQ(to_bytes(img.pixel(1, 1)), (Bytes{7, 8}));
}

TEST(Image, RoiCopiesTheRectangleAndRefusesToCrossTheBorder) {
  Image img(3, 4, ImageEncoding::Mono8);  // 4 wide, 3 high, byte i = i
  for (std::size_t i = 0; i < img.data_mut().size(); ++i) img.data_mut()[i] = static_cast<std::uint8_t>(i);
  EXPECT_EQ(img.roi(1, 1, 2, 2), std::optional<Bytes>(Bytes{5, 6, 9, 10}));
  EXPECT_EQ(img.roi(2, 1, 2, 2), std::optional<Bytes>(Bytes{6, 7, 10, 11}));  // touches the right and bottom edge
  EXPECT_EQ(img.roi(0, 0, 4, 3), std::optional<Bytes>(to_bytes(img.data())));
  EXPECT_EQ(img.roi(3, 0, 2, 1), std::nullopt);   // crosses the right border
  EXPECT_EQ(img.roi(0, 2, 1, 2), std::nullopt);   // crosses the bottom border
  EXPECT_EQ(img.roi(4, 0, 1, 1), std::nullopt);   // starts outside
  EXPECT_EQ(img.roi(kU32Max, 0, 2, 1), std::nullopt);  // x + w would wrap in 32 bits
  EXPECT_EQ(img.roi(0, kU32Max, 1, 2), std::nullopt);
  EXPECT_EQ(img.roi(1, 1, 0, 2), std::optional<Bytes>(Bytes{}));

  Image rgb(2, 2, ImageEncoding::Rgb8);
  rgb.set_pixel(1, 0, {1, 2, 3});
  rgb.set_pixel(1, 1, {4, 5, 6});
  EXPECT_EQ(rgb.roi(1, 0, 1, 2), std::optional<Bytes>(Bytes{1, 2, 3, 4, 5, 6}));
}

TEST(Image, FrameIdKeeps31CharactersAndRefusesMore) {
  Image img(1, 1, ImageEncoding::Mono8);
  EXPECT_TRUE(img.set_frame_id("camera_front"));
  EXPECT_EQ(img.frame_id(), "camera_front");
  const std::string max(31, 'c');
  EXPECT_TRUE(img.set_frame_id(max));
  EXPECT_EQ(img.frame_id(), max);
  EXPECT_FALSE(img.set_frame_id(std::string(32, 'x')));
  EXPECT_EQ(img.frame_id(), max);
  EXPECT_EQ(&img.set_timestamp_ns(123), &img);
  EXPECT_EQ(img.timestamp_ns(), 123u);
}

TEST(Image, CopiesAreIndependent) {
  Image a(1, 2, ImageEncoding::Mono8);
  Image b = a;
  b.set_pixel(0, 0, {42});
  EXPECT_EQ(to_bytes(a.pixel(0, 0)), (Bytes{0}));
  EXPECT_NE(a, b);
}

Image sample_image() {
  Image img(3, 4, ImageEncoding::Bgr8);
  for (std::size_t i = 0; i < img.data_mut().size(); ++i) img.data_mut()[i] = static_cast<std::uint8_t>(3 * i + 1);
  img.set_frame_id("cam_left");
  img.set_timestamp_ns(1'700'000'000'123'456'789ULL);
  return img;
}

TEST(Image, DescriptorRoundTrip) {
  const Image img = sample_image();
  const ImageDescriptor d = img.descriptor();
  EXPECT_EQ(d.width, 4u);
  EXPECT_EQ(d.height, 3u);
  EXPECT_EQ(d.encoding, ImageEncoding::Bgr8);
  EXPECT_EQ(d.step, 12u);
  EXPECT_EQ(d.frame_id_str(), "cam_left");
  EXPECT_EQ(d.timestamp_ns, 1'700'000'000'123'456'789ULL);
  EXPECT_EQ(d.data_size, 36u);
  EXPECT_EQ(d.pool_id, 0u);  // heap
  const auto back = Image::from_descriptor(d, img.data());
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(*back, img);
}

TEST(Image, FromDescriptorRejectsMismatchedSizes) {
  const Image img = sample_image();
  const ImageDescriptor good = img.descriptor();
  const Bytes bytes = to_bytes(img.data());
  EXPECT_EQ(Image::from_descriptor(good, std::span(bytes).first(35)), std::nullopt);
  Bytes longer = bytes;
  longer.push_back(0);
  EXPECT_EQ(Image::from_descriptor(good, longer), std::nullopt);

  ImageDescriptor d = good;
  d.data_size = 35;
  EXPECT_EQ(Image::from_descriptor(d, std::span(bytes).first(35)), std::nullopt);
  d = good;
  d.step = 11;  // shorter than a row
  d.data_size = 33;
  EXPECT_EQ(Image::from_descriptor(d, std::span(bytes).first(33)), std::nullopt);
  d = good;
  d.width = 0;
  EXPECT_EQ(Image::from_descriptor(d, bytes), std::nullopt);
  d = good;
  d.encoding = static_cast<ImageEncoding>(99);
  EXPECT_EQ(Image::from_descriptor(d, bytes), std::nullopt);
  d = good;
  d.frame_id.fill('x');  // no terminating NUL
  EXPECT_EQ(Image::from_descriptor(d, bytes), std::nullopt);
}

TEST(Image, FromDescriptorKeepsAPaddedStep) {
  ImageDescriptor d{};
  d.width = 2;
  d.height = 2;
  d.encoding = ImageEncoding::Rgb8;
  d.step = 8;  // 6 bytes of pixels + 2 bytes of padding per row
  d.data_size = 16;
  const Bytes bytes{1, 2, 3, 4, 5, 6, 0xEE, 0xEE, 7, 8, 9, 10, 11, 12, 0xEE, 0xEE};
  auto img = Image::from_descriptor(d, bytes);
  ASSERT_TRUE(img.has_value());
  EXPECT_EQ(img->step(), 8u);
  EXPECT_EQ(to_bytes(img->pixel(0, 1)), (Bytes{7, 8, 9}));
  EXPECT_EQ(img->roi(1, 0, 1, 2), std::optional<Bytes>(Bytes{4, 5, 6, 10, 11, 12}));
  img->fill({0, 0, 0});
  EXPECT_EQ(to_bytes(img->data()), (Bytes{0, 0, 0, 0, 0, 0, 0xEE, 0xEE, 0, 0, 0, 0, 0, 0, 0xEE, 0xEE}));
  EXPECT_EQ(img->descriptor(), d);
}

TEST(Image, InconsistentJsonImageIsHandledSafely) {
  // JSON can describe an image whose bytes do not match its size.
  auto j = horus::to_json(Image(2, 2, ImageEncoding::Rgb8));
  j["data"] = nlohmann::json::array({1, 2, 3, 4, 5, 6});  // 2 of 4 pixels
  Image img = horus::from_json<Image>(j);
  EXPECT_FALSE(img.is_consistent());
  EXPECT_EQ(to_bytes(img.pixel(1, 0)), (Bytes{4, 5, 6}));
  EXPECT_EQ(img.pixel(0, 1), std::nullopt);  // no bytes there
  EXPECT_FALSE(img.set_pixel(1, 1, {1, 1, 1}));
  EXPECT_EQ(img.roi(0, 0, 1, 1), std::nullopt);
  img.fill({9, 9, 9});
  EXPECT_EQ(to_bytes(img.data()), (Bytes{1, 2, 3, 4, 5, 6}));
  EXPECT_TRUE(sample_image().is_consistent());
}

TEST(Image, JsonRoundTripAndFormatting) {
  const Image img = sample_image();
  ExpectJsonRoundTrip(img);
  const auto j = horus::to_json(img);
  EXPECT_EQ(j["width"], 4);
  EXPECT_EQ(j["encoding"], "Bgr8");
  EXPECT_EQ(j["frame_id"], "cam_left");
  const std::string text = fmt::format("{}", img);
  EXPECT_NE(text.find("Image {"), std::string::npos) << text;
  EXPECT_NE(text.find("width: 4"), std::string::npos) << text;
  EXPECT_NE(text.find("frame_id: \"cam_left\""), std::string::npos) << text;
  EXPECT_EQ(horus::type_name<Image>(), "horus::msg::Image");
}

TEST(Image, LogSummaryGivesSizeAndEncoding) {
  EXPECT_EQ(Image(480, 640, ImageEncoding::Rgb8).log_summary(), "Image(640x480 Rgb8, 900 KiB)");
  EXPECT_EQ(Image(2, 3, ImageEncoding::Mono8).log_summary(), "Image(3x2 Mono8, 6 B)");
  EXPECT_EQ(horus::log_summary(Image(1080, 1920, ImageEncoding::Rgba8)), "Image(1920x1080 Rgba8, 7.9 MiB)");
}

TEST(ImageDescriptor, IsFixedSizeAndPrintsLikeAnImage) {
  static_assert(horus::reflect::is_fixed_size<ImageDescriptor>);
  ImageDescriptor d = Image(480, 640, ImageEncoding::Rgb8).descriptor();
  EXPECT_EQ(d.log_summary(), "ImageDescriptor(640x480 Rgb8, 900 KiB, heap)");
  d.pool_id = 1;
  d.slot_id = 42;
  d.generation = 7;
  d.offset = 4096;
  ASSERT_TRUE(d.set_frame_id("cam"));
  EXPECT_FALSE(d.set_frame_id(std::string(32, 'y')));
  EXPECT_EQ(d.frame_id_str(), "cam");
  d.timestamp_ns = 99;
  EXPECT_EQ(d.log_summary(), "ImageDescriptor(640x480 Rgb8, 900 KiB, pool 1 slot 42)");
  ExpectJsonRoundTrip(d);
  const std::string text = fmt::format("{}", d);
  EXPECT_NE(text.find("ImageDescriptor {"), std::string::npos) << text;
  EXPECT_NE(text.find("slot_id: 42"), std::string::npos) << text;
}

// ===========================================================================
// Point types

TEST(PointTypes, HaveHorusSizes) {
  static_assert(sizeof(PointXYZ) == 12);
  static_assert(sizeof(PointXYZRGB) == 16);
  static_assert(sizeof(PointXYZI) == 16);
  static_assert(horus::reflect::is_fixed_size<PointXYZ> && horus::reflect::is_fixed_size<PointXYZRGB> &&
                horus::reflect::is_fixed_size<PointXYZI>);
  EXPECT_EQ(horus::reflect::field_count<PointXYZRGB>, 7u);
}

TEST(PointXYZ, DistancesInMetres) {
  EXPECT_FLOAT_EQ(PointXYZ::make(3, 4, 0).distance(), 5.0f);
  EXPECT_FLOAT_EQ(PointXYZ::make(0, 0, 0).distance_to(PointXYZ::make(1, 2, 2)), 3.0f);
  EXPECT_EQ(PointXYZ::make(1, 1, 1).distance_to(PointXYZ::make(1, 1, 1)), 0.0f);
}

TEST(PointXYZRGB, MakeIsOpaqueAndPacksRgba) {
  const auto p = PointXYZRGB::make(1, 2, 3, 255, 128, 64);
  EXPECT_EQ(p.a, 255);
  EXPECT_EQ(p.rgb_packed(), 0xFF8040FFu);
  EXPECT_EQ(p.xyz(), PointXYZ::make(1, 2, 3));
  const auto w = PointXYZRGB::from_xyz(PointXYZ::make(4, 5, 6));
  EXPECT_EQ(w, (PointXYZRGB{4, 5, 6, 255, 255, 255, 255}));
}

TEST(PointXYZI, FromXyzHasZeroIntensity) {
  const auto p = PointXYZI::from_xyz(PointXYZ::make(1, 2, 3));
  EXPECT_EQ(p, (PointXYZI{1, 2, 3, 0}));
  EXPECT_EQ(PointXYZI::make(1, 2, 3, 9).xyz(), PointXYZ::make(1, 2, 3));
}

TEST(PointTypes, JsonRoundTripAndFormatting) {
  ExpectJsonRoundTrip(PointXYZ::make(1.5f, -2, 3));
  ExpectJsonRoundTrip(PointXYZRGB::make(1.5f, -2, 3, 10, 20, 30));
  ExpectJsonRoundTrip(PointXYZI::make(1.5f, -2, 3, 77));
  EXPECT_EQ(fmt::format("{}", PointXYZ::make(1, 2, 3)), "PointXYZ { x: 1, y: 2, z: 3 }");
  EXPECT_EQ(fmt::format("{}", PointXYZRGB::make(1, 2, 3, 4, 5, 6)),
            "PointXYZRGB { x: 1, y: 2, z: 3, r: 4, g: 5, b: 6, a: 255 }");
  EXPECT_EQ(fmt::format("{}", PointXYZI::make(1, 2, 3, 4)), "PointXYZI { x: 1, y: 2, z: 3, intensity: 4 }");
}

// ===========================================================================
// PointCloud

TEST(PointCloud, FromXyzMakesAnF32XyzCloud) {
  const std::vector<std::array<float, 3>> pts{{1, 2, 3}, {4, 5, 6}};
  const PointCloud pc = PointCloud::from_xyz(pts);
  EXPECT_EQ(pc.point_count(), 2u);
  EXPECT_EQ(pc.fields_per_point(), 3u);
  EXPECT_EQ(pc.dtype(), TensorDtype::F32);
  EXPECT_TRUE(pc.is_xyz());
  EXPECT_FALSE(pc.has_intensity());
  EXPECT_FALSE(pc.has_color());
  EXPECT_EQ(pc.data().size(), 24u);
  EXPECT_EQ(pc.extract_xyz(), std::optional(pts));
  EXPECT_EQ(to_bytes(pc.point_at(1)), bytes_of(std::array<float, 3>{4, 5, 6}));

  const std::vector<PointXYZ> typed{PointXYZ::make(1, 2, 3), PointXYZ::make(4, 5, 6)};
  EXPECT_EQ(PointCloud::from_xyz(typed), pc);
}

TEST(PointCloud, FromXyziHasIntensityAndExtractXyzDropsIt) {
  const std::vector<std::array<float, 4>> pts{{1, 2, 3, 0.8f}, {4, 5, 6, 0.5f}};
  const PointCloud pc = PointCloud::from_xyzi(pts);
  EXPECT_EQ(pc.fields_per_point(), 4u);
  EXPECT_FALSE(pc.is_xyz());
  EXPECT_TRUE(pc.has_intensity());
  EXPECT_FALSE(pc.has_color());
  EXPECT_EQ(pc.extract_xyz(), (std::optional<std::vector<std::array<float, 3>>>({{1, 2, 3}, {4, 5, 6}})));
  EXPECT_EQ(to_bytes(pc.point_at(0)), bytes_of(std::array<float, 4>{1, 2, 3, 0.8f}));
  const std::vector<PointXYZI> typed{PointXYZI::make(1, 2, 3, 0.8f), PointXYZI::make(4, 5, 6, 0.5f)};
  EXPECT_EQ(PointCloud::from_xyzi(typed), pc);
}

TEST(PointCloud, FromXyzrgbHasColourButNoIntensity) {
  const std::vector<std::array<float, 6>> pts{{1, 2, 3, 255, 0, 10}};
  const PointCloud pc = PointCloud::from_xyzrgb(pts);
  EXPECT_EQ(pc.fields_per_point(), 6u);
  EXPECT_TRUE(pc.has_color());
  EXPECT_FALSE(pc.has_intensity());  // field 3 is red here (HORUS would say true)
  EXPECT_EQ(pc.extract_xyz(), (std::optional<std::vector<std::array<float, 3>>>({{1, 2, 3}})));
  const std::vector<PointXYZRGB> typed{PointXYZRGB::make(1, 2, 3, 255, 0, 10)};
  EXPECT_EQ(PointCloud::from_xyzrgb(typed), pc);
}

TEST(PointCloud, MakeGivesAZeroFilledCloudOfAnyLayout) {
  const PointCloud pc = PointCloud::make(10, 5, TensorDtype::U16);
  EXPECT_EQ(pc.point_count(), 10u);
  EXPECT_EQ(pc.point_size(), 10u);
  EXPECT_EQ(pc.data().size(), 100u);
  EXPECT_TRUE(pc.has_intensity());  // XYZI + one more field (e.g. ring)
  EXPECT_FALSE(pc.has_color());
  EXPECT_EQ(to_bytes(pc.point_at(9)), Bytes(10, 0));
  EXPECT_EQ(pc.point_at(10), std::nullopt);
  EXPECT_EQ(PointCloud::create(10, 5, TensorDtype::U16), std::optional(pc));
}

TEST(PointCloud, ExtractXyzNeedsF32AndThreeFields) {
  EXPECT_EQ(PointCloud::make(4, 3, TensorDtype::U16).extract_xyz(), std::nullopt);
  EXPECT_EQ(PointCloud::make(4, 3, TensorDtype::F64).extract_xyz(), std::nullopt);
  EXPECT_EQ(PointCloud::make(4, 2, TensorDtype::F32).extract_xyz(), std::nullopt);
  EXPECT_TRUE(PointCloud::make(4, 3, TensorDtype::F32).extract_xyz().has_value());
}

TEST(PointCloud, MakeThrowsNamingTheProblem) {
  EXPECT_TRUE(ThrowsNaming([] { PointCloud::make(10, 0, TensorDtype::F32); }, {"PointCloud", "fields_per_point"}));
  EXPECT_TRUE(ThrowsNaming([] { PointCloud::make(10, 3, static_cast<TensorDtype>(13)); }, {"unknown"}));
  EXPECT_TRUE(ThrowsNaming([] { PointCloud::make((1ULL << 27) + 1, 4, TensorDtype::F32); }, {"2147483664 bytes"}));
  EXPECT_TRUE(ThrowsNaming([] { PointCloud::make(std::numeric_limits<std::uint64_t>::max(), 3, TensorDtype::F32); },
                           {"overflows"}));
  EXPECT_EQ(PointCloud::create(10, 0, TensorDtype::F32), std::nullopt);
  EXPECT_EQ(PointCloud::create((1ULL << 27) + 1, 4, TensorDtype::F32), std::nullopt);
}

TEST(PointCloud, EmptyCloudIsValid) {
  const PointCloud pc = PointCloud::from_xyz(std::vector<std::array<float, 3>>{});
  EXPECT_EQ(pc.point_count(), 0u);
  EXPECT_TRUE(pc.data().empty());
  EXPECT_EQ(pc.point_at(0), std::nullopt);
  EXPECT_EQ(pc.extract_xyz(), std::optional(std::vector<std::array<float, 3>>{}));
  EXPECT_TRUE(pc.is_consistent());
  const PointCloud def;
  EXPECT_EQ(def.fields_per_point(), 0u);
  EXPECT_EQ(def.extract_xyz(), std::nullopt);
}

TEST(PointCloud, CopyFromFrameAndTimestamp) {
  PointCloud pc = PointCloud::make(2, 3, TensorDtype::F32);
  const auto src = bytes_of(std::array<float, 6>{1, 2, 3, 4, 5, 6});
  EXPECT_FALSE(pc.copy_from(std::span(src).first(23)));
  EXPECT_EQ(to_bytes(pc.data()), Bytes(24, 0));
  EXPECT_TRUE(pc.copy_from(src));
  EXPECT_EQ(pc.extract_xyz(), (std::optional<std::vector<std::array<float, 3>>>({{1, 2, 3}, {4, 5, 6}})));
  EXPECT_TRUE(pc.set_frame_id("lidar_top"));
  EXPECT_FALSE(pc.set_frame_id(std::string(40, 'l')));
  EXPECT_EQ(pc.frame_id(), "lidar_top");
  EXPECT_EQ(pc.set_timestamp_ns(5).timestamp_ns(), 5u);
}

PointCloud sample_cloud() {
  PointCloud pc = PointCloud::from_xyzi(std::vector<std::array<float, 4>>{{1, 2, 3, 4}, {-1, -2, -3, 40}});
  pc.set_frame_id("velodyne");
  pc.set_timestamp_ns(123456);
  return pc;
}

TEST(PointCloud, DescriptorRoundTripAndRejection) {
  const PointCloud pc = sample_cloud();
  const PointCloudDescriptor d = pc.descriptor();
  EXPECT_EQ(d.point_count, 2u);
  EXPECT_EQ(d.fields_per_point, 4u);
  EXPECT_EQ(d.dtype, TensorDtype::F32);
  EXPECT_EQ(d.data_size, 32u);
  EXPECT_EQ(d.frame_id_str(), "velodyne");
  EXPECT_EQ(d.timestamp_ns, 123456u);
  EXPECT_EQ(PointCloud::from_descriptor(d, pc.data()), std::optional(pc));

  const Bytes bytes = to_bytes(pc.data());
  EXPECT_EQ(PointCloud::from_descriptor(d, std::span(bytes).first(31)), std::nullopt);
  PointCloudDescriptor bad = d;
  bad.point_count = 3;
  EXPECT_EQ(PointCloud::from_descriptor(bad, bytes), std::nullopt);
  bad = d;
  bad.data_size = 31;
  EXPECT_EQ(PointCloud::from_descriptor(bad, std::span(bytes).first(31)), std::nullopt);
  bad = d;
  bad.fields_per_point = 0;
  bad.data_size = 0;
  EXPECT_EQ(PointCloud::from_descriptor(bad, std::span<const std::uint8_t>{}), std::nullopt);
  bad = d;
  bad.dtype = static_cast<TensorDtype>(42);
  EXPECT_EQ(PointCloud::from_descriptor(bad, bytes), std::nullopt);
  bad = d;
  bad.frame_id.fill('f');
  EXPECT_EQ(PointCloud::from_descriptor(bad, bytes), std::nullopt);
}

TEST(PointCloud, JsonRoundTripFormattingAndSummary) {
  const PointCloud pc = sample_cloud();
  ExpectJsonRoundTrip(pc);
  EXPECT_EQ(horus::to_json(pc)["dtype"], "F32");
  const std::string text = fmt::format("{}", pc);
  EXPECT_NE(text.find("PointCloud {"), std::string::npos) << text;
  EXPECT_NE(text.find("fields_per_point: 4"), std::string::npos) << text;

  EXPECT_EQ(PointCloud::make(1000, 3, TensorDtype::F32).log_summary(), "PointCloud(1000 points xyz f32, 11.7 KiB)");
  EXPECT_EQ(pc.log_summary(), "PointCloud(2 points xyzi f32, 32 B)");
  EXPECT_EQ(PointCloud::make(4, 5, TensorDtype::U16).log_summary(), "PointCloud(4 points 5 fields u16, 40 B)");
  EXPECT_EQ(PointCloud::make(4, 6, TensorDtype::F64).log_summary(), "PointCloud(4 points xyzrgb f64, 192 B)");
}

TEST(PointCloudDescriptor, IsFixedSizePrintsAndRoundTrips) {
  static_assert(horus::reflect::is_fixed_size<PointCloudDescriptor>);
  PointCloudDescriptor d = PointCloud::make(1000, 3, TensorDtype::F32).descriptor();
  EXPECT_EQ(d.log_summary(), "PointCloudDescriptor(1000 points xyz f32, 11.7 KiB, heap)");
  d.pool_id = 2;
  d.slot_id = 5;
  d.generation = 9;
  d.offset = 64;
  d.timestamp_ns = 77;
  ASSERT_TRUE(d.set_frame_id("lidar"));
  EXPECT_EQ(d.log_summary(), "PointCloudDescriptor(1000 points xyz f32, 11.7 KiB, pool 2 slot 5)");
  ExpectJsonRoundTrip(d);
  EXPECT_NE(fmt::format("{}", d).find("point_count: 1000"), std::string::npos);
}

// ===========================================================================
// DepthImage

TEST(DepthImage, MetersIsF32AndMillimetersIsU16) {
  const DepthImage m = DepthImage::meters(480, 640);
  EXPECT_EQ(m.width(), 640u);
  EXPECT_EQ(m.height(), 480u);
  EXPECT_EQ(m.dtype(), TensorDtype::F32);
  EXPECT_TRUE(m.is_meters());
  EXPECT_FALSE(m.is_millimeters());
  EXPECT_EQ(m.depth_scale(), 1.0f);
  EXPECT_EQ(m.data().size(), 480u * 640u * 4u);

  const DepthImage mm = DepthImage::millimeters(2, 3);
  EXPECT_EQ(mm.dtype(), TensorDtype::U16);
  EXPECT_TRUE(mm.is_millimeters());
  EXPECT_FALSE(mm.is_meters());
  EXPECT_EQ(mm.data().size(), 12u);
  EXPECT_EQ(mm.width(), 3u);
}

TEST(DepthImage, FactoriesThrowAndCreateReturnsNullopt) {
  EXPECT_TRUE(ThrowsNaming([] { DepthImage::meters(0, 10); }, {"DepthImage", "10x0", "greater than zero"}));
  EXPECT_TRUE(ThrowsNaming([] { DepthImage::millimeters(10, 0); }, {"millimeters", "greater than zero"}));
  EXPECT_TRUE(ThrowsNaming([] { DepthImage::meters(1, (1u << 29) + 1); }, {"2147483652 bytes"}));
  EXPECT_TRUE(ThrowsNaming([] { DepthImage::meters(kU32Max, kU32Max); }, {"overflows"}));
  EXPECT_EQ(DepthImage::create_meters(0, 1), std::nullopt);
  EXPECT_EQ(DepthImage::create_millimeters(1, 0), std::nullopt);
  EXPECT_EQ(DepthImage::create_meters(1, (1u << 29) + 1), std::nullopt);
  EXPECT_EQ(DepthImage::create_meters(2, 2), std::optional(DepthImage::meters(2, 2)));
  EXPECT_EQ(DepthImage::create_millimeters(2, 2), std::optional(DepthImage::millimeters(2, 2)));
}

TEST(DepthImage, MetersGetAndSetAtTheEdges) {
  DepthImage d = DepthImage::meters(480, 640);
  EXPECT_TRUE(d.set_depth(639, 479, 1.5f));
  EXPECT_EQ(d.get_depth(639, 479), 1.5f);
  EXPECT_EQ(d.get_depth(0, 0), 0.0f);
  EXPECT_FALSE(d.set_depth(640, 0, 1.0f));
  EXPECT_FALSE(d.set_depth(0, 480, 1.0f));
  EXPECT_EQ(d.get_depth(640, 0), std::nullopt);
  EXPECT_EQ(d.get_depth(0, 480), std::nullopt);
  EXPECT_EQ(d.get_depth_u16(0, 0), std::nullopt);  // not a U16 image
  EXPECT_TRUE(d.set_depth(1, 0, 1000.0f));         // F32 takes any value
  EXPECT_EQ(d.get_depth(1, 0), 1000.0f);
  EXPECT_TRUE(d.set_depth(2, 0, kNaNf));  // NaN marks "no measurement"
  EXPECT_TRUE(std::isnan(*d.get_depth(2, 0)));
  EXPECT_EQ(detail::load_at<float>(d.data(), (479u * 640u + 639u) * 4u), 1.5f);
}

TEST(DepthImage, MillimetersConvertWithTheScale) {
  DepthImage d = DepthImage::millimeters(2, 2);
  EXPECT_TRUE(d.set_depth(1, 1, 1.5f));
  EXPECT_EQ(d.get_depth_u16(1, 1), 1500);
  EXPECT_FLOAT_EQ(*d.get_depth(1, 1), 1.5f);
  EXPECT_TRUE(d.set_depth(0, 1, 0.7f));  // 699.99997 mm: rounded, not truncated
  EXPECT_EQ(d.get_depth_u16(0, 1), 700);
  EXPECT_EQ(d.get_depth_u16(2, 0), std::nullopt);
  EXPECT_EQ(d.get_depth_u16(0, 2), std::nullopt);

  // A sensor whose raw unit is 0.1 mm.
  EXPECT_TRUE(d.set_depth_scale(0.1f));
  EXPECT_EQ(d.depth_scale(), 0.1f);
  EXPECT_TRUE(d.set_depth(0, 0, 1.5f));
  EXPECT_EQ(d.get_depth_u16(0, 0), 15000);
  EXPECT_NEAR(*d.get_depth(0, 0), 1.5f, 1e-6f);
  EXPECT_NEAR(*d.get_depth(1, 1), 0.15f, 1e-6f);  // raw 1500 now means 0.15 m

  EXPECT_FALSE(d.set_depth_scale(0.0f));
  EXPECT_FALSE(d.set_depth_scale(-1.0f));
  EXPECT_FALSE(d.set_depth_scale(kNaNf));
  EXPECT_FALSE(d.set_depth_scale(kInff));
  EXPECT_EQ(d.depth_scale(), 0.1f);
}

TEST(DepthImage, MillimetersRefuseDepthsThatDoNotFit) {
  DepthImage d = DepthImage::millimeters(1, 2);
  EXPECT_FALSE(d.set_depth(0, 0, 70.0f));  // 70000 mm
  EXPECT_FALSE(d.set_depth(0, 0, -0.5f));
  EXPECT_FALSE(d.set_depth(0, 0, kNaNf));
  EXPECT_FALSE(d.set_depth(0, 0, kInff));
  EXPECT_EQ(d.get_depth_u16(0, 0), 0);
  EXPECT_TRUE(d.set_depth(1, 0, 65.535f));
  EXPECT_EQ(d.get_depth_u16(1, 0), 65535);
  EXPECT_TRUE(d.set_depth(0, 0, 0.0f));
}

TEST(DepthImage, StatisticsSkipInvalidPixels) {
  DepthImage d = DepthImage::meters(2, 3);
  const std::array<float, 6> values{0.0f, kNaNf, kInff, -1.0f, 1.0f, 3.0f};
  for (std::uint32_t i = 0; i < 6; ++i) ASSERT_TRUE(d.set_depth(i % 3, i / 3, values[i]));
  const auto [lo, hi, mean] = d.depth_statistics();
  EXPECT_EQ(lo, 1.0f);
  EXPECT_EQ(hi, 3.0f);
  EXPECT_EQ(mean, 2.0f);

  DepthImage none = DepthImage::meters(2, 2);
  none.set_depth(0, 0, kNaNf);
  none.set_depth(1, 0, -kInff);
  EXPECT_EQ(none.depth_statistics(), std::make_tuple(0.0f, 0.0f, 0.0f));
  EXPECT_EQ(DepthImage().depth_statistics(), std::make_tuple(0.0f, 0.0f, 0.0f));

  DepthImage mm = DepthImage::millimeters(1, 3);
  mm.set_depth(1, 0, 1.0f);
  mm.set_depth(2, 0, 2.0f);  // pixel 0 stays 0: no measurement
  const auto [mlo, mhi, mmean] = mm.depth_statistics();
  EXPECT_FLOAT_EQ(mlo, 1.0f);
  EXPECT_FLOAT_EQ(mhi, 2.0f);
  EXPECT_FLOAT_EQ(mmean, 1.5f);
}

TEST(DepthImage, CopyFromNeedsTheExactSize) {
  DepthImage d = DepthImage::millimeters(1, 2);
  const Bytes src = bytes_of(std::array<std::uint16_t, 2>{100, 200});
  EXPECT_FALSE(d.copy_from(std::span(src).first(3)));
  EXPECT_EQ(d.get_depth_u16(0, 0), 0);
  EXPECT_TRUE(d.copy_from(src));
  EXPECT_EQ(d.get_depth_u16(1, 0), 200);
}

DepthImage sample_depth() {
  DepthImage d = DepthImage::millimeters(2, 3);
  d.set_depth_scale(0.25f);
  d.set_depth(2, 1, 1.0f);
  d.set_frame_id("realsense");
  d.set_timestamp_ns(42);
  return d;
}

TEST(DepthImage, DescriptorRoundTripAndRejection) {
  const DepthImage d = sample_depth();
  const DepthImageDescriptor desc = d.descriptor();
  EXPECT_EQ(desc.width, 3u);
  EXPECT_EQ(desc.height, 2u);
  EXPECT_EQ(desc.dtype, TensorDtype::U16);
  EXPECT_EQ(desc.depth_scale, 0.25f);
  EXPECT_EQ(desc.data_size, 12u);
  EXPECT_EQ(desc.frame_id_str(), "realsense");
  EXPECT_EQ(DepthImage::from_descriptor(desc, d.data()), std::optional(d));

  const Bytes bytes = to_bytes(d.data());
  EXPECT_EQ(DepthImage::from_descriptor(desc, std::span(bytes).first(10)), std::nullopt);
  DepthImageDescriptor bad = desc;
  bad.dtype = TensorDtype::I16;  // same size, but not a depth format
  EXPECT_EQ(DepthImage::from_descriptor(bad, bytes), std::nullopt);
  bad = desc;
  bad.width = 2;
  EXPECT_EQ(DepthImage::from_descriptor(bad, bytes), std::nullopt);
  bad = desc;
  bad.depth_scale = 0.0f;
  EXPECT_EQ(DepthImage::from_descriptor(bad, bytes), std::nullopt);
  bad = desc;
  bad.data_size = 10;
  EXPECT_EQ(DepthImage::from_descriptor(bad, std::span(bytes).first(10)), std::nullopt);
  bad = desc;
  bad.frame_id.fill('r');
  EXPECT_EQ(DepthImage::from_descriptor(bad, bytes), std::nullopt);
}

TEST(DepthImage, JsonRoundTripFormattingAndSummary) {
  const DepthImage d = sample_depth();
  ExpectJsonRoundTrip(d);
  EXPECT_EQ(horus::to_json(d)["depth_scale"], 0.25);
  const std::string text = fmt::format("{}", d);
  EXPECT_NE(text.find("DepthImage {"), std::string::npos) << text;
  EXPECT_NE(text.find("dtype: U16"), std::string::npos) << text;
  EXPECT_EQ(DepthImage::meters(480, 640).log_summary(), "DepthImage(640x480 meters, 1.2 MiB)");
  EXPECT_EQ(DepthImage::millimeters(480, 640).log_summary(), "DepthImage(640x480 millimeters, 600 KiB)");
}

TEST(DepthImageDescriptor, IsFixedSizePrintsAndRoundTrips) {
  static_assert(horus::reflect::is_fixed_size<DepthImageDescriptor>);
  DepthImageDescriptor d = DepthImage::meters(480, 640).descriptor();
  EXPECT_EQ(d.log_summary(), "DepthImageDescriptor(640x480 meters, 1.2 MiB, heap)");
  d.pool_id = 3;
  d.slot_id = 1;
  d.generation = 2;
  d.offset = 128;
  d.depth_scale = 0.5f;
  d.timestamp_ns = 11;
  ASSERT_TRUE(d.set_frame_id("depth"));
  EXPECT_EQ(d.log_summary(), "DepthImageDescriptor(640x480 meters, 1.2 MiB, pool 3 slot 1)");
  ExpectJsonRoundTrip(d);
  EXPECT_NE(fmt::format("{}", d).find("depth_scale: 0.5"), std::string::npos);
}

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

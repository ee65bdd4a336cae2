// Unit tests of Image and ImageEncoding (image.hpp).
#include "msg_perception_test.hpp"

namespace {

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

}  // namespace

// Unit tests of the point types, PointCloud (point_cloud.hpp) and DepthImage (perception.hpp).
#include "msg_perception_test.hpp"

namespace {

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

}  // namespace

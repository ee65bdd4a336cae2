// Unit tests of the camera and image-region messages: the layouts the spec fixes, CameraInfo,
// StereoInfo, RegionOfInterest, CompressedImage, BoundingBox2D and 3D, Detection and
// Detection3D (vision.hpp, detection.hpp).
#include "msg_vision_test.hpp"

namespace {

// ===========================================================================
// Layout the spec fixes (field types and array sizes)

static_assert(std::is_same_v<decltype(CameraInfo::distortion_model), std::array<char, 16>>);
static_assert(std::is_same_v<decltype(CameraInfo::distortion_coefficients), std::array<double, 8>>);
static_assert(std::is_same_v<decltype(CameraInfo::camera_matrix), std::array<double, 9>>);
static_assert(std::is_same_v<decltype(CameraInfo::rectification_matrix), std::array<double, 9>>);
static_assert(std::is_same_v<decltype(CameraInfo::projection_matrix), std::array<double, 12>>);
static_assert(std::is_same_v<decltype(CameraInfo::frame_id), std::array<char, 32>>);
static_assert(std::is_same_v<decltype(StereoInfo::left_camera), CameraInfo>);
static_assert(std::is_same_v<decltype(StereoInfo::baseline), double>);
static_assert(std::is_same_v<decltype(CompressedImage::format), std::array<char, 8>>);
static_assert(std::is_same_v<decltype(CompressedImage::data), std::vector<std::uint8_t>>);
static_assert(std::is_same_v<decltype(CompressedImage::frame_id), std::array<char, 32>>);
static_assert(sizeof(BoundingBox2D) == 4 * sizeof(float));
static_assert(sizeof(BoundingBox3D) == 9 * sizeof(float));
static_assert(std::is_same_v<decltype(Detection::bbox), BoundingBox2D>);
static_assert(std::is_same_v<decltype(Detection::class_name), std::array<char, 32>>);
static_assert(std::is_same_v<decltype(Detection3D::bbox), BoundingBox3D>);
static_assert(std::is_same_v<decltype(Detection3D::velocity), std::array<float, 3>>);
static_assert(sizeof(Landmark) == 16);
static_assert(sizeof(Landmark3D) == 20);
static_assert(sizeof(SegmentationMask) == 64);
static_assert(sizeof(TrackedObject) == 96);
static_assert(sizeof(TrackingHeader) == 32);
static_assert(std::tuple_size_v<decltype(LandmarkArray::landmarks)> == 468);
static_assert(std::is_same_v<decltype(TrackedObject::class_name), std::array<char, 16>>);

TEST(Layout, FieldOrderFollowsTheSpecTables) {
  const auto names = [](auto tag) {
    std::string out;
    horus::reflect::for_each_field_desc<typename decltype(tag)::type>([&](const auto& fd) {
      if (!out.empty()) out += ',';
      out += fd.name;
    });
    return out;
  };
  EXPECT_EQ(names(std::type_identity<CameraInfo>{}),
            "width,height,distortion_model,distortion_coefficients,camera_matrix,rectification_matrix,"
            "projection_matrix,frame_id,timestamp_ns");
  EXPECT_EQ(names(std::type_identity<StereoInfo>{}), "left_camera,right_camera,baseline,depth_scale");
  EXPECT_EQ(names(std::type_identity<CompressedImage>{}), "format,data,width,height,frame_id,timestamp_ns");
  EXPECT_EQ(names(std::type_identity<RegionOfInterest>{}), "x_offset,y_offset,width,height,do_rectify");
  EXPECT_EQ(names(std::type_identity<BoundingBox3D>{}), "cx,cy,cz,length,width,height,roll,pitch,yaw");
  EXPECT_EQ(names(std::type_identity<Detection>{}), "bbox,confidence,class_id,class_name,instance_id");
  EXPECT_EQ(names(std::type_identity<Detection3D>{}), "bbox,confidence,class_id,class_name,velocity,instance_id");
}

// ===========================================================================
// CameraInfo

TEST(CameraInfo, MakeFillsIntrinsicsProjectionAndIdentityRectification) {
  const CameraInfo c = CameraInfo::make(640, 480, 525.0, 520.0, 320.5, 240.25);
  EXPECT_EQ(c.width, 640u);
  EXPECT_EQ(c.height, 480u);
  EXPECT_EQ(c.camera_matrix, (std::array<double, 9>{525.0, 0, 320.5, 0, 520.0, 240.25, 0, 0, 1}));
  EXPECT_EQ(c.rectification_matrix, (std::array<double, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
  EXPECT_EQ(c.projection_matrix, (std::array<double, 12>{525.0, 0, 320.5, 0, 0, 520.0, 240.25, 0, 0, 0, 1, 0}));
  EXPECT_EQ(c.distortion_coefficients, (std::array<double, 8>{}));
  EXPECT_EQ(c.distortion_model_str(), "");
  EXPECT_EQ(c.timestamp_ns, 0u);
}

TEST(CameraInfo, FocalLengthsAndPrincipalPointComeFromTheCameraMatrix) {
  const CameraInfo c = CameraInfo::make(640, 480, 525.0, 520.0, 320.5, 240.25);
  EXPECT_EQ(c.focal_lengths(), std::make_pair(525.0, 520.0));
  EXPECT_EQ(c.principal_point(), std::make_pair(320.5, 240.25));
  CameraInfo changed = c;
  changed.camera_matrix[0] = 600.0;
  changed.camera_matrix[5] = 100.0;
  EXPECT_EQ(changed.focal_lengths().first, 600.0);
  EXPECT_EQ(changed.principal_point().second, 100.0);
}

TEST(CameraInfo, DefaultIsAllZerosUnlikeMake) {
  EXPECT_EQ(CameraInfo{}.rectification_matrix, (std::array<double, 9>{}));
  EXPECT_NE(CameraInfo{}, CameraInfo::make(0, 0, 0, 0, 0, 0));
}

TEST(CameraInfo, DistortionModelThatDoesNotFitIsRefused) {
  CameraInfo c = CameraInfo::make(640, 480, 500, 500, 320, 240);
  EXPECT_TRUE(c.set_distortion_model("plumb_bob"));
  EXPECT_EQ(c.distortion_model_str(), "plumb_bob");
  EXPECT_TRUE(c.set_distortion_model(std::string(15, 'm')));
  EXPECT_EQ(c.distortion_model_str(), std::string(15, 'm'));
  EXPECT_FALSE(c.set_distortion_model("rational_polynomial"));  // 19 characters
  EXPECT_EQ(c.distortion_model_str(), std::string(15, 'm'));

  EXPECT_EQ(c.with_distortion_model("equidistant").distortion_model_str(), "equidistant");
  EXPECT_THROW((void)c.with_distortion_model("rational_polynomial"), std::invalid_argument);
}

TEST(CameraInfo, FrameIdThatDoesNotFitIsRefused) {
  CameraInfo c{};
  EXPECT_TRUE(c.set_frame_id(k31));
  EXPECT_EQ(c.frame_id_str(), k31);
  EXPECT_FALSE(c.set_frame_id(k32));
  EXPECT_EQ(c.frame_id_str(), k31);
}

TEST(CameraInfo, LogSummaryHasSizeFocalLengthsAndUnits) {
  CameraInfo c = CameraInfo::make(640, 480, 525.0, 520.0, 320.0, 240.0);
  EXPECT_EQ(c.log_summary(), "CameraInfo(640x480 px, f 525.0/520.0 px, c 320.0/240.0 px)");
  c.set_distortion_model("plumb_bob");
  c.set_frame_id("camera_front");
  EXPECT_EQ(horus::log_summary(c),
            "CameraInfo(640x480 px, f 525.0/520.0 px, c 320.0/240.0 px, plumb_bob, frame camera_front)");
}

// ===========================================================================
// StereoInfo

StereoInfo stereo_pair() {
  StereoInfo s{};
  s.left_camera = CameraInfo::make(640, 480, 500.0, 500.0, 320.0, 240.0);
  s.right_camera = s.left_camera;
  s.baseline = 0.12;
  s.depth_scale = 0.001;
  return s;
}

TEST(StereoInfo, DepthIsBaselineTimesFocalLengthOverDisparity) {
  const StereoInfo s = stereo_pair();
  EXPECT_FLOAT_EQ(s.depth_from_disparity(60.0f), 1.0f);   // 0.12 m * 500 px / 60 px
  EXPECT_FLOAT_EQ(s.depth_from_disparity(6.0f), 10.0f);
  EXPECT_FLOAT_EQ(s.depth_from_disparity(0.5f), 120.0f);
}

TEST(StereoInfo, ZeroOrNegativeDisparityIsInfinitelyFar) {
  const StereoInfo s = stereo_pair();
  EXPECT_EQ(s.depth_from_disparity(0.0f), kInfF);
  EXPECT_EQ(s.depth_from_disparity(-0.0f), kInfF);
  EXPECT_EQ(s.depth_from_disparity(-3.0f), kInfF);
}

TEST(StereoInfo, InfiniteDisparityIsZeroDepthAndNaNStaysNaN) {
  const StereoInfo s = stereo_pair();
  EXPECT_EQ(s.depth_from_disparity(kInfF), 0.0f);
  EXPECT_TRUE(std::isnan(s.depth_from_disparity(kNaNF)));
  EXPECT_TRUE(std::isnan(s.disparity_from_depth(kNaNF)));
}

TEST(StereoInfo, DisparityFromDepthInvertsDepthFromDisparity) {
  const StereoInfo s = stereo_pair();
  EXPECT_FLOAT_EQ(s.disparity_from_depth(1.0f), 60.0f);
  EXPECT_FLOAT_EQ(s.disparity_from_depth(10.0f), 6.0f);
  for (float d : {0.25f, 3.0f, 47.5f, 200.0f}) EXPECT_FLOAT_EQ(s.disparity_from_depth(s.depth_from_disparity(d)), d);
}

TEST(StereoInfo, ZeroOrNegativeDepthGivesZeroDisparity) {
  const StereoInfo s = stereo_pair();
  EXPECT_EQ(s.disparity_from_depth(0.0f), 0.0f);
  EXPECT_EQ(s.disparity_from_depth(-2.0f), 0.0f);
  EXPECT_EQ(s.disparity_from_depth(kInfF), 0.0f);
}

TEST(StereoInfo, UncalibratedPairGivesNoDepth) {
  StereoInfo s = stereo_pair();
  s.baseline = 0.0;
  EXPECT_EQ(s.depth_from_disparity(10.0f), 0.0f);
  const StereoInfo zero{};
  EXPECT_EQ(zero.depth_from_disparity(10.0f), 0.0f);
  EXPECT_EQ(zero.depth_from_disparity(0.0f), kInfF);
}

TEST(StereoInfo, DepthScaleIsNotAppliedByTheHelpers) {
  StereoInfo s = stereo_pair();
  s.depth_scale = 1000.0;
  EXPECT_FLOAT_EQ(s.depth_from_disparity(60.0f), 1.0f);
}

TEST(StereoInfo, LogSummaryHasBaselineInMetres) {
  EXPECT_EQ(stereo_pair().log_summary(), "StereoInfo(640x480 px, baseline 0.120 m, fx 500.0 px, depth scale 0.001)");
}

// ===========================================================================
// RegionOfInterest

TEST(RegionOfInterest, MakeSetsFieldsWithoutRectification) {
  const RegionOfInterest r = RegionOfInterest::make(10, 20, 100, 80);
  EXPECT_EQ(r, (RegionOfInterest{10, 20, 100, 80, false}));
}

TEST(RegionOfInterest, ContainsIncludesLeftTopAndExcludesRightBottomEdges) {
  const RegionOfInterest r = RegionOfInterest::make(10, 20, 100, 80);
  EXPECT_TRUE(r.contains(50, 50));
  EXPECT_TRUE(r.contains(10, 20));     // top-left corner
  EXPECT_TRUE(r.contains(109, 99));    // last pixel
  EXPECT_FALSE(r.contains(110, 50));   // right edge
  EXPECT_FALSE(r.contains(50, 100));   // bottom edge
  EXPECT_FALSE(r.contains(9, 50));
  EXPECT_FALSE(r.contains(50, 19));
  EXPECT_FALSE(r.contains(5, 50));
}

TEST(RegionOfInterest, EmptyRegionContainsNothing) {
  EXPECT_FALSE(RegionOfInterest::make(10, 10, 0, 5).contains(10, 10));
  EXPECT_FALSE(RegionOfInterest::make(10, 10, 5, 0).contains(10, 10));
  EXPECT_EQ(RegionOfInterest::make(10, 10, 0, 5).area(), 0u);
}

TEST(RegionOfInterest, RegionReachingPastTwoToThe32DoesNotWrap) {
  const RegionOfInterest r = RegionOfInterest::make(kU32Max - 10, 0, 100, 1);
  EXPECT_TRUE(r.contains(kU32Max, 0));
  EXPECT_TRUE(r.contains(kU32Max - 10, 0));
  EXPECT_FALSE(r.contains(5, 0));  // x_offset + width wraps to 89 in 32 bits
  EXPECT_FALSE(r.fits_in(kU32Max, 1));
}

TEST(RegionOfInterest, AreaDoesNotOverflow) {
  EXPECT_EQ(RegionOfInterest::make(10, 20, 100, 80).area(), 8000u);
  EXPECT_EQ(RegionOfInterest::make(0, 0, 100000, 100000).area(), 10'000'000'000ULL);
}

TEST(RegionOfInterest, FitsInChecksTheImageBounds) {
  EXPECT_TRUE(RegionOfInterest::make(0, 0, 640, 480).fits_in(640, 480));
  EXPECT_TRUE(RegionOfInterest::make(540, 380, 100, 100).fits_in(640, 480));
  EXPECT_FALSE(RegionOfInterest::make(541, 380, 100, 100).fits_in(640, 480));
  EXPECT_FALSE(RegionOfInterest::make(540, 381, 100, 100).fits_in(640, 480));
  EXPECT_TRUE(RegionOfInterest::make(640, 480, 0, 0).fits_in(640, 480));
}

TEST(RegionOfInterest, LogSummaryHasUnits) {
  RegionOfInterest r = RegionOfInterest::make(10, 20, 100, 80);
  EXPECT_EQ(r.log_summary(), "RegionOfInterest(x 10 px, y 20 px, 100x80 px, raw)");
  r.do_rectify = true;
  EXPECT_EQ(horus::log_summary(r), "RegionOfInterest(x 10 px, y 20 px, 100x80 px, rectified)");
}

// ===========================================================================
// CompressedImage

TEST(CompressedImage, MakeKeepsFormatBytesAndSize) {
  const CompressedImage img = CompressedImage::make("jpeg", {0xFF, 0xD8, 0xFF, 0xE0}, 640, 480);
  EXPECT_EQ(img.format_str(), "jpeg");
  EXPECT_EQ(img.data, (std::vector<std::uint8_t>{0xFF, 0xD8, 0xFF, 0xE0}));
  EXPECT_EQ(img.width, 640u);
  EXPECT_EQ(img.height, 480u);
  EXPECT_EQ(img.frame_id_str(), "");
  EXPECT_EQ(img.timestamp_ns, 0u);
  const CompressedImage unknown_size = CompressedImage::make("png", {1, 2});
  EXPECT_EQ(unknown_size.width, 0u);
  EXPECT_EQ(unknown_size.height, 0u);
}

TEST(CompressedImage, FormatThatDoesNotFitIsRefused) {
  EXPECT_TRUE(CompressedImage::create("1234567", {}).has_value());
  EXPECT_FALSE(CompressedImage::create("12345678", {1}).has_value());
  EXPECT_THROW((void)CompressedImage::make("jpeg2000x", {1}), std::invalid_argument);
  CompressedImage img = CompressedImage::make("webp", {});
  EXPECT_FALSE(img.set_format("too_long_"));
  EXPECT_EQ(img.format_str(), "webp");
  EXPECT_TRUE(img.set_frame_id(k31));
  EXPECT_FALSE(img.set_frame_id(k32));
  EXPECT_EQ(img.frame_id_str(), k31);
}

TEST(CompressedImage, EqualityComparesTheBytes) {
  const CompressedImage a = CompressedImage::make("png", {1, 2, 3});
  CompressedImage b = a;
  EXPECT_EQ(a, b);
  b.data[2] = 4;
  EXPECT_NE(a, b);
  b.data = {1, 2, 3, 0};
  EXPECT_NE(a, b);
}

TEST(CompressedImage, IsVariableSize) {
  static_assert(!horus::reflect::is_fixed_size<CompressedImage>);
  EXPECT_NE(horus::reflect::type_signature<CompressedImage>().find("seq<u8> data"), std::string::npos);
}

TEST(CompressedImage, LogSummaryGivesFormatSizeAndKibibytes) {
  EXPECT_EQ(CompressedImage::make("jpeg", std::vector<std::uint8_t>(36045, 7), 640, 480).log_summary(),
            "CompressedImage(jpeg 640x480, 35.2 KiB)");
  EXPECT_EQ(CompressedImage::make("png", std::vector<std::uint8_t>(512), 32, 16).log_summary(),
            "CompressedImage(png 32x16, 512 B)");
  EXPECT_EQ(CompressedImage::make("jpeg", std::vector<std::uint8_t>(3 * 1024 * 1024 / 2), 4000, 3000).log_summary(),
            "CompressedImage(jpeg 4000x3000, 1.5 MiB)");
  EXPECT_EQ(horus::log_summary(CompressedImage{}), "CompressedImage(unknown ?x?, 0 B)");
}

// ===========================================================================
// BoundingBox2D

TEST(BoundingBox2D, FromCenterIsTheYoloConvention) {
  const BoundingBox2D b = BoundingBox2D::from_center(100.0f, 100.0f, 50.0f, 30.0f);
  EXPECT_EQ(b, BoundingBox2D::make(75.0f, 85.0f, 50.0f, 30.0f));
  EXPECT_EQ(b.center_x(), 100.0f);
  EXPECT_EQ(b.center_y(), 100.0f);
  EXPECT_EQ(b.center(), std::make_pair(100.0f, 100.0f));
  EXPECT_EQ(b.area(), 1500.0f);
}

TEST(BoundingBox2D, ContainsIncludesTheEdges) {
  const BoundingBox2D b = BoundingBox2D::make(10.0f, 20.0f, 30.0f, 40.0f);
  EXPECT_TRUE(b.contains(25.0f, 40.0f));
  EXPECT_TRUE(b.contains(10.0f, 20.0f));
  EXPECT_TRUE(b.contains(40.0f, 60.0f));
  EXPECT_FALSE(b.contains(40.5f, 30.0f));
  EXPECT_FALSE(b.contains(20.0f, 19.5f));
  EXPECT_FALSE(b.contains(kNaNF, 30.0f));
}

TEST(BoundingBox2D, IouOfIdenticalBoxesIsOne) {
  const BoundingBox2D b = BoundingBox2D::make(3.0f, 4.0f, 10.0f, 20.0f);
  EXPECT_FLOAT_EQ(b.iou(b), 1.0f);
}

TEST(BoundingBox2D, IouOfDisjointOrTouchingBoxesIsZero) {
  const BoundingBox2D a = BoundingBox2D::make(0.0f, 0.0f, 10.0f, 10.0f);
  EXPECT_EQ(a.iou(BoundingBox2D::make(20.0f, 20.0f, 5.0f, 5.0f)), 0.0f);
  EXPECT_EQ(a.iou(BoundingBox2D::make(20.0f, 0.0f, 5.0f, 10.0f)), 0.0f);  // overlaps in y only
  EXPECT_EQ(a.iou(BoundingBox2D::make(10.0f, 0.0f, 5.0f, 10.0f)), 0.0f);  // shares an edge
}

TEST(BoundingBox2D, IouOfPartialOverlapIsIntersectionOverUnion) {
  const BoundingBox2D a = BoundingBox2D::make(0.0f, 0.0f, 100.0f, 100.0f);
  const BoundingBox2D b = BoundingBox2D::make(50.0f, 50.0f, 100.0f, 100.0f);
  EXPECT_NEAR(a.iou(b), 2500.0f / 17500.0f, 1e-6f);
  EXPECT_EQ(a.iou(b), b.iou(a));
  const BoundingBox2D inner = BoundingBox2D::make(25.0f, 25.0f, 50.0f, 50.0f);
  EXPECT_FLOAT_EQ(a.iou(inner), 0.25f);
}

TEST(BoundingBox2D, IouIsZeroWithoutAreaOrWithNaN) {
  const BoundingBox2D empty = BoundingBox2D::make(5.0f, 5.0f, 0.0f, 0.0f);
  EXPECT_EQ(empty.iou(empty), 0.0f);
  EXPECT_EQ(empty.iou(BoundingBox2D::make(0.0f, 0.0f, 10.0f, 10.0f)), 0.0f);
  const BoundingBox2D nan_box = BoundingBox2D::make(kNaNF, 0.0f, 10.0f, 10.0f);
  EXPECT_EQ(nan_box.iou(BoundingBox2D::make(0.0f, 0.0f, 10.0f, 10.0f)), 0.0f);
}

// ===========================================================================
// BoundingBox3D

TEST(BoundingBox3D, MakeRotatesAboutZOnly) {
  const BoundingBox3D b = BoundingBox3D::make(1.0f, 2.0f, 0.5f, 4.5f, 2.0f, 1.5f, 0.1f);
  EXPECT_EQ(b, (BoundingBox3D{1.0f, 2.0f, 0.5f, 4.5f, 2.0f, 1.5f, 0.0f, 0.0f, 0.1f}));
  EXPECT_EQ(BoundingBox3D::with_rotation(1, 2, 3, 4, 5, 6, 0.1f, 0.2f, 0.3f),
            (BoundingBox3D{1, 2, 3, 4, 5, 6, 0.1f, 0.2f, 0.3f}));
}

TEST(BoundingBox3D, VolumeIsTheProductOfTheExtents) {
  EXPECT_FLOAT_EQ(BoundingBox3D::make(0, 0, 0, 2.0f, 3.0f, 4.0f, 0.0f).volume(), 24.0f);
  EXPECT_FLOAT_EQ(BoundingBox3D::make(0, 0, 0, 2.0f, 3.0f, 4.0f, 1.2f).volume(), 24.0f);
  EXPECT_EQ(BoundingBox3D::make(0, 0, 0, 2.0f, 0.0f, 4.0f, 0.0f).volume(), 0.0f);
}

// ===========================================================================
// Detection and Detection3D

TEST(Detection, MakeSetsNameConfidenceAndBox) {
  const Detection d = Detection::make("person", 0.85f, 10.0f, 20.0f, 50.0f, 100.0f);
  EXPECT_EQ(d.class_name_str(), "person");
  EXPECT_EQ(d.confidence, 0.85f);
  EXPECT_EQ(d.bbox, BoundingBox2D::make(10.0f, 20.0f, 50.0f, 100.0f));
  EXPECT_EQ(d.class_id, 0u);
  EXPECT_EQ(d.instance_id, 0u);
}

TEST(Detection, ClassNamesThatDoNotFitAreRefused) {
  EXPECT_TRUE(Detection::create(k31, 0.5f, 0, 0, 1, 1).has_value());
  EXPECT_FALSE(Detection::create(k32, 0.5f, 0, 0, 1, 1).has_value());
  EXPECT_THROW((void)Detection::make(k32, 0.5f, 0, 0, 1, 1), std::invalid_argument);
  Detection d = Detection::make("car", 0.9f, 0, 0, 1, 1);
  EXPECT_FALSE(d.set_class_name("this_is_a_very_long_class_name_that_should_be_refused"));
  EXPECT_EQ(d.class_name_str(), "car");
  EXPECT_TRUE(d.set_class_name(k31));
  EXPECT_EQ(d.class_name_str(), k31);
}

TEST(Detection, WithClassIdLeavesTheNameEmpty) {
  const Detection d = Detection::with_class_id(7, 0.6f, BoundingBox2D::make(1, 2, 3, 4));
  EXPECT_EQ(d.class_id, 7u);
  EXPECT_EQ(d.class_name_str(), "");
  EXPECT_EQ(d.bbox.height, 4.0f);
}

TEST(Detection, IsConfidentAtOrAboveTheThreshold) {
  const Detection d = Detection::make("person", 0.85f, 0, 0, 1, 1);
  EXPECT_TRUE(d.is_confident(0.5f));
  EXPECT_TRUE(d.is_confident(0.85f));
  EXPECT_FALSE(d.is_confident(0.9f));
  EXPECT_FALSE(d.is_confident(kNaNF));
  Detection nan_conf = d;
  nan_conf.confidence = kNaNF;
  EXPECT_FALSE(nan_conf.is_confident(0.0f));
}

TEST(Detection3D, MakeAndWithVelocity) {
  const Detection3D d =
      Detection3D::make("car", 0.9f, BoundingBox3D::make(1.0f, 2.0f, 0.5f, 4.5f, 2.0f, 1.5f, 0.1f))
          .with_velocity(3.0f, 4.0f, 0.0f);
  EXPECT_EQ(d.class_name_str(), "car");
  EXPECT_EQ(d.confidence, 0.9f);
  EXPECT_EQ(d.bbox.length, 4.5f);
  EXPECT_EQ(d.velocity, (std::array<float, 3>{3.0f, 4.0f, 0.0f}));
  EXPECT_FLOAT_EQ(d.speed(), 5.0f);
  EXPECT_TRUE(d.is_confident(0.9f));
  EXPECT_FALSE(d.is_confident(0.95f));
}

TEST(Detection3D, ClassNamesThatDoNotFitAreRefused) {
  EXPECT_FALSE(Detection3D::create(k32, 0.5f, BoundingBox3D{}).has_value());
  EXPECT_THROW((void)Detection3D::make(k32, 0.5f, BoundingBox3D{}), std::invalid_argument);
  Detection3D d = Detection3D::make("truck", 0.5f, BoundingBox3D{});
  EXPECT_FALSE(d.set_class_name(k32));
  EXPECT_EQ(d.class_name_str(), "truck");
}

}  // namespace

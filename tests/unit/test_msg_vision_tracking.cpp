// Unit tests of SegmentationMask, the landmarks, TrackedObject and TrackingHeader, the
// properties of every vision message, and their printing and JSON details.
#include "msg_vision_test.hpp"
#include "msg_properties_test.hpp"

namespace {

// ===========================================================================
// SegmentationMask

TEST(SegmentationMask, FactoriesSetTheMaskType) {
  const SegmentationMask s = SegmentationMask::semantic(640, 480, 21);
  EXPECT_TRUE(s.is_semantic());
  EXPECT_FALSE(s.is_instance());
  EXPECT_FALSE(s.is_panoptic());
  EXPECT_EQ(s.mask_type_enum(), SegmentationType::Semantic);
  EXPECT_EQ(s.num_classes, 21u);

  const SegmentationMask i = SegmentationMask::instance(100, 50);
  EXPECT_TRUE(i.is_instance());
  EXPECT_EQ(i.mask_type, 1u);
  EXPECT_EQ(i.num_classes, 0u);

  const SegmentationMask p = SegmentationMask::panoptic(100, 50, 80);
  EXPECT_TRUE(p.is_panoptic());
  EXPECT_EQ(p.mask_type_enum(), SegmentationType::Panoptic);
  EXPECT_EQ(p.width, 100u);
  EXPECT_EQ(p.height, 50u);
}

TEST(SegmentationMask, UnknownMaskTypeHasNoEnum) {
  SegmentationMask m = SegmentationMask::semantic(1, 1, 1);
  m.mask_type = 3;
  EXPECT_EQ(m.mask_type_enum(), std::nullopt);
  EXPECT_FALSE(m.is_semantic() || m.is_instance() || m.is_panoptic());
  m.mask_type = 256;  // would read as Semantic if cut to a byte
  EXPECT_EQ(m.mask_type_enum(), std::nullopt);
  m.set_mask_type(SegmentationType::Instance);
  EXPECT_EQ(m.mask_type, 1u);
  EXPECT_EQ(to_string(SegmentationType::Panoptic), "Panoptic");
}

TEST(SegmentationMask, DataSizeIsOneOrTwoBytesPerPixelWithoutOverflow) {
  EXPECT_EQ(SegmentationMask::semantic(1920, 1080, 80).data_size(), 1920u * 1080u);
  EXPECT_EQ(SegmentationMask::panoptic(1920, 1080, 80).data_size_u16(), 2u * 1920u * 1080u);
  EXPECT_EQ(SegmentationMask::instance(65536, 65536).data_size(), std::size_t{1} << 32);
  EXPECT_EQ(SegmentationMask::instance(0, 480).data_size(), 0u);
}

TEST(SegmentationMask, FrameIdThatDoesNotFitIsRefused) {
  const SegmentationMask m = SegmentationMask::semantic(640, 480, 20).with_frame_id("camera_front").with_timestamp(9);
  EXPECT_EQ(m.frame_id_str(), "camera_front");
  EXPECT_EQ(m.timestamp_ns, 9u);
  EXPECT_THROW((void)m.with_frame_id(k32), std::invalid_argument);
  SegmentationMask n = m;
  EXPECT_FALSE(n.set_frame_id(k32));
  EXPECT_EQ(n.frame_id_str(), "camera_front");
  EXPECT_TRUE(n.set_frame_id(k31));
}

TEST(SegmentationMask, ClassConstantsFollowCoco) {
  EXPECT_EQ(segmentation_classes::BACKGROUND, 0);
  EXPECT_EQ(segmentation_classes::PERSON, 1);
  EXPECT_EQ(segmentation_classes::STOP_SIGN, 13);
  EXPECT_EQ(segmentation_classes::DOG, 18);
}

TEST(SegmentationMask, LogSummaryHasTypeSizeAndClasses) {
  SegmentationMask m = SegmentationMask::semantic(640, 480, 21).with_frame_id("camera");
  m.seq = 7;
  EXPECT_EQ(m.log_summary(), "SegmentationMask(semantic 640x480 px, 21 classes, frame camera, seq 7)");
  EXPECT_EQ(horus::log_summary(SegmentationMask::instance(8, 4)), "SegmentationMask(instance 8x4 px, seq 0)");
}

// ===========================================================================
// Landmark, Landmark3D, LandmarkArray

TEST(Landmark, VisibleDistanceAndThreshold) {
  const Landmark a = Landmark::visible(0.0f, 0.0f, 0);
  const Landmark b = Landmark::visible(3.0f, 4.0f, 1);
  EXPECT_EQ(a.visibility, 1.0f);
  EXPECT_FLOAT_EQ(a.distance_to(b), 5.0f);
  const Landmark half = Landmark::make(1.0f, 2.0f, 0.5f, 3);
  EXPECT_TRUE(half.is_visible(0.3f));
  EXPECT_TRUE(half.is_visible(0.5f));
  EXPECT_FALSE(half.is_visible(0.8f));
  EXPECT_EQ(half.index, 3u);
}

TEST(Landmark3D, ToTwoDDropsZ) {
  const Landmark3D lm = Landmark3D::make(1.0f, 2.0f, 3.0f, 0.9f, 5);
  EXPECT_EQ(lm.to_2d(), Landmark::make(1.0f, 2.0f, 0.9f, 5));
  EXPECT_FLOAT_EQ(Landmark3D::visible(0, 0, 0, 0).distance_to(Landmark3D::visible(2, 3, 6, 1)), 7.0f);
  EXPECT_FALSE(lm.is_visible(0.95f));
}

TEST(LandmarkArray, PresetsHaveTheirSizesAndDimensions) {
  const LandmarkArray coco = LandmarkArray::coco_pose();
  EXPECT_EQ(coco.count(), 17u);
  EXPECT_EQ(coco.dimension, 2u);
  EXPECT_EQ(coco.count(), coco::NUM_LANDMARKS);
  const LandmarkArray pose = LandmarkArray::mediapipe_pose();
  EXPECT_EQ(pose.count(), 33u);
  EXPECT_TRUE(pose.is_3d());
  const LandmarkArray hand = LandmarkArray::mediapipe_hand();
  EXPECT_EQ(hand.count(), 21u);
  EXPECT_EQ(hand.dimension, 3u);
  const LandmarkArray face = LandmarkArray::mediapipe_face();
  EXPECT_EQ(face.count(), 468u);
  EXPECT_TRUE(face.full());
  EXPECT_FALSE(hand.full());
}

TEST(LandmarkArray, PresetsNumberTheirLandmarks) {
  const LandmarkArray coco = LandmarkArray::coco_pose();
  for (std::uint32_t i = 0; i < 17; ++i) EXPECT_EQ(coco.at(i)->index, i);
  EXPECT_EQ(coco.at(coco::LEFT_WRIST)->index, 9u);
  EXPECT_EQ(coco.landmarks[17], Landmark3D{});  // unused slots stay zero
  EXPECT_EQ(LandmarkArray::mediapipe_face().landmarks[467].index, 467u);
}

TEST(LandmarkArray, SizesBeyondCapacityAreRefused) {
  EXPECT_THROW((void)LandmarkArray::new_2d(469), std::invalid_argument);
  EXPECT_THROW((void)LandmarkArray::new_3d(1000), std::invalid_argument);
  EXPECT_EQ(LandmarkArray::new_3d(468).count(), 468u);
  EXPECT_EQ(LandmarkArray::new_2d(0).count(), 0u);
}

TEST(LandmarkArray, SetAndAtStayInsideTheActiveLandmarks) {
  LandmarkArray a = LandmarkArray::coco_pose();
  EXPECT_TRUE(a.set(coco::NOSE, Landmark::make(320.0f, 100.0f, 0.9f, coco::NOSE)));
  EXPECT_EQ(a.at(0), Landmark3D::make(320.0f, 100.0f, 0.0f, 0.9f, 0));
  EXPECT_EQ(a.at_2d(0), Landmark::make(320.0f, 100.0f, 0.9f, 0));
  EXPECT_FALSE(a.set(17, Landmark::visible(1, 1, 17)));
  EXPECT_EQ(a.landmarks[17], Landmark3D{});
  EXPECT_EQ(a.at(17), std::nullopt);
  EXPECT_EQ(a.at_2d(100), std::nullopt);
}

TEST(LandmarkArray, PushAppendsUntilFull) {
  LandmarkArray a = LandmarkArray::new_3d(0);
  EXPECT_TRUE(a.push(Landmark3D::visible(1, 2, 3, 0)));
  EXPECT_TRUE(a.push(Landmark::visible(4, 5, 1)));
  EXPECT_EQ(a.count(), 2u);
  EXPECT_EQ(a.at(1), Landmark3D::visible(4, 5, 0, 1));
  LandmarkArray face = LandmarkArray::mediapipe_face();
  EXPECT_FALSE(face.push(Landmark::visible(0, 0, 468)));
  EXPECT_EQ(face.count(), 468u);
}

TEST(LandmarkArray, CorruptCountIsClamped) {
  LandmarkArray a{};
  a.num_landmarks = 100000;
  EXPECT_EQ(a.count(), 468u);
  EXPECT_TRUE(a.at(467).has_value());
  EXPECT_FALSE(a.at(468).has_value());
  EXPECT_FALSE(a.push(Landmark{}));
}

TEST(LandmarkArray, VisibleCountAndDataSize) {
  LandmarkArray a = LandmarkArray::coco_pose();
  a.set(0, Landmark::make(1, 1, 0.9f, 0));
  a.set(1, Landmark::make(1, 1, 0.5f, 1));
  a.set(2, Landmark::make(1, 1, 0.2f, 2));
  EXPECT_EQ(a.visible_count(0.5f), 2u);
  EXPECT_EQ(a.visible_count(0.0f), 17u);
  EXPECT_EQ(a.data_size(), 17u * 16u);
  EXPECT_EQ(LandmarkArray::mediapipe_pose().data_size(), 33u * 20u);
}

TEST(LandmarkArray, BuildersSetConfidenceAndBox) {
  const LandmarkArray a = LandmarkArray::mediapipe_hand().with_confidence(0.8f).with_bbox(1, 2, 30, 40);
  EXPECT_EQ(a.confidence, 0.8f);
  EXPECT_EQ(a.bbox_x, 1.0f);
  EXPECT_EQ(a.bbox_y, 2.0f);
  EXPECT_EQ(a.bbox_width, 30.0f);
  EXPECT_EQ(a.bbox_height, 40.0f);
  EXPECT_EQ(a.count(), 21u);
}

TEST(LandmarkArray, LogSummaryIsShortForTheFaceMesh) {
  LandmarkArray face = LandmarkArray::mediapipe_face().with_confidence(0.93f);
  face.instance_id = 2;
  for (std::size_t i = 0; i < 400; ++i) face.landmarks[i].visibility = 1.0f;
  const std::string s = horus::log_summary(face);
  EXPECT_EQ(s, "LandmarkArray(468 landmarks, 3D, 400 visible >= 0.5, conf 0.93, instance 2)");
  EXPECT_LT(s.size(), 200u);
}

// ===========================================================================
// TrackedObject and TrackingHeader

TEST(TrackedObject, MakeStartsATentativeTrack) {
  const TrackedObject t = TrackedObject::make(1, BoundingBox2D::make(100, 100, 50, 50), 3, 0.95f);
  EXPECT_EQ(t.track_id, 1u);
  EXPECT_EQ(t.predicted_bbox, t.bbox);
  EXPECT_EQ(t.class_id, 3u);
  EXPECT_EQ(t.confidence, 0.95f);
  EXPECT_EQ(t.hits, 1u);
  EXPECT_EQ(t.age, 0u);
  EXPECT_TRUE(t.is_tentative());
  EXPECT_EQ(t.state_enum(), TrackState::Tentative);
}

TEST(TrackedObject, LifecycleConfirmAndDelete) {
  TrackedObject t = TrackedObject::make(1, BoundingBox2D::make(0, 0, 1, 1), 0, 1.0f);
  t.confirm();
  EXPECT_TRUE(t.is_confirmed());
  EXPECT_FALSE(t.is_tentative());
  EXPECT_EQ(t.state, 1u);
  t.mark_deleted();
  EXPECT_TRUE(t.is_deleted());
  EXPECT_EQ(t.state_enum(), TrackState::Deleted);
  t.state = 9;
  EXPECT_EQ(t.state_enum(), std::nullopt);
  EXPECT_FALSE(t.is_tentative() || t.is_confirmed() || t.is_deleted());
}

TEST(TrackedObject, UpdateTakesVelocityFromTheMotionOfTheCentre) {
  TrackedObject t = TrackedObject::make(1, BoundingBox2D::make(100, 100, 50, 50), 0, 0.95f);
  t.time_since_update = 2;
  t.update(BoundingBox2D::make(110, 105, 60, 50), 0.93f);  // centre moves by (15, 5)
  EXPECT_FLOAT_EQ(t.velocity_x, 15.0f);
  EXPECT_FLOAT_EQ(t.velocity_y, 5.0f);
  EXPECT_EQ(t.bbox, BoundingBox2D::make(110, 105, 60, 50));
  EXPECT_EQ(t.confidence, 0.93f);
  EXPECT_EQ(t.hits, 2u);
  EXPECT_EQ(t.age, 1u);
  EXPECT_EQ(t.time_since_update, 0u);
}

TEST(TrackedObject, MarkMissedPredictsAtConstantVelocity) {
  TrackedObject t = TrackedObject::make(1, BoundingBox2D::make(100, 100, 50, 50), 0, 0.95f);
  t.update(BoundingBox2D::make(110, 105, 50, 50), 0.9f);
  t.mark_missed();
  EXPECT_EQ(t.time_since_update, 1u);
  EXPECT_EQ(t.age, 2u);
  EXPECT_EQ(t.hits, 2u);
  EXPECT_FLOAT_EQ(t.predicted_bbox.x, 120.0f);
  EXPECT_FLOAT_EQ(t.predicted_bbox.y, 110.0f);
  t.mark_missed();
  EXPECT_FLOAT_EQ(t.predicted_bbox.x, 130.0f);
  EXPECT_FLOAT_EQ(t.predicted_bbox.y, 115.0f);
  EXPECT_EQ(t.predicted_bbox.width, 50.0f);
  EXPECT_EQ(t.bbox, BoundingBox2D::make(110, 105, 50, 50));
}

TEST(TrackedObject, SpeedAndHeading) {
  TrackedObject t{};
  EXPECT_EQ(t.speed(), 0.0f);
  EXPECT_EQ(t.heading(), 0.0f);
  t.velocity_x = 3.0f;
  t.velocity_y = 4.0f;
  EXPECT_FLOAT_EQ(t.speed(), 5.0f);
  t.velocity_x = 0.0f;
  t.velocity_y = -2.0f;
  EXPECT_FLOAT_EQ(t.heading(), -std::numbers::pi_v<float> / 2.0f);
}

TEST(TrackedObject, ClassNamesThatDoNotFitAreRefused) {
  TrackedObject t{};
  EXPECT_TRUE(t.set_class_name("person"));
  EXPECT_EQ(t.class_name_str(), "person");
  EXPECT_TRUE(t.set_class_name(std::string(15, 'x')));
  EXPECT_FALSE(t.set_class_name(std::string(16, 'y')));
  EXPECT_EQ(t.class_name_str(), std::string(15, 'x'));
}

TEST(TrackedObject, LogSummaryNamesTrackAndState) {
  TrackedObject t = TrackedObject::make(7, BoundingBox2D::make(0, 0, 10, 10), 1, 0.95f);
  t.confirm();
  t.set_class_name("person");
  t.age = 12;
  t.velocity_x = 3.0f;
  t.velocity_y = 4.0f;
  EXPECT_EQ(t.log_summary(), "TrackedObject(id 7, person, confirmed, conf 0.95, age 12 frames, 0 missed, speed 5.0)");
  EXPECT_EQ(horus::log_summary(TrackedObject{}),
            "TrackedObject(id 0, class 0, tentative, conf 0.00, age 0 frames, 0 missed, speed 0.0)");
}

TEST(TrackingHeader, MakeTimestampAndDataSize) {
  const TrackingHeader h = TrackingHeader::make(5, 42).with_timestamp(1234);
  EXPECT_EQ(h.num_tracks, 5u);
  EXPECT_EQ(h.frame_id, 42u);
  EXPECT_EQ(h.timestamp_ns, 1234u);
  EXPECT_EQ(h.total_tracks, 0u);
  EXPECT_EQ(h.data_size(), 5u * 96u);
  EXPECT_EQ(TrackingHeader::make(kU32Max, 0).data_size(), std::size_t{kU32Max} * 96u);
}

TEST(TrackingHeader, LogSummaryHasCounts) {
  TrackingHeader h = TrackingHeader::make(5, 42);
  h.active_tracks = 3;
  h.total_tracks = 17;
  EXPECT_EQ(horus::log_summary(h), "TrackingHeader(frame 42, 5 tracks, 3 active, 17 created)");
}

// ===========================================================================
// Properties of every message

template <>
CameraInfo sample<CameraInfo>() {
  CameraInfo c = CameraInfo::make(1280, 720, 910.5, 911.25, 640.5, 360.25).with_distortion_model("plumb_bob");
  c.distortion_coefficients = {0.1, -0.2, 0.001, -0.002, 0.05, 0.0, 0.0, 0.0};
  c.rectification_matrix[1] = 0.01;
  c.projection_matrix[3] = -0.12;
  c.set_frame_id("camera_left");
  c.timestamp_ns = 1'700'000'000'000'000'001ULL;
  return c;
}
template <>
StereoInfo sample<StereoInfo>() {
  StereoInfo s{};
  s.left_camera = sample<CameraInfo>();
  s.right_camera = sample<CameraInfo>();
  s.right_camera.set_frame_id("camera_right");
  s.baseline = 0.12;
  s.depth_scale = 0.001;
  return s;
}
template <>
RegionOfInterest sample<RegionOfInterest>() {
  RegionOfInterest r = RegionOfInterest::make(10, 20, 100, 80);
  r.do_rectify = true;
  return r;
}
template <>
CompressedImage sample<CompressedImage>() {
  CompressedImage img = CompressedImage::make("jpeg", {0xFF, 0xD8, 0x00, 0x7F, 0x80, 0xFF, 0xD9}, 640, 480);
  img.set_frame_id("camera_front");
  img.timestamp_ns = 77;
  return img;
}
template <>
BoundingBox2D sample<BoundingBox2D>() { return BoundingBox2D::make(1.5f, 2.25f, 30.0f, 40.5f); }
template <>
BoundingBox3D sample<BoundingBox3D>() { return BoundingBox3D::with_rotation(1, -2, 0.5f, 4.5f, 2, 1.5f, 0.1f, -0.2f, 0.3f); }
template <>
Detection sample<Detection>() {
  Detection d = Detection::make("person", 0.875f, 10, 20, 50, 100);
  d.class_id = 1;
  d.instance_id = 4;
  return d;
}
template <>
Detection3D sample<Detection3D>() {
  Detection3D d = Detection3D::make("car", 0.5f, sample<BoundingBox3D>()).with_velocity(10, -5, 0.25f);
  d.class_id = 3;
  d.instance_id = 12;
  return d;
}
template <>
SegmentationMask sample<SegmentationMask>() {
  SegmentationMask m = SegmentationMask::panoptic(640, 480, 80).with_frame_id("camera").with_timestamp(5);
  m.seq = 99;
  return m;
}
template <>
Landmark sample<Landmark>() { return Landmark::make(320.5f, 100.25f, 0.75f, coco::NOSE + 1); }
template <>
Landmark3D sample<Landmark3D>() { return Landmark3D::make(0.5f, -0.25f, 1.5f, 0.875f, 11); }
template <>
LandmarkArray sample<LandmarkArray>() {
  LandmarkArray a = LandmarkArray::coco_pose().with_confidence(0.875f).with_bbox(100, 50, 200, 400);
  a.instance_id = 2;
  a.timestamp_ns = 1000;
  a.set(coco::LEFT_WRIST, Landmark::make(150.5f, 300.25f, 0.5f, coco::LEFT_WRIST));
  a.landmarks[0].z = -0.5f;
  return a;
}
template <>
TrackedObject sample<TrackedObject>() {
  TrackedObject t = TrackedObject::make(123456789012ULL, BoundingBox2D::make(100, 100, 50, 50), 1, 0.95f);
  t.update(BoundingBox2D::make(110, 105, 50, 50), 0.875f);
  t.mark_missed();
  t.accel_x = 0.5f;
  t.accel_y = -0.25f;
  t.confirm();
  t.set_class_name("person");
  return t;
}
template <>
TrackingHeader sample<TrackingHeader>() {
  TrackingHeader h = TrackingHeader::make(5, 42).with_timestamp(18'446'744'073'709'551'615ULL);
  h.total_tracks = 17;
  h.active_tracks = 3;
  return h;
}

// The vision types: the properties every message has (msg_properties_test.hpp; CompressedImage is
// variable-size).
using VisionMessages =
    ::testing::Types<CameraInfo, StereoInfo, RegionOfInterest, CompressedImage, BoundingBox2D, BoundingBox3D, Detection,
                     Detection3D, SegmentationMask, Landmark, Landmark3D, LandmarkArray, TrackedObject, TrackingHeader>;
template <>
constexpr bool kVariableSize<CompressedImage> = true;
INSTANTIATE_TYPED_TEST_SUITE_P(Vision, MessageProperties, VisionMessages);

TEST(VariableSizeVisionMessages, CompressedImageIsNotFixedSizeAndEmptyByDefault) {
  static_assert(!horus::reflect::is_fixed_size<CompressedImage>);
  EXPECT_TRUE(CompressedImage{}.data.empty());
}

// ===========================================================================
// Printing and JSON details

TEST(Formatting, TextFieldsPrintAsTextAndFieldsAppear) {
  EXPECT_EQ(fmt::format("{}", sample<Detection>()),
            "Detection { bbox: BoundingBox2D { x: 10, y: 20, width: 50, height: 100 }, confidence: 0.875, "
            "class_id: 1, class_name: \"person\", instance_id: 4 }");
  EXPECT_EQ(fmt::format("{}", sample<RegionOfInterest>()),
            "RegionOfInterest { x_offset: 10, y_offset: 20, width: 100, height: 80, do_rectify: true }");
  EXPECT_EQ(fmt::format("{}", sample<CompressedImage>()),
            "CompressedImage { format: \"jpeg\", data: [255, 216, 0, 127, 128, 255, 217], width: 640, height: 480, "
            "frame_id: \"camera_front\", timestamp_ns: 77 }");
  const std::string cam = fmt::format("{}", sample<CameraInfo>());
  EXPECT_NE(cam.find("distortion_model: \"plumb_bob\""), std::string::npos) << cam;
  const std::string track = fmt::format("{}", sample<TrackedObject>());
  EXPECT_NE(track.find("class_name: \"person\""), std::string::npos) << track;
}

TEST(Json, CompressedImageDataIsAnArrayOfBytes) {
  const nlohmann::json j = horus::to_json(sample<CompressedImage>());
  EXPECT_EQ(j["format"], "jpeg");
  EXPECT_EQ(j["data"], nlohmann::json::array({255, 216, 0, 127, 128, 255, 217}));
  nlohmann::json bad = j;
  bad["data"][0] = 256;
  EXPECT_THROW((void)horus::from_json<CompressedImage>(bad), horus::JsonError);
  nlohmann::json long_format = j;
  long_format["format"] = "jpeg2000x";
  EXPECT_THROW((void)horus::from_json<CompressedImage>(long_format), horus::JsonError);
}

TEST(Json, NamesThatDoNotFitAreRejectedWhenRead) {
  nlohmann::json j = horus::to_json(sample<TrackedObject>());
  j["class_name"] = std::string(16, 'z');
  EXPECT_THROW((void)horus::from_json<TrackedObject>(j), horus::JsonError);
  nlohmann::json d = horus::to_json(sample<Detection>());
  d["class_name"] = k32;
  EXPECT_THROW((void)horus::from_json<Detection>(d), horus::JsonError);
}

}  // namespace

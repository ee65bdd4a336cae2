// Segmentation, landmark and tracking messages: SegmentationMask, Landmark,
// Landmark3D, LandmarkArray, TrackedObject, TrackingHeader.
//
// All fixed-size (trivially copyable). Text fields are NUL-terminated
// std::array<char, N> written through set_fixed_str(): text that does not fit
// is refused, never cut. Image coordinates are in pixels (or normalised to
// [0, 1] when the producer says so), 3D coordinates in metres, timestamps in
// ns since the epoch. Layouts follow HORUS's Rust structs without their
// private padding fields; see LandmarkArray for the one deliberate extension.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "horus/fixed_string.hpp"
#include "horus/msg/detection.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// What each pixel of a segmentation mask holds (SegmentationMask::mask_type).
enum class SegmentationType : std::uint8_t {
  Semantic = 0,  ///< a class id per pixel
  Instance = 1,  ///< an instance id per pixel
  Panoptic = 2,  ///< class and instance (u16 pixels when more than 256 ids)
};
HORUS_REFLECT_ENUM(SegmentationType, Semantic, Instance, Panoptic)

/// COCO-style class ids commonly used in semantic masks (as HORUS's `classes`;
/// COCO leaves 12 unused).
namespace segmentation_classes {
inline constexpr std::uint8_t BACKGROUND = 0;
inline constexpr std::uint8_t PERSON = 1;
inline constexpr std::uint8_t BICYCLE = 2;
inline constexpr std::uint8_t CAR = 3;
inline constexpr std::uint8_t MOTORCYCLE = 4;
inline constexpr std::uint8_t AIRPLANE = 5;
inline constexpr std::uint8_t BUS = 6;
inline constexpr std::uint8_t TRAIN = 7;
inline constexpr std::uint8_t TRUCK = 8;
inline constexpr std::uint8_t BOAT = 9;
inline constexpr std::uint8_t TRAFFIC_LIGHT = 10;
inline constexpr std::uint8_t FIRE_HYDRANT = 11;
inline constexpr std::uint8_t STOP_SIGN = 13;
inline constexpr std::uint8_t PARKING_METER = 14;
inline constexpr std::uint8_t BENCH = 15;
inline constexpr std::uint8_t BIRD = 16;
inline constexpr std::uint8_t CAT = 17;
inline constexpr std::uint8_t DOG = 18;
}  // namespace segmentation_classes

/// Descriptor of a segmentation mask of width x height pixels. The pixels
/// themselves travel separately (one byte per pixel, or two for panoptic masks
/// with more than 256 ids); this message says how to read them.
struct SegmentationMask {
  std::uint32_t width{};        ///< px
  std::uint32_t height{};       ///< px
  std::uint32_t num_classes{};  ///< classes of a semantic / panoptic mask (0 for instance masks)
  std::uint32_t mask_type{};    ///< a SegmentationType: 0 semantic, 1 instance, 2 panoptic
  std::uint64_t timestamp_ns{};
  std::uint64_t seq{};               ///< sequence number
  std::array<char, 32> frame_id{};   ///< NUL-terminated, at most 31 characters

  /// A semantic mask (a class id per pixel).
  static constexpr SegmentationMask semantic(std::uint32_t width_px, std::uint32_t height_px,
                                             std::uint32_t classes) noexcept {
    return SegmentationMask{width_px, height_px, classes, static_cast<std::uint32_t>(SegmentationType::Semantic),
                            0, 0, {}};
  }
  /// An instance mask (an instance id per pixel; num_classes 0).
  static constexpr SegmentationMask instance(std::uint32_t width_px, std::uint32_t height_px) noexcept {
    return SegmentationMask{width_px, height_px, 0, static_cast<std::uint32_t>(SegmentationType::Instance), 0, 0, {}};
  }
  /// A panoptic mask (class and instance).
  static constexpr SegmentationMask panoptic(std::uint32_t width_px, std::uint32_t height_px,
                                             std::uint32_t classes) noexcept {
    return SegmentationMask{width_px, height_px, classes, static_cast<std::uint32_t>(SegmentationType::Panoptic),
                            0, 0, {}};
  }

  /// The mask type, or nullopt when mask_type holds a value with no SegmentationType.
  constexpr std::optional<SegmentationType> mask_type_enum() const noexcept {
    if (mask_type > static_cast<std::uint32_t>(SegmentationType::Panoptic)) return std::nullopt;
    return static_cast<SegmentationType>(mask_type);
  }
  constexpr void set_mask_type(SegmentationType t) noexcept { mask_type = static_cast<std::uint32_t>(t); }

  constexpr bool is_semantic() const noexcept { return mask_type == 0; }
  constexpr bool is_instance() const noexcept { return mask_type == 1; }
  constexpr bool is_panoptic() const noexcept { return mask_type == 2; }

  /// Sets the frame; returns false, changing nothing, when it does not fit
  /// (at most 31 characters, no NUL).
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }

  /// A copy with the frame set. Throws std::invalid_argument when it does not
  /// fit (at most 31 characters; HORUS's Rust version cuts it).
  [[nodiscard]] SegmentationMask with_frame_id(std::string_view frame) const {
    SegmentationMask m = *this;
    if (!m.set_frame_id(frame))
      throw std::invalid_argument("SegmentationMask frame id '" + std::string(frame) + "' has " +
                                  std::to_string(frame.size()) + " characters; at most 31 fit");
    return m;
  }
  /// A copy with the timestamp set (ns).
  [[nodiscard]] constexpr SegmentationMask with_timestamp(std::uint64_t stamp_ns) const noexcept {
    SegmentationMask m = *this;
    m.timestamp_ns = stamp_ns;
    return m;
  }

  /// Bytes of the pixel data with one byte per pixel: width * height (64-bit, no overflow).
  constexpr std::size_t data_size() const noexcept {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  }
  /// Bytes of the pixel data with two bytes per pixel (panoptic, > 256 ids).
  constexpr std::size_t data_size_u16() const noexcept { return data_size() * 2; }

  /// "SegmentationMask(semantic 640x480 px, 21 classes, frame camera, seq 7)".
  std::string log_summary() const;

  friend constexpr bool operator==(const SegmentationMask&, const SegmentationMask&) = default;
};
HORUS_REFLECT(SegmentationMask, width, height, num_classes, mask_type, timestamp_ns, seq, frame_id)

// ---------------------------------------------------------------------------
/// A 2D keypoint (pose, face, hand): position in pixels or normalised [0, 1],
/// visibility / confidence in [0, 1], and its index in the skeleton (e.g.
/// coco::NOSE).
struct Landmark {
  float x{};
  float y{};
  float visibility{};  ///< 0..1
  std::uint32_t index{};

  static constexpr Landmark make(float x_, float y_, float visibility_01, std::uint32_t idx) noexcept {
    return Landmark{x_, y_, visibility_01, idx};
  }
  /// A fully visible landmark (visibility 1).
  static constexpr Landmark visible(float x_, float y_, std::uint32_t idx) noexcept {
    return Landmark{x_, y_, 1.0f, idx};
  }

  /// visibility >= threshold; false when either is NaN.
  constexpr bool is_visible(float threshold) const noexcept { return visibility >= threshold; }

  /// Euclidean distance, in the landmarks' unit (pixels or normalised).
  float distance_to(const Landmark& other) const noexcept { return std::hypot(x - other.x, y - other.y); }

  friend constexpr bool operator==(const Landmark&, const Landmark&) = default;
};
HORUS_REFLECT(Landmark, x, y, visibility, index)

/// A 3D keypoint: position in metres (or normalised, as MediaPipe gives it),
/// visibility in [0, 1] and skeleton index. 20 bytes, like HORUS's packed struct.
struct Landmark3D {
  float x{};
  float y{};
  float z{};  ///< depth
  float visibility{};  ///< 0..1
  std::uint32_t index{};

  static constexpr Landmark3D make(float x_, float y_, float z_, float visibility_01, std::uint32_t idx) noexcept {
    return Landmark3D{x_, y_, z_, visibility_01, idx};
  }
  /// A fully visible landmark (visibility 1).
  static constexpr Landmark3D visible(float x_, float y_, float z_, std::uint32_t idx) noexcept {
    return Landmark3D{x_, y_, z_, 1.0f, idx};
  }

  /// visibility >= threshold; false when either is NaN.
  constexpr bool is_visible(float threshold) const noexcept { return visibility >= threshold; }

  /// The 2D landmark (z dropped).
  constexpr Landmark to_2d() const noexcept { return Landmark{x, y, visibility, index}; }

  /// Euclidean distance in 3D.
  float distance_to(const Landmark3D& other) const noexcept {
    return std::hypot(x - other.x, y - other.y, z - other.z);
  }

  friend constexpr bool operator==(const Landmark3D&, const Landmark3D&) = default;
};
HORUS_REFLECT(Landmark3D, x, y, z, visibility, index)

/// Landmark indices of the COCO 17-keypoint body pose.
namespace coco {
inline constexpr std::uint32_t NOSE = 0;
inline constexpr std::uint32_t LEFT_EYE = 1;
inline constexpr std::uint32_t RIGHT_EYE = 2;
inline constexpr std::uint32_t LEFT_EAR = 3;
inline constexpr std::uint32_t RIGHT_EAR = 4;
inline constexpr std::uint32_t LEFT_SHOULDER = 5;
inline constexpr std::uint32_t RIGHT_SHOULDER = 6;
inline constexpr std::uint32_t LEFT_ELBOW = 7;
inline constexpr std::uint32_t RIGHT_ELBOW = 8;
inline constexpr std::uint32_t LEFT_WRIST = 9;
inline constexpr std::uint32_t RIGHT_WRIST = 10;
inline constexpr std::uint32_t LEFT_HIP = 11;
inline constexpr std::uint32_t RIGHT_HIP = 12;
inline constexpr std::uint32_t LEFT_KNEE = 13;
inline constexpr std::uint32_t RIGHT_KNEE = 14;
inline constexpr std::uint32_t LEFT_ANKLE = 15;
inline constexpr std::uint32_t RIGHT_ANKLE = 16;
inline constexpr std::uint32_t NUM_LANDMARKS = 17;
}  // namespace coco

// ---------------------------------------------------------------------------
/// The landmarks of one person, face or hand. The header fields are HORUS's
/// LandmarkArray (in its order); unlike HORUS, where this header is followed
/// by the landmark records, the landmarks travel in the message itself:
/// landmarks[0, num_landmarks) are in use, up to kMaxLandmarks (468, the
/// largest preset, MediaPipe face mesh). 2D sets (dimension 2) leave z at 0.
///
/// The presets size the set and number each landmark (landmarks[i].index = i)
/// with zero coordinates and visibility, ready to be filled in.
struct LandmarkArray {
  static constexpr std::size_t kMaxLandmarks = 468;
  static constexpr std::uint32_t COCO_POSE_LANDMARKS = 17;
  static constexpr std::uint32_t MEDIAPIPE_POSE_LANDMARKS = 33;
  static constexpr std::uint32_t MEDIAPIPE_HAND_LANDMARKS = 21;
  static constexpr std::uint32_t MEDIAPIPE_FACE_LANDMARKS = 468;

  std::uint32_t num_landmarks{};  ///< landmarks in use
  std::uint32_t dimension{};      ///< 2 for 2D, 3 for 3D
  std::uint32_t instance_id{};    ///< person / detection id
  float confidence{};             ///< 0..1, for the whole set
  std::uint64_t timestamp_ns{};
  float bbox_x{};       ///< px, bounding box of the landmarks
  float bbox_y{};       ///< px
  float bbox_width{};   ///< px
  float bbox_height{};  ///< px
  std::array<Landmark3D, kMaxLandmarks> landmarks{};

  /// n numbered 2D landmarks. Throws std::invalid_argument when n > kMaxLandmarks.
  static constexpr LandmarkArray new_2d(std::uint32_t n) { return sized(n, 2); }
  /// n numbered 3D landmarks. Throws std::invalid_argument when n > kMaxLandmarks.
  static constexpr LandmarkArray new_3d(std::uint32_t n) { return sized(n, 3); }

  /// COCO body pose: 17 2D landmarks (indices in namespace coco).
  static constexpr LandmarkArray coco_pose() { return new_2d(COCO_POSE_LANDMARKS); }
  /// MediaPipe pose: 33 3D landmarks.
  static constexpr LandmarkArray mediapipe_pose() { return new_3d(MEDIAPIPE_POSE_LANDMARKS); }
  /// MediaPipe hand: 21 3D landmarks.
  static constexpr LandmarkArray mediapipe_hand() { return new_3d(MEDIAPIPE_HAND_LANDMARKS); }
  /// MediaPipe face mesh: 468 3D landmarks.
  static constexpr LandmarkArray mediapipe_face() { return new_3d(MEDIAPIPE_FACE_LANDMARKS); }

  /// A copy with the whole-set confidence.
  [[nodiscard]] constexpr LandmarkArray with_confidence(float confidence_01) const noexcept {
    LandmarkArray a = *this;
    a.confidence = confidence_01;
    return a;
  }
  /// A copy with the bounding box (px).
  [[nodiscard]] constexpr LandmarkArray with_bbox(float x_px, float y_px, float width_px,
                                                  float height_px) const noexcept {
    LandmarkArray a = *this;
    a.bbox_x = x_px;
    a.bbox_y = y_px;
    a.bbox_width = width_px;
    a.bbox_height = height_px;
    return a;
  }

  /// num_landmarks, clamped to kMaxLandmarks (a received message may hold any value).
  constexpr std::size_t count() const noexcept { return std::min<std::size_t>(num_landmarks, kMaxLandmarks); }
  constexpr bool is_3d() const noexcept { return dimension == 3; }
  constexpr bool full() const noexcept { return count() >= kMaxLandmarks; }

  /// Landmark i, or nullopt when i >= count().
  constexpr std::optional<Landmark3D> at(std::size_t i) const noexcept {
    if (i >= count()) return std::nullopt;
    return landmarks[i];
  }
  /// Landmark i without z, or nullopt when i >= count().
  constexpr std::optional<Landmark> at_2d(std::size_t i) const noexcept {
    if (i >= count()) return std::nullopt;
    return landmarks[i].to_2d();
  }

  /// Replaces landmark i. Returns false, changing nothing, when i >= count().
  constexpr bool set(std::size_t i, const Landmark3D& lm) noexcept {
    if (i >= count()) return false;
    landmarks[i] = lm;
    return true;
  }
  /// Replaces landmark i with a 2D one (z = 0). Returns false when i >= count().
  constexpr bool set(std::size_t i, const Landmark& lm) noexcept {
    return set(i, Landmark3D{lm.x, lm.y, 0.0f, lm.visibility, lm.index});
  }

  /// Appends a landmark. Returns false, changing nothing, when the set is full.
  constexpr bool push(const Landmark3D& lm) noexcept {
    if (full()) return false;
    landmarks[count()] = lm;
    num_landmarks = static_cast<std::uint32_t>(count() + 1);
    return true;
  }
  /// Appends a 2D landmark (z = 0). Returns false when the set is full.
  constexpr bool push(const Landmark& lm) noexcept { return push(Landmark3D{lm.x, lm.y, 0.0f, lm.visibility, lm.index}); }

  /// Number of landmarks in use with visibility >= threshold.
  constexpr std::size_t visible_count(float threshold) const noexcept {
    std::size_t n = 0;
    for (std::size_t i = 0; i < count(); ++i)
      if (landmarks[i].is_visible(threshold)) ++n;
    return n;
  }

  /// Bytes of the landmarks in use as HORUS sends them after its header: 16
  /// per 2D Landmark, 20 per Landmark3D (dimension other than 2 counts as 3D).
  constexpr std::size_t data_size() const noexcept {
    return count() * (dimension == 2 ? sizeof(Landmark) : sizeof(Landmark3D));
  }

  /// "LandmarkArray(17 landmarks, 2D, 15 visible >= 0.5, conf 0.93, instance 2)".
  std::string log_summary() const;

  friend constexpr bool operator==(const LandmarkArray&, const LandmarkArray&) = default;

 private:
  static constexpr LandmarkArray sized(std::uint32_t n, std::uint32_t dim) {
    if (n > kMaxLandmarks)
      throw std::invalid_argument("LandmarkArray of " + std::to_string(n) + " landmarks; at most " +
                                  std::to_string(kMaxLandmarks) + " fit");
    LandmarkArray a{};
    a.num_landmarks = n;
    a.dimension = dim;
    for (std::uint32_t i = 0; i < n; ++i) a.landmarks[i].index = i;
    return a;
  }
};
HORUS_REFLECT(LandmarkArray, num_landmarks, dimension, instance_id, confidence, timestamp_ns, bbox_x, bbox_y,
              bbox_width, bbox_height, landmarks)

// ---------------------------------------------------------------------------
/// Life-cycle state of a track (TrackedObject::state).
enum class TrackState : std::uint8_t {
  Tentative = 0,  ///< new, not yet confirmed by enough hits
  Confirmed = 1,
  Deleted = 2,  ///< lost; about to be dropped
};
HORUS_REFLECT_ENUM(TrackState, Tentative, Confirmed, Deleted)

/// One object followed by a multi-object tracker (SORT, ByteTrack ...): its
/// current and predicted boxes, identity, class, motion and bookkeeping. Motion
/// is in the tracker's unit: pixels per frame for image trackers (m/s for
/// metric ones); counts are in frames.
struct TrackedObject {
  BoundingBox2D bbox{};            ///< last associated detection
  BoundingBox2D predicted_bbox{};  ///< the tracker's prediction for the next frame
  std::uint64_t track_id{};        ///< persistent across frames
  float confidence{};              ///< 0..1, of the last detection
  std::uint32_t class_id{};
  float velocity_x{};  ///< px/frame (or m/s)
  float velocity_y{};  ///< px/frame (or m/s)
  float accel_x{};     ///< px/frame^2 (or m/s^2)
  float accel_y{};     ///< px/frame^2 (or m/s^2)
  std::uint32_t age{};                ///< frames since the track started
  std::uint32_t hits{};               ///< frames with an associated detection
  std::uint32_t time_since_update{};  ///< consecutive frames without one
  std::uint32_t state{};              ///< a TrackState: 0 tentative, 1 confirmed, 2 deleted
  std::array<char, 16> class_name{};  ///< NUL-terminated, at most 15 characters

  /// A new tentative track from its first detection: predicted box = box,
  /// hits 1, everything else 0.
  static constexpr TrackedObject make(std::uint64_t id, const BoundingBox2D& box, std::uint32_t class_id_,
                                      float confidence_01) noexcept {
    TrackedObject t{};
    t.bbox = box;
    t.predicted_bbox = box;
    t.track_id = id;
    t.confidence = confidence_01;
    t.class_id = class_id_;
    t.hits = 1;
    t.state = static_cast<std::uint32_t>(TrackState::Tentative);
    return t;
  }

  /// Sets the class name; returns false, changing nothing, when it does not fit
  /// (at most 15 characters, no NUL).
  constexpr bool set_class_name(std::string_view name) noexcept { return set_fixed_str(class_name, name); }
  constexpr std::string_view class_name_str() const noexcept { return fixed_str_view(class_name); }

  /// The state, or nullopt when state holds a value with no TrackState.
  constexpr std::optional<TrackState> state_enum() const noexcept {
    if (state > static_cast<std::uint32_t>(TrackState::Deleted)) return std::nullopt;
    return static_cast<TrackState>(state);
  }
  constexpr void set_state(TrackState s) noexcept { state = static_cast<std::uint32_t>(s); }

  constexpr bool is_tentative() const noexcept { return state == 0; }
  constexpr bool is_confirmed() const noexcept { return state == 1; }
  constexpr bool is_deleted() const noexcept { return state == 2; }
  constexpr void confirm() noexcept { set_state(TrackState::Confirmed); }
  /// Marks the track lost (HORUS's delete(); `delete` is a C++ keyword).
  constexpr void mark_deleted() noexcept { set_state(TrackState::Deleted); }

  /// Associates a new detection: the velocity becomes the motion of the box
  /// centre since the last detection (per frame), the box and confidence are
  /// replaced, hits and age go up by one and time_since_update returns to 0.
  /// predicted_bbox is left to the tracker (or to mark_missed).
  constexpr void update(const BoundingBox2D& box, float confidence_01) noexcept {
    velocity_x = box.center_x() - bbox.center_x();
    velocity_y = box.center_y() - bbox.center_y();
    bbox = box;
    confidence = confidence_01;
    ++hits;
    time_since_update = 0;
    ++age;
  }

  /// A frame without a detection: time_since_update and age go up by one, and
  /// predicted_bbox becomes the last box moved at constant velocity over the
  /// frames missed so far (HORUS moves it by one frame's velocity whatever the
  /// number of misses; the two agree on the first miss).
  constexpr void mark_missed() noexcept {
    ++time_since_update;
    ++age;
    const auto k = static_cast<float>(time_since_update);
    predicted_bbox = BoundingBox2D{bbox.x + velocity_x * k, bbox.y + velocity_y * k, bbox.width, bbox.height};
  }

  /// Magnitude of the velocity (px/frame or m/s).
  float speed() const noexcept { return std::hypot(velocity_x, velocity_y); }
  /// Direction of motion in radians, atan2(velocity_y, velocity_x), in [-pi, pi];
  /// 0 for a track that does not move. In image coordinates y points down, so
  /// positive angles turn clockwise on screen.
  float heading() const noexcept { return std::atan2(velocity_y, velocity_x); }

  /// "TrackedObject(id 7, person, confirmed, conf 0.95, age 12 frames, 3 missed, speed 5.0)".
  std::string log_summary() const;

  friend constexpr bool operator==(const TrackedObject&, const TrackedObject&) = default;
};
HORUS_REFLECT(TrackedObject, bbox, predicted_bbox, track_id, confidence, class_id, velocity_x, velocity_y, accel_x,
              accel_y, age, hits, time_since_update, state, class_name)

// ---------------------------------------------------------------------------
/// Header of one frame of tracker output: how many TrackedObject records
/// follow, the frame number, and the tracker's totals. Note: frame_id here is
/// a frame counter (u32, as in HORUS), not a coordinate-frame name.
struct TrackingHeader {
  std::uint32_t num_tracks{};     ///< TrackedObject records in this frame
  std::uint32_t frame_id{};       ///< frame number
  std::uint64_t timestamp_ns{};
  std::uint64_t total_tracks{};   ///< tracks created so far (the next id)
  std::uint32_t active_tracks{};  ///< confirmed tracks

  /// The spec's TrackingHeader::new(num_tracks, frame_id); the rest 0.
  static constexpr TrackingHeader make(std::uint32_t tracks, std::uint32_t frame) noexcept {
    return TrackingHeader{tracks, frame, 0, 0, 0};
  }
  /// A copy with the timestamp set (ns).
  [[nodiscard]] constexpr TrackingHeader with_timestamp(std::uint64_t stamp_ns) const noexcept {
    TrackingHeader h = *this;
    h.timestamp_ns = stamp_ns;
    return h;
  }

  /// Bytes of the TrackedObject records that follow: num_tracks * sizeof(TrackedObject)
  /// (this library's TrackedObject, which has no padding beyond the compiler's).
  constexpr std::size_t data_size() const noexcept {
    return static_cast<std::size_t>(num_tracks) * sizeof(TrackedObject);
  }

  /// "TrackingHeader(frame 42, 5 tracks, 3 active, 17 created)".
  std::string log_summary() const;

  friend constexpr bool operator==(const TrackingHeader&, const TrackingHeader&) = default;
};
HORUS_REFLECT(TrackingHeader, num_tracks, frame_id, timestamp_ns, total_tracks, active_tracks)

static_assert(horus::reflect::is_fixed_size<SegmentationMask>,
              "SegmentationMask must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Landmark>, "Landmark must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Landmark3D>, "Landmark3D must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<LandmarkArray>,
              "LandmarkArray must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<TrackedObject>,
              "TrackedObject must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<TrackingHeader>,
              "TrackingHeader must be trivially copyable and standard layout");
static_assert(sizeof(Landmark) == 16 && sizeof(Landmark3D) == 20, "landmark records keep HORUS's sizes");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(SegmentationMask, Landmark, Landmark3D, LandmarkArray, TrackedObject, TrackingHeader)

}  // namespace horus::msg

HORUS_API_END

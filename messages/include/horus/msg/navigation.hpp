// Navigation messages: goals and their results, waypoints and paths, compact
// path plans, occupancy grids, cost maps and velocity obstacles.
//
// Goal, GoalResult, Waypoint, Path, NavPath, PathPlan, VelocityObstacle and
// VelocityObstacles are fixed-size (trivially copyable, zero-copy); `T{}` is
// all zeros. OccupancyGrid and CostMap are variable-size (their cells live in a
// std::vector) and travel serialized.
//
// Goal and NavGoal are one type (NavGoal is an alias): the spec's NavGoal
// table lists a subset of Goal's fields, in the same order with the same
// types, and HORUS has one struct (it was renamed Goal -> NavGoal). Path and
// NavPath are two types with the same layout: the spec names the fourth field
// `duration_seconds` for Path but `estimated_time` for NavPath.
//
// Units as in geometry.hpp: metres, radians, seconds, nanoseconds since the
// epoch. Grid cells are addressed (gx, gy) with gx along world x, gy along
// world y, stored row-major (index gy * width + gx).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "horus/fixed_string.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/msg/navigation_maps.hpp"  // OccupancyGrid, CostMap
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// State of a navigation goal (carried as a raw byte in GoalResult::status).
enum class GoalStatus : std::uint8_t {
  Pending = 0,    ///< waiting to be executed
  Active = 1,     ///< being pursued
  Succeeded = 2,  ///< reached
  Aborted = 3,    ///< given up because of an error
  Cancelled = 4,  ///< cancelled by the user
  Preempted = 5,  ///< replaced by a higher-priority goal
  TimedOut = 6,   ///< not reached within timeout_seconds
};
HORUS_REFLECT_ENUM(GoalStatus, Pending, Active, Succeeded, Aborted, Cancelled, Preempted, TimedOut)

// ---------------------------------------------------------------------------
/// A navigation target: a planar pose to reach and how close counts as reached.
struct Goal {
  Pose2D target_pose{};         ///< m, rad
  double tolerance_position{};  ///< m, acceptable position error (inclusive)
  double tolerance_angle{};     ///< rad, acceptable heading error (inclusive)
  double timeout_seconds{};     ///< s to reach the goal, 0 = no limit
  std::uint8_t priority{};      ///< 0 = highest
  std::uint32_t goal_id{};
  std::uint64_t timestamp_ns{};

  /// The spec's Goal::new(pose, position_tol, angle_tol): no timeout, priority 1
  /// (as HORUS), goal_id 0; the timestamp is left 0.
  static constexpr Goal make(const Pose2D& target, double position_tolerance_m, double angle_tolerance_rad) noexcept {
    Goal g{};
    g.target_pose = target;
    g.tolerance_position = position_tolerance_m;
    g.tolerance_angle = angle_tolerance_rad;
    g.priority = 1;
    return g;
  }

  /// A copy with timeout_seconds set (s, 0 = no limit).
  [[nodiscard]] constexpr Goal with_timeout(double timeout_s) const noexcept {
    Goal g = *this;
    g.timeout_seconds = timeout_s;
    return g;
  }
  /// A copy with the priority set (0 = highest).
  [[nodiscard]] constexpr Goal with_priority(std::uint8_t goal_priority) const noexcept {
    Goal g = *this;
    g.priority = goal_priority;
    return g;
  }

  /// Distance between the positions <= tolerance_position (heading ignored).
  /// False when anything involved is NaN.
  bool is_position_reached(const Pose2D& current) const noexcept {
    return target_pose.distance_to(current) <= tolerance_position;
  }

  /// |heading difference| <= tolerance_angle, the difference wrapped into
  /// [-pi, pi] first: 3.13 and -3.13 are 0.023 rad apart. Works for headings of
  /// any size (HORUS only unwraps differences below 3 pi). False on NaN.
  bool is_orientation_reached(const Pose2D& current) const noexcept {
    return std::abs(msg::normalize_angle(target_pose.theta - current.theta)) <= tolerance_angle;
  }

  /// Position and heading both within tolerance (boundaries count as reached).
  bool is_reached(const Pose2D& current) const noexcept {
    return is_position_reached(current) && is_orientation_reached(current);
  }

  friend constexpr bool operator==(const Goal&, const Goal&) = default;
};
HORUS_REFLECT(Goal, target_pose, tolerance_position, tolerance_angle, timeout_seconds, priority, goal_id, timestamp_ns)

/// The navigation-messages page's name for Goal: the same type, so a NavGoal
/// has all 7 of Goal's fields, in Goal's order: target_pose,
/// tolerance_position, tolerance_angle, timeout_seconds, priority, goal_id,
/// timestamp_ns. The page's table omits priority and goal_id, which come
/// before timestamp_ns; so positional aggregate initialisation copied from the
/// page's example (`NavGoal{pose, 0.1, 0.05, 30.0, stamp}`) would put the
/// stamp into priority. Use designated initialisers, which name each field and
/// leave the others zero:
///
///   const NavGoal goal{.target_pose = Pose2D::make(5.0, 3.0, 0.0), .tolerance_position = 0.1,
///                      .tolerance_angle = 0.05, .timeout_seconds = 30.0, .timestamp_ns = stamp};
///
/// or Goal::make(pose, position_tol, angle_tol) (priority 1, as HORUS).
using NavGoal = Goal;

// ---------------------------------------------------------------------------
/// Feedback on a goal: status, remaining distance and time, progress, error text.
struct GoalResult {
  std::uint32_t goal_id{};
  std::uint8_t status{};                ///< a GoalStatus value (see status_enum())
  double distance_to_goal{};            ///< m
  double eta_seconds{};                 ///< s, estimated time to reach the goal
  float progress{};                     ///< 0.0 to 1.0
  std::array<char, 64> error_message{};  ///< NUL-terminated, at most 63 characters, empty if no error
  std::uint64_t timestamp_ns{};

  /// The spec's GoalResult::new(goal_id, status); the timestamp is left 0.
  static constexpr GoalResult make(std::uint32_t id, GoalStatus goal_status) noexcept {
    GoalResult r{};
    r.goal_id = id;
    r.status = static_cast<std::uint8_t>(goal_status);
    return r;
  }

  /// The status as a GoalStatus. A byte with no enumerator (> 6, e.g. from a
  /// newer sender) gives a GoalStatus whose to_string() is "".
  constexpr GoalStatus status_enum() const noexcept { return static_cast<GoalStatus>(status); }
  constexpr void set_status(GoalStatus goal_status) noexcept { status = static_cast<std::uint8_t>(goal_status); }

  /// Sets the error text; returns false, changing nothing, when it does not fit
  /// (at most 63 characters, no NUL). HORUS's with_error() cuts instead.
  constexpr bool set_error_message(std::string_view text) noexcept { return set_fixed_str(error_message, text); }
  constexpr std::string_view error_message_str() const noexcept { return fixed_str_view(error_message); }

  friend constexpr bool operator==(const GoalResult&, const GoalResult&) = default;
};
HORUS_REFLECT(GoalResult, goal_id, status, distance_to_goal, eta_seconds, progress, error_message, timestamp_ns)

// ---------------------------------------------------------------------------
/// One point of a path: where to be, how fast to go there, and whether to stop.
struct Waypoint {
  Pose2D pose{};              ///< m, rad
  Twist velocity{};           ///< desired velocity at this point, m/s and rad/s
  double time_from_start{};   ///< s from the start of the path
  float curvature{};          ///< 1/m (1 / turning radius), 0 = straight
  std::uint8_t stop_required{};  ///< 1 = stop at this waypoint

  /// The spec's Waypoint::new(pose): zero velocity, no stop.
  static constexpr Waypoint make(const Pose2D& p) noexcept {
    Waypoint w{};
    w.pose = p;
    return w;
  }
  /// A copy with the desired velocity set.
  [[nodiscard]] constexpr Waypoint with_velocity(const Twist& v) const noexcept {
    Waypoint w = *this;
    w.velocity = v;
    return w;
  }
  /// A copy that requires a stop: stop_required = 1 and a zero velocity.
  [[nodiscard]] constexpr Waypoint with_stop() const noexcept {
    Waypoint w = *this;
    w.stop_required = 1;
    w.velocity = Twist::stop();
    return w;
  }

  // The navigation page reads a waypoint as `wp.x, wp.y, wp.theta, wp.velocity`
  // (velocity as a speed); the fields themselves are pose and velocity (a
  // Twist), so these give the C++ equivalent: wp.x(), wp.y(), wp.theta(),
  // wp.speed().
  /// pose.x, in m.
  constexpr double x() const noexcept { return pose.x; }
  /// pose.y, in m.
  constexpr double y() const noexcept { return pose.y; }
  /// pose.theta (heading), in rad.
  constexpr double theta() const noexcept { return pose.theta; }
  /// The desired linear speed in m/s: the magnitude |velocity.linear| of the
  /// linear velocity vector (x, y, z), so never negative (a reversing waypoint,
  /// linear x = -0.5, gives 0.5). The angular part is ignored. An infinite
  /// linear component gives +inf (even beside a NaN, as IEEE hypot); otherwise
  /// NaN in any of them gives NaN.
  double speed() const noexcept {
    const auto& v = velocity.linear;
    // libstdc++'s three-argument std::hypot gives NaN for an infinity: handle it first.
    if (std::isinf(v[0]) || std::isinf(v[1]) || std::isinf(v[2])) return std::numeric_limits<double>::infinity();
    return std::hypot(v[0], v[1], v[2]);
  }

  friend constexpr bool operator==(const Waypoint&, const Waypoint&) = default;
};
HORUS_REFLECT(Waypoint, pose, velocity, time_from_start, curvature, stop_required)

namespace detail {
inline constexpr std::size_t kMaxPathWaypoints = 256;

// Shared by Path and NavPath (same layout, the time field is named differently).
template <class P>
constexpr std::size_t path_count(const P& p) noexcept {
  return std::min<std::size_t>(p.waypoint_count, kMaxPathWaypoints);
}

template <class P>
bool path_add_waypoint(P& p, const Waypoint& wp) noexcept {
  const std::size_t n = path_count(p);
  if (n >= kMaxPathWaypoints) return false;
  p.waypoints[n] = wp;
  p.waypoint_count = static_cast<std::uint16_t>(n + 1);
  if (n > 0) p.total_length += p.waypoints[n - 1].pose.distance_to(wp.pose);
  return true;
}

inline double polyline_length(std::span<const Waypoint> wps) noexcept {
  double length = 0.0;
  for (std::size_t i = 1; i < wps.size(); ++i) length += wps[i - 1].pose.distance_to(wps[i].pose);
  return length;
}

inline std::optional<std::size_t> closest_waypoint(std::span<const Waypoint> wps, const Pose2D& current) noexcept {
  if (wps.empty()) return std::nullopt;
  std::size_t best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < wps.size(); ++i) {
    const double d = current.distance_to(wps[i].pose);
    if (d < best_distance) {
      best_distance = d;
      best = i;
    }
  }
  return best;
}

inline float path_progress(std::span<const Waypoint> wps, const Pose2D& current) noexcept {
  const auto i = closest_waypoint(wps, current);
  if (!i) return 0.0f;
  return static_cast<float>(*i) / static_cast<float>(wps.size());
}
}  // namespace detail

// ---------------------------------------------------------------------------
/// A planned path of up to 256 waypoints (messages page: "Path"). Entries
/// [0, waypoint_count) are in use.
struct Path {
  static constexpr std::size_t kMaxWaypoints = detail::kMaxPathWaypoints;

  std::array<Waypoint, kMaxWaypoints> waypoints{};
  std::uint16_t waypoint_count{};
  double total_length{};       ///< m, sum of the segment lengths
  double duration_seconds{};   ///< s, estimated time to complete the path
  std::array<char, 32> frame_id{};   ///< NUL-terminated, at most 31 characters
  std::array<char, 32> algorithm{};  ///< planner name, NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// The spec's Path::new(): empty; the timestamp is left 0.
  static constexpr Path make() noexcept { return Path{}; }

  /// waypoint_count, clamped to 256 (a received message may hold any value).
  constexpr std::size_t count() const noexcept { return detail::path_count(*this); }
  constexpr bool is_empty() const noexcept { return count() == 0; }
  constexpr bool is_full() const noexcept { return count() >= kMaxWaypoints; }

  /// Appends a waypoint and adds the segment from the previous one to
  /// total_length. Returns false, changing nothing, when 256 are in use.
  bool add_waypoint(const Waypoint& wp) noexcept { return detail::path_add_waypoint(*this, wp); }

  /// Removes every waypoint (zeroing them) and resets total_length and
  /// duration_seconds; frame_id, algorithm and timestamp_ns are kept.
  constexpr void clear() noexcept {
    waypoints.fill(Waypoint{});
    waypoint_count = 0;
    total_length = 0.0;
    duration_seconds = 0.0;
  }

  /// The waypoints in use (HORUS's waypoints()).
  std::span<const Waypoint> valid_waypoints() const noexcept { return {waypoints.data(), count()}; }

  /// The length of the polyline through the waypoints in use, in metres,
  /// computed afresh (total_length is only kept up to date by add_waypoint).
  double compute_length() const noexcept { return detail::polyline_length(valid_waypoints()); }

  /// Index of the waypoint nearest to current (first one on ties), or nullopt when empty.
  std::optional<std::size_t> closest_waypoint_index(const Pose2D& current) const noexcept {
    return detail::closest_waypoint(valid_waypoints(), current);
  }
  /// Progress as HORUS computes it: closest index / count, in [0, 1) (0 when
  /// empty; it reaches (count - 1) / count at the last waypoint, never 1).
  float calculate_progress(const Pose2D& current) const noexcept {
    return detail::path_progress(valid_waypoints(), current);
  }

  /// Set the text fields; false, changing nothing, when the text does not fit.
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }
  constexpr bool set_algorithm(std::string_view name) noexcept { return set_fixed_str(algorithm, name); }
  constexpr std::string_view algorithm_str() const noexcept { return fixed_str_view(algorithm); }

  /// "Path(42 waypoints, 12.3 m)".
  std::string log_summary() const;

  friend constexpr bool operator==(const Path&, const Path&) = default;
};
HORUS_REFLECT(Path, waypoints, waypoint_count, total_length, duration_seconds, frame_id, algorithm, timestamp_ns)

// ---------------------------------------------------------------------------
/// A planned path of up to 256 waypoints (navigation page: "NavPath"). Same
/// layout and helpers as Path; its time field is called estimated_time.
struct NavPath {
  static constexpr std::size_t kMaxWaypoints = detail::kMaxPathWaypoints;

  std::array<Waypoint, kMaxWaypoints> waypoints{};
  std::uint16_t waypoint_count{};
  double total_length{};     ///< m, sum of the segment lengths
  double estimated_time{};   ///< s, estimated time to complete the path
  std::array<char, 32> frame_id{};   ///< NUL-terminated, at most 31 characters
  std::array<char, 32> algorithm{};  ///< planner name, NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// Empty path; the timestamp is left 0.
  static constexpr NavPath make() noexcept { return NavPath{}; }

  /// waypoint_count, clamped to 256 (a received message may hold any value).
  constexpr std::size_t count() const noexcept { return detail::path_count(*this); }
  constexpr bool is_empty() const noexcept { return count() == 0; }
  constexpr bool is_full() const noexcept { return count() >= kMaxWaypoints; }

  /// Appends a waypoint and adds the segment from the previous one to
  /// total_length. Returns false, changing nothing, when 256 are in use.
  bool add_waypoint(const Waypoint& wp) noexcept { return detail::path_add_waypoint(*this, wp); }

  /// Removes every waypoint (zeroing them) and resets total_length and
  /// estimated_time; frame_id, algorithm and timestamp_ns are kept.
  constexpr void clear() noexcept {
    waypoints.fill(Waypoint{});
    waypoint_count = 0;
    total_length = 0.0;
    estimated_time = 0.0;
  }

  /// The waypoints in use.
  std::span<const Waypoint> valid_waypoints() const noexcept { return {waypoints.data(), count()}; }

  /// The length of the polyline through the waypoints in use, in metres, computed afresh.
  double compute_length() const noexcept { return detail::polyline_length(valid_waypoints()); }

  /// Index of the waypoint nearest to current (first one on ties), or nullopt when empty.
  std::optional<std::size_t> closest_waypoint_index(const Pose2D& current) const noexcept {
    return detail::closest_waypoint(valid_waypoints(), current);
  }
  /// Closest index / count, in [0, 1) (0 when empty); see Path::calculate_progress.
  float calculate_progress(const Pose2D& current) const noexcept {
    return detail::path_progress(valid_waypoints(), current);
  }

  /// Set the text fields; false, changing nothing, when the text does not fit.
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }
  constexpr bool set_algorithm(std::string_view name) noexcept { return set_fixed_str(algorithm, name); }
  constexpr std::string_view algorithm_str() const noexcept { return fixed_str_view(algorithm); }

  /// "NavPath(42 waypoints, 12.3 m)".
  std::string log_summary() const;

  friend constexpr bool operator==(const NavPath&, const NavPath&) = default;
};
HORUS_REFLECT(NavPath, waypoints, waypoint_count, total_length, estimated_time, frame_id, algorithm, timestamp_ns)

// ---------------------------------------------------------------------------
/// A compact path: up to 256 waypoints packed as [x0, y0, theta0, x1, y1, ...]
/// (m, m, rad). Triples [0, waypoint_count) are in use.
struct PathPlan {
  static constexpr std::size_t kMaxWaypoints = 256;

  std::array<float, kMaxWaypoints * 3> waypoint_data{};  ///< packed [x, y, theta] triples
  std::array<float, 3> goal_pose{};                      ///< [x, y, theta] of the target
  std::uint16_t waypoint_count{};
  std::uint64_t timestamp_ns{};

  /// The spec's PathPlan::new(): empty; the timestamp is left 0.
  static constexpr PathPlan make() noexcept { return PathPlan{}; }

  /// A plan through the given [x, y, theta] waypoints towards goal. Only the
  /// first 256 are kept (as HORUS); check the size first if that matters.
  static constexpr PathPlan from_waypoints(std::span<const std::array<float, 3>> points,
                                           const std::array<float, 3>& goal) noexcept {
    PathPlan plan{};
    plan.goal_pose = goal;
    for (const auto& p : points.first(std::min(points.size(), kMaxWaypoints))) plan.add_waypoint(p[0], p[1], p[2]);
    return plan;
  }

  /// waypoint_count, clamped to 256 (a received message may hold any value).
  constexpr std::size_t count() const noexcept { return std::min<std::size_t>(waypoint_count, kMaxWaypoints); }
  constexpr bool is_empty() const noexcept { return count() == 0; }

  /// Appends (x, y, theta). Returns false, changing nothing, when 256 are in use.
  constexpr bool add_waypoint(float x, float y, float theta) noexcept {
    const std::size_t n = count();
    if (n >= kMaxWaypoints) return false;
    waypoint_data[n * 3] = x;
    waypoint_data[n * 3 + 1] = y;
    waypoint_data[n * 3 + 2] = theta;
    waypoint_count = static_cast<std::uint16_t>(n + 1);
    return true;
  }

  /// Waypoint i as [x, y, theta], or nullopt when i >= waypoint_count.
  constexpr std::optional<std::array<float, 3>> waypoint(std::size_t i) const noexcept {
    if (i >= count()) return std::nullopt;
    return std::array<float, 3>{waypoint_data[i * 3], waypoint_data[i * 3 + 1], waypoint_data[i * 3 + 2]};
  }

  /// "PathPlan(42 waypoints, goal (5.00, 3.00, 0.00))", goal in m, m, rad.
  std::string log_summary() const;

  friend constexpr bool operator==(const PathPlan&, const PathPlan&) = default;
};
HORUS_REFLECT(PathPlan, waypoint_data, goal_pose, waypoint_count, timestamp_ns)

// ---------------------------------------------------------------------------
/// A moving obstacle for velocity-obstacle collision avoidance.
struct VelocityObstacle {
  std::array<double, 2> position{};  ///< m, [x, y]
  std::array<double, 2> velocity{};  ///< m/s, [vx, vy]
  float radius{};                    ///< m
  float time_horizon{};              ///< s ahead to predict collisions
  std::uint32_t obstacle_id{};       ///< for tracking across messages

  friend constexpr bool operator==(const VelocityObstacle&, const VelocityObstacle&) = default;
};
HORUS_REFLECT(VelocityObstacle, position, velocity, radius, time_horizon, obstacle_id)

// ---------------------------------------------------------------------------
/// Up to 32 velocity obstacles; entries [0, count) are in use.
struct VelocityObstacles {
  static constexpr std::size_t kMaxObstacles = 32;

  std::array<VelocityObstacle, kMaxObstacles> obstacles{};
  std::uint8_t count{};
  std::uint64_t timestamp_ns{};

  /// count, clamped to 32 (a received message may hold any byte).
  constexpr std::size_t size() const noexcept { return std::min<std::size_t>(count, kMaxObstacles); }
  constexpr bool is_full() const noexcept { return size() >= kMaxObstacles; }

  /// Appends an obstacle. Returns false, changing nothing, when 32 are in use.
  constexpr bool add(const VelocityObstacle& obstacle) noexcept {
    const std::size_t n = size();
    if (n >= kMaxObstacles) return false;
    obstacles[n] = obstacle;
    count = static_cast<std::uint8_t>(n + 1);
    return true;
  }

  /// Removes every obstacle (zeroing them); timestamp_ns is kept.
  constexpr void clear() noexcept {
    obstacles.fill(VelocityObstacle{});
    count = 0;
  }

  /// The obstacles in use.
  std::span<const VelocityObstacle> valid_obstacles() const noexcept { return {obstacles.data(), size()}; }

  /// "VelocityObstacles(3 obstacles, ids 4, 7, 9)": the ids of the first 8, then "+N more".
  std::string log_summary() const;

  friend constexpr bool operator==(const VelocityObstacles&, const VelocityObstacles&) = default;
};
HORUS_REFLECT(VelocityObstacles, obstacles, count, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<Goal>, "Goal must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<GoalResult>, "GoalResult must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Waypoint>, "Waypoint must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Path>, "Path must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<NavPath>, "NavPath must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<PathPlan>, "PathPlan must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<VelocityObstacle>,
              "VelocityObstacle must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<VelocityObstacles>,
              "VelocityObstacles must be trivially copyable and standard layout");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(Goal, GoalResult, Waypoint, Path, NavPath, PathPlan, VelocityObstacle, VelocityObstacles)

}  // namespace horus::msg

HORUS_API_END

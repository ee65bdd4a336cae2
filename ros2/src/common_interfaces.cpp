// The ROS 2 common interfaces horus maps its messages to (Interfaces::standard()): each type's
// fields and constants as ROS 2 Jazzy's .msg files define them (builtin_interfaces and rosgraph_msgs
// from rcl_interfaces, tf2_msgs from geometry2, rmw_dds_common's graph messages; comments left out).
// Their type hashes are checked against ROS 2's published ones (tests/unit/test_ros2_interfaces.cpp).
#include <array>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "horus/ros2/interface.hpp"

namespace horus::ros2 {

namespace {

// clang-format off
constexpr std::array<std::pair<std::string_view, std::string_view>, 46> kCommonInterfaces{{
    {"builtin_interfaces/msg/Time",
     "int32 sec\n" "uint32 nanosec\n"},
    {"builtin_interfaces/msg/Duration",
     "int32 sec\n" "uint32 nanosec\n"},
    {"std_msgs/msg/Header",
     "builtin_interfaces/Time stamp\n" "string frame_id\n"},
    {"std_msgs/msg/String",
     "string data\n"},
    {"std_msgs/msg/Empty", ""},
    {"geometry_msgs/msg/Vector3",
     "float64 x\n" "float64 y\n" "float64 z\n"},
    {"geometry_msgs/msg/Point",
     "float64 x\n" "float64 y\n" "float64 z\n"},
    {"geometry_msgs/msg/Quaternion",
     "float64 x 0\n" "float64 y 0\n" "float64 z 0\n" "float64 w 1\n"},
    {"geometry_msgs/msg/Pose",
     "Point position\n" "Quaternion orientation\n"},
    {"geometry_msgs/msg/Pose2D",
     "float64 x\n" "float64 y\n" "float64 theta\n"},
    {"geometry_msgs/msg/PoseStamped",
     "std_msgs/Header header\n" "Pose pose\n"},
    {"geometry_msgs/msg/PoseWithCovariance",
     "Pose pose\n" "float64[36] covariance\n"},
    {"geometry_msgs/msg/Twist",
     "Vector3 linear\n" "Vector3 angular\n"},
    {"geometry_msgs/msg/TwistStamped",
     "std_msgs/Header header\n" "Twist twist\n"},
    {"geometry_msgs/msg/TwistWithCovariance",
     "Twist twist\n" "float64[36] covariance\n"},
    {"geometry_msgs/msg/Transform",
     "Vector3 translation\n" "Quaternion rotation\n"},
    {"geometry_msgs/msg/TransformStamped",
     "std_msgs/Header header\n"
     "string child_frame_id\n"
     "Transform transform\n"},
    {"geometry_msgs/msg/Wrench",
     "Vector3 force\n" "Vector3 torque\n"},
    {"geometry_msgs/msg/WrenchStamped",
     "std_msgs/Header header\n" "Wrench wrench\n"},
    {"geometry_msgs/msg/Accel",
     "Vector3 linear\n" "Vector3 angular\n"},
    {"sensor_msgs/msg/Imu",
     "std_msgs/Header header\n"
     "geometry_msgs/Quaternion orientation\n"
     "float64[9] orientation_covariance\n"
     "geometry_msgs/Vector3 angular_velocity\n"
     "float64[9] angular_velocity_covariance\n"
     "geometry_msgs/Vector3 linear_acceleration\n"
     "float64[9] linear_acceleration_covariance\n"},
    {"sensor_msgs/msg/LaserScan",
     "std_msgs/Header header\n"
     "float32 angle_min\n"
     "float32 angle_max\n"
     "float32 angle_increment\n"
     "float32 time_increment\n"
     "float32 scan_time\n"
     "float32 range_min\n"
     "float32 range_max\n"
     "float32[] ranges\n"
     "float32[] intensities\n"},
    {"sensor_msgs/msg/Range",
     "uint8 ULTRASOUND=0\n"
     "uint8 INFRARED=1\n"
     "std_msgs/Header header\n"
     "uint8 radiation_type\n"
     "float32 field_of_view\n"
     "float32 min_range\n"
     "float32 max_range\n"
     "float32 range\n"
     "float32 variance\n"},
    {"sensor_msgs/msg/BatteryState",
     "uint8 POWER_SUPPLY_STATUS_UNKNOWN = 0\n"
     "uint8 POWER_SUPPLY_STATUS_CHARGING = 1\n"
     "uint8 POWER_SUPPLY_STATUS_DISCHARGING = 2\n"
     "uint8 POWER_SUPPLY_STATUS_NOT_CHARGING = 3\n"
     "uint8 POWER_SUPPLY_STATUS_FULL = 4\n"
     "uint8 POWER_SUPPLY_HEALTH_UNKNOWN = 0\n"
     "uint8 POWER_SUPPLY_HEALTH_GOOD = 1\n"
     "uint8 POWER_SUPPLY_HEALTH_OVERHEAT = 2\n"
     "uint8 POWER_SUPPLY_HEALTH_DEAD = 3\n"
     "uint8 POWER_SUPPLY_HEALTH_OVERVOLTAGE = 4\n"
     "uint8 POWER_SUPPLY_HEALTH_UNSPEC_FAILURE = 5\n"
     "uint8 POWER_SUPPLY_HEALTH_COLD = 6\n"
     "uint8 POWER_SUPPLY_HEALTH_WATCHDOG_TIMER_EXPIRE = 7\n"
     "uint8 POWER_SUPPLY_HEALTH_SAFETY_TIMER_EXPIRE = 8\n"
     "uint8 POWER_SUPPLY_TECHNOLOGY_UNKNOWN = 0\n"
     "uint8 POWER_SUPPLY_TECHNOLOGY_NIMH = 1\n"
     "uint8 POWER_SUPPLY_TECHNOLOGY_LION = 2\n"
     "uint8 POWER_SUPPLY_TECHNOLOGY_LIPO = 3\n"
     "uint8 POWER_SUPPLY_TECHNOLOGY_LIFE = 4\n"
     "uint8 POWER_SUPPLY_TECHNOLOGY_NICD = 5\n"
     "uint8 POWER_SUPPLY_TECHNOLOGY_LIMN = 6\n"
     "uint8 POWER_SUPPLY_TECHNOLOGY_TERNARY = 7\n"
     "uint8 POWER_SUPPLY_TECHNOLOGY_VRLA = 8\n"
     "std_msgs/Header header\n"
     "float32 voltage\n"
     "float32 temperature\n"
     "float32 current\n"
     "float32 charge\n"
     "float32 capacity\n"
     "float32 design_capacity\n"
     "float32 percentage\n"
     "uint8 power_supply_status\n"
     "uint8 power_supply_health\n"
     "uint8 power_supply_technology\n"
     "bool present\n"
     "float32[] cell_voltage\n"
     "float32[] cell_temperature\n"
     "string location\n"
     "string serial_number\n"},
    {"sensor_msgs/msg/NavSatStatus",
     "int8 STATUS_UNKNOWN = -2\n"
     "int8 STATUS_NO_FIX = -1\n"
     "int8 STATUS_FIX = 0\n"
     "int8 STATUS_SBAS_FIX = 1\n"
     "int8 STATUS_GBAS_FIX = 2\n"
     "int8 status -2\n"
     "uint16 SERVICE_UNKNOWN = 0\n"
     "uint16 SERVICE_GPS = 1\n"
     "uint16 SERVICE_GLONASS = 2\n"
     "uint16 SERVICE_COMPASS = 4\n"
     "uint16 SERVICE_GALILEO = 8\n"
     "uint16 service\n"},
    {"sensor_msgs/msg/NavSatFix",
     "std_msgs/Header header\n"
     "NavSatStatus status\n"
     "float64 latitude\n"
     "float64 longitude\n"
     "float64 altitude\n"
     "float64[9] position_covariance\n"
     "uint8 COVARIANCE_TYPE_UNKNOWN = 0\n"
     "uint8 COVARIANCE_TYPE_APPROXIMATED = 1\n"
     "uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN = 2\n"
     "uint8 COVARIANCE_TYPE_KNOWN = 3\n"
     "uint8 position_covariance_type\n"},
    {"sensor_msgs/msg/JointState",
     "std_msgs/Header header\n"
     "string[] name\n"
     "float64[] position\n"
     "float64[] velocity\n"
     "float64[] effort\n"},
    {"sensor_msgs/msg/Image",
     "std_msgs/Header header\n"
     "uint32 height\n"
     "uint32 width\n"
     "string encoding\n"
     "uint8 is_bigendian\n"
     "uint32 step\n"
     "uint8[] data\n"},
    {"sensor_msgs/msg/CompressedImage",
     "std_msgs/Header header\n" "string format\n" "uint8[] data\n"},
    {"sensor_msgs/msg/RegionOfInterest",
     "uint32 x_offset\n"
     "uint32 y_offset\n"
     "uint32 height\n"
     "uint32 width\n"
     "bool do_rectify\n"},
    {"sensor_msgs/msg/CameraInfo",
     "std_msgs/Header header\n"
     "uint32 height\n"
     "uint32 width\n"
     "string distortion_model\n"
     "float64[] d\n"
     "float64[9] k\n"
     "float64[9] r\n"
     "float64[12] p\n"
     "uint32 binning_x\n"
     "uint32 binning_y\n"
     "RegionOfInterest roi\n"},
    {"sensor_msgs/msg/PointField",
     "uint8 INT8    = 1\n"
     "uint8 UINT8   = 2\n"
     "uint8 INT16   = 3\n"
     "uint8 UINT16  = 4\n"
     "uint8 INT32   = 5\n"
     "uint8 UINT32  = 6\n"
     "uint8 FLOAT32 = 7\n"
     "uint8 FLOAT64 = 8\n"
     "string name\n"
     "uint32 offset\n"
     "uint8  datatype\n"
     "uint32 count\n"},
    {"sensor_msgs/msg/PointCloud2",
     "std_msgs/Header header\n"
     "uint32 height\n"
     "uint32 width\n"
     "PointField[] fields\n"
     "bool    is_bigendian\n"
     "uint32  point_step\n"
     "uint32  row_step\n"
     "uint8[] data\n"
     "bool is_dense\n"},
    {"sensor_msgs/msg/Joy",
     "std_msgs/Header header\n" "float32[] axes\n" "int32[] buttons\n"},
    {"nav_msgs/msg/Odometry",
     "std_msgs/Header header\n"
     "string child_frame_id\n"
     "geometry_msgs/PoseWithCovariance pose\n"
     "geometry_msgs/TwistWithCovariance twist\n"},
    {"nav_msgs/msg/MapMetaData",
     "builtin_interfaces/Time map_load_time\n"
     "float32 resolution\n"
     "uint32 width\n"
     "uint32 height\n"
     "geometry_msgs/Pose origin\n"},
    {"nav_msgs/msg/OccupancyGrid",
     "std_msgs/Header header\n" "MapMetaData info\n" "int8[] data\n"},
    {"nav_msgs/msg/Path",
     "std_msgs/Header header\n" "geometry_msgs/PoseStamped[] poses\n"},
    {"tf2_msgs/msg/TFMessage",
     "geometry_msgs/TransformStamped[] transforms\n"},
    {"diagnostic_msgs/msg/KeyValue",
     "string key\n" "string value\n"},
    {"diagnostic_msgs/msg/DiagnosticStatus",
     "byte OK=0\n"
     "byte WARN=1\n"
     "byte ERROR=2\n"
     "byte STALE=3\n"
     "byte level\n"
     "string name\n"
     "string message\n"
     "string hardware_id\n"
     "KeyValue[] values\n"},
    {"diagnostic_msgs/msg/DiagnosticArray",
     "std_msgs/Header header\n" "DiagnosticStatus[] status\n"},
    {"rosgraph_msgs/msg/Clock",
     "builtin_interfaces/Time clock\n"},
    {"rmw_dds_common/msg/Gid",
     "char[16] data\n"},
    {"rmw_dds_common/msg/NodeEntitiesInfo",
     "string<=256 node_namespace\n"
     "string<=256 node_name\n"
     "Gid[] reader_gid_seq\n"
     "Gid[] writer_gid_seq\n"},
    {"rmw_dds_common/msg/ParticipantEntitiesInfo",
     "Gid gid\n" "NodeEntitiesInfo[] node_entities_info_seq\n"},
}};
// clang-format on

Interfaces make_standard() {
  Interfaces all;
  for (const auto& [name, text] : kCommonInterfaces) {
    auto added = all.add(name, text);
    if (!added) throw std::logic_error("ros2/src/common_interfaces.cpp: " + added.error().message());
  }
  return all;
}

}  // namespace

const Interfaces& Interfaces::standard() {
  static const Interfaces all = make_standard();
  return all;
}

}  // namespace horus::ros2

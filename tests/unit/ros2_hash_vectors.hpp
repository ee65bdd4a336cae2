// ROS 2's published type hashes (RIHS01), the expected values of test_ros2_interfaces.cpp: the
// five of issue 53, and those rosidl generated for ROS 2 Jazzy's common interfaces (as they appear
// in the `*__description.c` files rosidl_generator_c writes for packages that use them).
#pragma once

#include <array>
#include <string_view>
#include <utility>

namespace horus_test {

inline constexpr std::array<std::pair<std::string_view, std::string_view>, 5> kRos2PublishedHashes{{
    {"std_msgs/msg/String", "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"},
    {"geometry_msgs/msg/Twist", "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"},
    {"geometry_msgs/msg/Vector3", "RIHS01_cc12fe83e4c02719f1ce8070bfd14aecd40f75a96696a67a2a1f37f7dbb0765d"},
    {"std_msgs/msg/Header", "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01"},
    {"builtin_interfaces/msg/Time", "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197"},
}};

}  // namespace horus_test

// horus idl --ros2 DIR (idl_cmd.cpp).
#pragma once

#include <string>

namespace horus::tools {

// Writes the ROS 2 interface package of the standard messages (package.xml, CMakeLists.txt,
// msg/*.msg; horus-idlgen's emit_ros2) into `dir`, named `package`, and prints each type with its
// ROS 2 type hash. 0, or 1 with what went wrong.
int cmd_idl_ros2(const std::string& dir, const std::string& package);

}  // namespace horus::tools

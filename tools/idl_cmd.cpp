// horus idl --ros2 DIR: the standard messages as a ROS 2 interface package, for a ROS 2 workspace
// (colcon build), with each type's ROS 2 type hash (what its endpoints' USER_DATA will carry).
#include "idl_cmd.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "horus/idlgen/emit.hpp"
#include "horus/idlgen/model.hpp"
#include "horus/msg/all.hpp"
#include "horus/ros2/interface.hpp"

namespace horus::tools {

namespace {
bool write_file(const std::filesystem::path& path, const std::string& text) {
  std::error_code ec;
  std::filesystem::create_directories(path.parent_path(), ec);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  return static_cast<bool>(out);
}
}  // namespace

int cmd_idl_ros2(const std::string& dir, const std::string& package) {
  idlgen::Model model;
  msg::for_each_message([&]<class T>(std::string_view domain) { model.add<T>(domain); });
  idlgen::Ros2Options options;
  options.package = package;
  std::vector<idlgen::OutputFile> files;
  try {
    files = idlgen::emit_ros2(model, options);
  } catch (const std::invalid_argument& e) {
    fmt::print(stderr, "horus idl: {}\n", e.what());
    return 1;
  }
  ros2::Interfaces types;
  for (const auto& f : files) {
    if (!write_file(std::filesystem::path(dir) / f.name, f.text)) {
      fmt::print(stderr, "horus idl: cannot write {}/{}\n", dir, f.name);
      return 1;
    }
    if (f.name.starts_with("msg/")) (void)types.add(package + "/msg/" + f.name.substr(4, f.name.size() - 8), f.text);
  }
  for (const auto& name : types.names()) {
    auto hash = types.type_hash(name);
    fmt::print("{} {}\n", name, hash ? *hash : "(" + hash.error().message() + ")");
  }
  fmt::print(stderr, "horus idl: wrote the ROS 2 package {} ({} types) into {}\n", package, types.names().size(), dir);
  return 0;
}

}  // namespace horus::tools

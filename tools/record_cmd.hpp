// horus record / record info / record recover / play (record_cmd.cpp).
#pragma once

#include <atomic>
#include <string>
#include <vector>

namespace horus::tools {

struct RecordArgs {
  std::string ns;                   // shared-memory namespace
  std::string output;               // -o
  std::vector<std::string> topics;  // patterns
  bool all = false;
  double duration_s = 0;            // 0: until Ctrl-C
  double split_mb = 0;              // 0: one file
  std::string compression = "zstd";
  std::string format = "mcap";
  std::string profile = "horus";    // ros2: a rosbag2 bag (RecordProfile::Ros2)
  std::string backend;              // the fleet's transport (--backend), else the configuration's
  bool overwrite = false;           // replace an existing -o file (else refused)
  bool foxglove = false;            // also TOPIC/foxglove in Foxglove's schema (foxglove/schemas.hpp)
  std::string frame = "world";      // its frame when the message names none
};
int cmd_record(const RecordArgs& args, const std::atomic<bool>& stop);
int cmd_record_info(const std::string& file, bool json);
int cmd_record_recover(const std::string& file, const std::string& output);

struct PlayArgs {
  std::string file;
  double rate = 1.0;
  double start_s = 0;
  bool loop = false;
  std::vector<std::string> topics;  // patterns
  std::vector<std::string> remap;   // OLD=NEW
  bool ros2 = false;                // onto the ROS 2 wire: each topic mapped (TopicOptions::ros2)
};
int cmd_play(const PlayArgs& args, const std::atomic<bool>& stop);

}  // namespace horus::tools

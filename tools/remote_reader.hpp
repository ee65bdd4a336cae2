// A reader of a fleet topic that lives on other hosts only (horus topic echo/hz/bw): a network
// endpoint of its own on the topic's transport, best effort (it matches reliable and
// best-effort writers alike), decoding each sample through the type signature the owning host
// announced (horus/wire/dynamic.hpp), so it needs no C++ type.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace horus::tools {

class RemoteReader {
 public:
  struct Sample {
    nlohmann::json value;  // null when it did not decode (error says why)
    std::string error;
    std::size_t bytes = 0;  // the sample's body on the wire
    std::vector<std::byte> body;  // that body (XCDR1 without its header, or LCM's encoding)
    bool little_endian = true;
  };
  /// Opens `topic` on `transport` as `type_name` (hash, signature); an error names what failed.
  static std::unique_ptr<RemoteReader> open(const std::string& topic, const std::string& transport,
                                            const std::string& type_name, std::uint64_t type_hash,
                                            const std::string& signature, std::string& error);
  /// Opens the ROS 2 topic `ros_name` ("/scan": DDS topic rt/scan) on `transport` (a DDS one) as
  /// the ROS 2 type `ros_type` of horus/ros2/interface.hpp's common interfaces, decoded through
  /// its .msg (horus/ros2/dynamic.hpp): what `horus topic echo /scan` reads.
  static std::unique_ptr<RemoteReader> open_ros2(const std::string& ros_name, const std::string& transport,
                                                 const std::string& ros_type, std::string& error);
  virtual ~RemoteReader() = default;
  virtual std::optional<Sample> recv(bool decode) = 0;
  virtual bool wait(std::chrono::nanoseconds timeout) = 0;
  /// Samples that arrived while the queue (4096) was full.
  virtual std::uint64_t overflowed() const = 0;
};

}  // namespace horus::tools

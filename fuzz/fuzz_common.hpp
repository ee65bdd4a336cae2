// What the fuzz targets share: the messages they decode (chosen by the input's first byte) and
// a file made of the input (the readers of recordings and segments take a path).
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "horus/fleet_messages.hpp"
#include "horus/msg/generic.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/msg/navigation.hpp"
#include "horus/msg/navigation_maps.hpp"
#include "horus/msg/sensor.hpp"
#include "horus/msg/vision.hpp"

namespace horus::fuzz {

inline std::span<const std::byte> bytes(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const std::byte*>(data), size};
}

/// Calls f.template operator()<T>() for the message type that `selector` picks: fixed-size,
/// sequences and strings, nested structures, enums, a MessagePack payload, the fleet's own.
template <class F>
void with_type(std::uint8_t selector, F&& f) {
  switch (selector % 10) {
    case 0: f.template operator()<msg::Pose2D>(); break;
    case 1: f.template operator()<msg::LaserScan>(); break;
    case 2: f.template operator()<msg::JointState>(); break;
    case 3: f.template operator()<msg::Path>(); break;
    case 4: f.template operator()<msg::OccupancyGrid>(); break;
    case 5: f.template operator()<msg::CompressedImage>(); break;
    case 6: f.template operator()<msg::GenericMessage>(); break;
    case 7: f.template operator()<fleet::Heartbeat>(); break;
    case 8: f.template operator()<fleet::Announcement>(); break;
    default: f.template operator()<fleet::FleetView>(); break;
  }
}

/// The input as a file (a memfd: nothing on disk), for readers that take a path: "/proc/self/fd/N".
class MemFile {
 public:
  MemFile(const std::uint8_t* data, std::size_t size) : fd_(::memfd_create("horus-fuzz", MFD_CLOEXEC)) {
    std::size_t done = 0;
    while (fd_ >= 0 && done < size) {
      const ssize_t n = ::write(fd_, data + done, size - done);
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
  }
  ~MemFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  MemFile(const MemFile&) = delete;
  MemFile& operator=(const MemFile&) = delete;
  bool ok() const { return fd_ >= 0; }
  std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_ = -1;
};

}  // namespace horus::fuzz

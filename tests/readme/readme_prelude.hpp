// What every README block is compiled with (the precompiled header of readme_blocks): the header
// README.md tells users to include, and the stand-ins for a robot's own functions that its blocks
// call without defining them (fuse, drive, capture_into, ...): they do nothing.
#pragma once

#include <horus/horus.hpp>

#include <chrono>
#include <cstdint>
#include <functional>

namespace readme {

/// A block's function, registered under its README line (readme_blocks.cpp runs it).
struct Registration {
  Registration(int line, const char* mode, int (*run)());
};

}  // namespace readme

// The stand-ins.
inline void fuse(const auto&) {}
inline void drive(const auto&) {}
inline void capture_into(auto&&) {}
inline void stop_robot() {}
inline void stop_motors() {}
inline horus::msg::Pose2D current() { return horus::msg::Pose2D{1.0, 2.0, 0.5, 0}; }
inline std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

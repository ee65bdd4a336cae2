// The version of this build of horus.
#pragma once

#include <string_view>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// The project's version, "major.minor.patch" (CMake's project version).
std::string_view version_number() noexcept;

/// What this build is: the project's version and, when it was configured in a git checkout, what
/// `git describe --always --tags --dirty` said then: "0.1.0 (git 6bf2f1f)". A build from a
/// tarball says "0.1.0". (`horus --version` prints it.)
std::string_view version() noexcept;

}  // namespace horus

HORUS_API_END

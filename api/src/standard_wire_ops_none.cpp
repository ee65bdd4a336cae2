// HORUS_STANDARD_TYPES=OFF: the library has no network table of a standard message (a network
// topic of one fails to open with Errc::TypeMismatch, saying so); see api/CMakeLists.txt.
#include "standard_wire_ops.hpp"

namespace horus::detail::standard {

const WireOps* find_first(std::uint64_t) noexcept { return nullptr; }
const WireOps* find_second(std::uint64_t) noexcept { return nullptr; }

}  // namespace horus::detail::standard

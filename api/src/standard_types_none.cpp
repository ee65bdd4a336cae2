// HORUS_STANDARD_TYPES=OFF: no standard type is known at run time (find_standard_type gives null,
// AnyTopic cannot be opened, a verbose topic's lines have no summary); see api/CMakeLists.txt.
#include <span>

#include "horus/standard_types.hpp"

namespace horus::detail::standard {

std::span<const StandardType* const> first_half() noexcept { return {}; }
std::span<const StandardType* const> second_half() noexcept { return {}; }

}  // namespace horus::detail::standard

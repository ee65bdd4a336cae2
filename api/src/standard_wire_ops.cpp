// detail::standard_wire_ops: the library's network table of a standard message, by type hash.
#include "standard_wire_ops.hpp"

namespace horus::detail {

const WireOps* standard_wire_ops(std::uint64_t hash) noexcept {
  if (const WireOps* ops = standard::find_first(hash)) return ops;
  return standard::find_second(hash);
}

}  // namespace horus::detail

// The network tables (WireOps) of the standard messages, compiled once in the library: a list of
// domains per file (standard_wire_ops_*.cpp, two files built in parallel), looked up by type
// hash (standard_wire_ops.cpp). Internal to api/src.
#pragma once

#include <cstdint>
#include <utility>

#include "horus/detail/bridge_port.hpp"
#include "horus/msg/all.hpp"

namespace horus::detail::standard {

template <class... L>
struct Domains;

template <class... L>
struct Domains<msg::TypeList<L...>> {
  static_assert((reflect::StandardMessage<L> && ...),
                "a message of horus/msg/all.hpp lacks HORUS_STANDARD_MESSAGES in its header");
  static const WireOps* find(std::uint64_t hash) noexcept {
    static constexpr std::pair<std::uint64_t, const WireOps*> kTable[] = {{type_hash<L>, &kWireOpsOf<L>}...};
    for (const auto& [h, ops] : kTable)
      if (h == hash) return ops;
    return nullptr;
  }
};

// The two halves (about as much code each: the large-data types are in the first).
const WireOps* find_first(std::uint64_t hash) noexcept;
const WireOps* find_second(std::uint64_t hash) noexcept;

}  // namespace horus::detail::standard

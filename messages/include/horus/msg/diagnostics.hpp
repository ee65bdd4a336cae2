// Diagnostics messages: Heartbeat.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "horus/fixed_string.hpp"
#include "horus/format.hpp"
#include "horus/reflect.hpp"

namespace horus::msg {

// ---------------------------------------------------------------------------
/// Liveness signal of a node: published periodically, sequence counts up by one
/// per beat so a receiver can spot lost beats.
struct Heartbeat {
  std::array<char, 32> node_name{};  ///< NUL-terminated, at most 31 characters
  std::uint32_t node_id{};
  std::uint64_t sequence{};
  std::uint8_t alive{};   ///< 1 = alive
  double uptime{};        ///< s since the node started
  std::uint64_t timestamp_ns{};

  /// A live heartbeat (alive = 1, sequence 0) for the node, or nullopt when the
  /// name does not fit (at most 31 characters, no NUL).
  static constexpr std::optional<Heartbeat> create(std::string_view name, std::uint32_t id) noexcept {
    Heartbeat hb{};
    if (!hb.set_node_name(name)) return std::nullopt;
    hb.node_id = id;
    hb.alive = 1;
    return hb;
  }

  /// Throwing form of create(): std::invalid_argument when the name does not fit.
  static Heartbeat make(std::string_view name, std::uint32_t id) {
    if (auto hb = create(name, id)) return *hb;
    throw std::invalid_argument("Heartbeat node name '" + std::string(name) + "' has " + std::to_string(name.size()) +
                                " characters; at most 31 fit");
  }

  /// Sets the node name; returns false, changing nothing, when it does not fit.
  constexpr bool set_node_name(std::string_view name) noexcept { return set_fixed_str(node_name, name); }
  constexpr std::string_view node_name_str() const noexcept { return fixed_str_view(node_name); }

  /// Next beat: sequence + 1, alive = 1, uptime in seconds.
  constexpr void update(double uptime_s) noexcept {
    ++sequence;
    alive = 1;
    uptime = uptime_s;
  }

  friend constexpr bool operator==(const Heartbeat&, const Heartbeat&) = default;
};
HORUS_REFLECT(Heartbeat, node_name, node_id, sequence, alive, uptime, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<Heartbeat>, "Heartbeat must be trivially copyable and standard layout");

}  // namespace horus::msg

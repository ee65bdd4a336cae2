// horus/standard_types.hpp: the lookups over both halves of the standard types' tables, and the
// library's own use of them (a verbose topic's summary line).
#include <algorithm>
#include <array>

#include "horus/detail/traffic_log.hpp"
#include "horus/standard_types.hpp"

namespace horus {

namespace detail::standard {
std::span<const StandardType* const> first_half() noexcept;
std::span<const StandardType* const> second_half() noexcept;
}  // namespace detail::standard

std::span<const StandardType* const> standard_types() noexcept {
  static const std::vector<const StandardType*> all = [] {
    std::vector<const StandardType*> v;
    for (auto half : {detail::standard::first_half(), detail::standard::second_half()}) v.insert(v.end(), half.begin(), half.end());
    return v;
  }();
  return all;
}

const StandardType* find_standard_type(std::string_view name) noexcept {
  if (name.empty()) return nullptr;
  for (const StandardType* t : standard_types()) {
    const std::string_view q = t->name;
    if (q == name || (q.size() > name.size() + 2 && q.ends_with(name) && q.substr(q.size() - name.size() - 2, 2) == "::"))
      return t;
  }
  return nullptr;
}

const StandardType* find_standard_type(std::uint64_t hash) noexcept {
  for (const StandardType* t : standard_types())
    if (t->hash == hash) return t;
  return nullptr;
}

const StandardType* find_standard_type_by_lcm_fingerprint(std::uint64_t fingerprint) noexcept {
  if (fingerprint == 0) return nullptr;
  for (const StandardType* t : standard_types())
    if (t->lcm_fingerprint == fingerprint) return t;
  return nullptr;
}

namespace detail {

std::optional<std::string> standard_summary(std::uint64_t hash, const void* msg) {
  const StandardType* t = find_standard_type(hash);
  if (!t) return std::nullopt;
  return t->summary(msg);
}

}  // namespace detail

}  // namespace horus

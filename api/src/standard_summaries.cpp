// detail::standard_summary: horus::log_summary of every standard message, compiled once here for
// the traffic lines of verbose topics (horus/detail/traffic_log.hpp), looked up by type hash.
#include <cstdint>
#include <string>
#include <utility>

#include "horus/detail/traffic_log.hpp"
#include "horus/msg/all.hpp"

namespace horus::detail {

namespace {

template <class T>
std::string summary_of(const void* msg) {
  return horus::log_summary(*static_cast<const T*>(msg));
}

template <class... L>
struct Summaries;

template <class... L>
struct Summaries<msg::TypeList<L...>> {
  static std::optional<std::string> find(std::uint64_t hash, const void* msg) {
    static constexpr std::pair<std::uint64_t, std::string (*)(const void*)> kTable[] = {{type_hash<L>, &summary_of<L>}...};
    for (const auto& [h, summary] : kTable)
      if (h == hash) return summary(msg);
    return std::nullopt;
  }
};

}  // namespace

std::optional<std::string> standard_summary(std::uint64_t hash, const void* msg) {
  return Summaries<msg::AllMessages>::find(hash, msg);
}

}  // namespace horus::detail

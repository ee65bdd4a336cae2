#include <fmt/format.h>

#include "horus/dds/transports.hpp"
#include "horus/names.hpp"

namespace horus::dds {

Result<std::string> topic_name(std::string_view topic) {
  if (auto ok = validate_topic_name(topic); !ok) return std::unexpected(std::move(ok.error()));
  if (const auto pos = topic.find('-'); pos != std::string_view::npos)
    return fail(Errc::InvalidName,
                fmt::format("topic '{}': '-' at position {} cannot be carried by DDS (topic names there allow letters, "
                            "digits, '_' and '/'); use '_' for a topic on the cyclonedds or fastdds backend",
                            topic, pos));
  std::string out = "horus/";
  for (char c : topic) out += c == '.' ? '/' : c;
  return out;
}

}  // namespace horus::dds

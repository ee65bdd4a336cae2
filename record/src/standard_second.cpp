// The recorder sources and player sinks of the navigation, diagnostics, force, input,
// tracking, time, audio and generic messages (standard.hpp), and the lookup over both halves.
#include <fmt/format.h>

#include "standard_impl.hpp"

namespace horus {

namespace record_detail {

void open_standard_second(std::string_view type_name, std::string_view name, const TopicOptions& options,
                          StandardOpen& out) {
  open_standard(msg::detail::Concat<msg::NavigationMessages, msg::DiagnosticsMessages, msg::ForceMessages,
                                    msg::InputMessages, msg::TrackingMessages, msg::TimeMessages, msg::AudioMessages,
                                    msg::GenericMessages>::type{},
                type_name, name, options, out);
}

namespace {
Result<void> open_either(std::string_view type_name, std::string_view name, const TopicOptions& options,
                         StandardOpen& out) {
  open_standard_first(type_name, name, options, out);
  if (!out.known) open_standard_second(type_name, name, options, out);
  if (!out.known)
    return std::unexpected(Error(Errc::InvalidArgument,
                                 fmt::format("topic '{}': '{}' is not a standard message type (those of horus/msg/all.hpp: "
                                             "horus::msg::Pose2D, Image, ...)",
                                             name, type_name)));
  if (out.error) return std::unexpected(std::move(*out.error));
  return {};
}
}  // namespace

}  // namespace record_detail

Result<std::unique_ptr<RecordSource>> open_standard_source(std::string_view type_name, std::string_view name,
                                                           const TopicOptions& options) {
  record_detail::StandardOpen out;
  if (auto ok = record_detail::open_either(type_name, name, options, out); !ok) return std::unexpected(ok.error());
  return std::move(out.source);
}

Result<std::unique_ptr<PlaySink>> open_standard_sink(std::string_view type_name, std::string_view name,
                                                     bool lcm_encoding, std::uint64_t& type_hash,
                                                     const TopicOptions& options) {
  record_detail::StandardOpen out;
  out.want_sink = true;
  out.lcm_encoding = lcm_encoding;
  auto ok = record_detail::open_either(type_name, name, options, out);
  type_hash = out.hash;
  if (!ok) return std::unexpected(ok.error());
  return std::move(out.sink);
}

}  // namespace horus

#include "horus/record/standard.hpp"
#include "typed_reader_impl.hpp"

namespace horus::tools {

namespace {
detail::Opened open_any(std::string_view type_name, const std::string& name, const std::optional<Backend>& backend,
                        detail::Want want, std::string& error, detail::Opened out = {}) {
  error.clear();
  detail::open_first_half(type_name, name, backend, want, out, error);
  if (!out.known) detail::open_second_half(type_name, name, backend, want, out, error);
  return out;
}
}  // namespace

std::string standard_type(std::string_view type_name) {
  std::string error;
  return open_any(type_name, {}, std::nullopt, detail::Want::Name, error).qualified;
}

std::unique_ptr<TypedReader> open_reader(std::string_view type_name, const std::string& name, const Backend& backend,
                                         std::string& error) {
  return open_any(type_name, name, backend, detail::Want::Reader, error).reader;
}

std::unique_ptr<TypedWriter> open_writer(std::string_view type_name, const std::string& name,
                                         const std::optional<Backend>& backend, std::string& error) {
  return open_any(type_name, name, backend, detail::Want::Writer, error).writer;
}

std::string standard_type_by_lcm_fingerprint(std::uint64_t fingerprint) {
  if (fingerprint == 0) return {};
  std::string error;
  detail::Opened by_fingerprint;
  by_fingerprint.lcm_fingerprint = fingerprint;
  return open_any({}, {}, std::nullopt, detail::Want::Name, error, std::move(by_fingerprint)).qualified;
}

// Recording and playing go through the record library's sources and sinks of every standard
// type (horus/record/standard.hpp), compiled there once for this CLI and the Python package.
std::unique_ptr<RecordSource> open_record_source(std::string_view type_name, const std::string& name,
                                                 const std::optional<Backend>& backend, std::string& error) {
  error.clear();
  if (standard_type(type_name).empty()) return nullptr;
  TopicOptions options;
  options.backend = backend;
  auto source = open_standard_source(type_name, name, options);
  if (!source) error = source.error().message();
  return source ? std::move(*source) : nullptr;
}

std::unique_ptr<PlaySink> open_play_sink(std::string_view type_name, const std::string& name, bool lcm_encoding,
                                         std::uint64_t& type_hash, std::string& error) {
  error.clear();
  type_hash = 0;
  if (standard_type(type_name).empty()) return nullptr;
  auto sink = open_standard_sink(type_name, name, lcm_encoding, type_hash);
  if (!sink) error = sink.error().message();
  return sink ? std::move(*sink) : nullptr;
}

std::string bench_type(const BenchPayload& payload, std::string& error) {
  detail::Opened in;
  in.bench_payload = &payload;
  auto out = open_any(payload.type, {}, std::nullopt, detail::Want::BenchCheck, error, std::move(in));
  if (!out.known) error = "unknown message type '" + payload.type + "'";
  return error.empty() ? out.qualified : std::string();
}

std::unique_ptr<BenchPeer> open_bench_peer(const BenchPayload& payload, const BenchEndpoints& endpoints,
                                           std::string& error) {
  detail::Opened in;
  in.bench_payload = &payload;
  in.bench_endpoints = &endpoints;
  auto out = open_any(payload.type, {}, endpoints.backend, detail::Want::Bench, error, std::move(in));
  if (!out.known) error = "unknown message type '" + payload.type + "'";
  return std::move(out.bench);
}

namespace detail {
void open_first_half(std::string_view type_name, const std::string& name, const std::optional<Backend>& backend,
                     Want want, Opened& out, std::string& error) {
  using First = msg::detail::Concat<msg::GeometryMessages, msg::SensorMessages, msg::ControlMessages,
                                    msg::VisionMessages, msg::DetectionMessages, msg::PerceptionMessages>::type;
  open_as(First{}, type_name, name, backend, want, out, error);
}
}  // namespace detail

}  // namespace horus::tools

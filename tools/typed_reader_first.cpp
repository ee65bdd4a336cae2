#include "typed_reader_impl.hpp"

namespace horus::tools {

namespace {
// horus bench's peer of a standard type (its name qualified or not): the half that has it.
detail::Opened open_bench(std::string_view type_name, detail::Want want, std::string& error, detail::Opened out) {
  error.clear();
  const StandardType* type = find_standard_type(type_name);
  if (type == nullptr) {
    error = "unknown message type '" + std::string(type_name) + "'";
    return out;
  }
  detail::open_first_half(type->name, want, out, error);
  if (!out.known) detail::open_second_half(type->name, want, out, error);
  return out;
}
}  // namespace

std::string bench_type(const BenchPayload& payload, std::string& error) {
  detail::Opened in;
  in.bench_payload = &payload;
  auto out = open_bench(payload.type, detail::Want::BenchCheck, error, std::move(in));
  if (!out.known || !error.empty()) return {};
  return std::string(find_standard_type(payload.type)->name);
}

std::unique_ptr<BenchPeer> open_bench_peer(const BenchPayload& payload, const BenchEndpoints& endpoints,
                                           std::string& error) {
  detail::Opened in;
  in.bench_payload = &payload;
  in.bench_endpoints = &endpoints;
  return std::move(open_bench(payload.type, detail::Want::Bench, error, std::move(in)).bench);
}

namespace detail {
void open_first_half(std::string_view qualified, Want want, Opened& out, std::string& error) {
  using First = msg::detail::Concat<msg::GeometryMessages, msg::SensorMessages, msg::ControlMessages,
                                    msg::VisionMessages, msg::DetectionMessages, msg::PerceptionMessages>::type;
  open_as(First{}, qualified, want, out, error);
}
}  // namespace detail

}  // namespace horus::tools

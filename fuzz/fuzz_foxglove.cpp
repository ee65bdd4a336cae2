// libFuzzer target: what a Foxglove client sends `horus foxglove` (tools/foxglove/protocol.hpp):
// the first byte picks a text frame (JSON ops: subscribe, advertise, ...) or a binary frame
// (client message data); the rest is the frame. Every answer is an op or an error text; the
// connection-graph diff and the close reason are built from what parsed.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const auto* bytes = reinterpret_cast<const std::byte*>(data + 1);
  if (data[0] % 2 == 0) {
    auto op = horus::tools::fox::parse_client_text(std::string_view(reinterpret_cast<const char*>(data + 1), size - 1));
    if (!op) {
      (void)horus::tools::fox::close_reason(op.error());
      return 0;
    }
    if (const auto* adv = std::get_if<horus::tools::fox::ClientAdvertise>(&*op)) {
      horus::tools::fox::Graph g;
      for (const auto& c : adv->channels) g.published.push_back({c.topic, {c.schema_name}});
      (void)horus::tools::fox::graph_update({}, g);
    }
  } else {
    auto d = horus::tools::fox::parse_client_binary(std::span<const std::byte>(bytes, size - 1));
    if (d && !d->payload.empty() && d->payload.data() < bytes) __builtin_trap();  // the payload views the frame
  }
  return 0;
}

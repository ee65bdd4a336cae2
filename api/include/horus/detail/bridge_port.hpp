// BridgePort<T>: the handle a fleet topic's bridge uses (horus/detail/network_link.hpp), made
// from the same local port and slot codec as a user's handle. Two ports, so the transport's
// thread (import: decode and write into the bridge's lane) and the exporter (export: read every
// lane but that one; the engine's export thread or a publishing thread, one at a time) never
// share a codec's scratch state.
// Internal to horus: users include <horus/topic.hpp>.
#pragma once

#include <memory>

#include "horus/detail/network_link.hpp"
#include "horus/detail/slots.hpp"
#include "horus/detail/wire_ops.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::detail {

template <class T>
class TypedBridgePort final : public BridgePort {
  using Codec = SlotCodec<T>;
  using Port = LocalPort<typename Codec::Payload>;

 public:
  // Non-owning: the core owns the bridge, which destroys its port before the ring goes.
  explicit TypedBridgePort(TopicCore& core)
      : import_(std::shared_ptr<TopicCore>(std::shared_ptr<void>(), &core)),
        export_(std::shared_ptr<TopicCore>(std::shared_ptr<void>(), &core)) {
    import_.writer().wake_readers_only();  // the export skips the import's messages
    import_.writer().set_inline_export(nullptr);  // and never runs from the import's sends
  }

  bool take_lane(std::uint32_t lane, std::uint64_t from) override {
    return from != 0 ? import_.writer().adopt(lane, from) : import_.ensure_lane();
  }
  bool has_lane() const override { return import_.writer().has_lane(); }
  std::uint32_t lane() const override { return import_.writer().lane(); }
  std::uint64_t lane_token() const override { return import_.writer().token(); }
  bool deliver(net::WireFormat format, const net::Sample& sample) override {
    const std::uint64_t before = import_.writer().sent();
    import_codec_.deliver(import_, format, sample);
    return import_.writer().sent() != before;
  }
  bool deliver_foreign(const ForeignDecoder& decoder, const net::Sample& sample) override {
    const std::uint64_t before = import_.writer().sent();
    import_codec_.deliver_with(import_, [&](const ByteSink* sink) -> std::expected<T, std::string> {
      T m{};
      if (!decoder.decode(decoder.context, sample, &m, sink)) return std::unexpected(std::string());
      return m;
    });
    return import_.writer().sent() != before;
  }
  std::size_t import_room() override {
    return has_lane() ? static_cast<std::size_t>(import_.writer().room(export_.reader().token())) : SIZE_MAX;
  }

  bool take_entry(std::uint32_t entry, std::uint64_t from) override {
    return from != 0 ? export_.reader().adopt(entry, from) : export_.reader().subscribe();
  }
  bool has_entry() const override { return export_.reader().subscribed(); }
  std::uint32_t entry() const override { return export_.reader().entry(); }
  std::uint64_t entry_token() const override { return export_.reader().token(); }
  std::size_t export_pending(std::uint32_t own, const ExportSink& sink) override {
    std::size_t n = 0;
    while (auto m = export_codec_.read_except(export_, own)) {
      ++n;
      if (!sink.send(sink.ctx, &*m)) break;
    }
    return n;
  }
  std::uint64_t export_lost() const override { return export_.reader().noticed_lost() + export_codec_.lost(); }
  void leave() override {
    import_.writer().leave();
    export_.reader().leave();
  }

 private:
  Port import_;
  Codec import_codec_;
  Port export_;
  Codec export_codec_;
};

template <class T>
std::unique_ptr<BridgePort> make_bridge_port(TopicCore& core) {
  return std::make_unique<TypedBridgePort<T>>(core);
}

/// T's table, made from its reflection (any message type).
template <class T>
inline constexpr WireOps kWireOpsOf{&wire_expressible<T>, &wire_encoded_size<T>, &wire_encode<T>,
                                    &make_bridge_port<T>};

/// The table of the standard message whose type hash is `hash`, compiled once in the library
/// (api/src/standard_wire_ops_*.cpp); nullptr for any other hash.
const WireOps* standard_wire_ops(std::uint64_t hash) noexcept;

/// T's table: the library's for a standard message (a node's file then instantiates none of the
/// XCDR1 and LCM codecs), else made here. nullptr only when the library lacks a standard type
/// these headers have (headers and library of different versions).
template <class T>
const WireOps* wire_ops_of() noexcept {
  if constexpr (reflect::StandardMessage<T>) {
    return standard_wire_ops(type_hash<T>);
  } else {
    return &kWireOpsOf<T>;
  }
}

}  // namespace horus::detail

HORUS_API_END

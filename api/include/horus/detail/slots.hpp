// The slot codecs: how a message of each kind (horus/message_traits.hpp) goes into a ring slot
// and comes out of it, chosen once per type (SlotCodec<T>):
//   FixedSlots       trivially copyable T, copied into the slot
//   SerializedSlots  variable-size T, encoded with the local wire format into [length][bytes]
//   PooledSlots      large data: the bytes go to a pool slot of the publisher's lane (or are
//                    lent in place, Loan<T>), the ring slot carries T::Descriptor, and a
//                    received message borrows the pool slot (pinned while it lives)
// Each codec has the same operations, used by Topic<T> and by the network bridge's port:
//   prepare(port, m)    checks (and encodes) m before it is written; false: refused, logged
//   refusal(port, m)    the error send_blocking returns after prepare() said false
//   write(port, m)      writes a prepared m (overwriting the oldest slot of a full lane)
//   try_write(port, m)  writes a prepared m only if no other subscriber would lose a message
//   read / read_latest  the next message / the newest one
//   read_except(p, l)   read(), passing over lane l (the bridge's export: not what it imported)
//   deliver(port, f, s) a sample from the network, decoded and written into the ring
// Internal to horus: users include <horus/topic.hpp>.
#pragma once

#include <algorithm>
#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "horus/detail/local_port.hpp"
#include "horus/detail/wire_ops.hpp"
#include "horus/loan.hpp"
#include "horus/message_traits.hpp"
#include "horus/wire/local.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::detail {

/// A sample that gave no message: reported (counted, logged) unless its decoder did (no text).
inline void report_delivery_failure(TopicCore& core, const std::string& what) {
  if (!what.empty()) report_network_decode_failure(core, what);
}

/// A fixed-size message travels by copy.
template <class T>
class FixedSlots {
 public:
  using Payload = T;
  using Port = LocalPort<T>;
  static constexpr std::uint32_t kPayloadBytes = sizeof(T);
  static constexpr std::uint64_t kPoolBytes = 0;

  bool prepare(Port&, const T&) noexcept { return true; }
  Error refusal(Port& port, const T&) const { return too_large_error(port.core(), sizeof(T)); }
  [[gnu::always_inline]] bool write(Port& port, const T& msg) noexcept {
    port.writer().write(msg);
    return true;
  }
  // Topic::send's path (the lane claimed): false when the handle is observed (RingWriter::observe),
  // told by the branch the send takes anyway for receivers that wait. Sent either way.
  [[gnu::always_inline]] bool write_plain(Port& port, const T& msg) noexcept { return port.writer().write(msg); }
  bool try_write(Port& port, const T& msg) noexcept {
    if (!port.writer().has_space(port.reader().token())) return false;
    port.writer().write(msg);
    return true;
  }
  [[gnu::always_inline]] std::optional<T> read(Port& port) noexcept {
    Slot s;
    if (port.reader().read(s.value)) return s.value;
    return std::nullopt;
  }
  std::optional<T> read_except(Port& port, std::uint32_t own) noexcept {
    Slot s;
    if (port.reader().read_except(s.value, own)) return s.value;
    return std::nullopt;
  }
  std::optional<T> read_latest(Port& port) noexcept {
    Slot s;
    if (!port.reader().read_latest(s.value)) return std::nullopt;
    return s.value;
  }
  void deliver(Port& port, net::WireFormat format, const net::Sample& sample) {
    deliver_with(port, [&](const ByteSink* sink) { return wire_decode<T>(format, sample, sink); });
  }
  template <class Decode>
  void deliver_with(Port& port, Decode&& decode) {
    auto m = decode(nullptr);
    if (!m) return report_delivery_failure(port.core(), m.error());
    write(port, *m);
  }
  std::size_t max_message_size(const TopicCore&) const noexcept { return sizeof(T); }
  std::uint64_t lost() const noexcept { return 0; }
  void set_blocking(bool) noexcept {}
  std::optional<Error> full_error(Port&) noexcept { return std::nullopt; }

 private:
  // Uninitialised storage the ring copies into (avoids zeroing T before overwriting it).
  union Slot {
    Slot() noexcept {}
    T value;
  };
};

/// A variable-size message is encoded (horus/wire/local.hpp) into [length][bytes].
template <class T>
class SerializedSlots {
 public:
  using Payload = shm::ByteMessage;
  using Port = LocalPort<Payload>;
  static constexpr std::uint32_t kPayloadBytes = static_cast<std::uint32_t>(default_slot_bytes<T>);
  static constexpr std::uint64_t kPoolBytes = 0;

  /// Encodes into scratch_ (false, counted and logged, when over the slot size).
  bool prepare(Port& port, const T& msg) {
    const std::size_t n = codec::encoded_size(msg);
    encoded_size_ = n;
    const std::size_t max = port.writer().max_bytes();
    if (n > max) [[unlikely]] {
      ++port.counters.too_large;
      report_too_large(port.core(), n, port.counters.too_large);
      return false;
    }
    if (scratch_.size() < n) scratch_.resize(std::min<std::size_t>(std::max(n, scratch_.size() * 2), max));
    encoded_size_ = codec::encode(msg, std::span<std::byte>(scratch_));
    return true;
  }
  Error refusal(Port& port, const T&) const { return too_large_error(port.core(), encoded_size_); }
  bool write(Port& port, const T&) noexcept {
    port.writer().write_bytes(encoded());
    return true;
  }
  bool try_write(Port& port, const T&) noexcept {
    if (!port.writer().has_space(port.reader().token())) return false;
    port.writer().write_bytes(encoded());
    return true;
  }
  /// The next message that decodes; one that does not (a corrupt slot) is skipped and counted.
  std::optional<T> read(Port& port) {
    prepare_inbox(port);
    while (port.reader().read(inbox_)) {
      if (auto m = decode_inbox(port)) return m;
      ++port.counters.undelivered;
    }
    return std::nullopt;
  }
  std::optional<T> read_except(Port& port, std::uint32_t own) {
    prepare_inbox(port);
    while (port.reader().read_except(inbox_, own)) {
      if (auto m = decode_inbox(port)) return m;
      ++port.counters.undelivered;
    }
    return std::nullopt;
  }
  std::optional<T> read_latest(Port& port) {
    prepare_inbox(port);
    if (!port.reader().read_latest(inbox_)) return std::nullopt;
    return decode_inbox(port);
  }
  void deliver(Port& port, net::WireFormat format, const net::Sample& sample) {
    deliver_with(port, [&](const ByteSink* sink) { return wire_decode<T>(format, sample, sink); });
  }
  template <class Decode>
  void deliver_with(Port& port, Decode&& decode) {
    auto m = decode(nullptr);
    if (!m) return report_delivery_failure(port.core(), m.error());
    if (!prepare(port, *m)) {
      ++port.counters.send_failures;
      return;
    }
    write(port, *m);
  }
  std::size_t max_message_size(const TopicCore& core) const noexcept {
    return shm::max_serialized_size(core.payload_size);
  }
  std::uint64_t lost() const noexcept { return 0; }
  void set_blocking(bool) noexcept {}
  std::optional<Error> full_error(Port&) noexcept { return std::nullopt; }

 private:
  std::span<const std::byte> encoded() const noexcept { return {scratch_.data(), encoded_size_}; }
  void prepare_inbox(const Port& port) { inbox_.reserve(shm::max_serialized_size(port.core().payload_size)); }
  std::optional<T> decode_inbox(Port& port) {
    auto m = codec::decode<T>(inbox_.view());
    if (m) return std::move(*m);
    ++port.counters.decode_failures;
    report_decode_failure(port.core(), m.error(), port.counters.decode_failures);
    return std::nullopt;
  }

  std::vector<std::byte> scratch_;  // the encoding buffer
  std::size_t encoded_size_ = 0;
  shm::ByteMessage inbox_;  // the last slot read
};

/// Large data: bytes in the topic's pool, T::Descriptor in the ring.
template <class T>
class PooledSlots {
 public:
  using Descriptor = typename T::Descriptor;
  using Payload = Descriptor;
  using Port = LocalPort<Payload>;
  static constexpr std::uint32_t kPayloadBytes = sizeof(Descriptor);
  static constexpr std::uint64_t kPoolBytes = default_slot_bytes<T>;

  /// A message over the pool's slot size, or whose metadata does not describe its bytes
  /// (receivers could not rebuild it), is refused and logged.
  bool prepare(Port& port, const T& msg) {
    auto& core = port.core();
    const ByteBuffer& b = msg.buffer();
    if (b.size() > core.pool.slot_bytes()) [[unlikely]] {
      ++port.counters.too_large;
      report_too_large(core, b.size(), port.counters.too_large);
      return false;
    }
    // A borrowed view of the bytes (nothing copied), rebuilt as a receiver will.
    if (!T::adopt(msg.descriptor(), ByteBuffer::borrow(const_cast<std::uint8_t*>(b.data()), b.size(), {}, false)))
        [[unlikely]] {
      report_inconsistent(core, ++inconsistent_);
      return false;
    }
    return true;
  }
  Error refusal(Port& port, const T& msg) const {
    auto& core = port.core();
    if (msg.buffer().size() > core.pool.slot_bytes()) return too_large_error(core, msg.buffer().size());
    return Error(Errc::InvalidArgument, "topic '" + core.name + "': the " + std::string(horus::type_name<T>()) +
                                            " message's metadata does not describe its bytes (" +
                                            msg.descriptor().log_summary() + "); message not sent");
  }
  bool write(Port& port, const T& msg) { return write_pooled(port, msg, claim_slot(port)); }
  bool try_write(Port& port, const T& msg) {
    if (!port.writer().has_space(port.reader().token())) return false;
    // Only slots every subscriber has read: a pool slot must not take an unread message away.
    // The cached read limit may be old: look at the cursors again before giving up.
    auto& core = port.core();
    auto c = core.pool.claim(port.writer().lane(), core.claimer, port.writer().read_by_all());
    if (!c) {
      port.writer().refresh_space(port.reader().token());
      c = claim_slot(port, port.writer().read_by_all());
    }
    return write_pooled(port, msg, c);
  }
  std::optional<T> read(Port& port) {
    Descriptor d;
    while (port.reader().read(d)) {
      if (auto m = adopt(port, d)) return m;
      ++port.counters.undelivered;
    }
    return std::nullopt;
  }
  std::optional<T> read_except(Port& port, std::uint32_t own) {
    Descriptor d;
    while (port.reader().read_except(d, own)) {
      if (auto m = adopt(port, d)) return m;
      ++port.counters.undelivered;
    }
    return std::nullopt;
  }
  std::optional<T> read_latest(Port& port) {
    Descriptor d;
    if (!port.reader().read_latest(d)) return std::nullopt;
    return adopt(port, d, /*count_loss=*/false);
  }

  /// Large data from the network: the bytes are decoded straight into a pool slot of the
  /// receiver's lane (one copy), then the descriptor is published as for a loan.
  void deliver(Port& port, net::WireFormat format, const net::Sample& sample) {
    deliver_with(port, [&](const ByteSink* sink) { return wire_decode<T>(format, sample, sink); });
  }
  template <class Decode>
  void deliver_with(Port& port, Decode&& decode) {
    struct Place {
      PooledSlots* self;
      Port* port;
      std::optional<shm::Pool::Claim> claim;
    } place{this, &port, std::nullopt};
    const ByteSink sink{&place, [](void* ctx, std::size_t n, ByteBuffer& out) {
                          auto& p = *static_cast<Place*>(ctx);
                          auto& core = p.port->core();
                          if (p.claim || n > core.pool.slot_bytes()) return false;
                          p.claim = p.self->claim_slot(*p.port);
                          if (!p.claim) return false;
                          out = ByteBuffer::borrow(core.pool.data(p.claim->slot), n,
                                                   ByteBuffer::Lease{p.port->shared_core(), &release_loan, p.claim->slot, p.claim->gen},
                                                   /*writable=*/true);
                          return true;
                        }};
    auto m = decode(&sink);
    if (!m) return report_delivery_failure(port.core(), m.error());  // a slot taken goes back with m
    if (!place.claim) {
      if (!prepare(port, *m) || !write(port, *m)) ++port.counters.send_failures;
      return;
    }
    if (!m->is_consistent()) return report_network_decode_failure(port.core(), "its metadata does not describe its bytes");
    publish(port, m->descriptor(), *place.claim);
  }

  /// Topic<T>::loan: a slot of the pool lent for a message described by desc.
  Result<Loan<T>> loan(Port& port, const Descriptor& desc) {
    auto& core = port.core();
    if (!port.ensure_lane()) return std::unexpected(no_lane_error(core, "nothing lent"));
    if (desc.data_size > core.pool.slot_bytes()) return std::unexpected(too_large_error(core, desc.data_size));
    auto claim = claim_slot(port);
    if (!claim) return std::unexpected(pool_exhausted_error(core));
    ByteBuffer bytes = ByteBuffer::borrow(core.pool.data(claim->slot), desc.data_size,
                                          ByteBuffer::Lease{port.shared_core(), &release_loan, claim->slot, claim->gen},
                                          /*writable=*/true);
    auto value = T::adopt(desc, std::move(bytes));
    if (!value) {
      core.pool.abandon(*claim);
      const std::string type(horus::type_name<T>());
      return fail(Errc::InvalidArgument, "topic '" + core.name + "': cannot lend a slot for " + type +
                                             ": the descriptor is not valid (use " + type + "::describe to make one)");
    }
    return Loan<T>(std::move(*value), &core, *claim);
  }

  /// What Topic<T>::send(Loan) does with a loan: Publish (in place, nothing copied), Copy (not
  /// this handle's slot any more: send the value as any message), or Refused (counted, logged).
  enum class LoanSend { Publish, Copy, Refused };
  LoanSend check_loan(Port& port, const Loan<T>& l) {
    const auto& core = port.core();
    const auto& pool = core.pool;
    const ByteBuffer& b = l.value_.buffer();
    const bool in_place = l.core_ == &core && port.writer().has_lane() &&
                          l.claim_.slot / pool.slots_per_lane() == port.writer().lane() && b.borrowed() &&
                          b.data() == pool.data(l.claim_.slot) && pool.claimed(l.claim_);
    if (!in_place) return LoanSend::Copy;
    // Metadata edited (through reflection) so that it no longer describes the bytes: a cheap
    // check here (a loan starts from a valid descriptor); receivers check the rest.
    if (!l.value_.is_consistent()) [[unlikely]] {
      report_inconsistent(core, ++inconsistent_);
      return LoanSend::Refused;  // the loan's slot is given back as it is destroyed
    }
    return LoanSend::Publish;
  }
  void publish_loan(Port& port, const Loan<T>& l) { publish(port, l.value_.descriptor(), l.claim_); }

  std::size_t max_message_size(const TopicCore& core) const noexcept { return core.pool.slot_bytes(); }
  std::uint64_t lost() const noexcept { return pool_lost_; }
  void set_blocking(bool on) noexcept { blocking_ = on; }
  /// send_blocking timed out with room in the ring: what stayed full is the pool (subscribers
  /// keep every slot pinned).
  std::optional<Error> full_error(Port& port) {
    if (!port.writer().has_space(port.reader().token())) return std::nullopt;
    port.core().pool.header().exhausted.fetch_add(1, std::memory_order_relaxed);
    ++pool_exhausted_;
    return pool_exhausted_error(port.core());
  }

 private:
  // Claims the oldest free slot of our lane (with a stamp of at most max_stamp).
  std::optional<shm::Pool::Claim> claim_slot(Port& port, std::uint64_t max_stamp = ~std::uint64_t{0}) {
    auto& core = port.core();
    auto c = core.pool.claim(port.writer().lane(), core.claimer, max_stamp);
    // Every slot pinned: pins of processes that died are cleared (at most every 50 ms), then retry.
    if (!c && reap_dead_participants(core)) c = core.pool.claim(port.writer().lane(), core.claimer, max_stamp);
    if (!c && !blocking_) {  // send_blocking counts once, at its end
      core.pool.header().exhausted.fetch_add(1, std::memory_order_relaxed);
      report_pool_exhausted(core, ++pool_exhausted_);
    }
    return c;
  }

  // Copies msg's bytes into the claimed pool slot (none: false) and publishes its descriptor.
  bool write_pooled(Port& port, const T& msg, const std::optional<shm::Pool::Claim>& c) {
    if (!c) return false;
    const auto bytes = msg.buffer().view();
    if (!bytes.empty()) std::memcpy(port.core().pool.data(c->slot), bytes.data(), bytes.size());
    publish(port, msg.descriptor(), *c);
    return true;
  }

  void publish(Port& port, Descriptor d, const shm::Pool::Claim& c) {
    auto& pool = port.core().pool;
    d.pool_id = 1;
    d.slot_id = c.slot;
    d.offset = pool.offset_of(c.slot);
    d.generation = pool.publish(c, port.writer().head() + 1);
    port.writer().write(d);
  }

  // A received descriptor: pins its slot and lends the bytes to a T (no copy). Nothing when the
  // slot was reused meanwhile (counted as a drop) or the descriptor is not valid (a decode failure).
  std::optional<T> adopt(Port& port, const Descriptor& d, bool count_loss = true) {
    auto& core = port.core();
    const auto& pool = core.pool;
    if (d.pool_id != 1 || d.slot_id >= pool.slot_count() || d.data_size > pool.slot_bytes()) [[unlikely]] {
      ++port.counters.decode_failures;
      report_decode_failure(core, "its descriptor names no slot of the topic's pool", port.counters.decode_failures);
      return std::nullopt;
    }
    if (!pool.pin(d.slot_id, d.generation, core.participant)) [[unlikely]] {
      if (count_loss) {  // read_latest polls the same message again: not a new loss each time
        ++pool_lost_;
        pool.header().reused.fetch_add(1, std::memory_order_relaxed);
      }
      return std::nullopt;
    }
    ByteBuffer bytes = ByteBuffer::borrow(pool.data(d.slot_id), d.data_size,
                                          ByteBuffer::Lease{port.shared_core(), &release_pin, d.slot_id, core.participant},
                                          /*writable=*/false);
    auto m = T::adopt(d, std::move(bytes));
    if (!m) [[unlikely]] {
      ++port.counters.decode_failures;
      report_decode_failure(core, "its descriptor is not valid", port.counters.decode_failures);
    }
    return m;
  }

  std::uint64_t pool_lost_ = 0;       // descriptors whose slot was reused before we pinned it
  std::uint64_t pool_exhausted_ = 0;  // sends that found every slot of our lane pinned
  std::uint64_t inconsistent_ = 0;    // sends refused: metadata that does not describe the bytes
  bool blocking_ = false;             // inside send_blocking's retries
};

template <class T>
using SlotCodec = std::conditional_t<PoolMessage<T>, PooledSlots<T>,
                                     std::conditional_t<is_serialized_message<T>, SerializedSlots<T>, FixedSlots<T>>>;

}  // namespace horus::detail

HORUS_API_END

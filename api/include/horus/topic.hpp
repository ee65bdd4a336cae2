// horus::Topic<T>: typed publish/subscribe on a named topic.
//
//   horus::Topic<horus::msg::CmdVel> pub("cmd_vel");   // throws horus::Exception on error
//   auto sub = horus::Topic<horus::msg::CmdVel>::open("cmd_vel");  // or std::expected
//   pub.send(horus::msg::CmdVel::make(1.0f, 0.5f));
//   if (auto m = sub->recv()) { ... }
//
// Two handles with the same name are connected, with no broker and no
// configuration. Every subscriber gets every message once, in each publisher's
// order; a full ring overwrites the oldest message and the subscriber that lost
// it counts the drop (dropped_count()).
//
// Roles. A handle subscribes when it is opened, so it receives every message
// sent after that. A handle whose first call is a send (before any receive call)
// becomes a pure publisher and stops counting as a subscriber (publish_only() does
// it at once); if it receives later, it subscribes from that moment on.
//
// Threads. One handle belongs to one thread at a time (like iceoryx publishers
// or a std::vector): open one handle per thread; handles are cheap and all
// handles of a name share one ring.
//
// The parts (docs/ARCHITECTURE.md): a local port (detail/local_port.hpp: the handle's lane and
// subscriber entry in the ring), a slot codec chosen once by the type's kind (detail/slots.hpp:
// fixed-size, serialized, pooled), and for fleet topics the fleet layer's non-template bridge
// seen through detail/network_link.hpp, which knows T only through a table of functions.
#pragma once

#include <chrono>
#include <cstdint>
#include <expected>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include "horus/backend.hpp"
#include "horus/topic_options.hpp"
#include "horus/detail/bridge_port.hpp"
#include "horus/detail/network_link.hpp"
#include "horus/detail/slots.hpp"
#include "horus/detail/traffic_log.hpp"
#include "horus/detail/waiting.hpp"
#include "horus/detail/watch.hpp"
#include "horus/error.hpp"
#include "horus/loan.hpp"
#include "horus/message_traits.hpp"
#include "horus/metrics.hpp"
#include "horus/names.hpp"
#include "horus/qos.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

class WaitSet;  // horus/waitset.hpp

template <class T>
class Topic {
  static_assert(Reflected<T>,
                "horus::Topic<T>: T must be a message declared with HORUS_MESSAGE or HORUS_REFLECT");
  static_assert(std::is_default_constructible_v<T>, "horus::Topic<T>: T must be default constructible");
  static_assert(!std::is_trivially_copyable_v<T> || sizeof(T) <= (1u << 20),
                "horus::Topic<T>: fixed-size messages are at most 1 MiB (they are copied through the stack); "
                "large data (images, point clouds) uses the large-data classes");
  using Codec = detail::SlotCodec<T>;
  using Port = detail::LocalPort<typename Codec::Payload>;

 public:
  using message_type = T;
  /// True when messages are serialized into slots (variable-size T) rather than copied.
  static constexpr bool kSerialized = is_serialized_message<T>;
  /// True when T's bytes travel through the topic's pool and the ring carries T::Descriptor.
  static constexpr bool kPooled = is_pool_message<T>;
  /// Large data: the fixed-size description the ring carries (T::Descriptor).
  using descriptor_type = typename detail::DescriptorOf<T>::type;

  /// Opens (or creates) the topic with the default capacity; throws horus::Exception.
  explicit Topic(std::string_view name) : Topic(value_or_throw(open(name))) {}

  /// Opens (or creates) the topic with the default capacity (16 to 1024 slots by message size).
  static Result<Topic> open(std::string_view name) { return make(name, TopicOptions{}); }

  /// Opens (or creates) the topic with choices made in code (backend, capacity, slot size).
  static Result<Topic> open(std::string_view name, const TopicOptions& options) { return make(name, options); }

  /// Opens (or creates) the topic with `capacity` slots per publisher (a power of two).
  /// `slot_size` matters for a serialized T only: the largest encoded message the topic accepts
  /// (default_slot_bytes<T> when not given); opening an existing serialized topic with another
  /// slot size is Errc::ConfigMismatch. For a fixed-size T a slot holds sizeof(T), and a
  /// `slot_size` is only checked to be at least that. Opening an existing topic with a
  /// different capacity is Errc::ConfigMismatch. Default capacity: 16 to 1024 slots by message
  /// size; 4 for serialized topics whose slots are 1 MiB or more (images: the ring is virtual
  /// memory, touched only as messages are written, but 16 x 8 MiB per publisher is a lot).
  static Result<Topic> with_capacity(std::string_view name, std::uint32_t capacity,
                                     std::optional<std::size_t> slot_size = std::nullopt) {
    return make(name, TopicOptions{std::nullopt, capacity, slot_size});
  }

  /// A moved-from handle may only be destroyed or assigned to.
  Topic(Topic&&) noexcept = default;
  Topic& operator=(Topic&&) noexcept = default;
  Topic(const Topic&) = delete;
  Topic& operator=(const Topic&) = delete;
  ~Topic() = default;

  // -- sending ---------------------------------------------------------------

  /// Publishes. Never blocks: a full ring overwrites its oldest message. A message is refused
  /// only when all kMaxPublishers lanes are taken, or (serialized T) when it encodes to more
  /// than max_message_size() bytes; it is then counted in metrics().send_failures() and logged.
  [[gnu::always_inline]] void send(const T& msg) {
    if constexpr (requires { codec_.write_plain(port_, msg); }) {
      // A fixed-size message: a handle with a deadline or verbose lines is told by the writer's
      // own slow branch (RingWriter::observe), so a plain send loads no flag of ours.
      if (port_.ensure_lane()) [[likely]] {
        if (codec_.write_plain(port_, msg)) [[likely]]
          return;
        return after_send(msg, true);
      }
      ++port_.counters.send_failures;
      return after_send(msg, false);
    } else {
      after_send(msg, send_local(msg));
    }
  }

  /// Large data: lends a slot of the topic's pool for a message described by `desc` (e.g.
  /// Image::describe(1080, 1920, ImageEncoding::Rgb8)). Fill it in place (loan->data_mut(),
  /// set_timestamp_ns, ...), then send(std::move(loan)): nothing is copied. Errors:
  /// MessageTooLarge when desc.data_size exceeds the slot size, LimitReached when every slot of
  /// this publisher is pinned by subscribers or lent, or every publisher lane is taken, and
  /// InvalidArgument for a descriptor T cannot have (T::describe never gives one).
  Result<Loan<T>> loan(const descriptor_type& desc)
    requires kPooled
  {
    return codec_.loan(port_, desc);
  }

  /// Publishes a loan of this handle without copying its bytes. A loan whose bytes were
  /// replaced (resized, assigned another size) or that came from another handle is sent by
  /// copy instead; failures count in metrics().send_failures() as for send().
  void send(Loan<T>&& loan)
    requires kPooled
  {
    Loan<T> l = std::move(loan);
    switch (codec_.check_loan(port_, l)) {
      case Codec::LoanSend::Copy: return send(static_cast<const T&>(*l));
      case Codec::LoanSend::Refused:
        ++port_.counters.send_failures;
        if (watch_.active()) [[unlikely]]
          watched_send(*l, false);
        return;
      case Codec::LoanSend::Publish: break;
    }
    codec_.publish_loan(port_, l);
    if (watch_.active()) [[unlikely]]
      watched_send(*l, true);
  }

  /// Publishes only if no subscriber would lose an unread message; else gives the message back
  /// (also when it is refused for its size).
  std::expected<void, T> try_send(const T& msg) {
    if (port_.ensure_lane() && codec_.prepare(port_, msg) && try_commit(msg)) {
      if (watch_.active()) [[unlikely]]
        watched_send(msg, true);
      return {};
    }
    ++port_.counters.send_failures;
    if (watch_.active()) [[unlikely]]
      watched_send(msg, false);
    return std::unexpected<T>(msg);
  }

  /// Publishes, waiting up to `timeout` for space (spin, then yield, then 100 us sleeps).
  /// Space means: no other subscriber would lose an unread message (a handle never waits for
  /// its own subscription). Errc::Timeout when the ring stayed full, Errc::LimitReached at once
  /// when every publisher lane of the topic is taken.
  Result<void> send_blocking(const T& msg, std::chrono::nanoseconds timeout);

  // -- receiving -------------------------------------------------------------

  /// Takes the next unread message (FIFO per publisher), or nothing. A serialized message that
  /// does not decode (a corrupt slot) is skipped, counted in metrics().decode_failures() and logged.
  /// (has_message() and pending_count() count such a message until recv() skips it.)
  [[gnu::always_inline]] std::optional<T> recv() {
    if (!port_.ensure_subscribed()) [[unlikely]] {
      ++port_.counters.recv_failures;
      return std::nullopt;
    }
    if (auto m = read_next()) return m;
    ++port_.counters.recv_failures;  // also marks this handle as a receiver (see LocalPort::receives)
    return std::nullopt;
  }

  /// Takes the next unread message, waiting up to `timeout` for one (every scope and backend:
  /// in-process, shared memory, and what arrives from DDS or LCM). A zero or negative timeout
  /// does not wait (as recv()). The thread sleeps in the kernel (futex) until a publisher's
  /// send wakes it; it uses no CPU while it waits. Nothing when the timeout passed.
  std::optional<T> recv_for(std::chrono::nanoseconds timeout) {
    if (!port_.ensure_subscribed()) [[unlikely]] {
      ++port_.counters.recv_failures;
      return std::nullopt;
    }
    if (auto m = read_next()) return m;
    if (timeout > std::chrono::nanoseconds::zero()) {
      const auto deadline = detail::deadline_after(timeout);
      while (wait_until(deadline))
        if (auto m = read_next()) return m;  // (a corrupt slot skipped: wait again)
    }
    ++port_.counters.recv_failures;
    return std::nullopt;
  }

  /// Waits up to `timeout` until recv() would return a message; true then. A zero or negative
  /// timeout does not wait (as has_message()).
  bool wait_for(std::chrono::nanoseconds timeout) {
    port_.received = true;
    if (!port_.ensure_subscribed()) return false;
    if (port_.reader().has_message()) return true;
    return timeout > std::chrono::nanoseconds::zero() && wait_until(detail::deadline_after(timeout));
  }

  /// Same as recv(), for symmetry with try_send().
  [[gnu::always_inline]] std::optional<T> try_recv() { return recv(); }

  /// The newest message on the topic, without waiting; repeated calls return the same message
  /// until a newer one arrives. Everything up to it counts as read (messages already
  /// overwritten still count as dropped), so a following recv() returns only newer messages.
  /// With capacity 1 and a publisher that never pauses, the only slot is nearly always being
  /// rewritten and this may return nothing: use a capacity of 2 or more for "latest" topics.
  /// For a serialized T (the spec limits read_latest to Copy types; horus allows it, for latched
  /// maps) every call copies and decodes the newest message again; a newest message that does
  /// not decode gives nothing.
  std::optional<T> read_latest() {
    port_.received = true;
    auto m = codec_.read_latest(port_);
    if (m && watch_.active()) [[unlikely]]
      return watched_latest(std::move(m));
    return m;
  }

  // -- state -----------------------------------------------------------------

  std::string_view name() const noexcept { return core().name; }
  /// True if recv() would return a message.
  bool has_message() {
    port_.received = true;
    return port_.ensure_subscribed() && port_.reader().has_message();
  }
  /// Unread messages waiting for this handle.
  std::uint64_t pending_count() {
    port_.received = true;
    return port_.ensure_subscribed() ? port_.reader().pending() : 0;
  }
  /// Messages lost to overwrites: this handle's own losses when it subscribes; for a pure
  /// publisher, the losses of all subscribers of the topic. Large data: a message whose pool
  /// slot was reused before this handle read it (subscribers kept the spare slots pinned)
  /// counts as dropped too. Fleet topics: plus what was lost on the way to or from the network
  /// since this handle opened (host-wide: the bridge's takeovers, a transport's losses).
  std::uint64_t dropped_count() const noexcept {
    const std::uint64_t net = core().net ? detail::network_dropped(core()) - net_dropped_base_ : 0;
    if (port_.reader().subscribed()) return port_.reader().lost() + codec_.lost() + net + watch_.expired();
    const auto& ring = core().ring;
    std::uint64_t n = ring.header().dropped_total.load(std::memory_order_relaxed) + ring.undetected_losses();
    if constexpr (kPooled) n += core().pool.header().reused.load(std::memory_order_relaxed);
    return n + net;
  }
  /// TopicOptions::deadline: the full periods this handle went without a message since it
  /// opened. A handle that sends counts the periods between its own sends (it missed its
  /// period: DDS's offered deadline); one that only receives, the periods without a message
  /// received (requested deadline: a watchdog). A gap of 2.5 periods is 2 misses; 0 without
  /// a deadline. Executor::on_deadline_missed calls back when it grows.
  std::uint64_t deadline_missed_count() const noexcept { return watch_.missed(); }
  /// TopicOptions::lifespan: messages recv() did not deliver because their timestamp_ns was
  /// older than the lifespan (they also count in dropped_count()).
  std::uint64_t expired_count() const noexcept { return watch_.expired(); }
  /// Publishers currently holding a lane of this topic; for a fleet topic, the host's
  /// publishing handles plus the remote writers matched by the host's bridge (the bridge's own
  /// lane is not counted).
  std::uint32_t pub_count() const noexcept { return detail::network_publishers(core()); }
  /// Handles currently subscribed to this topic; for a fleet topic, the host's subscribing
  /// handles plus the remote readers matched by the host's bridge.
  std::uint32_t sub_count() const noexcept { return detail::network_subscribers(core()); }
  TopicMetrics metrics() const noexcept {
    const auto& c = port_.counters;
    return TopicMetrics(port_.writer().sent(), port_.reader().delivered() - c.undelivered, c.send_failures,
                        c.recv_failures, dropped_count(), core().ring.total_sent(),
                        c.decode_failures + port_.reader().corrupt() + detail::network_decode_failures(core()));
  }
  /// Network backends: problems the backend reported for this topic in this process (a remote
  /// endpoint with another message type under the same DDS topic, an incompatible QoS); each
  /// is also logged. Samples that do not decode (not XCDR1, another LCM fingerprint) count in
  /// metrics().decode_failures(); messages the backend lost (LCM: datagrams the kernel
  /// dropped) count in dropped_count().
  std::uint64_t network_errors() const noexcept { return detail::network_errors(core()); }
  /// Declares this handle a pure publisher now, as its first send would: it stops counting as a
  /// subscriber, so it never holds back send_blocking/try_send of other handles while it only
  /// waits to publish (a receive subscribes it again, from that moment on). Does nothing on a
  /// handle that has received.
  void publish_only() noexcept { port_.publish_only(); }
  /// Fleet topics: true while this process is the host's bridge of the topic (it exports what
  /// the host's publishers write and imports what other hosts send); false on other topics.
  bool is_bridge() const noexcept { return detail::network_holds_bridge(core()); }
  /// Threads (of every process on the host) blocked in recv_for/wait_for/WaitSet on this topic.
  std::uint32_t waiter_count() const noexcept { return detail::network_waiters(core()); }
  /// Slots per publisher lane.
  std::uint32_t capacity() const noexcept { return core().ring.capacity(); }
  /// Largest message the topic carries: sizeof(T), for a serialized T the largest encoded
  /// size, for large data the pool slot's bytes.
  std::size_t max_message_size() const noexcept { return codec_.max_message_size(core()); }
  /// Where this topic's messages travel (see Backend).
  Backend backend() const noexcept { return core().backend; }
  /// How far its messages go: process, host or fleet (backend().scope()).
  Scope scope() const noexcept { return core().backend.scope(); }
  /// The qualified message type name ("horus::msg::CmdVel").
  static constexpr std::string_view type_name() noexcept { return horus::type_name<T>(); }

 private:
  explicit Topic(std::shared_ptr<detail::TopicCore> core) : port_(std::move(core)) {}

  friend class WaitSet;
  friend class Executor;  // the deadline's next miss (on_deadline_missed)

  // recv() and recv_for(): the next message, expired ones skipped (lifespan).
  [[gnu::always_inline]] std::optional<T> read_next() {
    auto m = codec_.read(port_);
    if (m && watch_.active()) [[unlikely]] {
      // The slow path sees the message through a copy (small T) and answers whether to deliver
      // it: the message received, the caller's return slot, never has its address taken, so the
      // fast path keeps it in registers (passing the slot to a noinline call cost a store and a
      // reload per receive, +1.3 ns same-thread: bench/compare_builds.sh).
      for (;;) {
        bool keep = false;
        if constexpr (kSmallMessage) {
          const T copy = *m;
          keep = watched(copy);
        } else {
          keep = watched(*m);
        }
        if (keep) break;
        m = codec_.read(port_);  // expired (lifespan): the next one
        if (!m) break;
      }
    }
    return m;
  }
  // A received message of an active handle: false when it expired (skipped, counted).
  [[gnu::noinline, gnu::cold]] bool watched(const T& m) noexcept {
    if (!watch_.take(m)) return false;
    if (watch_.logs()) log_traffic(detail::Traffic::Recv, m);
    return true;
  }
  [[gnu::noinline, gnu::cold]] std::optional<T> watched_latest(std::optional<T> m) {
    if (!watch_.fresh(*m)) return std::nullopt;  // the newest expired (not counted again at each call)
    if (watch_.logs() && watch_.newer_latest(core().ring.total_sent())) log_traffic(detail::Traffic::Latest, *m);
    return m;
  }
  // Small enough to be copied for watched_send (send() keeps the caller's message in registers).
  static constexpr bool kSmallMessage = std::is_trivially_copyable_v<T> && sizeof(T) <= 64;
  // After a send, sent or refused: an active handle's deadline and traffic line.
  [[gnu::always_inline]] void after_send(const T& msg, bool sent) {
    if (watch_.active()) [[unlikely]] {
      if constexpr (kSmallMessage) {
        // A copy made here, on this path only: the caller's message never has its address
        // taken, so a loop that sends keeps it in registers (what it did before there were
        // traffic lines: bench/compare_builds.sh).
        const T copy = msg;
        watched_send(copy, sent);
      } else {
        watched_send(msg, sent);
      }
    }
  }
  // After a send of an active handle, sent or refused: the deadline, and the traffic line.
  [[gnu::noinline, gnu::cold]] void watched_send(const T& msg, bool sent) noexcept {
    if (sent) watch_.sent();  // the offered deadline counts what went out
    if (watch_.logs()) log_traffic(sent ? detail::Traffic::Send : detail::Traffic::Refused, msg);
  }
  // TopicOptions::verbose: a line for a message sent or received, if the topic's limit admits it.
  // Never throws (a summary that cannot be made costs its line, not the message): callers on
  // the receive path then need no unwinding for it, which keeps recv()'s code as it was.
  [[gnu::noinline]] void log_traffic(detail::Traffic what, const T& msg) noexcept {
    const auto held = detail::admit_traffic(core(), traffic_);
    if (!held) return;
    std::uint64_t count = 0;
    switch (what) {
      case detail::Traffic::Send: count = port_.writer().sent(); break;
      case detail::Traffic::Refused: count = port_.counters.send_failures; break;
      case detail::Traffic::Recv: count = port_.reader().delivered() - port_.counters.undelivered; break;
      case detail::Traffic::Latest: break;
    }
    const bool receiving = what == detail::Traffic::Recv || what == detail::Traffic::Latest;
    try {
      detail::write_traffic(core(), traffic_, what, count, receiving ? dropped_count() : 0, *held,
                            detail::traffic_summary(msg));
    } catch (...) {
      detail::write_traffic(core(), traffic_, what, count, receiving ? dropped_count() : 0, *held,
                            "(its summary failed)");
    }
  }
  // What a WaitSet waits on: this handle's subscriber entry. The handle stays a subscriber
  // (its first send does not make it a pure publisher). Nothing when no entry is free.
  std::optional<detail::WaitTarget> wait_target() {
    port_.received = true;
    if (!port_.ensure_subscribed()) return std::nullopt;
    return detail::WaitTarget{port_.shared_core(), port_.reader().entry(), port_.reader().token()};
  }

  bool wait_until(detail::WaitClock::time_point deadline) {
    return detail::wait_for_unread(core(), port_.reader().entry(), port_.reader().token(), deadline);
  }

  detail::TopicCore& core() const noexcept { return port_.core(); }

  static Topic value_or_throw(Result<Topic> r) {
    if (!r) throw Exception(std::move(r.error()));
    return std::move(*r);
  }

  static Result<Topic> make(std::string_view name, const TopicOptions& options);

  // Writes msg into the local ring (and pool); false when it was refused (counted).
  [[gnu::always_inline]] bool send_local(const T& msg) {
    if (!port_.ensure_lane() || !codec_.prepare(port_, msg) || !codec_.write(port_, msg)) [[unlikely]] {
      ++port_.counters.send_failures;
      return false;
    }
    return true;
  }

  Result<void> committed(const T& msg) {  // send_blocking sent
    if (watch_.active()) [[unlikely]]
      watched_send(msg, true);
    return {};
  }

  // Writes a prepared msg if there is space (a fleet topic's bridge is one of the subscribers).
  bool try_commit(const T& msg) { return codec_.try_write(port_, msg); }

  // What a fleet topic's bridge knows of T (horus/detail/network_link.hpp): compiled once in the
  // library for the standard messages, made here for the others.
  static const detail::WireOps* wire_ops() noexcept { return detail::wire_ops_of<T>(); }

  Port port_;    // the topic, and this handle's lane and subscriber entry
  Codec codec_;  // the slot codec's state (scratch buffers, pool counters)
  std::uint64_t net_dropped_base_ = 0;  // the bridge's dropped count when this handle opened
  detail::Watch watch_;                 // deadline, lifespan and verbose (TopicOptions)
  detail::TrafficLogSettings traffic_;  // verbose: the level and rate of its lines
};

}  // namespace horus

#include "horus/detail/topic_impl.hpp"  // the members defined out of the class

HORUS_API_END

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
// becomes a pure publisher and stops counting as a subscriber; if it receives
// later, it subscribes from that moment on.
//
// Threads. One handle belongs to one thread at a time (like iceoryx publishers
// or a std::vector): open one handle per thread; handles are cheap and all
// handles of a name share one ring.
#pragma once

#include <chrono>
#include <cstring>
#include <cstdint>
#include <expected>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <type_traits>
#include <vector>

#include "horus/byte_buffer.hpp"
#include "horus/codec.hpp"
#include "horus/error.hpp"
#include "horus/dds/cdr.hpp"
#include "horus/lcm/codec.hpp"
#include "horus/metrics.hpp"
#include "horus/network.hpp"
#include "horus/qos.hpp"
#include "horus/reflect.hpp"
#include "horus/shm/heap_region.hpp"
#include "horus/shm/pool.hpp"
#include "horus/shm/ring.hpp"
#include "horus/shm/shm_segment.hpp"

namespace horus {

/// Where a topic's messages travel.
///   InProcess     a ring in this process's memory (HORUS_BACKEND=inproc, or per topic in code)
///   SharedMemory  a ring in a POSIX shared-memory segment that every process of this host
///                 (and HORUS_NAMESPACE) opening the name attaches to; the default
///   CycloneDds    Cyclone DDS over UDP: other processes and hosts of the DDS domain
///                 (HORUS_BACKEND=cyclonedds); handles of this process share an in-process ring
///   FastDds       the same through Fast DDS (HORUS_BACKEND=fastdds); both speak DDSI-RTPS
///                 and XCDR1, so a Cyclone DDS process and a Fast DDS process talk
///   Lcm           LCM over UDP multicast (HORUS_BACKEND=lcm; HORUS_LCM_URL): channel = topic
///                 name, lcm-gen compatible encoding (horus-idlgen's .lcm types)
enum class Backend { InProcess, SharedMemory, CycloneDds, FastDds, Lcm };
std::string_view to_string(Backend b) noexcept;

/// True for the backends that reach other hosts (DDS, LCM).
constexpr bool is_network(Backend b) noexcept {
  return b == Backend::CycloneDds || b == Backend::FastDds || b == Backend::Lcm;
}

/// True when this build of horus has backend b (DDS backends need their Debian packages at build time).
bool backend_available(Backend b) noexcept;

/// Per-topic choices made in code (they take precedence over the environment).
struct TopicOptions {
  std::optional<Backend> backend;         // default: HORUS_BACKEND, else shared memory
  std::optional<std::uint32_t> capacity;  // slots per publisher, a power of two
  std::optional<std::size_t> slot_size;   // serialized messages: the largest encoded message;
                                          // large data: the largest message's bytes (pool slot)
  // Network backends only (the defaults come from net::default_qos<T>, horus/qos.hpp):
  std::optional<net::Reliability> reliability = std::nullopt;
  std::optional<net::Durability> durability = std::nullopt;
};

/// The backend HORUS_BACKEND selects (auto|shm|inproc|cyclonedds|fastdds|lcm; unset means auto =
/// shm); an error names a bad value and lists the valid ones.
Result<Backend> backend_from_environment();

/// The network settings of this process: HORUS_DOMAIN_ID (DDS domain, 0 to 232, default 0)
/// and HORUS_DDS_LOCALHOST (1/true/yes: loopback only, no multicast; 0/false/no or unset: the
/// LAN). An error names the variable, its value and what is expected.
Result<net::Config> network_config_from_environment();

/// The DDS topic name of a horus topic: "horus/" + the name with '.' made '/'
/// ("fleet.robot_1.pose" -> "horus/fleet/robot_1/pose"). DDS topic names allow letters,
/// digits, '_' and '/' only, so a name with '-' is an error (InvalidName) on DDS backends.
Result<std::string> dds_topic_name(std::string_view topic);

/// The LCM channel of a horus topic: the topic name itself ("fleet.robot_1.pose"). LCM
/// channels are at most 63 bytes, so a longer name is an error (InvalidName) on the lcm backend.
Result<std::string> lcm_channel_name(std::string_view topic);

/// Longest topic name accepted.
inline constexpr std::size_t kMaxTopicNameLength = 128;

/// Checks a topic name: 1 to 128 characters from letters, digits, '_', '.', '-';
/// dot-separated segments ("sensors.imu", "robot_1.cmd_vel"); no empty segment,
/// no leading '-'. The error names the offending character and the rule.
Result<void> validate_topic_name(std::string_view name);

/// A message type Topic<T> can carry: any reflected message. Trivially copyable ones travel
/// by copy; the others (vectors, strings, large-data classes) are serialized (horus/codec.hpp).
template <class T>
concept Message = Reflected<T> && std::is_default_constructible_v<T>;

/// Large-data messages (Image, PointCloud, DepthImage, Tensor): the topic keeps their bytes in
/// a pool of slots beside its ring, and the ring carries only T::Descriptor (zero-copy).
namespace detail {
template <class T>
concept PoolMessageParts = requires(const T& t, const typename T::Descriptor& d, ByteBuffer&& b) {
  requires std::is_trivially_copyable_v<typename T::Descriptor>;
  { t.descriptor() } -> std::same_as<typename T::Descriptor>;
  { t.buffer() } -> std::same_as<const ByteBuffer&>;
  { T::adopt(d, std::move(b)) } -> std::same_as<std::optional<T>>;
  d.pool_id;
  d.slot_id;
  d.generation;
  d.offset;
  d.data_size;
};
}  // namespace detail

template <class T>
concept PoolMessage = requires { typename T::Descriptor; } && detail::PoolMessageParts<T>;

namespace detail {
struct NoDescriptor {};
template <class T, bool = PoolMessage<T>>
struct DescriptorOf {
  using type = NoDescriptor;
};
template <class T>
struct DescriptorOf<T, true> {
  using type = typename T::Descriptor;
};
}  // namespace detail

/// True when Topic<T> keeps T's bytes in a shared-memory pool (PoolMessage).
template <class T>
inline constexpr bool is_pool_message = PoolMessage<T>;

/// True when Topic<T> serializes T rather than copying it.
template <class T>
inline constexpr bool is_serialized_message = !std::is_trivially_copyable_v<T> && !PoolMessage<T>;

namespace detail {
template <class T>
concept HasDefaultSlotBytes = requires { { T::kDefaultSlotBytes } -> std::convertible_to<std::size_t>; };
}  // namespace detail

/// Largest encoded message a serialized topic accepts unless the slot size is given:
/// T::kDefaultSlotBytes when T declares it (Image: a 1920x1080 RGBA frame), else 64 KiB.
template <class T>
inline constexpr std::size_t default_slot_bytes = [] {
  if constexpr (detail::HasDefaultSlotBytes<T>) {
    static_assert(T::kDefaultSlotBytes >= 1 && T::kDefaultSlotBytes <= (std::size_t{1} << 30) - 8,
                  "T::kDefaultSlotBytes must be 1 byte to 1 GiB - 8");
    return static_cast<std::size_t>(T::kDefaultSlotBytes);
  } else {
    return std::size_t{64 * 1024};
  }
}();

namespace detail {

struct TypeInfo {
  std::string_view name;
  std::uint64_t hash;
  std::uint32_t size;        // sizeof(T) (a pooled type: sizeof(T::Descriptor)); for a serialized type,
                             // the default largest encoded message
  bool serialized = false;   // variable-size: slots hold [length][encoded bytes]
  std::uint64_t pool_bytes = 0;  // large data: default bytes per pool slot (0: no pool)
};

struct NetworkState;  // topic.cpp: the transport, the endpoint and its listener
struct NetworkStateDeleter {
  void operator()(NetworkState* s) const noexcept;
};

/// The shared state of one topic in this process: its ring and the memory it lives in.
struct TopicCore {
  std::string name;
  std::string type_name;
  std::uint64_t type_hash = 0;
  std::uint32_t payload_size = 0;  // ring payload: sizeof(T), or 8 + largest encoded message
  bool serialized = false;
  Backend backend = Backend::InProcess;
  int pid = 0;                             // the process that opened it (a forked child opens its own)
  shm::HeapRegion region;                  // InProcess
  std::optional<shm::ShmSegment> segment;  // SharedMemory
  shm::Ring ring;
  shm::Pool pool;                // large data only
  std::uint32_t participant = 0;  // our index in the segment's participant table (what pins pool slots)
  shm::Pool::Claimer claimer;     // this process, as the pool records who writes a slot
  std::atomic<std::int64_t> last_reap_ns{0};  // reap_dead_participants' rate limit

  // Network backends. Received samples are decoded by `sink` and written into the ring by
  // `bridge`, a handle of this topic that only publishes. Declared last: the endpoint (net)
  // goes first, so no callback runs once the bridge and the ring are gone.
  std::mutex net_mutex;
  std::atomic<bool> bridge_publishing{false};         // the bridge holds a ring lane
  std::atomic<std::uint64_t> net_decode_failures{0};  // samples that did not decode
  std::atomic<std::uint64_t> net_errors{0};           // incompatible endpoints reported
  std::atomic<std::uint64_t> net_lost{0};             // messages the backend reported lost
  bool net_loopback = false;  // the backend delivers our own samples back (LCM): send skips the ring
  std::atomic<bool> net_receiving{true};  // what the endpoint was last told (set_receiving)
  std::unique_ptr<void, void (*)(void*)> bridge{nullptr, nullptr};
  void (*sink)(void* bridge, const net::Sample& sample) = nullptr;
  std::unique_ptr<NetworkState, NetworkStateDeleter> net;
};

/// Finds or creates the topic `name` for a message type; checks name, type and configuration.
Result<std::shared_ptr<TopicCore>> open_core(std::string_view name, const TypeInfo& type,
                                             const TopicOptions& options);
/// A host-unique, non-zero identity for a handle's lane and subscriber entry: (pid << 32) | n.
std::uint64_t next_token() noexcept;
/// Logs (once per handle) that a send found no free lane / a receive no free subscriber entry.
void report_no_lane(const TopicCore& core);
void report_no_subscriber_slot(const TopicCore& core);
/// Logs a serialized message refused for its size, or a received one that did not decode.
void report_too_large(const TopicCore& core, std::size_t size, std::uint64_t count);
void report_decode_failure(const TopicCore& core, const std::string& what, std::uint64_t count);
/// The error send_blocking returns for a message over the slot size.
Error too_large_error(const TopicCore& core, std::size_t size);
/// Logs (first and every 1024th) that a large-data send found every pool slot of its lane pinned.
void report_pool_exhausted(const TopicCore& core, std::uint64_t count);
/// Logs (first and every 1024th) a large-data message refused because its metadata does not
/// describe its bytes (e.g. an Image edited through JSON).
void report_inconsistent(const TopicCore& core, std::uint64_t count);
/// The error for the same, from send_blocking or loan().
Error pool_exhausted_error(const TopicCore& core);

/// Network backends: creates the topic's endpoint (once per core; the caller holds net_mutex
/// and has set bridge and sink).
Result<void> attach_network(TopicCore& core, const net::Qos& qos);
/// The QoS the topic's endpoint was created with.
net::Qos network_qos(const TopicCore& core) noexcept;
/// Sends one sample through the topic's endpoint.
Result<void> network_write(TopicCore& core, std::size_t body_size, const net::BodyWriter& writer);
/// Remote endpoints matched with this process's (0 without a network backend).
std::uint32_t network_publishers(const TopicCore& core) noexcept;
std::uint32_t network_subscribers(const TopicCore& core) noexcept;
/// Tells the endpoint whether a handle of this process reads the topic (Endpoint::set_receiving),
/// when that changed. Never called from the backend's threads.
void network_receiving(TopicCore& core, bool on) noexcept;
/// Logs (first and every 1024th) a received sample that did not decode, and counts it.
void report_network_decode_failure(TopicCore& core, const std::string& what);
/// Logs (first and every 1024th) a sample the network backend refused to send.
void report_network_send_failure(const TopicCore& core, const Error& error, std::uint64_t count);

/// This process's pid, cached (updated in a child after fork()): leases compare it with their
/// topic's to do nothing in a forked child, which must not release its parent's pins.
int current_pid() noexcept;
/// Shared memory: releases what processes that died held (pins, lanes, subscriber entries), at
/// most once per 50 ms per topic; true when some process was reaped.
bool reap_dead_participants(TopicCore& core);
/// Pool leases: a received message unpins its slot; a loan dropped unsent gives its slot back.
void release_pin(const void* core, std::uint64_t slot, std::uint64_t participant) noexcept;
void release_loan(const void* core, std::uint64_t slot, std::uint64_t gen) noexcept;

}  // namespace detail

template <class T>
class Topic;

/// A pool slot lent to a publisher (Topic<T>::loan): a T whose bytes are the slot itself, to be
/// filled in place and published with Topic<T>::send(std::move(loan)), which copies nothing.
/// Its bytes start with whatever the slot held before: write all of them. Dropping a loan
/// unsent gives the slot back. A loan must be sent through the handle that lent it.
template <class T>
class Loan {
 public:
  T& operator*() noexcept { return value_; }
  T* operator->() noexcept { return &value_; }
  const T& operator*() const noexcept { return value_; }
  const T* operator->() const noexcept { return &value_; }

 private:
  friend class Topic<T>;
  Loan(T value, const void* core, shm::Pool::Claim claim) : value_(std::move(value)), core_(core), claim_(claim) {}
  T value_;
  const void* core_;
  shm::Pool::Claim claim_;
};

template <class T>
class Topic {
  static_assert(Reflected<T>,
                "horus::Topic<T>: T must be a message declared with HORUS_MESSAGE or HORUS_REFLECT");
  static_assert(std::is_default_constructible_v<T>, "horus::Topic<T>: T must be default constructible");
  static_assert(!std::is_trivially_copyable_v<T> || sizeof(T) <= (1u << 20),
                "horus::Topic<T>: fixed-size messages are at most 1 MiB (they are copied through the stack); "
                "large data (images, point clouds) uses the large-data classes");

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

  Topic(Topic&&) noexcept = default;
  /// A moved-from handle may only be destroyed or assigned to.
  Topic& operator=(Topic&& other) noexcept {
    if (this == &other) return *this;
    // Release our lane and subscription while our ring is still mapped, then take other's.
    Topic old(std::move(*this));
    core_ = std::move(other.core_);
    writer_ = std::move(other.writer_);
    reader_ = std::move(other.reader_);
    send_failures_ = other.send_failures_;
    recv_failures_ = other.recv_failures_;
    too_large_ = other.too_large_;
    decode_failures_ = other.decode_failures_;
    undelivered_ = other.undelivered_;
    pool_lost_ = other.pool_lost_;
    pool_exhausted_ = other.pool_exhausted_;
    networked_ = other.networked_;
    net_lost_base_ = other.net_lost_base_;
    net_send_failures_ = other.net_send_failures_;
    inconsistent_ = other.inconsistent_;
    encoded_size_ = other.encoded_size_;
    scratch_ = std::move(other.scratch_);
    inbox_ = std::move(other.inbox_);
    received_ = other.received_;
    no_lane_reported_ = other.no_lane_reported_;
    no_sub_reported_ = other.no_sub_reported_;
    return *this;
  }
  Topic(const Topic&) = delete;
  Topic& operator=(const Topic&) = delete;
  ~Topic() = default;

  // -- sending ---------------------------------------------------------------

  /// Publishes. Never blocks: a full ring overwrites its oldest message. A message is refused
  /// only when all kMaxPublishers lanes are taken, or (serialized T) when it encodes to more
  /// than max_message_size() bytes; it is then counted in metrics().send_failures() and logged.
  [[gnu::always_inline]] void send(const T& msg) {
    if (networked_) [[unlikely]] {
      send_networked(msg);
      return;
    }
    send_local(msg);
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
    if (!writer_.has_lane() && !become_publisher())
      return fail(Errc::LimitReached, "topic '" + core_->name + "': all " + std::to_string(shm::kMaxPublishers) +
                                          " publisher lanes are in use; nothing lent");
    if (desc.data_size > core_->pool.slot_bytes())
      return std::unexpected(detail::too_large_error(*core_, desc.data_size));
    auto claim = claim_slot();
    if (!claim) return std::unexpected(detail::pool_exhausted_error(*core_));
    ByteBuffer bytes = ByteBuffer::borrow(core_->pool.data(claim->slot), desc.data_size,
                                          ByteBuffer::Lease{core_, &detail::release_loan, claim->slot, claim->gen},
                                          /*writable=*/true);
    auto value = T::adopt(desc, std::move(bytes));
    if (!value) {
      core_->pool.abandon(*claim);
      return fail(Errc::InvalidArgument,
                  "topic '" + core_->name + "': cannot lend a slot for " + std::string(type_name()) +
                      ": the descriptor is not valid (use " + std::string(type_name()) + "::describe to make one)");
    }
    return Loan<T>(std::move(*value), core_.get(), *claim);
  }

  /// Publishes a loan of this handle without copying its bytes. A loan whose bytes were
  /// replaced (resized, assigned another size) or that came from another handle is sent by
  /// copy instead; failures count in metrics().send_failures() as for send().
  void send(Loan<T>&& loan)
    requires kPooled
  {
    Loan<T> l = std::move(loan);
    const auto& pool = core_->pool;
    const ByteBuffer& b = l.value_.buffer();
    const bool in_place = l.core_ == core_.get() && writer_.has_lane() &&
                          l.claim_.slot / pool.slots_per_lane() == writer_.lane() && b.borrowed() &&
                          b.data() == pool.data(l.claim_.slot) && pool.claimed(l.claim_);
    if (!in_place) {
      send(static_cast<const T&>(l.value_));
      return;
    }
    // Metadata edited (through reflection) so that it no longer describes the bytes: a cheap
    // check here (a loan starts from a valid descriptor); receivers check the rest.
    if (!l.value_.is_consistent()) [[unlikely]] {
      detail::report_inconsistent(*core_, ++inconsistent_);
      ++send_failures_;
      return;  // the loan's slot is given back as it is destroyed
    }
    if (networked_ && core_->net_loopback) [[unlikely]] {
      network_send(l.value_);  // comes back through the network; the slot is given back
      return;
    }
    publish(l.value_.descriptor(), l.claim_);
    if (networked_) [[unlikely]] network_send(l.value_);
  }

  /// Publishes only if no subscriber would lose an unread message; else gives the message back
  /// (also when it is refused for its size).
  std::expected<void, T> try_send(const T& msg) {
    if (try_write(msg)) return {};
    ++send_failures_;
    return std::unexpected<T>(msg);
  }

  /// Publishes, waiting up to `timeout` for space (spin, then yield, then 100 us sleeps).
  /// Space means: no other subscriber would lose an unread message (a handle never waits for
  /// its own subscription). Errc::Timeout when the ring stayed full, Errc::LimitReached at once
  /// when every publisher lane of the topic is taken.
  Result<void> send_blocking(const T& msg, std::chrono::nanoseconds timeout) {
    using clock = std::chrono::steady_clock;
    if (!writer_.has_lane() && !become_publisher()) {
      ++send_failures_;
      return fail(Errc::LimitReached, "topic '" + core_->name + "': all " + std::to_string(shm::kMaxPublishers) +
                                          " publisher lanes are in use; message not sent");
    }
    if constexpr (kSerialized) {
      if (!encode(msg)) {  // once: the retries below send these bytes
        ++send_failures_;
        return std::unexpected(detail::too_large_error(*core_, encoded_size_));
      }
    } else if constexpr (kPooled) {
      if (!fits(msg)) {
        ++send_failures_;
        if (msg.buffer().size() > core_->pool.slot_bytes())
          return std::unexpected(detail::too_large_error(*core_, msg.buffer().size()));
        return fail(Errc::InvalidArgument, "topic '" + core_->name + "': the " + std::string(type_name()) +
                                               " message's metadata does not describe its bytes (" +
                                               msg.descriptor().log_summary() + "); message not sent");
      }
    }
    struct Blocking {  // a full pool is the returned error (counted once), not a log line per retry
      bool& flag;
      explicit Blocking(bool& f) : flag(f) { flag = true; }
      ~Blocking() { flag = false; }
    } blocking(blocking_);
    if (networked_ && core_->net_loopback) [[unlikely]] {
      // LCM: no flow control and nothing to wait for (the ring is filled by what comes back);
      // a send the backend refuses is that error, not a timeout.
      if (network_send(msg)) return {};
      return fail(Errc::Io, "topic '" + core_->name + "': the " + std::string(to_string(core_->backend)) +
                                " backend did not send the message (the log says why); message not sent");
    }
    if (try_commit(msg)) return {};
    const auto deadline = clock::now() + timeout;
    for (int i = 0; i < 256; ++i) {
      shm::cpu_relax();
      if (try_commit(msg)) return {};
    }
    for (int i = 0; i < 8; ++i) {
      std::this_thread::yield();
      if (try_commit(msg)) return {};
    }
    for (auto now = clock::now(); now < deadline; now = clock::now()) {
      std::this_thread::sleep_for(std::min<clock::duration>(std::chrono::microseconds(100), deadline - now));
      if (try_commit(msg)) return {};
      // A subscriber that died with unread messages must not hold us back: reap (every 50 ms).
      if (detail::reap_dead_participants(*core_) && try_commit(msg)) return {};
    }
    ++send_failures_;
    if constexpr (kPooled) {
      // The ring had room: what stayed full is the pool (subscribers keep every slot pinned).
      if (writer_.has_space(reader_.token())) {
        core_->pool.header().exhausted.fetch_add(1, std::memory_order_relaxed);
        ++pool_exhausted_;
        return std::unexpected(detail::pool_exhausted_error(*core_));
      }
    }
    return fail(Errc::Timeout, "topic '" + core_->name + "': ring stayed full for " +
                                   std::to_string(std::chrono::duration<double, std::milli>(timeout).count()) +
                                   " ms (a subscriber has " + std::to_string(core_->ring.capacity()) +
                                   " unread messages); message not sent");
  }

  // -- receiving -------------------------------------------------------------

  /// Takes the next unread message (FIFO per publisher), or nothing. A serialized message that
  /// does not decode (a corrupt slot) is skipped, counted in metrics().decode_failures() and logged.
  /// (has_message() and pending_count() count such a message until recv() skips it.)
  [[gnu::always_inline]] std::optional<T> recv() {
    if (!reader_.subscribed()) [[unlikely]] {
      if (!resubscribe()) {
        ++recv_failures_;
        return std::nullopt;
      }
    }
    if constexpr (kSerialized) {
      prepare_inbox();
      while (reader_.read(inbox_)) {
        if (auto m = decode_inbox()) return m;
        ++undelivered_;
      }
    } else if constexpr (kPooled) {
      descriptor_type d;
      while (reader_.read(d)) {
        if (auto m = adopt(d)) return m;
        ++undelivered_;
      }
    } else {
      Slot s;
      if (reader_.read(s.value)) return s.value;
    }
    ++recv_failures_;  // also marks this handle as a receiver (see receives())
    return std::nullopt;
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
    received_ = true;
    if constexpr (kSerialized) {
      prepare_inbox();
      if (!reader_.read_latest(inbox_)) return std::nullopt;
      return decode_inbox();
    } else if constexpr (kPooled) {
      descriptor_type d;
      if (!reader_.read_latest(d)) return std::nullopt;
      return adopt(d, /*count_loss=*/false);
    } else {
      Slot s;
      if (!reader_.read_latest(s.value)) return std::nullopt;
      return s.value;
    }
  }

  // -- state -----------------------------------------------------------------

  std::string_view name() const noexcept { return core_->name; }
  /// True if recv() would return a message.
  bool has_message() {
    received_ = true;
    return (reader_.subscribed() || resubscribe()) && reader_.has_message();
  }
  /// Unread messages waiting for this handle.
  std::uint64_t pending_count() {
    received_ = true;
    return (reader_.subscribed() || resubscribe()) ? reader_.pending() : 0;
  }
  /// Messages lost to overwrites: this handle's own losses when it subscribes; for a pure
  /// publisher, the losses of all subscribers of the topic.
  /// Large data: a message whose pool slot was reused before this handle read it (subscribers
  /// kept the spare slots pinned) counts as dropped too.
  std::uint64_t dropped_count() const noexcept {
    const std::uint64_t net = core_->net_lost.load(std::memory_order_relaxed) - net_lost_base_;
    if (reader_.subscribed()) return reader_.lost() + pool_lost_ + net;
    const auto& ring = core_->ring;
    std::uint64_t n = ring.header().dropped_total.load(std::memory_order_relaxed) + ring.undetected_losses();
    if constexpr (kPooled) n += core_->pool.header().reused.load(std::memory_order_relaxed);
    return n + net;
  }
  /// Publishers currently holding a lane of this topic; on a network backend, this process's
  /// publishing handles plus the remote writers matched with it.
  std::uint32_t pub_count() const noexcept {
    if (!core_->bridge) return core_->ring.publisher_count();
    // The bridge (which writes what arrives into the ring) holds a lane once a sample arrived.
    const std::uint32_t bridge = core_->bridge_publishing.load(std::memory_order_acquire) ? 1 : 0;
    return core_->ring.publisher_count() - bridge + detail::network_publishers(*core_);
  }
  /// Handles currently subscribed to this topic; on a network backend, plus the remote readers
  /// matched with this process.
  std::uint32_t sub_count() const noexcept {
    return core_->ring.subscriber_count() + (core_->net ? detail::network_subscribers(*core_) : 0);
  }
  TopicMetrics metrics() const noexcept {
    return TopicMetrics(writer_.sent(), reader_.delivered() - undelivered_, send_failures_, recv_failures_,
                        dropped_count(), core_->ring.total_sent(),
                        decode_failures_ + reader_.corrupt() +
                            core_->net_decode_failures.load(std::memory_order_relaxed));
  }
  /// Network backends: problems the backend reported for this topic in this process (a remote
  /// endpoint with another message type under the same DDS topic, an incompatible QoS); each
  /// is also logged. Samples that do not decode (not XCDR1, another LCM fingerprint) count in
  /// metrics().decode_failures(); messages the backend lost (LCM: datagrams the kernel
  /// dropped) count in dropped_count().
  std::uint64_t network_errors() const noexcept { return core_->net_errors.load(std::memory_order_relaxed); }
  /// Slots per publisher lane.
  std::uint32_t capacity() const noexcept { return core_->ring.capacity(); }
  /// Largest message the topic carries: sizeof(T), or for a serialized T the largest encoded size.
  std::size_t max_message_size() const noexcept {
    if constexpr (kPooled) return core_->pool.slot_bytes();
    return kSerialized ? shm::max_serialized_size(core_->payload_size) : sizeof(T);
  }
  /// Where this topic's messages travel (see Backend).
  Backend backend() const noexcept { return core_->backend; }
  /// The qualified message type name ("horus::msg::CmdVel").
  static constexpr std::string_view type_name() noexcept { return horus::type_name<T>(); }

 private:
  // Uninitialised storage the ring copies into (avoids zeroing T before overwriting it).
  union Slot {
    Slot() noexcept {}
    T value;
  };

  explicit Topic(std::shared_ptr<detail::TopicCore> core)
      : core_(std::move(core)),
        writer_(core_->ring, detail::next_token()),
        reader_(core_->ring, detail::next_token()) {}

  static Result<Topic> make(std::string_view name, const TopicOptions& options) {
    const detail::TypeInfo type{horus::type_name<T>(), horus::type_hash<T>, static_cast<std::uint32_t>(payload_bytes()),
                                kSerialized, kPooled ? default_slot_bytes<T> : 0};
    auto core = detail::open_core(name, type, options);
    if (!core) return std::unexpected(std::move(core.error()));
    Topic topic(std::move(*core));
    if (!topic.reader_.subscribe()) {
      return fail(Errc::LimitReached, "topic '" + std::string(name) + "' already has " +
                                          std::to_string(shm::kMaxSubscribers) +
                                          " subscribing handles; close some before opening more");
    }
    if (is_network(topic.core_->backend)) {
      if (auto ok = topic.connect_network(options); !ok) return std::unexpected(std::move(ok.error()));
      topic.networked_ = true;
      topic.net_lost_base_ = topic.core_->net_lost.load(std::memory_order_relaxed);
      if (topic.core_->net_loopback) detail::network_receiving(*topic.core_, true);
    }
    return topic;
  }

  // Network backends, first handle of the topic in this process: a bridge handle that writes
  // received samples into the ring, then the endpoint (so no sample arrives before the bridge).
  Result<void> connect_network(const TopicOptions& options) {
    auto& core = *core_;
    if constexpr (!lcm::expressible<T>) {
      if (core.backend == Backend::Lcm)
        return fail(Errc::Config, "topic '" + core.name + "': " + std::string(type_name()) +
                                      " cannot travel over LCM: it has a variable-size array of variable-size arrays "
                                      "or an array of size 0, which LCM types cannot express (horus/idlgen/"
                                      "lcm_mapping.hpp); use another backend for it");
    }
    std::lock_guard lock(core.net_mutex);
    if (core.net) {
      // The topic's endpoint exists: a handle asking for another QoS is an error, not ignored.
      const net::Qos have = detail::network_qos(core);
      if ((options.reliability && *options.reliability != have.reliability) ||
          (options.durability && *options.durability != have.durability))
        return fail(Errc::ConfigMismatch,
                    "topic '" + core.name + "' is open in this process as " + std::string(net::to_string(have.reliability)) +
                        ", " + std::string(net::to_string(have.durability)) +
                        "; cannot open it with another reliability or durability (open it with the same, or "
                        "without either to accept them)");
      return {};
    }
    if (!core.bridge) {
      // Non-owning: the core owns the bridge, and destroys it after the endpoint.
      std::shared_ptr<detail::TopicCore> self(std::shared_ptr<void>(), &core);
      core.bridge = std::unique_ptr<void, void (*)(void*)>(new Topic(std::move(self)),
                                                           [](void* p) { delete static_cast<Topic*>(p); });
      core.sink = &network_sink;
    }
    net::Qos qos{net::default_qos<T>::reliability, net::default_qos<T>::durability, core.ring.capacity()};
    if (options.reliability) qos.reliability = *options.reliability;
    if (options.durability) qos.durability = *options.durability;
    return detail::attach_network(core, qos);
  }

  // A sample from the network (one at a time per topic): decoded and written into the ring.
  static void network_sink(void* bridge, const net::Sample& sample) {
    auto& b = *static_cast<Topic*>(bridge);
    // LCM brings back everything this process sends: when every handle of the topic here only
    // publishes, nobody reads the ring, so nothing is decoded.
    if (b.core_->net_loopback && b.core_->ring.subscriber_count() == 0) return;
    if (!b.writer_.has_lane()) [[unlikely]] {
      if (!b.become_publisher()) {
        ++b.send_failures_;
        return;
      }
      b.core_->bridge_publishing.store(true, std::memory_order_release);
    }
    if constexpr (kPooled) {
      b.sink_pooled(sample);
      return;
    }
    auto m = b.decode_sample(sample, nullptr);
    if (!m) {
      detail::report_network_decode_failure(*b.core_, m.error());
      return;
    }
    b.send_local(*m);
  }

  // The backend's wire format: LCM for the lcm backend, XCDR1 for DDS.
  std::expected<T, std::string> decode_sample(const net::Sample& sample, const ByteSink* sink) const {
    if constexpr (lcm::expressible<T>) {
      if (core_->backend == Backend::Lcm) return lcm::decode<T>(sample.body, sink);
    }
    return cdr::decode<T>(sample.body, sample.little_endian, sink);
  }


  // A network topic: into the ring (this process's handles, and read_latest of handles opened
  // later, as on shared memory), then to the network. A handle inherited through fork() sends
  // nothing: DDS participants do not survive fork (open topics in the child).
  [[gnu::noinline]] void send_networked(const T& msg) {
    if (core_->pid != detail::current_pid()) [[unlikely]] {
      ++send_failures_;
      return;
    }
    if (core_->net_loopback) {  // it comes back through the network, once
      // A lane: this handle counts in pub_count(), and a pure publisher stops receiving.
      if (!writer_.has_lane() && !become_publisher()) [[unlikely]] {
        ++send_failures_;
        return;
      }
      if constexpr (kPooled) {
        if (!fits(msg)) [[unlikely]] {  // too large or inconsistent: refused here as on other backends
          ++send_failures_;
          return;
        }
      }
      network_send(msg);
      return;
    }
    if (send_local(msg)) network_send(msg);
  }

  // Large data from the network: the bytes are decoded straight into a pool slot of the
  // bridge's lane (one copy), then the descriptor is published as for a loan.
  void sink_pooled(const net::Sample& sample) {
    struct Place {
      Topic* self;
      std::optional<shm::Pool::Claim> claim;
    } place{this, std::nullopt};
    const ByteSink sink{&place, [](void* ctx, std::size_t n, ByteBuffer& out) {
                               auto& p = *static_cast<Place*>(ctx);
                               auto& core = *p.self->core_;
                               if (p.claim || n > core.pool.slot_bytes()) return false;
                               p.claim = p.self->claim_slot();
                               if (!p.claim) return false;
                               out = ByteBuffer::borrow(core.pool.data(p.claim->slot), n,
                                                        ByteBuffer::Lease{p.self->core_, &detail::release_loan,
                                                                          p.claim->slot, p.claim->gen},
                                                        /*writable=*/true);
                               return true;
                             }};
    auto m = decode_sample(sample, &sink);
    if (!m) {  // a slot taken is given back as the half-built message goes
      detail::report_network_decode_failure(*core_, m.error());
      return;
    }
    if (!place.claim || !m->is_consistent()) {
      if (!place.claim) send_local(*m);
      else detail::report_network_decode_failure(*core_, "its metadata does not describe its bytes");
      return;
    }
    publish(m->descriptor(), *place.claim);
  }

  // Encodes msg (XCDR1, or LCM) straight into the backend's buffer; false (counted, logged) on failure.
  bool network_send(const T& msg) {
    if constexpr (lcm::expressible<T>) {
      if (core_->backend == Backend::Lcm) return network_send_as<true>(msg);
    }
    return network_send_as<false>(msg);
  }

  template <bool kLcm>
  bool network_send_as(const T& msg) {
    std::size_t n = 0;
    try {
      if constexpr (kLcm) n = lcm::encoded_size(msg);
      else n = cdr::encoded_size(msg);
    } catch (const std::logic_error& e) {
      ++send_failures_;
      detail::report_network_send_failure(*core_, Error(Errc::MessageTooLarge, e.what()), ++net_send_failures_);
      return false;
    }
    const net::BodyWriter writer{[](void* ctx, std::span<std::byte> body) {
                                   // Cannot throw: body has encoded_size(msg) bytes. Called from
                                   // the backend's C code, so nothing may escape regardless.
                                   try {
                                     if constexpr (kLcm) lcm::encode(*static_cast<const T*>(ctx), body);
                                     else cdr::encode(*static_cast<const T*>(ctx), body);
                                   } catch (...) {
                                     std::memset(body.data(), 0, body.size());
                                   }
                                 },
                                 const_cast<void*>(static_cast<const void*>(&msg))};
    if (auto ok = detail::network_write(*core_, n, writer); !ok) [[unlikely]] {
      ++send_failures_;
      detail::report_network_send_failure(*core_, ok.error(), ++net_send_failures_);
      return false;
    }
    return true;
  }

  static constexpr std::size_t payload_bytes() noexcept {
    if constexpr (kPooled) return sizeof(descriptor_type);
    else if constexpr (kSerialized) return default_slot_bytes<T>;
    else return sizeof(T);
  }

  // Writes msg into the local ring (and pool); false when it was refused (counted).
  [[gnu::always_inline]] bool send_local(const T& msg) {
    if (!writer_.has_lane()) [[unlikely]] {
      if (!become_publisher()) {
        ++send_failures_;
        return false;
      }
    }
    if constexpr (kSerialized) {
      if (!encode(msg)) {
        ++send_failures_;
        return false;
      }
      writer_.write_bytes(encoded());
    } else if constexpr (kPooled) {
      if (!fits(msg) || !write_pooled(msg, claim_slot())) {
        ++send_failures_;
        return false;
      }
    } else {
      writer_.write(msg);
    }
    return true;
  }

  static Topic value_or_throw(Result<Topic> r) {
    if (!r) throw Exception(std::move(r.error()));
    return std::move(*r);
  }

  bool try_write(const T& msg) {
    if (!writer_.has_lane() && !become_publisher()) return false;
    if constexpr (kSerialized) {
      if (!encode(msg)) return false;  // a message too large is refused (and logged) before any wait
    } else if constexpr (kPooled) {
      if (!fits(msg)) return false;
    }
    return try_commit(msg);
  }

  // Writes msg if there is space, then sends it to the network (network backends).
  bool try_commit(const T& msg) {
    if (networked_ && core_->net_loopback) [[unlikely]] return network_send(msg);
    if (!try_commit_local(msg)) return false;
    if (networked_) [[unlikely]] network_send(msg);
    return true;
  }

  // Writes msg (for a serialized T: the bytes encode() left in scratch_) if there is space.
  bool try_commit_local(const T& msg) {
    if (!writer_.has_space(reader_.token())) return false;
    if constexpr (kSerialized) {
      writer_.write_bytes(encoded());
    } else if constexpr (kPooled) {
      // Only slots every subscriber has read: a pool slot must not take an unread message away.
      // The cached read limit may be old: look at the cursors again before giving up.
      auto c = core_->pool.claim(writer_.lane(), core_->claimer, writer_.read_by_all());
      if (!c) {
        writer_.refresh_space(reader_.token());
        c = claim_slot(writer_.read_by_all());
      }
      return write_pooled(msg, c);
    } else {
      writer_.write(msg);
    }
    return true;
  }

  // Large data: a message over the pool's slot size, or whose metadata does not describe its
  // bytes (receivers could not rebuild it), is refused and logged.
  bool fits(const T& msg) {
    const ByteBuffer& b = msg.buffer();
    if (b.size() > core_->pool.slot_bytes()) [[unlikely]] {
      encoded_size_ = b.size();
      ++too_large_;
      detail::report_too_large(*core_, b.size(), too_large_);
      return false;
    }
    // A borrowed view of the bytes (nothing copied), rebuilt as a receiver will.
    if (!T::adopt(msg.descriptor(), ByteBuffer::borrow(const_cast<std::uint8_t*>(b.data()), b.size(), {}, false)))
        [[unlikely]] {
      detail::report_inconsistent(*core_, ++inconsistent_);
      return false;
    }
    return true;
  }

  // Claims the oldest free slot of our lane (with a stamp of at most max_stamp).
  std::optional<shm::Pool::Claim> claim_slot(std::uint64_t max_stamp = ~std::uint64_t{0}) {
    const auto& pool = core_->pool;
    auto c = pool.claim(writer_.lane(), core_->claimer, max_stamp);
    // Every slot pinned: pins of processes that died are cleared (at most every 50 ms), then retry.
    if (!c && detail::reap_dead_participants(*core_)) c = pool.claim(writer_.lane(), core_->claimer, max_stamp);
    if (!c && !blocking_) count_exhausted();  // send_blocking counts once, at its end
    return c;
  }
  void count_exhausted() {
    core_->pool.header().exhausted.fetch_add(1, std::memory_order_relaxed);
    detail::report_pool_exhausted(*core_, ++pool_exhausted_);
  }

  // Copies msg's bytes into the claimed pool slot (none: false) and publishes its descriptor.
  bool write_pooled(const T& msg, const std::optional<shm::Pool::Claim>& c) {
    if (!c) return false;
    const auto bytes = msg.buffer().view();
    if (!bytes.empty()) std::memcpy(core_->pool.data(c->slot), bytes.data(), bytes.size());
    publish(msg.descriptor(), *c);
    return true;
  }

  void publish(descriptor_type d, const shm::Pool::Claim& c) {
    d.pool_id = 1;
    d.slot_id = c.slot;
    d.offset = core_->pool.offset_of(c.slot);
    d.generation = core_->pool.publish(c, writer_.head() + 1);
    writer_.write(d);
  }

  // A received descriptor: pins its slot and lends the bytes to a T (no copy). Nothing when the
  // slot was reused meanwhile (counted as a drop) or the descriptor is not valid (a decode failure).
  std::optional<T> adopt(const descriptor_type& d, bool count_loss = true) {
    const auto& pool = core_->pool;
    if (d.pool_id != 1 || d.slot_id >= pool.slot_count() || d.data_size > pool.slot_bytes()) [[unlikely]] {
      ++decode_failures_;
      detail::report_decode_failure(*core_, "its descriptor names no slot of the topic's pool", decode_failures_);
      return std::nullopt;
    }
    if (!pool.pin(d.slot_id, d.generation, core_->participant)) [[unlikely]] {
      if (count_loss) {  // read_latest polls the same message again: not a new loss each time
        ++pool_lost_;
        pool.header().reused.fetch_add(1, std::memory_order_relaxed);
      }
      return std::nullopt;
    }
    ByteBuffer bytes = ByteBuffer::borrow(pool.data(d.slot_id), d.data_size,
                                          ByteBuffer::Lease{core_, &detail::release_pin, d.slot_id, core_->participant},
                                          /*writable=*/false);
    auto m = T::adopt(d, std::move(bytes));
    if (!m) [[unlikely]] {
      ++decode_failures_;
      detail::report_decode_failure(*core_, "its descriptor is not valid", decode_failures_);
    }
    return m;
  }

  // Serialized messages: encode into scratch_ (false, logged, when too large; the caller counts it).
  bool encode(const T& msg) {
    const std::size_t n = codec::encoded_size(msg);
    encoded_size_ = n;
    if (n > writer_.max_bytes()) [[unlikely]] {
      ++too_large_;
      detail::report_too_large(*core_, n, too_large_);
      return false;
    }
    if (scratch_.size() < n) scratch_.resize(std::min<std::size_t>(std::max(n, scratch_.size() * 2), writer_.max_bytes()));
    encoded_size_ = codec::encode(msg, std::span<std::byte>(scratch_));
    return true;
  }
  std::span<const std::byte> encoded() const noexcept { return {scratch_.data(), encoded_size_}; }

  void prepare_inbox() { inbox_.reserve(shm::max_serialized_size(core_->payload_size)); }
  std::optional<T> decode_inbox() {
    auto m = codec::decode<T>(inbox_.view());
    if (m) return std::move(*m);
    ++decode_failures_;
    detail::report_decode_failure(*core_, m.error(), decode_failures_);
    return std::nullopt;
  }

  // True once this handle has used a receiving method (then its first send keeps it subscribed).
  bool receives() const noexcept { return received_ || recv_failures_ != 0 || reader_.delivered() != 0; }

  [[gnu::noinline]] bool become_publisher() {
    if (writer_.ensure_lane()) {
      if (!receives()) {
        reader_.unsubscribe();  // a pure publisher: stop counting as a subscriber
        // Nobody here reads the topic: a backend that brings our own traffic back can stop.
        if (networked_ && core_->net_loopback && core_->ring.subscriber_count() == 0)
          detail::network_receiving(*core_, false);
      }
      return true;
    }
    if (!no_lane_reported_) detail::report_no_lane(*core_);
    no_lane_reported_ = true;
    return false;
  }

  [[gnu::noinline]] bool resubscribe() {
    if (reader_.subscribe()) {
      if (networked_ && core_->net_loopback) detail::network_receiving(*core_, true);
      return true;
    }
    if (!no_sub_reported_) detail::report_no_subscriber_slot(*core_);
    no_sub_reported_ = true;
    return false;
  }

  using Payload = std::conditional_t<kPooled, descriptor_type, std::conditional_t<kSerialized, shm::ByteMessage, T>>;

  std::shared_ptr<detail::TopicCore> core_;  // first: outlives writer_ and reader_
  shm::RingWriter<Payload> writer_;
  shm::RingReader<Payload> reader_;
  std::uint64_t send_failures_ = 0;
  std::uint64_t recv_failures_ = 0;
  std::uint64_t too_large_ = 0;
  std::uint64_t decode_failures_ = 0;
  std::uint64_t undelivered_ = 0;  // read by recv() but not decoded (not counted as received)
  // Large data only.
  std::uint64_t pool_lost_ = 0;       // descriptors whose slot was reused before we pinned it
  std::uint64_t pool_exhausted_ = 0;  // sends that found every slot of our lane pinned
  std::uint64_t inconsistent_ = 0;    // sends refused: metadata that does not describe the bytes
  bool blocking_ = false;             // inside send_blocking's retries
  bool networked_ = false;                 // a user handle of a network topic (not the bridge)
  std::uint64_t net_send_failures_ = 0;    // samples the network backend refused
  std::uint64_t net_lost_base_ = 0;        // core's net_lost when this handle was opened
  // Serialized messages only: the encoding buffer and the last slot read.
  std::vector<std::byte> scratch_;
  std::size_t encoded_size_ = 0;
  shm::ByteMessage inbox_;
  bool received_ = false;  // has_message/pending_count/read_latest were called
  bool no_lane_reported_ = false;
  bool no_sub_reported_ = false;
};

}  // namespace horus

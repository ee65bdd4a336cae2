// Opening a topic (the in-process registry of topics, the memory its ring lives in), and the
// per-topic reports and leases of horus/detail/topic_core.hpp.
#include <fmt/format.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>
#include <map>
#include <mutex>

#include "horus/detail/topic_core.hpp"

#include "horus/detail/network_link.hpp"
#include "horus/detail/traffic_log.hpp"
#include "horus/log.hpp"
#include "horus/names.hpp"
#include "horus/settings.hpp"
#include "horus/transport_registry.hpp"

namespace horus {
namespace detail {

// Here: NetworkLink is complete. A verbose topic says how many lines it held back at the end.
TopicCore::~TopicCore() { report_held_traffic(*this); }

namespace {
// Large data: each publisher has 2 x capacity pool slots, at most kMaxPoolSlotsPerLane.
constexpr std::uint32_t kMaxPoolCapacity = shm::kMaxPoolSlotsPerLane / 2;

Errc segment_errc(shm::SegmentError::Kind k) {
  switch (k) {
    case shm::SegmentError::Kind::TypeMismatch: return Errc::TypeMismatch;
    case shm::SegmentError::Kind::ConfigMismatch: return Errc::ConfigMismatch;
    case shm::SegmentError::Kind::LimitReached: return Errc::LimitReached;
    case shm::SegmentError::Kind::InvalidName: return Errc::InvalidName;
    case shm::SegmentError::Kind::Permission:
    case shm::SegmentError::Kind::Io: return Errc::Io;
  }
  return Errc::Io;
}

struct OpenTopics {  // the topics open in this process, by name and namespace
  static constexpr PartSpec kPart{"open topics", PartLifetime::UntilExit,
                                  "weak pointers: a topic that closes later does not look itself up"};
  std::mutex mutex;
  std::map<std::string, std::weak_ptr<TopicCore>, std::less<>> topics;

  OpenTopics() {
    // A thread opening a topic while another forks would leave the mutex locked in the child
    // (which could then open no topic): fork waits for the open instead.
    Process::get().at_fork({[] { Process::part<OpenTopics>().mutex.lock(); },
                            [] { Process::part<OpenTopics>().mutex.unlock(); },
                            [] { Process::part<OpenTopics>().mutex.unlock(); }});
  }
};

OpenTopics& open_topics() { return Process::part<OpenTopics>(); }

std::string describe(std::string_view type_name, std::uint64_t hash, std::uint32_t size) {
  return fmt::format("{} (layout hash {:016x}, {} bytes)", type_name, hash, size);
}
}  // namespace

namespace {

// What the ring holds for a type and the handle's options (slot size, capacity), checked.
struct Geometry {
  std::uint32_t payload = 0;     // ring payload: sizeof(T), or a length word and the encoded bytes
  std::uint64_t pool_bytes = 0;  // large data: one pool slot
};

Result<Geometry> geometry_of(std::string_view name, const TypeInfo& type, const TopicOptions& options) {
  const auto& capacity = options.capacity;
  const auto& slot_size = options.slot_size;
  Geometry g{type.size, type.pool_bytes};
  if (type.pool_bytes != 0) {
    constexpr std::uint64_t kMaxPoolSlot = std::uint64_t{1} << 31;
    g.pool_bytes = slot_size.value_or(type.pool_bytes);
    if (g.pool_bytes == 0 || g.pool_bytes > kMaxPoolSlot)
      return fail(Errc::InvalidArgument,
                  fmt::format("topic '{}': slot_size {} for {} messages is out of range; expected 1 to {} bytes (the "
                              "largest message's data, one pool slot)",
                              name, g.pool_bytes, type.name, kMaxPoolSlot));
    if (capacity && *capacity > kMaxPoolCapacity)
      return fail(Errc::InvalidArgument,
                  fmt::format("topic '{}': capacity {} is too large for {} messages; expected at most {} (each "
                              "publisher has 2 x capacity pool slots, at most {})",
                              name, *capacity, type.name, kMaxPoolCapacity, shm::kMaxPoolSlotsPerLane));
  } else if (type.serialized) {
    constexpr std::size_t kMaxSerialized = (std::size_t{1} << 30) - 8;
    const std::size_t max_bytes = slot_size.value_or(type.size);
    if (max_bytes == 0 || max_bytes > kMaxSerialized)
      return fail(Errc::InvalidArgument,
                  fmt::format("topic '{}': slot_size {} for serialized {} messages is out of range; expected 1 to {} "
                              "bytes (the largest encoded message the topic accepts)",
                              name, max_bytes, type.name, kMaxSerialized));
    g.payload = static_cast<std::uint32_t>(8 + max_bytes);
  } else if (slot_size && *slot_size < type.size) {
    return fail(Errc::InvalidArgument,
                fmt::format("topic '{}': slot_size {} is smaller than a {} message ({} bytes); expected at least {}",
                            name, *slot_size, type.name, type.size, type.size));
  }
  if (capacity) {
    if (auto err = shm::Ring::check_config({*capacity, g.payload, type.hash}))
      return fail(Errc::InvalidArgument, fmt::format("topic '{}': {}", name, *err));
  }
  return g;
}

// Where a topic lives: its backend (a fleet topic's transport, loaded), and its key in the
// registry. Topics are told apart by name and namespace: the shared-memory namespace for host
// and fleet topics (so one process can use a name in two namespaces), "" for in-process ones.
struct Placement {
  Backend backend = Backend::SharedMemory;
  const net::TransportInfo* transport = nullptr;  // looked up here, once per open
  bool shared = true;  // host and fleet topics: a shared-memory segment
  std::string shm_ns;
  mode_t mode = 0600;  // a new segment's (HORUS_SHM_MODE)
  std::string key;
};

Result<Placement> place(std::string_view name, const TopicOptions& options, const Settings& settings) {
  const Environment& env = settings.env();
  Placement p;
  if (options.backend) {
    p.backend = *options.backend;
  } else {
    auto b = backend_from(env.backend);
    if (!b) return std::unexpected(std::move(b.error()));
    p.backend = *b;
  }
  if (is_network(p.backend)) {
    p.transport = net::find_transport(p.backend.transport());
    if (p.transport == nullptr)
      return fail(Errc::Config, fmt::format("topic '{}': this build of horus has no {} backend (its Debian package was "
                                            "missing when horus was built)",
                                            name, to_string(p.backend)));
    p.backend = Backend::network(p.transport->name);  // the registry owns the name
    // A transport that is a plug-in loads now; the error names its file and what went wrong.
    if (auto loaded = net::load_transport(p.transport->name); !loaded)
      return fail(Errc::Config, fmt::format("topic '{}': {}", name, loaded.error().message()));
  }
  p.shared = p.backend.scope() != Scope::Process;
  if (auto n = shm::shm_namespace(env.shm_namespace)) {
    p.shm_ns = std::move(*n);
  } else if (p.shared) {
    return fail(Errc::Config, n.error().message);
  }
  if (p.shared) {
    auto mode = shm::shm_mode(env.shm_mode);
    if (!mode) return fail(Errc::Config, mode.error().message);
    p.mode = *mode;
  }
  p.key = std::string(name) + '\0' + (p.shared ? p.shm_ns : std::string());
  return p;
}

Error backend_clash(std::string_view name, const Backend& open, const Backend& asked) {
  return Error(Errc::ConfigMismatch,
               fmt::format("topic '{}' is open in this process on backend '{}'; cannot open it on '{}' (one backend "
                           "per topic and process)",
                           name, to_string(open), to_string(asked)));
}

// The topic this process has open under p's key, checked against this open's type and options;
// nullptr when there is none. Called with the registry's lock held.
Result<std::shared_ptr<TopicCore>> find_open(OpenTopics& reg, std::string_view name, const TypeInfo& type,
                                             const TopicOptions& options, const Geometry& g, const Placement& p) {
  const auto& capacity = options.capacity;
  const auto& slot_size = options.slot_size;
  // The same name with the other kind of key, in this process: one backend per topic.
  const std::string other = std::string(name) + '\0' + (p.shared ? std::string() : p.shm_ns);
  if (auto it = reg.topics.find(other); other != p.key && it != reg.topics.end()) {
    auto core = it->second.lock();
    if (core && core->pid == ::getpid() && core->backend != p.backend)
      return std::unexpected(backend_clash(name, core->backend, p.backend));
  }
  auto it = reg.topics.find(p.key);
  if (it == reg.topics.end()) return nullptr;
  auto core = it->second.lock();
  if (core && core->pid != ::getpid()) core.reset();  // inherited through fork(): attach anew
  if (!core) {
    reg.topics.erase(it);
    return nullptr;
  }
  if (core->backend != p.backend) return std::unexpected(backend_clash(name, core->backend, p.backend));
  if (core->type_hash != type.hash || core->type_name != type.name || core->serialized != type.serialized ||
      (!type.serialized && core->payload_size != type.size))
    return fail(Errc::TypeMismatch, fmt::format("topic '{}' carries {}; cannot open it as {}", name,
                                                describe(core->type_name, core->type_hash, core->payload_size),
                                                describe(type.name, type.hash, type.size)));
  if (type.pool_bytes != 0 && slot_size && g.pool_bytes != core->pool.slot_bytes())
    return fail(Errc::ConfigMismatch,
                fmt::format("topic '{}' exists with slot_size {} (pool slot bytes); cannot open it with slot_size "
                            "{} (open it with the same slot size, or without one to accept it)",
                            name, core->pool.slot_bytes(), *slot_size));
  if (type.serialized && slot_size && g.payload != core->payload_size)
    return fail(Errc::ConfigMismatch,
                fmt::format("topic '{}' exists with slot_size {} (largest encoded message); cannot open it with "
                            "slot_size {} (open it with the same slot size, or without one to accept it)",
                            name, shm::max_serialized_size(core->payload_size), *slot_size));
  if (capacity && *capacity != core->ring.capacity())
    return fail(Errc::ConfigMismatch,
                fmt::format("topic '{}' exists with capacity {}; cannot open it with capacity {} (open it "
                            "with the same capacity, or with Topic::open to accept the existing one)",
                            name, core->ring.capacity(), *capacity));
  return core;
}

// A host or fleet topic's ring (and pool) in its shared-memory segment, made or joined.
Result<void> attach_segment(TopicCore& core, std::string_view name, const TypeInfo& type, const TopicOptions& options,
                            const shm::RingConfig& cfg, const shm::PoolConfig& pool_cfg, const Placement& p) {
  shm::SegmentSpec spec;
  spec.scope = p.backend.scope() == Scope::Fleet ? shm::SegmentScope::Fleet : shm::SegmentScope::Host;
  if (p.transport != nullptr) spec.transport = p.transport->name;
  spec.type_name = type.name;
  spec.type_hash = type.hash;
  const std::string signature = type.signature != nullptr ? type.signature() : std::string();
  spec.signature = signature;
  spec.payload_size = cfg.payload_size;
  spec.serialized = type.serialized;
  spec.capacity = cfg.capacity;
  spec.capacity_required = options.capacity.has_value();
  spec.payload_required = !type.serialized || options.slot_size.has_value();
  spec.mode = p.mode;
  if (pool_cfg.slot_bytes != 0) {
    spec.pool_slot_bytes = pool_cfg.slot_bytes;
    spec.pool_slots_per_lane = pool_cfg.slots_per_lane;
    spec.pool_required = options.slot_size.has_value();
  }
  auto seg = shm::ShmSegment::open(p.shm_ns, name, spec);
  if (!seg) return fail(segment_errc(seg.error().kind), seg.error().message);
  core.ring = seg->ring();
  core.payload_size = seg->ring().payload_size();  // a serialized topic may have another slot size
  core.pool = seg->pool();
  core.participant = seg->participant();
  core.segment.emplace(std::move(*seg));
  return {};
}

// A process topic's ring (and pool) in this process's memory.
Result<void> allocate_private(TopicCore& core, std::string_view name, const shm::RingConfig& cfg,
                              const shm::PoolConfig& pool_cfg) {
  const bool pooled = pool_cfg.slot_bytes != 0;
  if (pooled) {
    if (auto err = shm::Pool::check_config(pool_cfg))
      return fail(Errc::InvalidArgument, fmt::format("topic '{}': {}", name, *err));
  }
  const std::size_t ring_bytes = (shm::Ring::required_size(cfg) + shm::kPoolPage - 1) / shm::kPoolPage * shm::kPoolPage;
  const std::size_t bytes = ring_bytes + (pooled ? shm::Pool::required_size(pool_cfg) : 0);
  try {
    core.region = shm::HeapRegion(bytes);
  } catch (const std::bad_alloc&) {
    return fail(Errc::Io, fmt::format("topic '{}': cannot map {} bytes for its ring", name, bytes));
  }
  shm::RingConfig heap_cfg = cfg;
  heap_cfg.process_private = true;  // this process's memory: private futex wake-ups
  core.ring = shm::Ring::format(core.region.data(), heap_cfg);
  if (pooled) core.pool = shm::Pool::format(static_cast<std::byte*>(core.region.data()) + ring_bytes, pool_cfg);
  return {};
}

// A new core for the topic: its identity, and its ring and pool where its scope puts them.
Result<std::shared_ptr<TopicCore>> make_core(std::string_view name, const TypeInfo& type, const TopicOptions& options,
                                             const Geometry& g, const Placement& p) {
  // Serialized topics with big slots (images) default to 4 slots per lane: the ring is virtual
  // memory, touched only as far as messages are written, but 16 slots of 8 MiB is a lot.
  const std::uint32_t default_cap = (type.serialized && g.payload >= (1u << 20)) || g.pool_bytes >= (1u << 20)
                                        ? 4u
                                        : shm::default_capacity(g.payload);
  const shm::RingConfig cfg{
      options.capacity.value_or(std::min(default_cap, type.pool_bytes != 0 ? kMaxPoolCapacity : default_cap)),
      g.payload, type.hash};
  // Large data: twice as many pool slots per publisher as ring slots, so a slot is reused only
  // after the ring has overwritten every message naming it (unless subscribers pin the spares).
  const shm::PoolConfig pool_cfg{g.pool_bytes, std::min(2 * cfg.capacity, shm::kMaxPoolSlotsPerLane)};
  auto core = std::make_shared<TopicCore>();
  core->name = std::string(name);
  core->type_name = std::string(type.name);
  core->type_hash = type.hash;
  core->payload_size = g.payload;
  core->serialized = type.serialized;
  core->backend = p.backend;
  core->transport = p.transport;
  core->pid = ::getpid();
  if (g.pool_bytes != 0) core->claimer = {static_cast<std::uint32_t>(core->pid), shm::process_start_time(core->pid)};
  auto made = p.shared ? attach_segment(*core, name, type, options, cfg, pool_cfg, p)
                       : allocate_private(*core, name, cfg, pool_cfg);
  if (!made) return std::unexpected(std::move(made.error()));
  return core;
}

}  // namespace

// Validate, place, look up, create.
Result<std::shared_ptr<TopicCore>> open_core(std::string_view name, const TypeInfo& type,
                                             const TopicOptions& options, const Settings& settings) {
  if (auto ok = validate_topic_name(name); !ok) return std::unexpected(std::move(ok.error()));
  auto g = geometry_of(name, type, options);
  if (!g) return std::unexpected(std::move(g.error()));
  auto p = place(name, options, settings);
  if (!p) return std::unexpected(std::move(p.error()));
  auto& reg = open_topics();
  std::lock_guard lock(reg.mutex);
  auto open = find_open(reg, name, type, options, *g, *p);
  if (!open || *open) return open;
  auto core = make_core(name, type, options, *g, *p);
  if (!core) return core;
  // Drop entries of topics that were closed, so the map does not grow without bound.
  std::erase_if(reg.topics, [](const auto& kv) { return kv.second.expired(); });
  reg.topics.emplace(p->key, *core);
  return core;
}

std::uint64_t next_token() noexcept {
  // (pid << 32) | counter: unique across the processes sharing a segment, and the pid tells
  // whose lane or subscriber entry it is when the owner has died (shm_segment.hpp).
  static std::atomic<std::uint32_t> counter{0};
  const std::uint32_t n = counter.fetch_add(1, std::memory_order_relaxed) + 1;
  return (static_cast<std::uint64_t>(::getpid()) << 32) | n;
}

void report_no_lane(const TopicCore& core) {
  log().error("topic '{}': all {} publisher lanes are in use; this handle's messages are refused and counted "
              "in metrics().send_failures() (close other publishing handles)",
              core.name, shm::kMaxPublishers);
}

namespace {
// Largest message a topic carries: its pool slot (large data) or its serialized slot.
std::uint64_t message_limit(const TopicCore& core) {
  return core.pool ? core.pool.slot_bytes() : shm::max_serialized_size(core.payload_size);
}

std::string encoded_size_text(std::size_t size) {
  if (size == std::numeric_limits<std::size_t>::max()) return "more than the format allows (a sequence over 2^32 - 1 elements)";
  return fmt::format("{} bytes", size);
}
}  // namespace

void report_too_large(const TopicCore& core, std::size_t size, std::uint64_t count) {
  // Every refusal is counted in send_failures(); the log says the first and then every 1024th.
  if (count == 1 || count % 1024 == 0)
    log().error("topic '{}': a {} message encodes to {}, over the topic's slot size of {} bytes; refused "
                "({} so far). Open the topic with Topic::with_capacity(name, capacity, slot_size) and a larger "
                "slot_size.",
                core.name, core.type_name, encoded_size_text(size), message_limit(core), count);
}

void report_decode_failure(const TopicCore& core, const std::string& what, std::uint64_t count) {
  if (count == 1 || count % 1024 == 0)
    log().error("topic '{}': a received {} message does not decode ({}); skipped ({} so far)", core.name,
                core.type_name, what, count);
}

Error too_large_error(const TopicCore& core, std::size_t size) {
  return Error(Errc::MessageTooLarge,
               fmt::format("topic '{}': a {} message encodes to {}, over the topic's slot size of {} bytes; "
                           "expected at most {} (open the topic with a larger slot_size)",
                           core.name, core.type_name, encoded_size_text(size), message_limit(core),
                           message_limit(core)));
}

void report_pool_exhausted(const TopicCore& core, std::uint64_t count) {
  if (count == 1 || count % 1024 == 0)
    log().error("topic '{}': every pool slot of this publisher ({}) is pinned by received {} messages still alive "
                "or lent; the message is refused ({} so far). Drop received messages sooner, or open the topic "
                "with a larger capacity.",
                core.name, core.pool.slots_per_lane(), core.type_name, count);
}

void report_inconsistent(const TopicCore& core, std::uint64_t count) {
  if (count == 1 || count % 1024 == 0)
    log().error("topic '{}': a {} message whose metadata does not describe its bytes (sizes, step, shape or "
                "frame id) is refused ({} so far); receivers could not rebuild it",
                core.name, core.type_name, count);
}

Error pool_exhausted_error(const TopicCore& core) {
  return Error(Errc::LimitReached,
               fmt::format("topic '{}': every pool slot of this publisher ({}) is pinned by received {} messages "
                           "still alive or lent; expected a free slot (drop received messages sooner, send or drop "
                           "loans, or open the topic with a larger capacity)",
                           core.name, core.pool.slots_per_lane(), core.type_name));
}

bool reap_dead_participants(TopicCore& core) {
  if (!core.segment) return false;
  const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                               std::chrono::steady_clock::now().time_since_epoch())
                               .count();
  std::int64_t last = core.last_reap_ns.load(std::memory_order_relaxed);
  if (now - last < 50'000'000 || !core.last_reap_ns.compare_exchange_strong(last, now)) return false;
  return core.segment->reap_dead() != 0;
}

void release_pin(const void* core, std::uint64_t slot, std::uint64_t participant) noexcept {
  const auto* c = static_cast<const TopicCore*>(core);
  if (c->pid != current_pid()) return;  // a forked child's copy: the pin is its parent's
  c->pool.unpin(static_cast<std::uint32_t>(slot), static_cast<std::uint32_t>(participant));
}

void release_loan(const void* core, std::uint64_t slot, std::uint64_t gen) noexcept {
  const auto* c = static_cast<const TopicCore*>(core);
  if (c->pid != current_pid()) return;  // a forked child's copy: the loan is its parent's
  c->pool.abandon({static_cast<std::uint32_t>(slot), gen});
}


void report_no_subscriber_slot(const TopicCore& core) {
  log().error("topic '{}': all {} subscriber entries are in use; this handle receives nothing (close other "
              "handles)",
              core.name, shm::kMaxSubscribers);
}

Error no_lane_error(const TopicCore& core, std::string_view what) {
  return Error(Errc::LimitReached, fmt::format("topic '{}': all {} publisher lanes are in use; {}", core.name,
                                               shm::kMaxPublishers, what));
}

Error subscriber_limit_error(std::string_view topic) {
  return Error(Errc::LimitReached, fmt::format("topic '{}' already has {} subscribing handles; close some before "
                                               "opening more",
                                               topic, shm::kMaxSubscribers));
}

Error ring_full_error(const TopicCore& core, std::chrono::nanoseconds timeout) {
  return Error(Errc::Timeout, "topic '" + core.name + "': ring stayed full for " +
                                  std::to_string(std::chrono::duration<double, std::milli>(timeout).count()) +
                                  " ms (a subscriber has " + std::to_string(core.ring.capacity()) +
                                  " unread messages); message not sent");
}

}  // namespace detail
}  // namespace horus

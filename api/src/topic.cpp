#include <fmt/format.h>

#include <pthread.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <map>
#include <limits>
#include <mutex>

#include "horus/topic.hpp"
#include "log.hpp"
#if defined(HORUS_HAVE_CYCLONEDDS) || defined(HORUS_HAVE_FASTDDS)
#include "horus/dds/transports.hpp"
#endif
#ifdef HORUS_HAVE_LCM
#include "horus/lcm/transport.hpp"
#endif

namespace horus {

std::string_view to_string(Errc code) noexcept {
  switch (code) {
    case Errc::InvalidName: return "invalid_name";
    case Errc::TypeMismatch: return "type_mismatch";
    case Errc::InvalidArgument: return "invalid_argument";
    case Errc::ConfigMismatch: return "config_mismatch";
    case Errc::LimitReached: return "limit_reached";
    case Errc::Timeout: return "timeout";
    case Errc::MessageTooLarge: return "message_too_large";
    case Errc::Config: return "config";
    case Errc::Io: return "io";
  }
  return "unknown";
}

std::string_view to_string(Backend b) noexcept {
  switch (b) {
    case Backend::InProcess: return "inproc";
    case Backend::SharedMemory: return "shm";
    case Backend::CycloneDds: return "cyclonedds";
    case Backend::FastDds: return "fastdds";
    case Backend::Lcm: return "lcm";
  }
  return "unknown";
}

bool backend_available(Backend b) noexcept {
  switch (b) {
    case Backend::InProcess:
    case Backend::SharedMemory: return true;
#ifdef HORUS_HAVE_CYCLONEDDS
    case Backend::CycloneDds: return true;
#else
    case Backend::CycloneDds: return false;
#endif
#ifdef HORUS_HAVE_FASTDDS
    case Backend::FastDds: return true;
#else
    case Backend::FastDds: return false;
#endif
#ifdef HORUS_HAVE_LCM
    case Backend::Lcm: return true;
#else
    case Backend::Lcm: return false;
#endif
  }
  return false;
}

namespace net {
std::string_view to_string(Reliability r) noexcept {
  return r == Reliability::Reliable ? "reliable" : "best effort";
}
std::string_view to_string(Durability d) noexcept {
  return d == Durability::TransientLocal ? "transient local" : "volatile";
}
}  // namespace net

Result<std::string> dds_topic_name(std::string_view topic) {
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

Result<std::string> lcm_channel_name(std::string_view topic) {
  if (auto ok = validate_topic_name(topic); !ok) return std::unexpected(std::move(ok.error()));
  constexpr std::size_t kMaxChannel = 63;  // LCM_MAX_CHANNEL_NAME_LENGTH
  if (topic.size() > kMaxChannel)
    return fail(Errc::InvalidName,
                fmt::format("topic '{}': {} characters is too long for an LCM channel (the channel is the topic "
                            "name, and LCM channels are at most {} bytes); use a name of at most {} characters on "
                            "the lcm backend",
                            topic, topic.size(), kMaxChannel, kMaxChannel));
  return std::string(topic);
}

Result<net::Config> network_config_from_environment() {
  net::Config config;
  if (const char* env = std::getenv("HORUS_DOMAIN_ID"); env != nullptr && *env != '\0') {
    const std::string_view v(env);
    std::uint32_t id = 0;
    bool ok = v.size() <= 3;
    for (char c : v) {
      ok = ok && c >= '0' && c <= '9';
      if (ok) id = id * 10 + static_cast<std::uint32_t>(c - '0');
    }
    if (!ok || id > 232)
      return fail(Errc::Config, fmt::format("HORUS_DOMAIN_ID={}: expected a DDS domain id, an integer from 0 to 232 "
                                            "(the RTPS port mapping has no room above 232)",
                                            v));
    config.domain_id = id;
  }
  if (const char* env = std::getenv("HORUS_DDS_LOCALHOST"); env != nullptr && *env != '\0') {
    const std::string_view v(env);
    if (v == "1" || v == "true" || v == "yes" || v == "on") {
      config.localhost_only = true;
    } else if (v == "0" || v == "false" || v == "no" || v == "off") {
      config.localhost_only = false;
    } else {
      return fail(Errc::Config, fmt::format("HORUS_DDS_LOCALHOST={}: expected 1, true, yes, on (loopback only) or "
                                            "0, false, no, off (the LAN)",
                                            v));
    }
  }
  return config;
}

namespace {
bool is_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' ||
         c == '-';
}

std::string printable(char c) {
  if (c >= 0x20 && c < 0x7f) return fmt::format("'{}'", c);
  return fmt::format("byte 0x{:02x}", static_cast<unsigned char>(c));
}
}  // namespace

Result<void> validate_topic_name(std::string_view name) {
  constexpr std::string_view rule =
      "expected 1 to 128 characters from letters, digits, '_', '.', '-', in dot-separated segments "
      "(e.g. 'sensors.imu', 'robot_1.cmd_vel')";
  if (name.empty()) return fail(Errc::InvalidName, fmt::format("invalid topic name '': the name is empty; {}", rule));
  if (name.size() > kMaxTopicNameLength)
    return fail(Errc::InvalidName, fmt::format("invalid topic name '{}...': {} characters is too long; {}",
                                               name.substr(0, 32), name.size(), rule));
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (!is_name_char(c)) {
      const std::string hint = c == '/' ? " ('/' is not allowed: use '.' as the separator)" : "";
      return fail(Errc::InvalidName, fmt::format("invalid topic name '{}': {} at position {} is not allowed{}; {}",
                                                 name, printable(c), i, hint, rule));
    }
  }
  if (name.front() == '.' || name.back() == '.')
    return fail(Errc::InvalidName,
                fmt::format("invalid topic name '{}': it starts or ends with '.'; {}", name, rule));
  if (name.find("..") != std::string_view::npos)
    return fail(Errc::InvalidName, fmt::format("invalid topic name '{}': it has an empty segment ('..'); {}", name, rule));
  if (name.front() == '-')
    return fail(Errc::InvalidName, fmt::format("invalid topic name '{}': it starts with '-'; {}", name, rule));
  return {};
}

Result<Backend> backend_from_environment() {
  const char* env = std::getenv("HORUS_BACKEND");
  if (env == nullptr || *env == '\0') return Backend::SharedMemory;
  const std::string_view v(env);
  if (v == "auto" || v == "shm") return Backend::SharedMemory;
  if (v == "inproc") return Backend::InProcess;
  for (Backend b : {Backend::CycloneDds, Backend::FastDds, Backend::Lcm}) {
    if (v != to_string(b)) continue;
    if (!backend_available(b))
      return fail(Errc::Config, fmt::format("HORUS_BACKEND={}: this build of horus has no {} backend (its Debian "
                                            "package was missing when horus was built; scripts/install-deps.sh "
                                            "installs it)",
                                            v, v));
    return b;
  }
  return fail(Errc::Config, fmt::format("HORUS_BACKEND={}: unknown backend; expected auto, shm, inproc, cyclonedds, "
                                        "fastdds or lcm",
                                        v));
}

namespace detail {

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

struct Registry {
  std::mutex mutex;
  std::map<std::string, std::weak_ptr<TopicCore>, std::less<>> topics;
};

Registry& registry() {
  static Registry r;
  return r;
}

std::string describe(std::string_view type_name, std::uint64_t hash, std::uint32_t size) {
  return fmt::format("{} (layout hash {:016x}, {} bytes)", type_name, hash, size);
}
}  // namespace

Result<std::shared_ptr<TopicCore>> open_core(std::string_view name, const TypeInfo& type,
                                             const TopicOptions& options) {
  const auto& capacity = options.capacity;
  const auto& slot_size = options.slot_size;
  if (auto ok = validate_topic_name(name); !ok) return std::unexpected(std::move(ok.error()));
  // The ring payload: sizeof(T), or for a serialized type a length word and the encoded bytes.
  std::uint32_t payload = type.size;
  std::uint64_t pool_bytes = type.pool_bytes;
  if (type.pool_bytes != 0) {
    constexpr std::uint64_t kMaxPoolSlot = std::uint64_t{1} << 31;
    pool_bytes = slot_size.value_or(type.pool_bytes);
    if (pool_bytes == 0 || pool_bytes > kMaxPoolSlot)
      return fail(Errc::InvalidArgument,
                  fmt::format("topic '{}': slot_size {} for {} messages is out of range; expected 1 to {} bytes (the "
                              "largest message's data, one pool slot)",
                              name, pool_bytes, type.name, kMaxPoolSlot));
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
    payload = static_cast<std::uint32_t>(8 + max_bytes);
  } else if (slot_size && *slot_size < type.size) {
    return fail(Errc::InvalidArgument,
                fmt::format("topic '{}': slot_size {} is smaller than a {} message ({} bytes); expected at least {}",
                            name, *slot_size, type.name, type.size, type.size));
  }
  if (capacity) {
    if (auto err = shm::Ring::check_config({*capacity, payload, type.hash}))
      return fail(Errc::InvalidArgument, fmt::format("topic '{}': {}", name, *err));
  }

  Backend backend = Backend::SharedMemory;
  if (options.backend) {
    backend = *options.backend;
  } else {
    auto env = backend_from_environment();
    if (!env) return std::unexpected(std::move(env.error()));
    backend = *env;
  }
  if (!backend_available(backend))
    return fail(Errc::Config, fmt::format("topic '{}': this build of horus has no {} backend (its Debian package was "
                                          "missing when horus was built)",
                                          name, to_string(backend)));

  // Topics are told apart by name and namespace: the shared-memory namespace for shared-memory
  // topics (so one process can use a name in two namespaces), "" for the others (in-process
  // and network topics keep a ring in this process).
  std::string ns;
  if (backend == Backend::SharedMemory) {
    auto n = shm::shm_namespace();
    if (!n) return fail(Errc::Config, n.error().message);
    ns = std::move(*n);
  }
  const std::string key = std::string(name) + '\0' + ns;

  auto& reg = registry();
  std::lock_guard lock(reg.mutex);
  {
    // The same name on the other backend, in this process: one backend per topic.
    std::string other_ns;
    if (backend != Backend::SharedMemory) {
      if (auto n = shm::shm_namespace()) other_ns = *n;
    }
    const std::string other = std::string(name) + '\0' + other_ns;
    if (auto it = reg.topics.find(other); other != key && it != reg.topics.end()) {
      auto core = it->second.lock();
      if (core && core->pid == ::getpid() && core->backend != backend)
        return fail(Errc::ConfigMismatch,
                    fmt::format("topic '{}' is open in this process on backend '{}'; cannot open it on '{}' (one "
                                "backend per topic and process)",
                                name, to_string(core->backend), to_string(backend)));
    }
  }
  if (auto it = reg.topics.find(key); it != reg.topics.end()) {
    auto core = it->second.lock();
    if (core && core->pid != ::getpid()) core.reset();  // inherited through fork(): attach anew
    if (core && core->backend != backend)
      return fail(Errc::ConfigMismatch,
                  fmt::format("topic '{}' is open in this process on backend '{}'; cannot open it on '{}' (one "
                              "backend per topic and process)",
                              name, to_string(core->backend), to_string(backend)));
    if (core) {
      if (core->type_hash != type.hash || core->type_name != type.name || core->serialized != type.serialized ||
          (!type.serialized && core->payload_size != type.size))
        return fail(Errc::TypeMismatch,
                    fmt::format("topic '{}' carries {}; cannot open it as {}", name,
                                describe(core->type_name, core->type_hash, core->payload_size),
                                describe(type.name, type.hash, type.size)));
      if (type.pool_bytes != 0 && slot_size && pool_bytes != core->pool.slot_bytes())
        return fail(Errc::ConfigMismatch,
                    fmt::format("topic '{}' exists with slot_size {} (pool slot bytes); cannot open it with slot_size "
                                "{} (open it with the same slot size, or without one to accept it)",
                                name, core->pool.slot_bytes(), *slot_size));
      if (type.serialized && slot_size && payload != core->payload_size)
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
    reg.topics.erase(it);
  }

  // Serialized topics with big slots (images) default to 4 slots per lane: the ring is virtual
  // memory, touched only as far as messages are written, but 16 slots of 8 MiB is a lot.
  const std::uint32_t default_cap =
      (type.serialized && payload >= (1u << 20)) || pool_bytes >= (1u << 20) ? 4u : shm::default_capacity(payload);
  const shm::RingConfig cfg{capacity.value_or(std::min(default_cap, type.pool_bytes != 0 ? kMaxPoolCapacity : default_cap)),
                            payload, type.hash};
  // Large data: twice as many pool slots per publisher as ring slots, so a slot is reused only
  // after the ring has overwritten every message naming it (unless subscribers pin the spares).
  const shm::PoolConfig pool_cfg{pool_bytes, std::min(2 * cfg.capacity, shm::kMaxPoolSlotsPerLane)};
  auto core = std::make_shared<TopicCore>();
  core->name = std::string(name);
  core->type_name = std::string(type.name);
  core->type_hash = type.hash;
  core->payload_size = payload;
  core->serialized = type.serialized;
  core->backend = backend;
  core->pid = ::getpid();
  (void)current_pid();  // registers the fork handler before any lease exists
  if (pool_bytes != 0)
    core->claimer = {static_cast<std::uint32_t>(core->pid), shm::process_start_time(core->pid)};
  if (backend == Backend::SharedMemory) {
    shm::SegmentSpec spec;
    spec.type_name = type.name;
    spec.type_hash = type.hash;
    spec.payload_size = payload;
    spec.serialized = type.serialized;
    spec.capacity = cfg.capacity;
    spec.capacity_required = capacity.has_value();
    spec.payload_required = !type.serialized || slot_size.has_value();
    auto mode = shm::shm_mode_from_environment();
    if (!mode) return fail(Errc::Config, mode.error().message);
    spec.mode = *mode;
    if (pool_bytes != 0) {
      spec.pool_slot_bytes = pool_cfg.slot_bytes;
      spec.pool_slots_per_lane = pool_cfg.slots_per_lane;
      spec.pool_required = slot_size.has_value();
    }
    auto seg = shm::ShmSegment::open(ns, name, spec);
    if (!seg) return fail(segment_errc(seg.error().kind), seg.error().message);
    core->ring = seg->ring();
    core->payload_size = seg->ring().header().payload_size;  // a serialized topic may have another slot size
    core->pool = seg->pool();
    core->participant = seg->participant();
    core->segment.emplace(std::move(*seg));
  } else {
    if (pool_bytes != 0) {
      if (auto err = shm::Pool::check_config(pool_cfg))
        return fail(Errc::InvalidArgument, fmt::format("topic '{}': {}", name, *err));
    }
    const std::size_t ring_bytes = (shm::Ring::required_size(cfg) + shm::kPoolPage - 1) / shm::kPoolPage * shm::kPoolPage;
    const std::size_t bytes = ring_bytes + (pool_bytes != 0 ? shm::Pool::required_size(pool_cfg) : 0);
    try {
      core->region = shm::HeapRegion(bytes);
    } catch (const std::bad_alloc&) {
      return fail(Errc::Io, fmt::format("topic '{}': cannot map {} bytes for its ring", name, bytes));
    }
    core->ring = shm::Ring::format(core->region.data(), cfg);
    if (pool_bytes != 0) core->pool = shm::Pool::format(static_cast<std::byte*>(core->region.data()) + ring_bytes, pool_cfg);
  }
  // Drop entries of topics that were closed, so the map does not grow without bound.
  std::erase_if(reg.topics, [](const auto& kv) { return kv.second.expired(); });
  reg.topics.emplace(key, core);
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

namespace {
std::atomic<int> g_pid{0};
void refresh_pid() noexcept { g_pid.store(static_cast<int>(::getpid()), std::memory_order_relaxed); }
}  // namespace

int current_pid() noexcept {
  static const bool registered = [] {
    refresh_pid();
    ::pthread_atfork(nullptr, nullptr, &refresh_pid);
    return true;
  }();
  (void)registered;
  return g_pid.load(std::memory_order_relaxed);
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

// ---------------------------------------------------------------------------
// Network backends.

struct NetworkState final : net::Listener {
  TopicCore* core = nullptr;
  net::Qos qos;
  std::shared_ptr<net::Transport> transport;
  std::unique_ptr<net::Endpoint> endpoint;
  std::mutex mutex;  // one sample at a time into the bridge
  std::atomic<std::uint64_t> errors{0};

  void on_sample(const net::Sample& sample) override {
    std::lock_guard lock(mutex);
    if (core->sink != nullptr) core->sink(core->bridge.get(), sample);
  }
  void on_lost(std::uint64_t count) override {
    const auto before = core->net_lost.fetch_add(count, std::memory_order_relaxed);
    // Log the first loss, then at most once per 1024 more (the count is in dropped_count()).
    if (before == 0 || before / 1024 != (before + count) / 1024)
      log().warn("topic '{}': the {} backend lost {} message(s) or datagram(s) ({} so far; they count in "
                 "dropped_count()). On LCM the kernel dropped datagrams because the socket receive buffer was "
                 "full: large messages need a larger buffer (HORUS_LCM_URL=...?recv_buf_size=N and sysctl "
                 "net.core.rmem_max)",
                 core->name, transport->name(), count, before + count);
  }
  void on_error(std::string_view message) override {
    core->net_errors.fetch_add(1, std::memory_order_relaxed);
    const auto n = errors.fetch_add(1, std::memory_order_relaxed) + 1;
    if (n <= 16 || n % 1024 == 0) log().error("{} [{}]", message, transport->name());
  }
};

void NetworkStateDeleter::operator()(NetworkState* s) const noexcept {
  if (s == nullptr) return;
  if (s->core->pid != current_pid()) {
    // A forked child's copy: the participant's threads live in the parent only. Deleting the
    // endpoint here would hang or tell peers that the parent's endpoints are gone: leave it.
    return;
  }
  s->endpoint.reset();  // no callback after this
  delete s;
}

namespace {
Result<std::shared_ptr<net::Transport>> transport_for(Backend backend, const net::Config& config) {
  switch (backend) {
#ifdef HORUS_HAVE_CYCLONEDDS
    case Backend::CycloneDds: return dds::cyclone_transport(config);
#endif
#ifdef HORUS_HAVE_FASTDDS
    case Backend::FastDds: return dds::fastdds_transport(config);
#endif
#ifdef HORUS_HAVE_LCM
    case Backend::Lcm: {
      auto url = lcm::url_from_environment();
      if (!url) return std::unexpected(std::move(url.error()));
      return lcm::lcm_transport(*url);
    }
#endif
    default: break;
  }
  (void)config;
  return fail(Errc::Config, fmt::format("this build of horus has no {} backend", to_string(backend)));
}
}  // namespace

namespace {
std::atomic<int> g_network_pid{0};  // the process that created this process's DDS participants
}  // namespace

Result<void> attach_network(TopicCore& core, const net::Qos& qos) {
  if (core.net) return {};
  if (const int owner = g_network_pid.load(); owner != 0 && owner != current_pid())
    return fail(Errc::Io, fmt::format("topic '{}': this process was forked from pid {} after that process used {}; "
                                      "network transports (DDS participants, LCM instances) do not survive fork() (their threads "
                                      "stay in the parent). "
                                      "Open network topics before forking only in the process that keeps them, or "
                                      "exec the child",
                                      core.name, owner, to_string(core.backend)));
  net::Config config;
  if (core.backend != Backend::Lcm) {  // LCM reads HORUS_LCM_URL instead
    auto c = network_config_from_environment();
    if (!c) return std::unexpected(std::move(c.error()));
    config = *c;
  }
  auto transport = transport_for(core.backend, config);
  if (!transport) return std::unexpected(std::move(transport.error()));
  std::unique_ptr<NetworkState, NetworkStateDeleter> state(new NetworkState());
  state->core = &core;
  state->qos = qos;
  state->transport = std::move(*transport);
  auto wire = core.backend == Backend::Lcm ? lcm_channel_name(core.name) : dds_topic_name(core.name);
  if (!wire) return std::unexpected(std::move(wire.error()));
  net::EndpointSpec spec;
  spec.topic = core.name;
  spec.wire_topic = std::move(*wire);
  spec.type_name = core.type_name;
  spec.type_hash = core.type_hash;
  spec.qos = qos;
  auto endpoint = state->transport->open(spec, *state);
  if (!endpoint) return std::unexpected(std::move(endpoint.error()));
  state->endpoint = std::move(*endpoint);
  core.net_loopback = state->transport->delivers_own_samples();
  core.net = std::move(state);
  g_network_pid.store(current_pid());
  return {};
}

net::Qos network_qos(const TopicCore& core) noexcept { return core.net ? core.net->qos : net::Qos{}; }

Result<void> network_write(TopicCore& core, std::size_t body_size, const net::BodyWriter& writer) {
  return core.net->endpoint->write(body_size, writer);
}

std::uint32_t network_publishers(const TopicCore& core) noexcept {
  return core.net ? core.net->endpoint->matched_publishers() : 0;
}

std::uint32_t network_subscribers(const TopicCore& core) noexcept {
  return core.net ? core.net->endpoint->matched_subscribers() : 0;
}

void network_receiving(TopicCore& core, bool on) noexcept {
  if (!core.net || core.net_receiving.load(std::memory_order_acquire) == on) return;
  // A mutex of its own: the endpoint may wait for the backend's receive thread, which never
  // takes this one (only user threads call here).
  static std::mutex receiving_mutex;
  std::lock_guard lock(receiving_mutex);
  if (core.net_receiving.load(std::memory_order_acquire) == on) return;
  core.net_receiving.store(on, std::memory_order_release);
  core.net->endpoint->set_receiving(on);
}

void report_network_decode_failure(TopicCore& core, const std::string& what) {
  const auto n = core.net_decode_failures.fetch_add(1, std::memory_order_relaxed) + 1;
  if (n == 1 || n % 1024 == 0)
    log().error("topic '{}': a {} sample from the network does not decode as {} ({}); dropped ({} so far)",
                core.name, core.type_name, core.backend == Backend::Lcm ? "an LCM message" : "XCDR1", what, n);
}

void report_network_send_failure(const TopicCore& core, const Error& error, std::uint64_t count) {
  if (count == 1 || count % 1024 == 0)
    log().error("topic '{}': the {} backend did not send a {} sample: {} ({} so far)", core.name,
                to_string(core.backend), core.type_name, error.message(), count);
}

void report_no_subscriber_slot(const TopicCore& core) {
  log().error("topic '{}': all {} subscriber entries are in use; this handle receives nothing (close other "
              "handles)",
              core.name, shm::kMaxSubscribers);
}

}  // namespace detail
}  // namespace horus

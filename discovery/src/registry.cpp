#include "horus/discovery/registry.hpp"

#include <algorithm>
#include <cstring>
#include <optional>
#include <map>
#include <thread>

#include "horus/shm/shm_segment.hpp"

namespace horus::discovery {

namespace {

// Fills what one look at a segment can tell (everything but the rate).
std::optional<TopicEntry> read_entry(const shm::SegmentInfo& info) {
  TopicEntry e;
  e.topic = info.topic;
  e.segment = info.name;
  e.segment_bytes = info.size;
  auto view = shm::SegmentView::open("/" + info.name);
  if (!view) return std::nullopt;
  const auto& h = view->header();
  e.type_name = std::string(h.type_name, strnlen(h.type_name, shm::kMaxTypeName));
  e.type_hash = h.type_hash;
  e.serialized = h.serialized != 0;
  e.message_size = e.serialized ? shm::max_serialized_size(h.payload_size) : h.payload_size;
  e.capacity = h.capacity;
  e.created_unix_ns = h.created_unix_ns;
  e.signature = std::string(view->signature());
  if (const shm::Pool pool = view->pool()) {
    e.pooled = true;
    e.pool_slot_bytes = pool.slot_bytes();
    e.pool_slots_per_publisher = pool.slots_per_lane();
    e.pool_pinned = pool.pinned_slots();
    e.pool_reused = pool.header().reused.load(std::memory_order_relaxed);
    e.pool_exhausted = pool.header().exhausted.load(std::memory_order_relaxed);
    e.dropped += e.pool_reused;
  }
  const shm::Ring ring = view->ring();
  e.messages_sent = ring.total_sent();
  e.dropped = ring.header().dropped_total.load(std::memory_order_relaxed) + ring.undetected_losses();
  e.publishers = ring.publisher_count();
  e.subscribers = ring.subscriber_count();
  const auto& b = h.bridge;
  const std::uint64_t import_token = b.import_token.load(std::memory_order_acquire);
  const std::uint64_t export_token = b.export_token.load(std::memory_order_acquire);
  if (h.scope == static_cast<std::uint32_t>(shm::SegmentScope::Fleet)) {
    e.scope = "fleet";
    e.transport = std::string(h.transport, strnlen(h.transport, shm::kMaxTransportName));
    e.bridge_claims = b.claims.load(std::memory_order_relaxed);
    e.exported = b.exported.load(std::memory_order_relaxed);
    e.imported = b.imported.load(std::memory_order_relaxed);
    e.bridge_dropped = b.dropped.load(std::memory_order_relaxed);
    e.malformed = b.malformed.load(std::memory_order_relaxed);
    e.remote_publishers = b.matched_publishers.load(std::memory_order_relaxed);
    e.remote_subscribers = b.matched_subscribers.load(std::memory_order_relaxed);
    const std::uint64_t owner = b.owner.load(std::memory_order_acquire);
    const auto holder = static_cast<pid_t>(owner >> 32);
    const auto slot = static_cast<std::uint32_t>(owner & 0xffff'ffffu) - 1u;
    if (owner != 0 && slot < shm::kMaxParticipants &&
        static_cast<pid_t>(h.participants[slot].pid.load(std::memory_order_acquire)) == holder &&
        shm::process_alive(holder, h.participants[slot].start_time.load(std::memory_order_relaxed)))
      e.bridge_pid = holder;
  }

  std::map<pid_t, Process> procs;
  for (const auto& p : h.participants) {
    const auto pid = static_cast<pid_t>(p.pid.load(std::memory_order_acquire));
    if (pid == 0) continue;
    auto& proc = procs[pid];
    proc.pid = pid;
    proc.alive = shm::process_alive(pid, p.start_time.load(std::memory_order_relaxed));
    proc.bridge = pid == e.bridge_pid;
  }
  for (std::uint32_t l = 0; l < shm::kMaxPublishers; ++l) {
    const std::uint64_t owner = ring.lane(l).owner.load(std::memory_order_acquire);
    if (owner == 0) continue;
    if (owner == import_token) {  // the bridge's import lane: not a user's handle
      --e.publishers;
      continue;
    }
    auto it = procs.find(shm::token_pid(owner));
    if (it != procs.end()) ++it->second.publishers;
  }
  for (std::uint32_t i = 0; i < shm::kMaxSubscribers; ++i) {
    const auto& s = ring.subscriber(i);
    if (s.state.load(std::memory_order_acquire) != shm::SubscriberEntry::kActive) continue;
    const std::uint64_t owner = s.owner.load(std::memory_order_acquire);
    if (owner == export_token) {  // the bridge's export entry
      --e.subscribers;
      continue;
    }
    auto it = procs.find(shm::token_pid(owner));
    if (it != procs.end()) ++it->second.subscribers;
  }
  e.stale = true;
  for (auto& [pid, proc] : procs) {
    if (proc.alive) e.stale = false;
    e.processes.push_back(proc);
  }
  return e;
}

std::uint64_t sent_now(const std::string& segment) {
  auto view = shm::SegmentView::open("/" + segment);
  return view ? view->ring().total_sent() : 0;
}

// Sets rate_hz of every entry from its sent count sampled `window` apart.
void sample_rates(std::vector<TopicEntry>& entries, std::chrono::milliseconds window) {
  if (window.count() <= 0 || entries.empty()) return;
  std::vector<std::uint64_t> before;
  for (const auto& e : entries) before.push_back(sent_now(e.segment));
  const auto t0 = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(window);  // the measurement window itself, not a wait for a condition
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::uint64_t after = sent_now(entries[i].segment);
    entries[i].rate_hz = after >= before[i] ? static_cast<double>(after - before[i]) / secs : 0.0;
  }
}

}  // namespace

std::vector<TopicEntry> list_topics(std::string_view ns, std::chrono::milliseconds window) {
  std::vector<TopicEntry> out;
  for (const auto& info : shm::list_segments(ns))
    if (auto e = read_entry(info)) out.push_back(std::move(*e));
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.topic < b.topic; });
  sample_rates(out, window);
  return out;
}

std::expected<TopicEntry, std::string> find_topic(std::string_view ns, std::string_view topic,
                                                  std::chrono::milliseconds window) {
  auto all = list_topics(ns, std::chrono::milliseconds(0));
  for (auto& e : all) {
    if (e.topic != topic) continue;
    std::vector<TopicEntry> one{std::move(e)};
    sample_rates(one, window);
    return std::move(one.front());
  }
  std::string known;
  for (const auto& e : all) known += (known.empty() ? "" : ", ") + e.topic;
  return std::unexpected("no topic '" + std::string(topic) + "' in namespace '" + std::string(ns) + "'" +
                         (known.empty() ? " (no topics at all)" : " (topics: " + known + ")"));
}

std::vector<std::string> clean(std::string_view ns) {
  std::vector<std::string> topics;
  const std::string prefix = "horus." + std::string(ns) + ".";
  for (auto& name : shm::clean_stale_segments(ns)) topics.push_back(name.substr(prefix.size()));
  return topics;
}

}  // namespace horus::discovery

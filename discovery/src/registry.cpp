// The local registry (registry.hpp): what the segments of a namespace say, read-only.
#include "horus/discovery/registry.hpp"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstring>
#include <optional>
#include <map>
#include <thread>

#include "horus/shm/shm_segment.hpp"

namespace horus::discovery {

namespace {

// Whether a process lives, asked of the kernel once per (pid, start time) and scan.
class Liveness {
 public:
  bool alive(pid_t pid, std::uint64_t start) {
    auto [it, fresh] = known_.try_emplace({pid, start}, false);
    if (fresh) it->second = shm::process_alive(pid, start);
    return it->second;
  }

 private:
  std::map<std::pair<pid_t, std::uint64_t>, bool> known_;
};

// A fleet topic's bridge: its counts and the process that holds it (when it lives).
void read_bridge(const shm::SegmentHeader& h, Liveness& live, TopicEntry& e) {
  const auto& b = h.bridge;
  e.scope = "fleet";
  e.transport = std::string(h.transport, strnlen(h.transport, shm::kMaxTransportName));
  e.bridge_claims = b.claims.load(std::memory_order_relaxed);
  e.exported = b.exported.load(std::memory_order_relaxed);
  e.imported = b.imported.load(std::memory_order_relaxed);
  e.bridge_dropped = b.dropped.load(std::memory_order_relaxed);
  e.budget_dropped = b.budget_dropped.load(std::memory_order_relaxed);
  e.malformed = b.malformed.load(std::memory_order_relaxed);
  e.remote_publishers = b.matched_publishers.load(std::memory_order_relaxed);
  e.remote_subscribers = b.matched_subscribers.load(std::memory_order_relaxed);
  const std::uint64_t owner = b.owner.load(std::memory_order_acquire);
  const auto holder = static_cast<pid_t>(owner >> 32);
  const auto slot = static_cast<std::uint32_t>(owner & 0xffff'ffffu) - 1u;
  if (owner != 0 && slot < shm::kMaxParticipants &&
      static_cast<pid_t>(h.participants[slot].pid.load(std::memory_order_acquire)) == holder &&
      live.alive(holder, h.participants[slot].start_time.load(std::memory_order_relaxed)))
    e.bridge_pid = holder;
}

// The processes of a segment, with their publishers and subscribers (the bridge's import lane
// and export entry, `import_token` and `export_token`, not counted as users' handles).
std::map<pid_t, Process> read_processes(const shm::SegmentHeader& h, const shm::Ring& ring, std::uint64_t import_token,
                                        std::uint64_t export_token, Liveness& live, TopicEntry& e) {
  // Only the entries that may be in use (high-water marks): a scan of a thousand segments
  // touches a few cache lines of each, not every entry of every table.
  std::map<pid_t, Process> procs;
  const std::uint32_t participants = std::min(h.participant_hwm.load(std::memory_order_acquire), shm::kMaxParticipants);
  for (std::uint32_t i = 0; i < participants; ++i) {
    const auto& p = h.participants[i];
    const auto pid = static_cast<pid_t>(p.pid.load(std::memory_order_acquire));
    if (pid == 0) continue;
    auto& proc = procs[pid];
    proc.pid = pid;
    proc.alive = live.alive(pid, p.start_time.load(std::memory_order_relaxed));
    proc.bridge = pid == e.bridge_pid;
  }
  const std::uint32_t lanes = std::min(ring.header().lane_hwm.load(std::memory_order_acquire), shm::kMaxPublishers);
  for (std::uint32_t l = 0; l < lanes; ++l) {
    const std::uint64_t owner = ring.lane(l).owner.load(std::memory_order_acquire);
    if (owner == 0) continue;
    if (owner == import_token) {  // the bridge's import lane: not a user's handle
      --e.publishers;
      continue;
    }
    auto it = procs.find(shm::token_pid(owner));
    if (it != procs.end()) ++it->second.publishers;
  }
  const std::uint32_t subs = std::min(ring.header().sub_hwm.load(std::memory_order_acquire), shm::kMaxSubscribers);
  for (std::uint32_t i = 0; i < subs; ++i) {
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
  return procs;
}

// Fills what one look at a segment can tell (everything but the rate).
std::optional<TopicEntry> read_entry(const std::string& file, const std::string& topic,
                                     const shm::SegmentView* view, Liveness& live) {
  TopicEntry e;
  e.topic = topic;
  e.segment = file;
  if (view == nullptr) return std::nullopt;
  e.segment_bytes = view->size();
  const auto& h = view->header();
  if (h.magic != shm::kSegmentMagic || h.layout_version != shm::kSegmentVersion ||
      h.ready.load(std::memory_order_acquire) != 1)
    return std::nullopt;
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
  const std::uint64_t import_token = h.bridge.import_token.load(std::memory_order_acquire);
  const std::uint64_t export_token = h.bridge.export_token.load(std::memory_order_acquire);
  if (h.scope == static_cast<std::uint32_t>(shm::SegmentScope::Fleet)) read_bridge(h, live, e);
  const std::map<pid_t, Process> procs = read_processes(h, ring, import_token, export_token, live, e);
  e.stale = true;
  for (auto& [pid, proc] : procs) {
    if (proc.alive) e.stale = false;
    e.processes.push_back(proc);
  }
  return e;
}

// Sets rate_hz of every entry from its sent count, looked at every 5 ms for `window`: from the
// first to the last time the count moved (a 2 Hz topic seen over 1 s moves twice or three times:
// (count moved) / (time between the moves) says 2.0, where a count over a 200 ms window said 5 or 0).
// A topic that moved once in the window gets that one message over the window.
void sample_rates(std::vector<TopicEntry>& entries, std::chrono::milliseconds window) {
  if (window.count() <= 0 || entries.empty()) return;
  using Clock = std::chrono::steady_clock;
  struct Watch {
    std::optional<shm::SegmentView> view;
    std::uint64_t start = 0, first = 0, last = 0;  // counts: at the start, at the first and last move
    Clock::time_point first_at{}, last_at{};
    int moves = 0;
  };
  std::vector<Watch> w(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i)
    if (auto v = shm::SegmentView::open("/" + entries[i].segment)) {
      w[i].start = w[i].last = v->ring().total_sent();
      w[i].view.emplace(std::move(*v));
    }
  const auto t0 = Clock::now();
  for (auto now = t0; now - t0 < window; now = Clock::now()) {
    // The measurement itself (a look every 5 ms), not a wait for a condition.
    std::this_thread::sleep_for(std::min<Clock::duration>(std::chrono::milliseconds(5), window - (now - t0)));
    const auto at = Clock::now();
    for (auto& x : w) {
      if (!x.view) continue;
      const std::uint64_t n = x.view->ring().total_sent();
      if (n == x.last) continue;
      if (x.moves++ == 0) {
        x.first = n;
        x.first_at = at;
      }
      x.last = n;
      x.last_at = at;
    }
  }
  const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const Watch& x = w[i];
    if (!x.view || x.last < x.start) {
      entries[i].rate_hz = 0.0;
    } else if (x.moves >= 2 && x.last_at > x.first_at) {
      entries[i].rate_hz = static_cast<double>(x.last - x.first) / std::chrono::duration<double>(x.last_at - x.first_at).count();
    } else {
      entries[i].rate_hz = static_cast<double>(x.last - x.start) / secs;
    }
  }
}

}  // namespace

struct Scanner::Cache {
  struct Mapped {
    ino_t ino = 0;
    std::optional<shm::SegmentView> view;  // nothing: it did not open (not a segment, gone)
  };
  std::map<std::string, Mapped> files;  // file name in /dev/shm -> its mapping
  struct timespec dir_mtime{};
};

Scanner::Scanner(std::string ns) : ns_(std::move(ns)), cache_(std::make_unique<Cache>()) {}
Scanner::~Scanner() = default;

bool Scanner::topics_changed() {
  struct stat st{};
  if (::stat("/dev/shm", &st) != 0) return true;
  const bool changed = st.st_mtim.tv_sec != cache_->dir_mtime.tv_sec || st.st_mtim.tv_nsec != cache_->dir_mtime.tv_nsec;
  cache_->dir_mtime = st.st_mtim;
  return changed;
}

std::vector<TopicEntry> Scanner::scan() {
  const std::string prefix = "horus." + ns_ + ".";
  std::map<std::string, Cache::Mapped> seen;
  if (DIR* dir = ::opendir("/dev/shm")) {
    while (dirent* ent = ::readdir(dir)) {
      const std::string_view file(ent->d_name);
      if (!file.starts_with(prefix)) continue;
      auto it = cache_->files.find(std::string(file));
      if (it != cache_->files.end() && it->second.ino == ent->d_ino && it->second.view) {
        seen.emplace(it->first, std::move(it->second));
        continue;
      }
      Cache::Mapped m;
      m.ino = ent->d_ino;
      if (auto v = shm::SegmentView::open("/" + std::string(file))) m.view.emplace(std::move(*v));
      seen.emplace(std::string(file), std::move(m));
    }
    ::closedir(dir);
  }
  cache_->files = std::move(seen);  // what went is unmapped
  Liveness live;
  std::vector<TopicEntry> out;
  for (const auto& [file, m] : cache_->files)
    if (auto e = read_entry(file, file.substr(prefix.size()), m.view ? &*m.view : nullptr, live))
      out.push_back(std::move(*e));
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.topic < b.topic; });
  return out;
}

std::vector<TopicEntry> list_topics(std::string_view ns, std::chrono::milliseconds window) {
  Scanner scanner{std::string(ns)};
  auto out = scanner.scan();
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

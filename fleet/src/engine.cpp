// The network engine of a process and transport (engine.hpp): its two threads and its tables.
#include "engine.hpp"

#include "horus/detail/process.hpp"

#include <pthread.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <map>
#include <queue>
#include <unordered_set>

#include "horus/config.hpp"
#include "fleet_internal.hpp"
#include "horus/detail/topic_core.hpp"
#include "horus/log.hpp"

namespace horus::fleet::detail {

using horus::detail::log;

namespace {
constexpr auto kPumpPeriod = std::chrono::microseconds(200);  // held samples, while a transport holds some
constexpr auto kRecheck = std::chrono::milliseconds(10);      // a topic attached: look once more (doorbell.hpp's race)
constexpr auto kReleaseLook = std::chrono::milliseconds(50);  // the board's count of claims given up
constexpr auto kPollHolder = std::chrono::milliseconds(50);   // a holder without a pidfd: is it alive?

int open_pidfd(pid_t pid) noexcept {
#ifdef SYS_pidfd_open
  return static_cast<int>(::syscall(SYS_pidfd_open, pid, 0));
#else
  (void)pid;
  return -1;
#endif
}

void name_thread(std::thread& t, const char* role, std::string_view transport) {
  char name[16];
  std::snprintf(name, sizeof(name), "horus-%s-%.*s", role, static_cast<int>(std::min<std::size_t>(transport.size(), 5)),
                transport.data());
  ::pthread_setname_np(t.native_handle(), name);
}

struct Registry {
  static constexpr horus::detail::PartSpec kPart{"network engines", horus::detail::PartLifetime::Process,
                                                 "a bridge may close during static destruction"};
  std::mutex mutex;
  std::map<std::string, std::weak_ptr<Engine>, std::less<>> engines;
};
Registry& registry() { return horus::detail::Process::part<Registry>(); }
}  // namespace

Result<std::shared_ptr<Engine>> Engine::of(const net::TransportInfo& info, const Settings& settings) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  if (auto it = r.engines.find(info.name); it != r.engines.end())
    if (auto e = it->second.lock()) return e;
  auto config = network_config(settings);
  if (!config) return std::unexpected(std::move(config.error()));
  auto transport = info.open(*config);
  if (!transport) return std::unexpected(std::move(transport.error()));
  auto ns = shm::shm_namespace(settings.env().shm_namespace);
  if (!ns) return fail(Errc::Config, ns.error().message);
  auto mode = shm::shm_mode(settings.env().shm_mode);
  if (!mode) return fail(Errc::Config, mode.error().message);
  auto bell = shm::EngineBell::claim(*ns, *mode);
  if (!bell)
    return fail(bell.error().kind == shm::SegmentError::Kind::LimitReached ? Errc::LimitReached : Errc::Io,
                "the " + std::string(info.name) + " network engine of this process: " + bell.error().message);
  std::shared_ptr<Engine> e(new Engine(info, *config, std::move(*transport), std::move(*bell)));
  r.engines[std::string(info.name)] = e;
  return e;
}

Engine::Engine(const net::TransportInfo& info, net::Config config, std::shared_ptr<net::Transport> transport,
               shm::EngineBell bell)
    : info_(info),
      config_(std::move(config)),
      transport_(std::move(transport)),
      bell_(std::move(bell)),
      creator_pid_(horus::detail::current_pid()),
      epoll_fd_(::epoll_create1(EPOLL_CLOEXEC)),
      event_fd_(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)) {
  if (epoll_fd_ >= 0 && event_fd_ >= 0) {
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.fd = event_fd_;
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, event_fd_, &ev);
  }
  export_thread_ = std::thread([this] { run_export(); });
  control_thread_ = std::thread([this] { run_control(); });
  name_thread(export_thread_, "net", info_.name);
  name_thread(control_thread_, "ctl", info_.name);
}

Engine::~Engine() {
  if (horus::detail::current_pid() != creator_pid_) {
    // A forked child's copy: the threads live in the parent only.
    export_thread_.detach();
    control_thread_.detach();
    new std::shared_ptr<net::Transport>(std::move(transport_));
    new std::shared_ptr<net::Transport>(std::move(control_transport_));
    new shm::EngineBell(std::move(bell_));  // the parent's slot on the board stays the parent's
    return;
  }
  stop_.store(true, std::memory_order_release);
  bell_.poke();
  kick();
  export_thread_.join();
  control_thread_.join();
  for (auto& [pid, fd] : pidfds_) ::close(fd);
  if (epoll_fd_ >= 0) ::close(epoll_fd_);
  if (event_fd_ >= 0) ::close(event_fd_);
}

Result<std::shared_ptr<net::Transport>> Engine::transport_for(std::string_view name) {
  if (!info_.on_control(name)) return transport_;
  std::lock_guard lock(control_transport_mutex_);  // not mutex_: opening a participant takes a while
  if (!control_transport_) {
    auto t = info_.open_control(config_);
    if (!t) return std::unexpected(std::move(t.error()));
    control_transport_ = std::move(*t);
  }
  return control_transport_;
}

// --- tables -------------------------------------------------------------------------------------

void Engine::add(Served& b) {
  {
    std::lock_guard lock(mutex_);
    auto free = std::find(by_index_.begin(), by_index_.end(), nullptr);
    if (free == by_index_.end()) free = by_index_.insert(by_index_.end(), nullptr);
    *free = &b;
    b.index = static_cast<std::uint32_t>(free - by_index_.begin());
    b.serial = next_serial_++;
    added_.push_back(b.serial);
  }
  kick();  // a watcher: the control thread watches its holder from now on
}

void Engine::remove(Served& b) {
  {
    std::lock_guard lock(mutex_);
    if (b.index < by_index_.size() && by_index_[b.index] == &b) by_index_[b.index] = nullptr;
    std::erase(held_, &b);
    while (!by_index_.empty() && by_index_.back() == nullptr) by_index_.pop_back();
  }
  // No thread pins it any more once the count is zero: the tables no longer lead to it.
  while (b.pins.load(std::memory_order_acquire) != 0) std::this_thread::yield();
}

std::uint64_t Engine::forward(const Served& b) const noexcept { return bell_.forward(b.index); }

void Engine::notify(const Served& b) noexcept { bell_.notify(b.index); }

void Engine::recheck(const Served& b, bool now) {
  {
    std::lock_guard lock(mutex_);
    recheck_.push_back(b.index);
  }
  if (now) bell_.notify(b.index);
  else bell_.poke();  // the export thread takes the later look into its deadline
}

void Engine::pump(Served& b) {
  {
    std::lock_guard lock(mutex_);
    // Only a bridge still served: one being removed (its endpoint not yet closed) stays out.
    if (b.index >= by_index_.size() || by_index_[b.index] != &b) return;
    if (std::find(held_.begin(), held_.end(), &b) == held_.end()) held_.push_back(&b);
  }
  bell_.poke();
}

void Engine::kick() noexcept {
  if (event_fd_ < 0) return;
  const std::uint64_t one = 1;
  (void)!::write(event_fd_, &one, sizeof(one));
}

void Engine::look(const Served& b) {
  {
    std::lock_guard lock(mutex_);
    added_.push_back(b.serial);  // due at the control thread's next pass, as a new bridge is
  }
  kick();
}

template <class Pick>
std::vector<Served*> Engine::pinned(Pick&& pick) {
  std::vector<Served*> out;
  std::lock_guard lock(mutex_);
  pick(out);
  for (Served* b : out) b->pins.fetch_add(1, std::memory_order_acq_rel);
  return out;
}

void Engine::unpin(const std::vector<Served*>& bridges) noexcept {
  for (Served* b : bridges) b->pins.fetch_sub(1, std::memory_order_acq_rel);
}

// --- send failures -------------------------------------------------------------------------------

void Engine::send_failed(std::string_view topic, const Error& error) {
  std::lock_guard lock(sends_mutex_);
  ++failed_sends_;
  if (sends_failing_.exchange(true, std::memory_order_relaxed)) return;  // reported for this outage
  failure_ = error.message();
  failing_since_ = Clock::now();
  log().error("the {} transport cannot send (first on topic '{}'): {}; messages that do not go out are counted in "
              "their topics' dropped_count(); reported again when sending works",
              info_.name, topic, failure_);
}

void Engine::send_recovered() noexcept {
  std::lock_guard lock(sends_mutex_);
  if (!sends_failing_.exchange(false, std::memory_order_relaxed)) return;
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - failing_since_).count();
  try {
    log().info("the {} transport sends again after {} ms; {} messages were not sent meanwhile", info_.name, ms,
               failed_sends_);
  } catch (...) {
  }
  failed_sends_ = 0;
}

// --- the export thread ----------------------------------------------------------------------------

void Engine::run_export() {
  t_engine_thread = true;
  std::vector<std::uint32_t> bits;
  std::vector<std::pair<Clock::time_point, std::uint32_t>> rechecks;  // (when, index)
  while (!stop_.load(std::memory_order_acquire)) {
    const std::uint32_t seen = bell_.word();
    bits.clear();
    bell_.take([&](std::uint32_t bit) { bits.push_back(bit); });
    const auto now = Clock::now();
    {
      std::lock_guard lock(mutex_);
      for (std::uint32_t index : recheck_)
        if (rechecks.size() < 4096) rechecks.emplace_back(now + kRecheck, index);
      recheck_.clear();
    }
    for (auto it = rechecks.begin(); it != rechecks.end();) {
      if (it->first <= now) {
        bits.push_back(it->second % shm::kEngineBits);
        it = rechecks.erase(it);
      } else {
        ++it;
      }
    }
    bool pumping = false;
    auto work = pinned([&](std::vector<Served*>& out) {
      for (std::uint32_t bit : bits)
        for (std::size_t i = bit; i < by_index_.size(); i += shm::kEngineBits)
          if (by_index_[i] != nullptr && std::find(out.begin(), out.end(), by_index_[i]) == out.end())
            out.push_back(by_index_[i]);
    });
    for (Served* b : work) b->service();
    unpin(work);
    auto held = pinned([&](std::vector<Served*>& out) { out = held_; });
    std::vector<Served*> done;
    for (Served* b : held) {
      // Nothing held when it returned; but a transport thread that held a sample since then
      // found it listed and did not add it again: keep it for the next pass.
      if (!b->pump_held() && !b->holding()) done.push_back(b);
    }
    if (!done.empty()) {
      std::lock_guard lock(mutex_);
      for (Served* b : done)  // still pinned: not freed meanwhile
        if (!b->holding()) std::erase(held_, b);
      pumping = !held_.empty();
    } else {
      pumping = !held.empty();
    }
    unpin(held);
    auto deadline = Clock::time_point::max();
    if (pumping) deadline = Clock::now() + kPumpPeriod;
    for (const auto& r : rechecks) deadline = std::min(deadline, r.first);
    if (stop_.load(std::memory_order_acquire)) break;
    bell_.wait(seen, deadline);
  }
}

// --- the control thread ------------------------------------------------------------------------

void Engine::watch_holders() {
  std::unordered_set<pid_t> want;
  {
    std::lock_guard lock(mutex_);
    for (Served* b : by_index_)
      if (b != nullptr)
        if (const pid_t pid = b->watched_pid(); pid > 0 && pid != ::getpid()) want.insert(pid);
  }
  for (auto it = pidfds_.begin(); it != pidfds_.end();) {
    if (want.contains(it->first)) {
      ++it;
      continue;
    }
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, it->second, nullptr);
    ::close(it->second);
    it = pidfds_.erase(it);
  }
  for (pid_t pid : want) {
    if (pidfds_.contains(pid)) continue;
    const int fd = open_pidfd(pid);
    if (fd < 0) continue;  // gone already (the claim tells), or no pidfd: the 50 ms look remains
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.fd = fd;
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &ev);
    pidfds_.emplace(pid, fd);
  }
}

// Each bridge has its own due time (a min-heap of (due, serial)): a holder's matched counts and
// gate, a watcher's retry; an idle watcher is due only when something happens: its holder's pidfd
// fires, or a claim is given up somewhere on the host (the board's release count, looked at
// every 50 ms: one load). So an idle process visits its topics about once a second, not 20 times.
void Engine::run_control() {
  t_engine_thread = true;
  using Entry = std::pair<Clock::time_point, std::uint64_t>;  // (due, serial)
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> due;
  std::unordered_set<pid_t> gone;
  std::uint64_t releases = shm::bridge_releases();
  auto next_release_look = Clock::now();
  bool watch_dirty = true;
  // Makes every watcher (or every watcher of `pid`, when > 0) due now.
  auto wake_watchers = [&](pid_t pid, Clock::time_point now) {
    std::lock_guard lock(mutex_);
    for (Served* b : by_index_)
      if (b != nullptr && !b->is_holder() && (pid <= 0 || b->watched_pid() == pid)) due.emplace(now, b->serial);
  };
  while (!stop_.load(std::memory_order_acquire)) {
    auto now = Clock::now();
    auto next = std::min(run_jobs(now), next_release_look);
    if (!due.empty()) next = std::min(next, due.top().first);
    const auto wait = std::chrono::ceil<std::chrono::milliseconds>(next - Clock::now()).count();
    const int timeout_ms = static_cast<int>(std::clamp<long long>(wait, 0, 60'000));
    epoll_event events[16];
    int n = 0;
    if (epoll_fd_ >= 0) n = ::epoll_wait(epoll_fd_, events, 16, timeout_ms);
    else std::this_thread::sleep_for(std::chrono::milliseconds(std::min(timeout_ms, 50)));  // no epoll: poll
    if (stop_.load(std::memory_order_acquire)) break;
    now = Clock::now();
    for (int i = 0; i < n; ++i) {
      if (events[i].data.fd == event_fd_) {
        std::uint64_t v;
        while (::read(event_fd_, &v, sizeof(v)) > 0) {
        }
        std::lock_guard lock(mutex_);
        for (std::uint64_t serial : added_) due.emplace(now, serial);
        added_.clear();
        watch_dirty = true;
        continue;
      }
      for (auto& [pid, fd] : pidfds_)
        if (fd == events[i].data.fd) gone.insert(pid);
    }
    for (pid_t pid : gone) wake_watchers(pid, now);
    if (now >= next_release_look) {
      next_release_look = now + kReleaseLook;
      if (const std::uint64_t r = shm::bridge_releases(); r != releases) {
        releases = r;
        wake_watchers(0, now);
      }
    }
    std::vector<std::uint64_t> serials;
    while (!due.empty() && due.top().first <= now) {
      if (std::find(serials.begin(), serials.end(), due.top().second) == serials.end())
        serials.push_back(due.top().second);
      due.pop();
    }
    if (serials.empty()) continue;
    auto work = pinned([&](std::vector<Served*>& out) {
      for (Served* b : by_index_)
        if (b != nullptr && std::find(serials.begin(), serials.end(), b->serial) != serials.end()) out.push_back(b);
    });
    for (Served* b : work) {
      const pid_t watched = b->watched_pid();
      const bool no_pidfd = watched > 0 && !pidfds_.contains(watched);
      auto at = b->control(now, watched > 0 && (gone.contains(watched) || no_pidfd));
      const pid_t after = b->watched_pid();
      if (after != b->watched_seen) {
        b->watched_seen = after;
        watch_dirty = true;
      }
      // A holder nobody can watch through a pidfd: look at its liveness every 50 ms.
      if (after > 0 && !pidfds_.contains(after)) at = std::min(at, now + kPollHolder);
      if (at != Clock::time_point::max()) due.emplace(at, b->serial);
    }
    gone.clear();
    if (watch_dirty) {
      watch_holders();
      watch_dirty = false;
    }
    unpin(work);
  }
}

std::uint64_t Engine::add_job(Job job) {
  std::uint64_t id;
  {
    std::lock_guard lock(jobs_mutex_);
    id = next_job_++;
    jobs_.push_back(JobEntry{id, std::move(job), Clock::time_point{}, false});
  }
  kick();
  return id;
}

void Engine::remove_job(std::uint64_t id) {
  std::unique_lock lock(jobs_mutex_);
  job_done_.wait(lock, [&] { return running_job_ != id; });
  std::erase_if(jobs_, [&](const JobEntry& j) { return j.id == id; });
}

void Engine::wake_job(std::uint64_t id) {
  {
    std::lock_guard lock(jobs_mutex_);
    for (auto& j : jobs_)
      if (j.id == id) {
        j.due = Clock::time_point{};
        j.woken = true;
      }
  }
  kick();
}

Clock::time_point Engine::run_jobs(Clock::time_point now) {
  std::unique_lock lock(jobs_mutex_);
  for (int round = 0; round < 16; ++round) {  // bounded: a job due again at once waits a turn
    auto it = std::find_if(jobs_.begin(), jobs_.end(), [&](const JobEntry& j) { return j.due <= now; });
    if (it == jobs_.end()) break;
    const std::uint64_t id = it->id;
    Job job = it->job;  // a copy: the list may change while it runs
    it->woken = false;
    running_job_ = id;
    lock.unlock();
    Clock::time_point due;
    try {
      due = job(now);
    } catch (const std::exception& e) {
      log().error("fleet: a job of the {} engine failed: {}", info_.name, e.what());
      due = now + std::chrono::seconds(1);
    }
    lock.lock();
    running_job_ = 0;
    job_done_.notify_all();
    for (auto& j : jobs_)
      if (j.id == id) j.due = j.woken ? Clock::time_point{} : due;  // woken while it ran: due again
    now = Clock::now();
  }
  auto next = Clock::time_point::max();
  for (const auto& j : jobs_) next = std::min(next, j.due);
  return next;
}

}  // namespace horus::fleet::detail

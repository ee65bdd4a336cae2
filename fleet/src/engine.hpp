// The network engine: one per process and network transport, serving every fleet topic's
// bridge of the process with two threads, whatever the number of topics.
//
//   export thread   sleeps on the process's slot of the host's engine board (shm/engine_board.hpp):
//                   a publisher of any process that rings a held topic's doorbell sets the topic's
//                   bit there and wakes it. It re-arms each notified topic, exports what the
//                   host's publishers wrote (Bridge::service), and pumps the samples a reliable
//                   transport held back for room (every 200 us while any are held).
//   control thread  sleeps in epoll on the pidfds of the processes holding the bridges this
//                   process only watches (one pidfd per holder, not per topic), an eventfd and
//                   its timers: takeover (a holder that exited: its pidfd; or that closed the
//                   topic: the board's count of claims given up, one load every 50 ms), the gate
//                   of a successor, and the jobs others give it (the fleet agent's announcements).
//                   Matched counts come with the transport's events, receiving follows the
//                   doorbell: an idle engine visits no topic.
//
// Nothing of the engine runs per message in the publishing process while it holds the topic's
// bridge: its handles export inline (Bridge::export_inline); the engine wakes for what the
// host's other processes publish. The engine lives while a bridge or the fleet agent holds it.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "horus/error.hpp"
#include "horus/network.hpp"
#include "horus/settings.hpp"
#include "horus/shm/engine_board.hpp"
#include "horus/transport_registry.hpp"

namespace horus::fleet::detail {

using Clock = std::chrono::steady_clock;

/// What an engine serves: a fleet topic's bridge in this process (bridge.hpp, the only one). The
/// engine's threads call these; the engine knows nothing else of a bridge (no include of
/// bridge.hpp here nor in engine.cpp).
class Served {
 public:
  /// The export thread, notified: re-arms the doorbell, exports, resumes receiving.
  virtual void service() noexcept = 0;
  /// The export thread: takes what the transport held once there is room; false when nothing is
  /// held any more.
  virtual bool pump_held() noexcept = 0;
  /// Whether the transport holds samples back for room (pump_held() until it does not).
  virtual bool holding() const noexcept = 0;
  /// The control thread: claims a bridge nobody (alive) holds, opens a successor's gate, steps a
  /// hand-over; returns when it wants to be called next (max: only when something happens).
  /// `gone`: the holder's pidfd fired, or it has none.
  virtual Clock::time_point control(Clock::time_point now, bool gone) noexcept = 0;
  /// The process holding the bridge, for a watcher (0: nobody, or this process holds it).
  virtual pid_t watched_pid() const noexcept = 0;
  virtual bool is_holder() const noexcept = 0;

  // The engine's bookkeeping (set by Engine::add, under its mutex).
  std::uint32_t index = 0;     // the engine's bit
  std::uint64_t serial = 0;    // unique per engine
  pid_t watched_seen = -1;     // the control thread's: the holder it watches now
  std::atomic<int> pins{0};    // engine threads using it now (Engine::remove waits for none)

 protected:
  Served() = default;
  ~Served() = default;
};

/// True on an engine's threads: they never wait on the network without bound (bridge.cpp).
inline thread_local bool t_engine_thread = false;

class Engine {
 public:
  /// This process's engine for `info` (made at the first call, kept while held). The first call's
  /// `settings` open the transport (its network settings) and the engine's bell (the
  /// shared-memory namespace and mode); later calls return the engine they made.
  static Result<std::shared_ptr<Engine>> of(const net::TransportInfo& info, const Settings& settings);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  const net::TransportInfo& info() const noexcept { return info_; }
  const std::shared_ptr<net::Transport>& transport() const noexcept { return transport_; }
  /// The transport for topic `name`: the fleet layer's own topics (horus.fleet.*) get the
  /// transport's control instance where it has one (TransportInfo::open_control: their own
  /// sockets and receive threads, so heartbeats do not wait behind data), others the data one.
  Result<std::shared_ptr<net::Transport>> transport_for(std::string_view name);

  /// Serves `b` from now on (a holder or a watcher); gives it its bit on the board.
  void add(Served& b);
  /// Stops serving `b`: when this returns no engine thread uses it.
  void remove(Served& b);
  /// The value `b`'s topic doorbell forwards to (its bit on this engine's slot).
  std::uint64_t forward(const Served& b) const noexcept;
  /// Asks the export thread to look at `b` (it became the holder, was ungated, holds samples).
  void notify(const Served& b) noexcept;
  /// `b` was attached: look at it now and once more 10 ms later (a send that raced the
  /// engine's registration as a waiter is seen then: doorbell.hpp's race).
  void recheck(const Served& b, bool now = true);
  /// `b`'s transport holds samples back for room: pump them until it does not.
  void pump(Served& b);
  /// Wakes the control thread (a watcher should look at its claim now).
  void kick() noexcept;
  /// Makes `b` due on the control thread now (Bridge::control: a hand-over to look at).
  void look(const Served& b);

  /// A send of topic `topic` failed in the transport (Errc::Io: the network refused it, a link
  /// is down): logged once for the transport, not per topic and message; the messages are
  /// counted in their topics' dropped_count(). send_worked() after a failure logs the recovery.
  void send_failed(std::string_view topic, const Error& error);
  void send_worked() noexcept {
    if (sends_failing_.load(std::memory_order_relaxed)) [[unlikely]]
      send_recovered();
  }

  /// A job of the control thread: called when due, returns when it is due next.
  using Job = std::function<Clock::time_point(Clock::time_point now)>;
  std::uint64_t add_job(Job job);
  /// When this returns the job does not run and will not again.
  void remove_job(std::uint64_t id);
  /// Makes the job with this id due now.
  void wake_job(std::uint64_t id);
  /// The host's link budget (on the engine board, shared by the host's bridges).
  bool admit_link(std::size_t bytes, double ns_per_byte, std::int64_t tolerance_ns) noexcept {
    return bell_.admit_link(bytes, ns_per_byte, tolerance_ns);
  }

 private:
  Engine(const net::TransportInfo& info, net::Config config, std::shared_ptr<net::Transport> transport,
         shm::EngineBell bell);
  void run_export();
  void run_control();
  // Pins (under mutex_) the bridges `pick` selects; the caller unpins them.
  template <class Pick>
  std::vector<Served*> pinned(Pick&& pick);
  static void unpin(const std::vector<Served*>& bridges) noexcept;
  void watch_holders();  // one pidfd per process holding a bridge this process watches
  Clock::time_point run_jobs(Clock::time_point now);

  const net::TransportInfo& info_;
  const net::Config config_;  // the settings the transports opened with (and the control instance opens with)
  std::shared_ptr<net::Transport> transport_;
  std::mutex control_transport_mutex_;
  std::shared_ptr<net::Transport> control_transport_;  // opened by the first horus.fleet.* topic
  shm::EngineBell bell_;
  const int creator_pid_;

  std::mutex mutex_;                  // the tables below
  std::vector<Served*> by_index_;     // index: the bridge's bit (mod kEngineBits); null: free
  std::vector<Served*> held_;         // bridges whose transport holds samples back
  std::vector<std::uint32_t> recheck_;  // bridges to look at once more (recheck())
  std::vector<std::uint64_t> added_;    // bridges the control thread has not seen yet (serials)
  std::uint64_t next_serial_ = 1;
  std::atomic<bool> stop_{false};
  std::atomic<bool> sends_failing_{false};  // send_failed() since the last send that worked
  std::mutex sends_mutex_;
  std::uint64_t failed_sends_ = 0;          // in the current outage
  std::string failure_;                     // its first error
  Clock::time_point failing_since_{};
  void send_recovered() noexcept;

  // The control thread's.
  int epoll_fd_ = -1;
  int event_fd_ = -1;
  std::unordered_map<pid_t, int> pidfds_;  // holder pid -> pidfd (registered in epoll_fd_)
  struct JobEntry {
    std::uint64_t id;
    Job job;
    Clock::time_point due;
    bool woken;  // wake_job() since it last started
  };
  std::mutex jobs_mutex_;
  std::condition_variable job_done_;
  std::vector<JobEntry> jobs_;
  std::uint64_t next_job_ = 1;
  std::uint64_t running_job_ = 0;

  std::thread export_thread_;
  std::thread control_thread_;
};

}  // namespace horus::fleet::detail

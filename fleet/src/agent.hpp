// The fleet agent: one per process and network backend, alive while the process has a fleet
// topic (or a horus::Fleet) open on it. When its process holds the host's bridge of
// horus.fleet.heartbeat, it publishes the host's heartbeats and announcements; otherwise it
// only stands by, and takes over with the bridge. Its jobs, each in a file of its own:
//   agent.cpp           its thread: reads the settings, opens the fleet layer's topics, runs the
//                       executor; presence() (one agent per transport while held)
//   agent_view.cpp      heartbeats (from the executor's thread: nothing else runs there, so they
//                       leave on time under load), the hosts heard and the fleet view
//   agent_announce.cpp  the announcer: scans the host's topics and processes and announces them,
//                       a job of the network engine's control thread (engine.hpp)
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "engine.hpp"
#include "fleet_internal.hpp"
#include "horus/config.hpp"
#include "horus/discovery/registry.hpp"
#include "horus/executor.hpp"
#include "horus/fleet.hpp"
#include "horus/topic.hpp"

namespace horus::fleet::detail {

/// The first line of a file ("" when it cannot be read).
inline std::string read_line(const char* path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

/// FNV-1a over `s`, from `h` (host identity, announcement versions).
inline std::uint64_t fnv(std::uint64_t h, std::string_view s) noexcept {
  for (char c : s) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

class Agent {
 public:
  /// `settings`: what the operation that started it took (the agent's own come from them).
  Agent(std::string transport, Settings settings);
  ~Agent();
  Agent(const Agent&) = delete;
  Agent& operator=(const Agent&) = delete;

 private:
  // -- its thread: the settings, the topics, the heartbeats' executor (agent.cpp)
  void run();
  bool open_topics();

  // -- heartbeats and the fleet view, on the executor's thread (agent_view.cpp)
  void on_heartbeat(const Heartbeat& h);
  // The executor's thread, every heartbeat period: hosts lost (as horus::Fleet judges them),
  // and, by the process that speaks for the host, the view: at once when a host joined, was
  // lost or rejoined, else once a second (ages, link figures).
  void keep_view(bool speaker);
  void on_request(const Request& r);
  // The executor's thread, every heartbeat period: only the heartbeat, so that it leaves on
  // time however long scanning the host's topics or sending an announcement takes (both on the
  // announcer's thread: with 150 topics under load a scan took up to 270 ms).
  void tick();

  // -- the announcer, a job of the engine's control thread (agent_announce.cpp)
  // The announcer (a job of the engine's control thread): scans the host's topics (every
  // announce period, at most 500 ms apart) and announces when due, on change, and when asked;
  // idle while another process speaks for the host. Returns when it is due next.
  std::chrono::steady_clock::time_point announcer_step(std::chrono::steady_clock::time_point now);
  // Makes the announcer due now (a request, or this process now speaks for the host).
  void wake_announcer();
  // The host's processes and topics, from its shared-memory segments (the local registry).
  void scan();
  static bool encoded_too_large(const Announcement& a);

  struct Heard {
    std::uint64_t sent_ns;
    std::uint64_t received_ns;
  };
  struct Sample {
    std::uint64_t messages;
    std::chrono::steady_clock::time_point at;
  };

  const std::string transport_;
  const Settings started_with_;
  const std::uint64_t self_ = host_id();
  const std::string name_ = host_name();
  FleetSettings settings_;
  Executor executor_;
  std::optional<Topic<Heartbeat>> heartbeat_;
  std::optional<Topic<Announcement>> announce_;
  std::optional<Topic<Request>> request_;
  std::map<std::uint64_t, Heard> heard_;
  struct Tracked {
    ViewedHost view;
    detail::LinkStats link;
    std::uint64_t last_ns = 0;  // its last heartbeat (steady clock)
  };
  std::map<std::uint64_t, Tracked> tracked_;  // the executor's thread's
  static std::int64_t lost_since(const Tracked& t) { return t.view.lost_since_unix_ns; }
  std::optional<Topic<FleetView>> view_;
  bool view_dirty_ = false;
  std::uint64_t view_version_ = 0;
  std::uint64_t view_sent_ns_ = 0;
  std::map<std::string, Sample> samples_;
  Announcement current_;                        // the announcer's
  std::atomic<std::uint64_t> sent_version_{0};  // the announcer writes, heartbeats carry it
  std::atomic<std::uint32_t> processes_{0}, topics_{0};
  std::uint64_t seq_ = 0;
  std::atomic<bool> holder_{false};  // tick() decides, the announcer follows
  bool open_error_logged_ = false;
  bool announce_error_logged_ = false;
  std::mutex mutex_;  // guards what follows
  std::condition_variable cv_;
  std::chrono::steady_clock::time_point announce_due_{};
  std::chrono::steady_clock::time_point next_scan_{}, next_look_{}, last_announce_{};
  std::unique_ptr<discovery::Scanner> scanner_;  // the announcer's: segments stay mapped between scans
  bool rescan_ = false;
  std::chrono::steady_clock::duration scan_cost_{};  // what the last scan took (it spaces the next ones)
  bool asked_ = false;  // a request (or this process now speaks for the host): announce even without news
  std::uint64_t traffic_ = 0, sent_traffic_ = 0;  // the topics' counts at the last scan and the last announcement
  bool stopping_ = false;
  std::shared_ptr<detail::Engine> engine_;  // runs the announcer (set by the agent's thread)
  std::atomic<std::uint64_t> job_{0};
  std::thread thread_;  // last: starts once everything above exists
};

}  // namespace horus::fleet::detail

// The pieces of the LCM transport (private to backend_lcm):
//   lcm_url.cpp        URL parsing and the environment (check_url, url_from),
//                      channel names (check_channel, channel_name)
//   lcm_drops.cpp      kernel drop counting: this process's UDP sockets in /proc/self/net/udp
//   lcm_udpm_rx.cpp    horus's own receiver of LCM's UDP multicast protocol (UdpmReceiver)
//   lcm_engine.cpp     the instance: the publishing lcm_t, what receives (the udpm receiver, or a
//                      liblcm instance), the receive thread (Engine), subscriptions
//   lcm_transport.cpp  the endpoint, the transport, the per-URL cache, registration
#pragma once

#include "horus/export.hpp"
#include <array>
#include <cerrno>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <lcm/lcm.h>

#include "horus/error.hpp"
#include "horus/lcm/transport.hpp"
#include "horus/network.hpp"
#include "horus/transport/endpoint_gate.hpp"

namespace horus::lcm::detail {

// ---- URLs (lcm_url.cpp) -----------------------------------------------------------------------

enum class Provider { Udpm, Memq, File, Tcpq };

struct UrlInfo {
  Provider provider = Provider::Udpm;
  std::uint16_t port = 0;                 // udpm
  std::array<std::uint8_t, 4> group{};    // udpm: the multicast group
  std::uint32_t recv_buf_size = 0;        // udpm: the receive socket's buffer (0: the system's)
  bool transmit_only = false;             // udpm: never receives
  bool file_read = true;                  // file: mode r (the default)
};

/// Checks `url` and says what it is (Errc::Config naming the problem otherwise). Exported from
/// libhorus.so for the fuzzer (fuzz_lcm), not part of the ABI (docs/ABI.md).
HORUS_API Result<UrlInfo> parse_url(std::string_view url);
/// What to check when LCM cannot start `url` (empty when there is nothing to add).
std::string provider_hint(const std::string& url, const UrlInfo& info);
/// A decimal number 0..max, digits only.
std::optional<std::uint64_t> parse_decimal(std::string_view s, std::uint64_t max) noexcept;

// ---- kernel drops (lcm_drops.cpp) -------------------------------------------------------------

/// One row of /proc/net/udp.
struct UdpRow {
  std::uint16_t local_port = 0;
  bool unconnected = false;  // rem_address 00000000:0000
  std::uint64_t inode = 0;
  std::uint32_t drops = 0;
};

/// The whole of a (small, /proc) file; false when it cannot be read.
bool read_whole_file(const char* path, std::string& out);
void for_each_udp_row(const std::string& table, const std::function<void(const UdpRow&)>& f);
/// This process's unconnected UDP sockets bound to `port` (LCM's receive socket binds
/// INADDR_ANY:port; its send socket is connected to the group), sorted.
std::vector<std::uint64_t> udp_sockets_on_port(std::uint16_t port);
/// The kernel's drops counter of socket `inode` (`table` is scratch space), if readable.
std::optional<std::uint32_t> socket_drops(std::uint64_t inode, std::string& table);

// ---- udpm receive (lcm_udpm_rx.cpp) ----------------------------------------------------------

/// A complete LCM message as it arrived; valid during the call only.
struct UdpmMessage {
  std::string_view channel;
  std::span<const std::byte> data;
  std::int64_t recv_utime;  // the kernel's receive time of its (last) datagram, system clock, us
};

/// horus's own receiver of LCM's UDP multicast protocol (LC02 datagrams, LC03 fragments),
/// read by the engine's receive thread itself. liblcm's udpm receives in a thread of its own
/// and hands each message to the thread that calls lcm_handle through a pipe: one more thread
/// woken per message. Sending stays liblcm's (lcm_publish). One socket bound to the URL's port
/// (SO_REUSEADDR, as liblcm's), joined to its group only (IP_MULTICAST_ALL off), with the
/// kernel's drop count (SO_RXQ_OVFL) and receive time (SO_TIMESTAMP) of each datagram.
class UdpmReceiver {
 public:
  /// Errc::Io naming the step that failed (no multicast route: joining the group fails).
  static Result<std::unique_ptr<UdpmReceiver>> open(const std::string& url, const UrlInfo& info);
  UdpmReceiver(const UdpmReceiver&) = delete;
  UdpmReceiver& operator=(const UdpmReceiver&) = delete;
  ~UdpmReceiver();

  /// What the receive thread polls: an epoll descriptor holding the socket, readable while a
  /// datagram waits. Not the socket itself: a thread in poll() on a descriptor keeps its socket
  /// alive, so closing it (the last endpoint stopped receiving) would not free the port at once.
  int fd() const noexcept { return epoll_fd_; }
  struct Lost {
    std::uint64_t kernel = 0;   // datagrams the kernel dropped for a full buffer (SO_RXQ_OVFL)
    std::uint64_t network = 0;  // messages that never arrived whole: gaps in a sender's sequence
                                // numbers, messages abandoned in reassembly (a sender that moved
                                // on, a first fragment missed, limits)
  };
  /// Reads up to `budget` datagrams the socket holds now (never blocks) and calls `deliver` for
  /// each complete message. Returns what was lost meanwhile.
  Lost drain(const std::function<void(const UdpmMessage&)>& deliver, int budget);

 private:
  struct Partial {
    std::uint32_t seqno = 0;
    std::string channel;
    std::vector<std::byte> data;
    std::vector<bool> seen;  // per fragment
    std::uint32_t remaining = 0;
    std::int64_t last_us = 0;
  };
  explicit UdpmReceiver(int fd);
  std::uint64_t take(std::span<const std::byte> datagram, std::uint64_t sender, std::int64_t recv_us,
                     bool kernel_dropped, const std::function<void(const UdpmMessage&)>& deliver);
  // Per sender: the last sequence number seen, and the last one counted as lost in reassembly.
  struct Sequence {
    std::uint32_t last = 0;
    std::uint32_t counted = 0;
    bool any_counted = false;
  };
  static constexpr std::size_t kMaxSenders = 4096;
  // take()'s parts (lcm_udpm_rx.cpp).
  Sequence& track_sequence(std::uint64_t sender, std::uint32_t seqno, bool kernel_dropped, std::uint64_t& gap);
  std::uint64_t take_fragment(std::span<const std::byte> datagram, std::uint64_t sender, std::uint32_t seqno,
                              Sequence& seq, std::uint64_t gap, std::int64_t recv_us,
                              const std::function<void(const UdpmMessage&)>& deliver);
  std::uint64_t make_room(std::uint32_t size);

  const int fd_;        // the socket
  const int epoll_fd_;  // holds fd_ (see fd())
  std::vector<std::byte> buffer_;                       // one datagram
  std::uint32_t kernel_drops_ = 0;                      // SO_RXQ_OVFL's last value
  std::unordered_map<std::uint64_t, Partial> partials_;  // by sender (address, port)
  std::uint64_t partial_bytes_ = 0;
  std::unordered_map<std::uint64_t, Sequence> sequences_;  // by sender
};

// ---- the instance (lcm_engine.cpp) ------------------------------------------------------------

/// How long a message may wait in LCM's receive queue (udpm). liblcm's own thread reads the
/// socket into a queue that grows without bound (horus sets no queue capacity: LCM would drop
/// silently at it); when this process dispatches slower than messages arrive, the ones that
/// waited longer than this are dropped (cheaply: not decoded) and counted, so the queue and
/// the memory stay bounded and every loss shows in dropped_count().
inline constexpr std::int64_t kMaxQueueAgeUs = 500'000;

/// One open endpoint as the receive thread sees it (the `user` pointer of its LCM subscription).
/// Its listener calls go through its gate.
struct Subscription : std::enable_shared_from_this<Subscription> {
  Subscription(net::Listener& l, std::string label) : gate(l, std::move(label)) {}
  net::EndpointGate gate;                // closed first by ~LcmEndpoint: no listener call after
  lcm_subscription_t* handle = nullptr;  // guarded by the engine's handle lock
  // udpm: in the engine's table of its own receiver (the counterpart of `handle`), and the
  // channel it is filed under; guarded by the engine's handle lock.
  bool listening = false;
  std::string channel;
  std::atomic<bool> paused{false};       // set_receiving(false): samples are not delivered
  // udpm: a message that waited longer than this in LCM's receive queue is dropped and counted
  // (0: no limit). Receive thread only, like the counts below.
  std::int64_t max_queue_age_us = 0;
  std::uint64_t stale = 0;        // messages dropped for their age
  std::uint64_t kernel_lost = 0;  // datagrams the kernel dropped on the socket, as reported here
  std::uint64_t network_lost = 0;  // messages the network lost (udpm sequence gaps), as reported here

  const std::string& label() const noexcept { return gate.label(); }
  void report(std::string_view message) noexcept {
    gate.run([&](net::EndpointGate::Calls& calls) { calls.error(message); });
  }
};

/// What the receive thread owns: the lcm_t (destroyed last, by whichever thread releases the
/// engine last: the transport, or the receive thread when it was detached).
class Engine {
 public:
  /// `pub`: the instance that publishes. Memq, file and tcpq receive through it too (a memq
  /// instance is its own bus, a log file is opened once); udpm receives through a second
  /// instance that exists while an endpoint receives (receiver_locked), so a process that
  /// only publishes has no receive socket and never sees its own datagrams.
  Engine(std::string url, const UrlInfo& info, lcm_t* pub, int event_fd) noexcept
      : url_(std::move(url)), info_(info), pub_(pub), event_fd_(event_fd) {}
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;
  ~Engine();

  const std::string& url() const noexcept { return url_; }
  const UrlInfo& info() const noexcept { return info_; }
  bool on_receive_thread() const noexcept;

  /// Memq, file and tcpq: receives through the publishing instance from the start (udpm
  /// starts when an endpoint first receives). Called once, before the receive thread starts.
  Result<void> start_receiving_now();

  static void run(std::shared_ptr<Engine> self) { self->loop(); }
  void request_stop() noexcept;
  void poke() noexcept;  // wakes the receive thread

  /// lcm_publish; `error` is errno after a failure (0 when liblcm left none).
  int publish(const char* channel, const void* data, unsigned size, int& error) noexcept {
    errno = 0;
    const int rc = lcm_publish(pub_, channel, data, size);  // internally locked in every provider
    error = rc == 0 ? 0 : errno;
    return rc;
  }

  /// Registers an endpoint's subscription; `receive` false: it starts paused (set_receiving).
  Result<void> subscribe(const std::shared_ptr<Subscription>& sub, const std::string& channel, bool receive);
  /// Stops or resumes the LCM subscription of an open endpoint (Endpoint::set_receiving): while
  /// it is off, LCM's reader drops the channel's datagrams before queueing them.
  void set_receiving(const std::shared_ptr<Subscription>& sub, const std::string& channel, bool on) noexcept;
  /// After this returns, `sub` gets no more callbacks.
  void unsubscribe(const std::shared_ptr<Subscription>& sub) noexcept;

 private:
  class HandleLock;

  /// The receiving instance, created (udpm) and announced to the receive thread on first use.
  /// Called with handle_mutex_ held.
  Result<lcm_t*> receiver_locked();
  /// udpm (unless transmit_only): horus's own receiver serves the subscriptions, not a liblcm
  /// receiving instance.
  bool native() const noexcept { return info_.provider == Provider::Udpm && !info_.transmit_only; }
  /// Whether `sub` receives now (an LCM subscription, or a place in the native receiver's table).
  static bool receives(const Subscription& sub) noexcept { return sub.handle != nullptr || sub.listening; }
  /// Takes `sub` out of the native receiver's table. Called with handle_mutex_ held.
  void unlist_locked(Subscription& sub) noexcept;
  /// Hands a message of the native receiver to the subscriptions of its channel.
  void dispatch_native_locked(const UdpmMessage& m) noexcept;
  /// Datagrams the kernel dropped: every subscription of the process counts them (LCM does
  /// not say of which channel). Called with handle_mutex_ held.
  void report_kernel_drops_locked(std::uint64_t count) noexcept;
  void report_network_losses_locked(std::uint64_t count) noexcept;
  void report_lost_locked(std::uint64_t delta, std::uint64_t Subscription::*counter,
                          const std::function<std::string(std::uint64_t)>& message) noexcept;
  /// lcm_subscribe on the receiving instance. Called with handle_mutex_ held.
  Result<void> lcm_subscribe_locked(Subscription& sub, const std::string& channel);
  std::unique_lock<std::mutex> lock_for_dispatch();
  void run_deferred_locked() noexcept;
  void stop_receiving_if_idle_locked() noexcept;
  void report_all_locked(const std::function<std::string()>& make_message) noexcept;
  void loop() noexcept;
  void account_drops() noexcept;

  const std::string url_;
  const UrlInfo info_;
  lcm_t* const pub_;
  const int event_fd_;
  lcm_t* recv_ = nullptr;        // the receiving instance, while one receives; guarded by handle_mutex_
  std::atomic<int> lcm_fd_{-1};  // recv_'s descriptor (-1: none), published after recv_
  std::atomic<std::uint64_t> recv_gen_{0};  // +1 for each receiving instance created or destroyed
  bool in_handle_ = false;       // the receive thread is inside lcm_handle (under handle_mutex_)
  std::atomic<bool> stop_{false};

  std::mutex handle_mutex_;  // held by the receive thread around lcm_handle and listener calls
  std::condition_variable handle_cv_;
  std::atomic<int> waiting_{0};                          // threads waiting for handle_mutex_
  std::vector<std::shared_ptr<Subscription>> subs_;      // open endpoints; guarded by handle_mutex_
  std::vector<std::shared_ptr<Subscription>> deferred_;  // to unsubscribe; guarded by handle_mutex_
  // udpm: horus's own receiver while an endpoint receives, and its subscriptions by channel;
  // guarded by handle_mutex_.
  struct ChannelHash {
    using is_transparent = void;
    std::size_t operator()(std::string_view s) const noexcept { return std::hash<std::string_view>{}(s); }
  };
  std::unique_ptr<UdpmReceiver> rx_;
  std::unordered_map<std::string, std::vector<std::shared_ptr<Subscription>>, ChannelHash, std::equal_to<>> channels_;
  std::vector<std::shared_ptr<Subscription>> scratch_;  // the receive thread's copy of a channel's list

  // The receive socket's drop accounting (set with recv_); guarded by handle_mutex_.
  std::uint64_t drop_inode_ = 0;
  std::uint32_t last_drops_ = 0;
  std::string udp_table_;
  std::chrono::steady_clock::time_point last_drop_check_{};  // receive thread only
};

}  // namespace horus::lcm::detail

// The instance of the LCM transport: the lcm_t that publishes, what receives (udpm: horus's own
// receiver, lcm_udpm_rx.cpp, which exists while an endpoint receives; otherwise the same lcm_t)
// and one receive thread. With udpm the thread reads the socket and dispatches itself (no
// liblcm receive thread, no pipe: one thread woken per message, as in a raw LCM program); with
// the other providers the thread (Engine::run) polls {the receiving lcm fd, an eventfd that
// wakes or stops it} and calls lcm_handle(), which runs the handlers of one message in that
// thread. Every listener call is made by that thread while it holds Engine::handle_mutex_,
// through the endpoint's gate (horus/transport/endpoint_gate.hpp).
//
// Subscribing and unsubscribing. liblcm 1.3.1 cannot unsubscribe safely while another thread is
// inside lcm_handle(): lcm_dispatch_handlers() walks the channel's handler array by index with
// LCM's lock released around each callback, and lcm_unsubscribe() reorders that array
// (g_ptr_array_remove_fast), so a handler can be skipped or called twice. So every
// lcm_subscribe/lcm_unsubscribe runs under handle_mutex_ too, i.e. never concurrently with
// lcm_handle. Threads that need it announce themselves first (waiting_) and the receive thread
// gives way before its next lcm_handle, so open() and ~LcmEndpoint wait for at most the message
// being dispatched, never for the poll timeout. When ~LcmEndpoint or open() runs on the receive
// thread itself (from a listener callback), the lock is already held: subscribing is done at once
// (LCM allows it in a handler), unsubscribing is deferred until lcm_handle() returns, and the
// closed gate stops the subscription's callbacks at once.
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <cstring>
#include <iterator>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "lcm_internal.hpp"

namespace horus::lcm::detail {
namespace {

constexpr int kPollTimeoutMs = 100;
constexpr int kNativePollTimeoutMs = 1000;
constexpr auto kDropCheckPeriod = std::chrono::milliseconds(100);

thread_local const Engine* tl_receive_engine = nullptr;  // set on each engine's receive thread

// A channel as an exact GLib regex: LCM subscribes to "^<channel>$".
std::string regex_escape(std::string_view channel) {
  static constexpr std::string_view kMeta = ".[]()*+?{}|^$\\";
  std::string out;
  out.reserve(channel.size() * 2);
  for (char c : channel) {
    if (kMeta.find(c) != std::string_view::npos) out += '\\';
    out += c;
  }
  return out;
}

std::int64_t unix_us() noexcept {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// True (and counted, reported on the first and every 4096th) when the message waited too long
// in LCM's queue. recv_utime is the kernel's receive time (SO_TIMESTAMP, the system clock); an
// age over a minute is a clock step, not a backlog.
bool drop_if_stale(Subscription& sub, std::int64_t recv_utime, net::EndpointGate::Calls& calls) {
  if (sub.max_queue_age_us <= 0) return false;
  const std::int64_t age = unix_us() - recv_utime;
  if (age <= sub.max_queue_age_us || age > 60'000'000) return false;
  calls.lost(1);
  if (sub.stale++ % 4096 == 0)
    calls.error(sub.label() + ": dropped " + std::to_string(sub.stale) +
                " message(s) so far that waited more than " + std::to_string(sub.max_queue_age_us / 1000) +
                " ms in LCM's receive queue (this one " + std::to_string(age / 1000) +
                " ms): this process reads slower than the fleet sends; they count in dropped_count()");
  return true;
}

// One message to one subscription, on the receive thread. The caller holds `sub` alive: the
// listener may close its own endpoint, and the gate stays alive until the call leaves it.
void deliver(const std::shared_ptr<Subscription>& sub, std::span<const std::byte> body, std::int64_t recv_utime) {
  sub->gate.run([&](net::EndpointGate::Calls& calls) {
    if (sub->paused.load(std::memory_order_acquire)) return;
    if (drop_if_stale(*sub, recv_utime, calls)) return;
    calls.sample(net::Sample{body, false});  // LCM encodes big-endian
  });
}

void on_message(const lcm_recv_buf_t* rb, const char* /*channel*/, void* user) {
  auto* raw = static_cast<Subscription*>(user);
  if (!raw->gate.is_open() || raw->paused.load(std::memory_order_acquire)) return;
  deliver(raw->shared_from_this(),
          std::span<const std::byte>(static_cast<const std::byte*>(rb->data), rb->data_size), rb->recv_utime);
}

}  // namespace

// Holds handle_mutex_, ahead of the receive thread; a no-op on the receive thread, which
// holds it whenever it runs listener code.
class Engine::HandleLock {
 public:
  explicit HandleLock(Engine& e) : engine_(e), on_thread_(e.on_receive_thread()) {
    if (on_thread_) return;
    engine_.waiting_.fetch_add(1, std::memory_order_acq_rel);
    lock_ = std::unique_lock(engine_.handle_mutex_);
  }
  HandleLock(const HandleLock&) = delete;
  HandleLock& operator=(const HandleLock&) = delete;
  ~HandleLock() {
    if (on_thread_) return;
    engine_.waiting_.fetch_sub(1, std::memory_order_acq_rel);
    lock_.unlock();
    engine_.handle_cv_.notify_all();
  }
  bool on_receive_thread() const noexcept { return on_thread_; }

 private:
  Engine& engine_;
  const bool on_thread_;
  std::unique_lock<std::mutex> lock_;
};

Engine::~Engine() {
  // lcm_destroy unsubscribes what is left and stops LCM's own threads.
  if (recv_ != nullptr && recv_ != pub_) lcm_destroy(recv_);
  lcm_destroy(pub_);
  ::close(event_fd_);
}

bool Engine::on_receive_thread() const noexcept { return tl_receive_engine == this; }

void Engine::poke() noexcept {
  const std::uint64_t one = 1;
  while (::write(event_fd_, &one, sizeof one) < 0 && errno == EINTR) {
  }
}

void Engine::request_stop() noexcept {
  stop_.store(true, std::memory_order_release);
  poke();
}

Result<void> Engine::start_receiving_now() {
  std::lock_guard lock(handle_mutex_);
  auto lcm = receiver_locked();
  if (!lcm) return std::unexpected(std::move(lcm.error()));
  return {};
}

Result<lcm_t*> Engine::receiver_locked() {
  if (native()) {
    if (rx_ == nullptr) {
      auto rx = UdpmReceiver::open(url_, info_);
      if (!rx) return std::unexpected(std::move(rx.error()));
      rx_ = std::move(*rx);
      recv_gen_.fetch_add(1, std::memory_order_acq_rel);
      lcm_fd_.store(rx_->fd(), std::memory_order_release);
      poke();  // the receive thread polls the socket from now on
    }
    return pub_;
  }
  if (recv_ != nullptr) return recv_;
  // udpm: LCM's receive socket is created by lcm_get_fileno(); the sockets on its port that
  // appear meanwhile are ours (creations of receive sockets are serialized by this lock).
  static std::mutex socket_creation;
  std::unique_lock<std::mutex> sockets;
  std::vector<std::uint64_t> before;
  lcm_t* lcm = pub_;
  if (info_.provider == Provider::Udpm) {
    sockets = std::unique_lock(socket_creation);
    before = udp_sockets_on_port(info_.port);
    lcm = lcm_create(url_.c_str());
    if (lcm == nullptr)
      return fail(Errc::Io, "LCM could not start a receiving instance for URL '" + url_ +
                                "' (liblcm printed the reason on stderr)" + provider_hint(url_, info_));
  }
  const int fd = lcm_get_fileno(lcm);
  if (fd < 0) {
    if (lcm != pub_) lcm_destroy(lcm);
    std::string what = "LCM could not start the receive side for URL '" + url_ + "' (liblcm printed the reason on stderr";
    if (info_.provider == Provider::Udpm) what += "; its self test, a message sent to itself, did not come back";
    return fail(Errc::Io, what + ")" + provider_hint(url_, info_));
  }
  if (info_.provider == Provider::Udpm) {
    std::vector<std::uint64_t> added;
    const std::vector<std::uint64_t> after = udp_sockets_on_port(info_.port);
    std::set_difference(after.begin(), after.end(), before.begin(), before.end(), std::back_inserter(added));
    if (added.size() == 1) {
      if (const auto drops = socket_drops(added[0], udp_table_)) {
        drop_inode_ = added[0];
        last_drops_ = *drops;
      }
    }
  }
  recv_ = lcm;
  recv_gen_.fetch_add(1, std::memory_order_acq_rel);
  lcm_fd_.store(fd, std::memory_order_release);
  poke();  // the receive thread polls the new descriptor from now on
  return recv_;
}

Result<void> Engine::lcm_subscribe_locked(Subscription& sub, const std::string& channel) {
  auto lcm = receiver_locked();
  if (!lcm) return fail(lcm.error().code(), sub.label() + ": " + lcm.error().message());
  if (native()) {
    auto& list = channels_[channel];
    list.push_back(sub.shared_from_this());
    sub.channel = channel;
    sub.listening = true;
    return {};
  }
  lcm_subscription_t* handle = lcm_subscribe(*lcm, regex_escape(channel).c_str(), &on_message, &sub);
  if (handle == nullptr) {
    stop_receiving_if_idle_locked();  // an instance created for nothing goes again
    return fail(Errc::Io, sub.label() + ": liblcm refused the subscription (it printed the reason on stderr)");
  }
  lcm_subscription_set_queue_capacity(handle, 0);  // unlimited (never silent): kMaxQueueAgeUs bounds it
  sub.handle = handle;
  return {};
}

Result<void> Engine::subscribe(const std::shared_ptr<Subscription>& sub, const std::string& channel, bool receive) {
  if (info_.provider == Provider::Udpm) sub->max_queue_age_us = kMaxQueueAgeUs;
  HandleLock lock(*this);
  subs_.reserve(subs_.size() + 1);  // so that push_back below cannot throw after subscribing
  if (receive) {
    if (auto ok = lcm_subscribe_locked(*sub, channel); !ok) return ok;
  } else {
    sub->paused.store(true, std::memory_order_release);
  }
  subs_.push_back(sub);
  return {};
}

void Engine::set_receiving(const std::shared_ptr<Subscription>& sub, const std::string& channel, bool on) noexcept {
  sub->paused.store(!on, std::memory_order_release);
  HandleLock lock(*this);
  if (!sub->gate.is_open()) return;
  if (on) {
    std::erase(deferred_, sub);  // an unsubscribe still waiting for lcm_handle to return
    if (receives(*sub)) return;
    try {
      if (auto ok = lcm_subscribe_locked(*sub, channel); !ok)
        sub->report(ok.error().message() + "; nothing arrives on this channel until it is resumed again");
    } catch (...) {
    }
    return;
  }
  if (sub->listening) {  // the native receiver's table: dispatch walks a copy, so at once
    unlist_locked(*sub);
    stop_receiving_if_idle_locked();
    return;
  }
  if (sub->handle == nullptr) return;
  if (lock.on_receive_thread()) {
    try {
      deferred_.push_back(sub);
    } catch (...) {  // stays subscribed; paused keeps its samples out
    }
    return;
  }
  lcm_unsubscribe(recv_, sub->handle);
  sub->handle = nullptr;
  stop_receiving_if_idle_locked();
}

void Engine::unsubscribe(const std::shared_ptr<Subscription>& sub) noexcept {
  sub->gate.close();
  HandleLock lock(*this);
  std::erase(subs_, sub);
  if (sub->listening) {
    unlist_locked(*sub);
    stop_receiving_if_idle_locked();
    return;
  }
  if (sub->handle == nullptr) return;
  if (lock.on_receive_thread()) {
    // Inside lcm_handle (a listener closed an endpoint): unsubscribe once it returns.
    try {
      deferred_.push_back(sub);
      return;
    } catch (...) {  // no memory: LCM allows unsubscribing from a handler (the gate stops it)
    }
  }
  lcm_unsubscribe(recv_, sub->handle);
  sub->handle = nullptr;
  stop_receiving_if_idle_locked();
}

std::unique_lock<std::mutex> Engine::lock_for_dispatch() {
  std::unique_lock lock(handle_mutex_);
  handle_cv_.wait(lock, [this] { return waiting_.load(std::memory_order_acquire) == 0; });
  return lock;
}

// Called with handle_mutex_ held, outside lcm_handle.
void Engine::run_deferred_locked() noexcept {
  for (const auto& sub : deferred_) {
    if (sub->handle != nullptr) lcm_unsubscribe(recv_, sub->handle);
    sub->handle = nullptr;
  }
  deferred_.clear();
  stop_receiving_if_idle_locked();
}

// udpm: once no endpoint receives, the receiving instance goes (its socket would keep getting
// the group's datagrams, this process's own included). Called with handle_mutex_ held, outside
// lcm_handle.
void Engine::stop_receiving_if_idle_locked() noexcept {
  // Never inside lcm_handle or the native receiver's drain (a handler of this very instance is
  // running): the receive thread calls this again once it has returned (run_deferred_locked).
  if (native()) {
    if (rx_ == nullptr || !channels_.empty() || in_handle_) return;
    lcm_fd_.store(-1, std::memory_order_release);
    recv_gen_.fetch_add(1, std::memory_order_acq_rel);
    poke();  // the receive thread stops polling the socket (it checks it again under the lock)
    rx_.reset();
    return;
  }
  if (info_.provider != Provider::Udpm || recv_ == nullptr || !deferred_.empty() || in_handle_) return;
  for (const auto& sub : subs_)
    if (sub->handle != nullptr) return;
  lcm_fd_.store(-1, std::memory_order_release);
  recv_gen_.fetch_add(1, std::memory_order_acq_rel);
  poke();  // the receive thread stops polling the descriptor (it checks it again under the lock)
  lcm_t* const lcm = std::exchange(recv_, nullptr);
  drop_inode_ = 0;
  lcm_destroy(lcm);
}

void Engine::unlist_locked(Subscription& sub) noexcept {
  sub.listening = false;
  auto it = channels_.find(sub.channel);
  if (it == channels_.end()) return;
  std::erase_if(it->second, [&](const auto& s) { return s.get() == &sub; });
  if (it->second.empty()) channels_.erase(it);
}

// On the receive thread, inside the native receiver's drain: listeners may open or close
// endpoints meanwhile (the table changes; the copy walked here does not).
void Engine::dispatch_native_locked(const UdpmMessage& m) noexcept {
  auto it = channels_.find(m.channel);
  if (it == channels_.end()) return;  // our own datagrams of a channel nobody here reads, say
  try {
    scratch_.assign(it->second.begin(), it->second.end());
  } catch (...) {
    return;
  }
  for (const auto& sub : scratch_)  // the copy holds each alive (no shared_from_this per message)
    if (sub->gate.is_open() && !sub->paused.load(std::memory_order_acquire)) deliver(sub, m.data, m.recv_utime);
  scratch_.clear();
}

// Called with handle_mutex_ held. Listener code may open or close endpoints meanwhile.
void Engine::report_all_locked(const std::function<std::string()>& make_message) noexcept {
  std::vector<std::shared_ptr<Subscription>> subs;
  std::string message;
  try {
    subs = subs_;
    message = make_message();
  } catch (...) {
    return;
  }
  for (const auto& sub : subs) sub->report(message);
}

void Engine::loop() noexcept {
  tl_receive_engine = this;
  bool lcm_open = true;  // false once lcm_handle failed: do not spin on a descriptor that stays readable
  std::uint64_t open_gen = 0;  // the receiving instance lcm_open is about
  last_drop_check_ = std::chrono::steady_clock::now();
  while (!stop_.load(std::memory_order_acquire)) {
    // The instance (its generation) first, then its descriptor: a descriptor number can come
    // back for the next instance, the generation cannot.
    const std::uint64_t gen = recv_gen_.load(std::memory_order_acquire);
    const int lcm_fd = lcm_fd_.load(std::memory_order_acquire);  // -1 while no endpoint receives
    if (gen != open_gen) {
      open_gen = gen;
      lcm_open = true;  // a new instance
    }
    const bool poll_lcm = lcm_open && lcm_fd >= 0;
    pollfd fds[2] = {{event_fd_, POLLIN, 0}, {lcm_fd, POLLIN, 0}};
    // The native receiver has nothing to do on a timer (its drops come with the datagrams).
    const int n = ::poll(fds, poll_lcm ? 2 : 1, native() ? kNativePollTimeoutMs : kPollTimeoutMs);
    if (n < 0 && errno != EINTR) {
      const int err = errno;
      std::unique_lock lock = lock_for_dispatch();
      report_all_locked([&] {
        return "LCM URL '" + url_ + "': the receive thread stopped: poll() failed: " + std::strerror(err) +
               "; no more samples will arrive";
      });
      break;
    }
    if (n > 0 && (fds[0].revents & POLLIN) != 0) {
      std::uint64_t value = 0;
      [[maybe_unused]] const ssize_t r = ::read(event_fd_, &value, sizeof value);
    }
    if (stop_.load(std::memory_order_acquire)) break;
    if (n > 0 && poll_lcm && native() && (fds[1].revents & (POLLIN | POLLERR)) != 0) {
      std::unique_lock lock = lock_for_dispatch();
      // The receiver may have gone (nobody receives any more) while we polled its socket.
      if (rx_ == nullptr || recv_gen_.load(std::memory_order_relaxed) != gen) continue;
      in_handle_ = true;
      const auto lost = rx_->drain([this](const UdpmMessage& m) { dispatch_native_locked(m); }, 64);
      in_handle_ = false;
      if (lost.kernel != 0) report_kernel_drops_locked(lost.kernel);
      if (lost.network != 0) report_network_losses_locked(lost.network);
      run_deferred_locked();
      continue;  // no lcm_handle, no /proc look: the socket says what it lost
    }
    if (n > 0 && poll_lcm && (fds[1].revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
      std::unique_lock lock = lock_for_dispatch();
      // The instance may have gone (nobody receives any more) while we polled its descriptor.
      if (recv_ == nullptr || recv_gen_.load(std::memory_order_relaxed) != gen) continue;
      in_handle_ = true;
      const int rc = lcm_handle(recv_);  // dispatches one message; the fd said one is queued
      in_handle_ = false;
      if (rc != 0) {
        lcm_open = false;
        // A log read to its end (file://, mode r) is not an error.
        if (!(info_.provider == Provider::File && info_.file_read))
          report_all_locked([&] {
            return "LCM URL '" + url_ + "': lcm_handle() failed (liblcm printed the reason on stderr); " +
                   "no more samples will arrive through this transport";
          });
      }
      run_deferred_locked();
    }
    account_drops();
  }
  {
    std::unique_lock lock(handle_mutex_);
    run_deferred_locked();
  }
  tl_receive_engine = nullptr;
}

// Reads the kernel's drops counter of the LCM receive socket; reports increases.
void Engine::account_drops() noexcept {
  const auto now = std::chrono::steady_clock::now();
  if (now - last_drop_check_ < kDropCheckPeriod) return;
  last_drop_check_ = now;
  if (lcm_fd_.load(std::memory_order_relaxed) < 0) return;  // nothing receives
  std::unique_lock lock = lock_for_dispatch();  // the socket changes with the receiving instance
  if (drop_inode_ == 0) return;
  std::optional<std::uint32_t> drops;
  try {
    drops = socket_drops(drop_inode_, udp_table_);
  } catch (...) {
    return;
  }
  if (!drops) return;
  const std::uint32_t delta = *drops - last_drops_;  // the counter is 32-bit and wraps
  last_drops_ = *drops;
  if (delta == 0) return;
  report_kernel_drops_locked(delta);
  run_deferred_locked();
}

void Engine::report_kernel_drops_locked(std::uint64_t delta) noexcept {
  report_lost_locked(delta, &Subscription::kernel_lost, [this](std::uint64_t total) {
    return "LCM URL '" + url_ + "': the kernel dropped " + std::to_string(total) +
           " datagram(s) so far on the receive socket, whose buffer was full (LCM does not say of which channel: "
           "every LCM topic of the process counts them in dropped_count()); large or bursty messages need a larger "
           "buffer: ?recv_buf_size=N in the URL and sysctl net.core.rmem_max";
  });
}

void Engine::report_network_losses_locked(std::uint64_t delta) noexcept {
  report_lost_locked(delta, &Subscription::network_lost, [this](std::uint64_t total) {
    return "LCM URL '" + url_ + "': " + std::to_string(total) +
           " message(s) from other hosts never arrived whole so far (gaps in their senders' sequence numbers, "
           "fragments missing: the network lost them; LCM does not say of which channel: every LCM topic of the "
           "process counts them in dropped_count())";
  });
}

// Every receiving subscription counts `delta` in its dropped_count and in `counter`, and logs
// the first time and every 4096.
void Engine::report_lost_locked(std::uint64_t delta, std::uint64_t Subscription::*counter,
                                const std::function<std::string(std::uint64_t)>& message) noexcept {
  std::vector<std::shared_ptr<Subscription>> subs;
  try {
    subs = subs_;
  } catch (...) {
    return;
  }
  for (const auto& sub : subs) {
    // A paused endpoint (nobody in the process reads it) loses nothing it wanted.
    sub->gate.run([&](net::EndpointGate::Calls& calls) {
      if (sub->paused.load(std::memory_order_acquire)) return;
      calls.lost(delta);
      std::uint64_t& total = (*sub).*counter;
      const std::uint64_t before = total;
      total += delta;
      if (before == 0 || before / 4096 != total / 4096) calls.error(message(total));
    });
  }
}

}  // namespace horus::lcm::detail

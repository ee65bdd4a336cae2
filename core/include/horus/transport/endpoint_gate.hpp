// The endpoint gate: how a transport calls an endpoint's net::Listener.
//
// The rules of horus/network.hpp, in one place for every transport:
//  - one call at a time per endpoint: run() waits for a thread inside, drain() leaves the work
//    to it;
//  - none after close(): once close() has returned, no listener call begins, and a call in
//    progress on another thread has ended (close() waits for it);
//  - closing from inside the endpoint's own callback (the listener destroys its endpoint): close()
//    then returns at once, the call in progress finishes, and the Calls it holds make no further
//    listener call;
//  - no exception reaches the transport's threads: a throwing on_sample() is reported through
//    on_error(), a throwing on_error() or on_lost() is dropped.
// The gate does not own the endpoint: a transport keeps the gate in a shared object (held by
// the endpoint and by whatever its threads hold), so that the last reference may be dropped on
// the transport's own thread, e.g. when a listener closed its endpoint from a callback.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>

#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::net {

class EndpointGate {
 public:
  /// `label` starts every message the gate writes ("topic 'a.b' (DDS topic 'horus/a/b')").
  EndpointGate(Listener& listener, std::string label);
  EndpointGate(const EndpointGate&) = delete;
  EndpointGate& operator=(const EndpointGate&) = delete;

  const std::string& label() const noexcept { return label_; }

  /// The listener calls a thread may make while it is inside the gate.
  class Calls {
   public:
    /// Hands a sample over; an exception the listener throws becomes an on_error()
    /// "<label>: the sample handler failed[: <what>]".
    void sample(const Sample& sample) noexcept;
    void error(std::string_view message) noexcept;
    void lost(std::uint64_t count) noexcept;
    void matched() noexcept;
    /// Listener::room() (0 after close, or when it throws).
    std::size_t room() noexcept;
    /// False once the endpoint was closed (from inside this very call).
    bool open() const noexcept { return gate_.is_open(); }

   private:
    friend class EndpointGate;
    explicit Calls(EndpointGate& gate) noexcept : gate_(gate) {}
    EndpointGate& gate_;
  };

  /// Runs `body(Calls&)` inside the gate unless it is closed; waits while another thread is
  /// inside. On a thread already inside (a nested call from the listener), runs it at once.
  template <class Body>
  void run(Body&& body) noexcept {
    const auto self = std::this_thread::get_id();
    if (owner_.load(std::memory_order_acquire) == self) {
      if (is_open()) invoke(body);
      return;
    }
    std::lock_guard lock(mutex_);
    if (!is_open()) return;
    owner_.store(self, std::memory_order_release);
    invoke(body);
    owner_.store(std::thread::id{}, std::memory_order_release);
  }

  /// Never waits: notes that there is work, and runs `body(Calls&)` unless another thread is
  /// inside the gate, in which case that thread runs it again before it leaves. For transports
  /// that call back on threads which must not block (Fast DDS).
  template <class Body>
  void drain(Body&& body) noexcept {
    const auto self = std::this_thread::get_id();
    pending_.store(true, std::memory_order_release);
    if (owner_.load(std::memory_order_acquire) == self) return;  // the loop below picks it up
    for (;;) {
      {
        std::unique_lock lock(mutex_, std::try_to_lock);
        if (!lock.owns_lock()) return;  // the thread inside sees pending_ after it unlocks
        owner_.store(self, std::memory_order_release);
        while (pending_.exchange(false, std::memory_order_acq_rel))
          if (is_open()) invoke(body);
        owner_.store(std::thread::id{}, std::memory_order_release);
      }
      if (!pending_.load(std::memory_order_acquire)) return;
    }
  }

  /// After this returns no listener call begins. Waits for a call in progress on another
  /// thread; from inside the endpoint's own call, returns at once.
  void close() noexcept;

  bool is_open() const noexcept { return open_.load(std::memory_order_acquire); }
  /// True on the thread that is inside the gate.
  bool inside() const noexcept { return owner_.load(std::memory_order_acquire) == std::this_thread::get_id(); }

 private:
  template <class Body>
  void invoke(Body& body) noexcept {
    Calls calls(*this);
    try {
      body(calls);
    } catch (...) {  // out of memory building a message: nothing sensible to do on this thread
    }
  }

  Listener& listener_;
  const std::string label_;
  std::mutex mutex_;                             // held by the thread inside
  std::atomic<std::thread::id> owner_{};         // the thread inside, if any
  std::atomic<bool> pending_{false};             // drain(): work noted
  std::atomic<bool> open_{true};
};

}  // namespace horus::net

HORUS_API_END

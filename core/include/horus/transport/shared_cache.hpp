// The per-configuration transport cache: one instance (a DDS participant, an lcm_t with its
// receive thread) per key and process, shared by every topic that uses that key.
//
// The shutdown rule, the same for every transport:
//  - What keeps an instance alive: the shared_ptrs handed out by get(), i.e. the Transport
//    handles and every Endpoint opened on it (each holds one). The cache itself holds only a
//    weak reference: it never keeps an instance alive.
//  - When it is destroyed: when the last of those references is dropped, i.e. when the last
//    topic on it closes. A get() for its key after that creates a new instance, but only once
//    the old one's destructor has finished (the instance owns its CacheTicket, destroyed last,
//    which removes the entry): a get() meanwhile waits up to 10 s, then fails with
//    Errc::Timeout. So a key never has two instances at once (a DDS domain id is free again,
//    a multicast socket closed).
//  - Which thread destroys it: whichever drops the last reference; an application thread
//    closing its last topic, or a transport's own thread when a listener closes the last topic
//    from inside its callback. The instance's destructor must cope with the latter (LCM
//    detaches its receive thread instead of joining itself). Never under the cache's lock:
//    get() drops the references it takes only after unlocking.
//  - Creation: under the cache's lock, so one instance is created at a time per cache.
//  - On fork(): nothing happens. A child inherits the entries and the instances (copies whose
//    threads stay in the parent); it must neither use them nor destroy them. api/ refuses
//    network topics in a forked child and never drops a forked copy's references
//    (api/src/topic_core.cpp, fleet/src/bridge.cpp); a program that calls a transport directly after fork() must exec.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include "horus/detail/process.hpp"
#include "horus/error.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::net {

class SharedCacheBase;

/// Owned by a cached instance (as its first member, or a base: destroyed last). Removes the
/// instance's entry when destroyed, once the instance is registered; before that (a creation
/// that fails) it does nothing.
class CacheTicket {
 public:
  CacheTicket() = default;
  CacheTicket(CacheTicket&& other) noexcept;
  CacheTicket& operator=(CacheTicket&&) = delete;
  ~CacheTicket();

 private:
  friend class SharedCacheBase;
  struct State;
  std::shared_ptr<State> state_;
};

/// The type-erased part (see SharedCache<T>).
class SharedCacheBase {
 public:
  using Create = std::function<Result<std::shared_ptr<void>>(CacheTicket ticket)>;
  SharedCacheBase();
  SharedCacheBase(const SharedCacheBase&) = delete;
  SharedCacheBase& operator=(const SharedCacheBase&) = delete;

 protected:
  ~SharedCacheBase() = default;  // never runs: a cache lives as long as the process (instance())
  Result<std::shared_ptr<void>> get_erased(std::string_view key, const Create& create, std::string_view timeout_message);

 private:
  friend class CacheTicket;
  struct Entry {
    std::weak_ptr<void> instance;
    std::shared_ptr<CacheTicket::State> ticket;
  };
  void release(const std::shared_ptr<CacheTicket::State>& ticket) noexcept;

  std::mutex mutex_;
  std::condition_variable changed_;  // an entry was removed
  std::map<std::string, Entry, std::less<>> entries_;
};

template <class T>
class SharedCache final : public SharedCacheBase {
 public:
  /// The live instance of `key`, or the one `create(CacheTicket)` makes (it hands the ticket to
  /// the instance). `timeout_message` is the error when the previous instance of `key` is still
  /// being destroyed after 10 s.
  template <class Create>
  Result<std::shared_ptr<T>> get(std::string_view key, Create&& create, std::string_view timeout_message) {
    auto got = get_erased(
        key,
        [&](CacheTicket ticket) -> Result<std::shared_ptr<void>> {
          Result<std::shared_ptr<T>> made = create(std::move(ticket));
          if (!made) return std::unexpected(std::move(made.error()));
          return std::shared_ptr<void>(std::move(*made));
        },
        timeout_message);
    if (!got) return std::unexpected(std::move(got.error()));
    return std::static_pointer_cast<T>(std::move(*got));
  }

  /// The process's cache of T (a part of the process context, never ended: an endpoint that
  /// closes during static destruction still finds its transport). T::kCacheName names it.
  static constexpr horus::detail::PartSpec kPart{T::kCacheName, horus::detail::PartLifetime::Process,
                                                 "an endpoint closing during static destruction finds its transport"};
  static SharedCache& instance() { return horus::detail::Process::part<SharedCache>(); }

 private:
  friend class horus::detail::Process;
  SharedCache() = default;
};

}  // namespace horus::net

HORUS_API_END

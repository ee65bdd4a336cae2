#include "horus/transport/shared_cache.hpp"

#include <atomic>
#include <utility>

namespace horus::net {

struct CacheTicket::State {
  SharedCacheBase* cache = nullptr;
  std::string key;
  std::atomic<bool> armed{false};  // the entry is in the cache (set under its lock)
};

CacheTicket::CacheTicket(CacheTicket&& other) noexcept : state_(std::move(other.state_)) {}

CacheTicket::~CacheTicket() {
  if (state_ && state_->armed.load(std::memory_order_acquire)) state_->cache->release(state_);
}

SharedCacheBase::SharedCacheBase() = default;

void SharedCacheBase::release(const std::shared_ptr<CacheTicket::State>& ticket) noexcept {
  {
    std::lock_guard lock(mutex_);
    auto it = entries_.find(ticket->key);
    if (it != entries_.end() && it->second.ticket == ticket) entries_.erase(it);
  }
  changed_.notify_all();
}

Result<std::shared_ptr<void>> SharedCacheBase::get_erased(std::string_view key, const Create& create,
                                                          std::string_view timeout_message) {
  std::shared_ptr<void> existing;  // declared before the lock: released after it
  std::unique_lock lock(mutex_);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (;;) {
    auto it = entries_.find(key);
    if (it == entries_.end()) break;
    existing = it->second.instance.lock();
    if (existing) return existing;
    // The last user just released it: wait until its destructor has finished.
    if (changed_.wait_until(lock, deadline) == std::cv_status::timeout && entries_.find(key) != entries_.end())
      return fail(Errc::Timeout, std::string(timeout_message));
  }
  auto state = std::make_shared<CacheTicket::State>();
  state->cache = this;
  state->key = std::string(key);
  CacheTicket ticket;
  ticket.state_ = state;
  auto created = create(std::move(ticket));  // a failed creation drops the ticket unarmed
  if (!created) return std::unexpected(std::move(created.error()));
  entries_.insert_or_assign(state->key, Entry{*created, state});
  state->armed.store(true, std::memory_order_release);
  return std::move(*created);
}

}  // namespace horus::net

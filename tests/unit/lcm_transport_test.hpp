// What the LCM transport's unit tests (unit/test_lcm_transport.cpp, unit/test_lcm_udpm.cpp, one
// binary) share: includes, a listener that collects what an endpoint reports, byte patterns, a
// channel per test process, sending and opening endpoints.
#pragma once

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "horus/lcm/transport.hpp"
#include "horus/network.hpp"

namespace {

using namespace std::chrono_literals;
using horus::Errc;
using horus::net::Endpoint;
using horus::net::EndpointSpec;
using horus::net::Transport;
using Clock = std::chrono::steady_clock;

/// Collects what an endpoint reports.
class Collector final : public horus::net::Listener {
 public:
  void on_sample(const horus::net::Sample& sample) override {
    std::lock_guard lock(mutex_);
    samples_.emplace_back(sample.body.begin(), sample.body.end());
    little_endian_seen_ = little_endian_seen_ || sample.little_endian;
    changed_.notify_all();
  }
  void on_error(std::string_view message) override {
    std::lock_guard lock(mutex_);
    errors_.emplace_back(message);
    changed_.notify_all();
  }
  void on_lost(std::uint64_t count) override {
    std::lock_guard lock(mutex_);
    lost_ += count;
    changed_.notify_all();
  }

  /// Waits until `pred(samples)` holds or the timeout passes; returns whether it held.
  template <class Pred>
  bool wait_until(Pred pred, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return pred(samples_); });
  }
  bool wait_for_count(std::size_t n, std::chrono::milliseconds timeout) {
    return wait_until([n](const auto& s) { return s.size() >= n; }, timeout);
  }
  /// Waits until at least `n` messages were reported lost or the timeout passes.
  bool wait_for_lost(std::chrono::milliseconds timeout, std::uint64_t n = 1) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return lost_ >= n; });
  }
  std::vector<std::vector<std::byte>> samples() const {
    std::lock_guard lock(mutex_);
    return samples_;
  }
  std::size_t count() const {
    std::lock_guard lock(mutex_);
    return samples_.size();
  }
  std::uint64_t lost() const {
    std::lock_guard lock(mutex_);
    return lost_;
  }
  std::vector<std::string> errors() const {
    std::lock_guard lock(mutex_);
    return errors_;
  }
  bool little_endian_seen() const {
    std::lock_guard lock(mutex_);
    return little_endian_seen_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::vector<std::byte>> samples_;
  std::vector<std::string> errors_;
  std::uint64_t lost_ = 0;
  bool little_endian_seen_ = false;
};

inline std::vector<std::byte> bytes_of(std::string_view text) {
  std::vector<std::byte> out(text.size());
  if (!text.empty()) std::memcpy(out.data(), text.data(), text.size());
  return out;
}

inline std::vector<std::byte> pattern(std::size_t size, std::uint32_t seed) {
  std::vector<std::byte> out(size);
  std::uint32_t x = seed * 2654435761u + 1;
  for (auto& b : out) {
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    b = static_cast<std::byte>(x);
  }
  return out;
}

inline horus::Result<void> send(Endpoint& endpoint, std::span<const std::byte> body) {
  const horus::net::BodyWriter writer{
      [](void* context, std::span<std::byte> out) {
        const auto* src = static_cast<const std::span<const std::byte>*>(context);
        if (!out.empty()) std::memcpy(out.data(), src->data(), out.size());
      },
      &body};
  return endpoint.write(body.size(), writer);
}

inline EndpointSpec spec(const std::string& channel) {
  EndpointSpec s;
  s.topic = channel;
  s.wire_topic = channel;
  s.type_name = "test::Bytes";
  s.type_hash = 1;
  return s;
}

/// A channel name unique to this process.
inline std::string channel(std::string_view base) {
  return "horus/test/" + std::to_string(::getpid()) + "/" + std::string(base);
}

inline std::unique_ptr<Endpoint> open_endpoint(Transport& transport, const std::string& channel_name,
                                               horus::net::Listener& listener) {
  auto endpoint = transport.open(spec(channel_name), listener);
  EXPECT_TRUE(endpoint) << (endpoint ? "" : endpoint.error().message());
  return endpoint ? std::move(*endpoint) : nullptr;
}

}  // namespace

// Shared helpers of the tests: a checkable test message, deadlines, a publisher on a thread, a
// temporary file.
#pragma once

#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>

#include "horus/reflect.hpp"

namespace horus_test {

/// A message whose payload can be checked for tearing: every word derives from (publisher, seq).
struct Stamp {
  std::uint32_t publisher{};
  std::uint32_t spare{};
  std::uint64_t seq{};
  std::array<std::uint64_t, 5> body{};
  std::uint64_t check{};

  static constexpr std::uint64_t mix(std::uint64_t x) noexcept {
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    return x;
  }
  static Stamp make(std::uint32_t publisher, std::uint64_t seq) noexcept {
    Stamp s;
    s.publisher = publisher;
    s.seq = seq;
    std::uint64_t sum = publisher;
    for (std::size_t i = 0; i < s.body.size(); ++i) {
      s.body[i] = mix(seq * 31 + i + (static_cast<std::uint64_t>(publisher) << 40));
      sum += s.body[i];
    }
    s.check = mix(sum ^ seq);
    return s;
  }
  bool intact() const noexcept {
    std::uint64_t sum = publisher;
    for (std::size_t i = 0; i < body.size(); ++i) {
      if (body[i] != mix(seq * 31 + i + (static_cast<std::uint64_t>(publisher) << 40))) return false;
      sum += body[i];
    }
    return check == mix(sum ^ seq);
  }
};
HORUS_REFLECT(Stamp, publisher, spare, seq, body, check)

/// A second type, for type-mismatch tests.
struct Other {
  double value{};
};
HORUS_REFLECT(Other, value)

/// A per-test unique topic name, so tests never share rings by accident.
inline std::string unique_name(const std::string& base) {
  static std::atomic<int> n{0};
  // The pid keeps names apart between test processes running at once: shared-memory topics
  // are visible to every process of the host.
  return "test." + base + "." + std::to_string(::getpid()) + "." + std::to_string(n.fetch_add(1));
}

/// Deadline for loops in tests: they never spin forever.
class Deadline {
 public:
  explicit Deadline(std::chrono::milliseconds d) : end_(std::chrono::steady_clock::now() + d) {}
  bool expired() const { return std::chrono::steady_clock::now() >= end_; }

 private:
  std::chrono::steady_clock::time_point end_;
};

/// Waits for a condition instead of a fixed time: calls `done()` until it is true (then true at
/// once) or `timeout` passed (false: the caller's assertion says what did not happen). Polls
/// every `poll`, so a test waits as long as the condition takes and no longer.
template <class Predicate>
bool eventually(Predicate done, std::chrono::milliseconds timeout,
                std::chrono::milliseconds poll = std::chrono::milliseconds(2)) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(poll);
  }
}

// Calls send() every `period` on another thread until destroyed (a live publisher for a
// tool or a server under test). The period is kept by waiting for the stop, so the destructor
// ends it at once.
class Publishing {
 public:
  template <class Send>
  Publishing(std::chrono::milliseconds period, Send send)
      : thread_([this, period, send]() mutable {
          std::unique_lock lock(mutex_);
          for (int i = 0; !stop_; ++i) {
            lock.unlock();
            send(i);
            lock.lock();
            stopped_.wait_for(lock, period, [this] { return stop_; });
          }
        }) {}
  ~Publishing() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    stopped_.notify_all();
    thread_.join();
  }

 private:
  std::mutex mutex_;
  std::condition_variable stopped_;
  bool stop_ = false;
  std::thread thread_;  // last: started once the members it uses exist
};

// A file in the test's temporary directory ($TMPDIR, else /tmp) holding `text`, removed at the
// end; a new path for each (HORUS_CONFIG is read once per value).
struct TempFile {
  std::string path;
  explicit TempFile(const std::string& text, const std::string& suffix = ".yaml") {
    static std::atomic<int> n{0};
    const char* dir = std::getenv("TMPDIR");
    path = std::string(dir != nullptr ? dir : "/tmp") + "/horus_test_file_" + std::to_string(::getpid()) + "_" +
           std::to_string(++n) + suffix;
    std::ofstream(path) << text;
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile() { std::remove(path.c_str()); }
};

}  // namespace horus_test

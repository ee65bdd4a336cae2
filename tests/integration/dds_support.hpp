// Helpers of the DDS tests: a peer process, topic options for a backend, and a round trip of
// every type of a list through an echoing peer.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "message_samples.hpp"

extern char** environ;

namespace horus_test {

using Backend = horus::Backend;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

inline std::string short_name(std::string_view q) { return std::string(q.substr(q.rfind("::") + 2)); }

inline horus::TopicOptions on(Backend b) {
  horus::TopicOptions o;
  o.backend = b;
  return o;
}

/// A peer process: stdin is a pipe (closing it stops the peer), its stdout says "ready".
/// `program` runs with `args` and the environment, HORUS_BACKEND replaced by `backend`'s name.
class Peer {
 public:
#ifdef HORUS_DDS_PEER
  Peer(Backend backend, std::vector<std::string> args) : Peer(HORUS_DDS_PEER, backend, std::move(args)) {}
#endif
  Peer(const std::string& program, Backend backend, std::vector<std::string> args) {
    int in[2], out[2];
    EXPECT_EQ(::pipe(in), 0);
    EXPECT_EQ(::pipe(out), 0);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, in[0], 0);
    posix_spawn_file_actions_adddup2(&fa, out[1], 1);
    posix_spawn_file_actions_addclose(&fa, in[1]);
    posix_spawn_file_actions_addclose(&fa, out[0]);
    std::vector<std::string> env_strings{"HORUS_BACKEND=" + std::string(horus::to_string(backend))};
    for (char** e = environ; *e != nullptr; ++e)
      if (std::string_view(*e).rfind("HORUS_BACKEND=", 0) != 0) env_strings.emplace_back(*e);
    std::vector<char*> env;
    for (auto& s : env_strings) env.push_back(s.data());
    env.push_back(nullptr);
    args.insert(args.begin(), program);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    EXPECT_EQ(::posix_spawn(&pid_, program.c_str(), &fa, nullptr, argv.data(), env.data()), 0);
    posix_spawn_file_actions_destroy(&fa);
    ::close(in[0]);
    ::close(out[1]);
    stdin_ = in[1];
    stdout_ = out[0];
  }
  ~Peer() { stop(); }
  Peer(const Peer&) = delete;
  Peer& operator=(const Peer&) = delete;

  // Waits for the peer's "ready" line.
  bool ready(std::chrono::milliseconds timeout = 30s) {
    std::string got;
    const auto deadline = Clock::now() + timeout;
    while (Clock::now() < deadline) {
      pollfd p{stdout_, POLLIN, 0};
      if (::poll(&p, 1, 50) > 0) {
        char buf[64];
        const auto n = ::read(stdout_, buf, sizeof(buf));
        if (n <= 0) return false;
        got.append(buf, static_cast<std::size_t>(n));
        if (got.find("ready\n") != std::string::npos) return true;
      }
    }
    return false;
  }

  // Closes its stdin and waits (at most 10 s, then SIGKILL); the exit status.
  int stop() {
    if (pid_ <= 0) return status_;
    ::close(stdin_);
    ::close(stdout_);
    const auto deadline = Clock::now() + 10s;
    int st = 0;
    while (::waitpid(pid_, &st, WNOHANG) == 0) {
      if (Clock::now() > deadline) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, &st, 0);
        break;
      }
      std::this_thread::sleep_for(5ms);
    }
    pid_ = -1;
    status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    return status_;
  }

 private:
  pid_t pid_ = -1;
  int stdin_ = -1;
  int stdout_ = -1;
  int status_ = -1;
};

/// Sends a sample of every type of the list on <prefix>.<Type> and expects it back, equal
/// field for field, on <prefix>.<Type>.echo (from an echoing peer); the failures, one per type.

template <class T>
struct RoundTrip {
  std::optional<horus::Topic<T>> out;
  std::optional<horus::Topic<T>> back;
  T sent = horus_test::topic_sample<T>();
  bool done = false;
  std::string failure;
};

template <class... T>
std::vector<std::string> round_trip_all(Backend mine, const std::string& prefix, horus::msg::TypeList<T...>) {
  std::tuple<RoundTrip<T>...> trips;
  std::vector<std::string> failures;
  auto open = [&]<class M>(RoundTrip<M>& r) {
    const std::string base = prefix + "." + short_name(horus::type_name<M>());
    auto out = horus::Topic<M>::open(base, on(mine));
    auto back = horus::Topic<M>::open(base + ".echo", on(mine));
    if (!out || !back) {
      failures.push_back(short_name(horus::type_name<M>()) + ": " + (!out ? out.error() : back.error()).message());
      r.done = true;
      return;
    }
    r.out.emplace(std::move(*out));
    r.back.emplace(std::move(*back));
  };
  std::apply([&](auto&... r) { (open(r), ...); }, trips);
  // Send every 300 ms until the echo comes back (best-effort types may lose a sample while
  // discovery completes), for at most 90 s.
  const auto deadline = Clock::now() + 90s;
  auto last_send = Clock::now() - 1s;
  std::size_t pending = sizeof...(T);
  while (pending > 0 && Clock::now() < deadline) {
    const bool resend = Clock::now() - last_send > 300ms;
    if (resend) last_send = Clock::now();
    pending = 0;
    auto step = [&]<class M>(RoundTrip<M>& r) {
      if (r.done) return;
      if (resend) r.out->send(r.sent);
      while (auto got = r.back->recv()) {
        if (auto same = horus_test::SameMessage(*got, r.sent); !same) r.failure = same.message();
        r.done = true;
      }
      if (!r.done) ++pending;
    };
    std::apply([&](auto&... r) { (step(r), ...); }, trips);
    std::this_thread::sleep_for(2ms);
  }
  auto collect = [&]<class M>(RoundTrip<M>& r) {
    const auto name = short_name(horus::type_name<M>());
    if (!r.done) failures.push_back(name + ": no echo within 90 s");
    else if (!r.failure.empty()) failures.push_back(name + ": came back different: " + r.failure);
  };
  std::apply([&](auto&... r) { (collect(r), ...); }, trips);
  return failures;
}

}  // namespace horus_test

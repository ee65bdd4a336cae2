// Helpers of the DDS and LCM tests: a peer process and topic options for a backend. The round
// trip of every type through an echoing peer is in message_trips.hpp (compiled once).
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
#include <string_view>
#include <thread>
#include <tuple>
#include <vector>

#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "message_trips.hpp"
#include "message_samples.hpp"
#include "test_support.hpp"

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
/// `program` runs with `args` and the environment, HORUS_BACKEND replaced by `backend`'s name
/// and HORUS_NAMESPACE by one of its own (it stands for another host), plus `more_env`
/// ("NAME=value" each).
class Peer {
 public:
#ifdef HORUS_DDS_PEER
  Peer(Backend backend, std::vector<std::string> args) : Peer(HORUS_DDS_PEER, backend, std::move(args)) {}
#endif
  Peer(const std::string& program, Backend backend, std::vector<std::string> args, std::vector<std::string> more_env = {}) {
    int in[2], out[2];
    EXPECT_EQ(::pipe(in), 0);
    EXPECT_EQ(::pipe(out), 0);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, in[0], 0);
    posix_spawn_file_actions_adddup2(&fa, out[1], 1);
    posix_spawn_file_actions_addclose(&fa, in[1]);
    posix_spawn_file_actions_addclose(&fa, out[0]);
    // Another host as far as horus can tell: its own shared-memory namespace, so it meets this
    // process through the network backend and not in /dev/shm (a fleet topic would otherwise
    // take the shared-memory path between them).
    std::vector<std::string> env_strings{"HORUS_BACKEND=" + std::string(horus::to_string(backend)),
                                         "HORUS_NAMESPACE=peer" + std::to_string(::getpid())};
    env_strings.insert(env_strings.end(), more_env.begin(), more_env.end());
    for (char** e = environ; *e != nullptr; ++e) {
      const std::string_view v(*e);
      if (v.rfind("HORUS_BACKEND=", 0) != 0 && v.rfind("HORUS_NAMESPACE=", 0) != 0) env_strings.emplace_back(*e);
    }
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

  // Writes `text` to its stdin ('q' there means quit).
  bool say(std::string_view text) { return ::write(stdin_, text.data(), text.size()) == static_cast<ssize_t>(text.size()); }

  // Waits until it exits on its own (at most `timeout`): true once it has (stop() then gives its
  // status at once), false while it still runs.
  bool exited(std::chrono::milliseconds timeout) {
    return pid_ <= 0 || eventually(
                            [&] {
                              int st = 0;
                              if (::waitpid(pid_, &st, WNOHANG) != pid_) return false;
                              pid_ = -1;
                              ::close(stdin_);
                              ::close(stdout_);
                              status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
                              return true;
                            },
                            timeout, 5ms);
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

#ifdef HORUS_FLEET_MEMBER
/// Two horus processes of one host (one shared-memory namespace, so one bridge) beside a
/// third-party program that echoes <prefix>.Pose2D on <prefix>.Pose2D.echo (already running):
/// one process publishes 200 numbered Pose2D, the other reads them (each once, from shared
/// memory) and a third reads the echoes (each once: the third-party program got each message
/// once, and what it sent reached the host once). Returns what went wrong.
inline std::vector<std::string> same_host_exactly_once(Backend backend, const std::string& prefix) {
  const std::string topic = prefix + ".Pose2D";
  const std::string start = std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                                               (std::chrono::system_clock::now() + 3s).time_since_epoch())
                                               .count());
  Peer publisher(HORUS_FLEET_MEMBER, backend, {topic, "fleet", "1", "200", start, "1", "30"});
  Peer reader(HORUS_FLEET_MEMBER, backend, {topic, "fleet", "0", "200", start, "1", "30"});
  Peer echoes(HORUS_FLEET_MEMBER, backend, {topic + ".echo", "fleet", "0", "200", start, "1", "30"});
  // They publish, read and exit on their own: at most <seconds> (30) after they started.
  for (Peer* p : {&publisher, &reader, &echoes}) (void)p->exited(40s);
  std::vector<std::string> failures;
  if (const int rc = publisher.stop(); rc != 0) failures.push_back("the publisher (and reader of its own) exited " + std::to_string(rc));
  if (const int rc = reader.stop(); rc != 0) failures.push_back("the other process did not get each message once (exit " + std::to_string(rc) + ")");
  if (const int rc = echoes.stop(); rc != 0) failures.push_back("the echoes did not arrive each once (exit " + std::to_string(rc) + ")");
  return failures;
}
#endif

}  // namespace horus_test

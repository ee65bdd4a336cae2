// Helpers of the multi-process tests: run a function in a child process, wait for it with a
// deadline (tests never hang), and a pipe to say "ready" between parent and child.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "horus/shm/shm_segment.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

namespace horus_test {

/// Runs a shell command; its standard output and error in `out`, its exit status returned (-1
/// when it did not exit normally).
inline int run_command(const std::string& cmd, std::string& out) {
  out.clear();
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (p == nullptr) return -1;
  char buf[4096];
  while (std::fgets(buf, sizeof(buf), p) != nullptr) out += buf;
  const int status = ::pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// A fixture for shared-memory tests between processes: HORUS_BACKEND unset, and after each
/// test no segment this process made (topic names hold the pid) is left in /dev/shm.
class ShmProcessTest : public ::testing::Test {
 protected:
  void SetUp() override { ::unsetenv("HORUS_BACKEND"); }
  void TearDown() override {
    const auto ns = horus::shm::shm_namespace();
    ASSERT_TRUE(ns);
    for (const auto& s : horus::shm::list_segments(*ns))
      if (s.topic.find("." + std::to_string(::getpid()) + ".") != std::string::npos)
        ADD_FAILURE() << "left in /dev/shm: " << s.name;
  }
};

/// Runs f (returning an exit status) in a child process; an exception exits with 2.
template <class F>
pid_t spawn(F&& f) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    int rc = 1;
    try {
      rc = f();
    } catch (...) {
      rc = 2;
    }
    ::_exit(rc);
  }
  return pid;
}

// Waits for a child, at most `timeout`: then kills it and returns -2 (tests never hang).
inline int wait_for(pid_t pid, std::chrono::seconds timeout = std::chrono::seconds(60)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  for (;;) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0) return -1;
    if (std::chrono::steady_clock::now() >= deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return -2;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

/// A one-byte pipe for "ready" signals between parent and child.
struct Pipe {
  int fd[2]{-1, -1};
  Pipe() { EXPECT_EQ(::pipe(fd), 0); }
  ~Pipe() {
    ::close(fd[0]);
    ::close(fd[1]);
  }
  void signal() const { (void)!::write(fd[1], "x", 1); }
  bool wait(std::chrono::seconds timeout = std::chrono::seconds(20)) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    ::fcntl(fd[0], F_SETFL, O_NONBLOCK);
    char c;
    while (std::chrono::steady_clock::now() < deadline) {
      if (::read(fd[0], &c, 1) == 1) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return false;
  }
};

}  // namespace horus_test

// RepeatFilter (core/include/horus/detail/repeat_filter.hpp): a transport's line that repeats
// while a link is down is logged once, then again only after a quiet time, with the count held.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>

#include "horus/detail/repeat_filter.hpp"

namespace {

using horus::detail::RepeatFilter;
using namespace std::chrono_literals;

TEST(RepeatFilter, NumbersDoNotMakeALineNew) {
  EXPECT_EQ(RepeatFilter::kind_of("ddsi_udp_conn_write to udp/239.255.0.1:11651 failed with retcode -1"),
            "ddsi_udp_conn_write to udp/#.#.#.#:# failed with retcode -#");
  EXPECT_EQ(RepeatFilter::kind_of("no digits"), "no digits");
  EXPECT_EQ(RepeatFilter::kind_of(""), "");
}

TEST(RepeatFilter, ALineIsShownOnceThenAgainAfterAQuietTimeWithTheCountHeldBack) {
  RepeatFilter f(10s);
  const auto t0 = RepeatFilter::Clock::time_point{} + 1000s;
  ASSERT_EQ(f.admit("send failed", t0), 0u);
  for (int i = 1; i <= 20; ++i) EXPECT_FALSE(f.admit("send failed", t0 + i * 1s).has_value()) << i;  // every second
  EXPECT_EQ(f.admit("another line", t0 + 21s), 0u);  // a change is shown at once
  // Quiet for 10 s: shown again, with the 20 held back.
  EXPECT_EQ(f.admit("send failed", t0 + 30s), 20u);
  EXPECT_FALSE(f.admit("send failed", t0 + 31s).has_value());
}

TEST(RepeatFilter, ItKeepsABoundedNumberOfKinds) {
  RepeatFilter f(10s, 4);
  const auto t0 = RepeatFilter::Clock::time_point{} + 1000s;
  for (int i = 0; i < 4; ++i) EXPECT_EQ(f.admit("kind " + std::string(1, static_cast<char>('a' + i)), t0 + i * 1ms), 0u);
  EXPECT_EQ(f.admit("kind e", t0 + 5ms), 0u);   // forgets "kind a", the oldest
  EXPECT_EQ(f.admit("kind a", t0 + 6ms), 0u);   // new again
  EXPECT_FALSE(f.admit("kind e", t0 + 7ms).has_value());
}

// A transport's thread that logs lines of a new kind each, without pause (detached).
void start_logging_thread() {
  std::thread([] {
    for (unsigned n = 0;; ++n) {
      std::string kind = "transport line ";
      for (unsigned v = n; v != 0; v /= 26) kind.push_back(static_cast<char>('a' + v % 26));
      horus::detail::log_transport_line(spdlog::level::warn, "Test", kind);
    }
  }).detach();
}

// Waits for `child` until `limit` (waitpid has no deadline: polled); a child still running then
// is killed. Its wait status, or nothing when it had to be killed.
std::optional<int> wait_child(pid_t child, std::chrono::seconds limit) {
  int status = 0;
  const auto until = std::chrono::steady_clock::now() + limit;
  while (::waitpid(child, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() >= until) {
      ::kill(child, SIGKILL);
      ::waitpid(child, &status, 0);
      return std::nullopt;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return status;
}

// A transport's own thread logs while the process exits (Fast DDS's participant factory does,
// from its log thread, during the exit handlers): the line is dropped, the process ends with its
// status. Before, the logger's sinks were destroyed under it (SIGSEGV in 1 of ~30 `horus fleet
// --once` on Fast DDS). Each child exits while its thread logs lines of new kinds without pause.
TEST(TransportLog, AThreadThatLogsWhileTheProcessExitsDoesNotCrashIt) {
  constexpr int kChildren = 12;
  for (int i = 0; i < kChildren; ++i) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      const int null = ::open("/dev/null", O_WRONLY);
      if (null >= 0) ::dup2(null, 2);  // the lines themselves are not the point
      horus::detail::open_transport_log();
      start_logging_thread();
      std::this_thread::sleep_for(std::chrono::milliseconds(5 + i));  // exit at various points of its lines
      std::exit(7);  // the exit handlers and the statics' destructors run while the thread logs
    }
    const auto ended = wait_child(child, std::chrono::seconds(10));
    ASSERT_TRUE(ended.has_value()) << "child " << i << " did not end within 10 s of exit()";
    const int status = *ended;
    ASSERT_TRUE(WIFEXITED(status)) << "child " << i << " ended by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    EXPECT_EQ(WEXITSTATUS(status), 7) << "child " << i;
  }
}

// A process forks while a transport thread logs (spdlog holds its console lock across fork()):
// the child ends when it exits, within the exit handler's bound, instead of waiting forever for
// a lock its parent's thread held. Run in a child of its own, whose thread logs without pause.
TEST(TransportLog, AChildForkedWhileATransportThreadLogsEndsWhenItExits) {
  const pid_t parent = ::fork();
  ASSERT_GE(parent, 0);
  if (parent == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) ::dup2(null, 2);
    horus::detail::open_transport_log();
    start_logging_thread();
    for (int i = 0; i < 10; ++i) {
      const pid_t child = ::fork();
      if (child < 0) ::_exit(2);
      if (child == 0) std::exit(5);  // the exit handlers run in a copy of a process whose thread was writing
      const auto ended = wait_child(child, std::chrono::seconds(5));
      if (!ended) ::_exit(3);  // hung in exit()
      if (!WIFEXITED(*ended) || WEXITSTATUS(*ended) != 5) ::_exit(4);
    }
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(parent, &status, 0), parent);
  ASSERT_TRUE(WIFEXITED(status)) << "the forking process ended by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "3: a child hung in exit(); 4: a child did not exit with its status; 2: fork failed";
}

}  // namespace

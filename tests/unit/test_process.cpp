// The process context (core/include/horus/detail/process.hpp): the settings snapshot is read once
// and again only when the environment changed; the fork rules run the layers' handlers in
// pthread_atfork's order, and a forked child knows its own pid and fork generation.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdlib>
#include <string>

#include "horus/config.hpp"
#include "horus/detail/process.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/topic.hpp"

namespace {

using horus::detail::Process;

TEST(Process, TheSettingsSnapshotIsReadOnceAndAgainOnlyWhenTheEnvironmentChanged) {
  ::unsetenv("HORUS_BRIDGE");
  auto first = Process::get().environment();
  const std::uint64_t reads = Process::get().environment_reads();
  // Unchanged: the same snapshot, nothing read again, whoever asks (a topic's choice included).
  EXPECT_EQ(Process::get().environment().get(), first.get());
  (void)horus::backend_from_environment();
  (void)horus::fleet_transport();
  EXPECT_EQ(Process::get().environment().get(), first.get());
  EXPECT_EQ(Process::get().environment_reads(), reads);

  // A variable set, replaced, removed: each is seen by the next use.
  ::setenv("HORUS_BRIDGE", "0", 1);
  auto set = Process::get().environment();
  EXPECT_NE(set.get(), first.get());
  EXPECT_EQ(set->bridge, "0");
  ::setenv("HORUS_BRIDGE", "1", 1);
  EXPECT_EQ(Process::get().environment()->bridge, "1");
  ::unsetenv("HORUS_BRIDGE");
  EXPECT_EQ(Process::get().environment()->bridge, "");
  EXPECT_EQ(Process::get().environment_reads(), reads + 3);
  // An older snapshot stays valid for whoever holds it.
  EXPECT_EQ(set->bridge, "0");
}

TEST(Process, OpeningATopicReadsTheEnvironmentOnceForEveryLayer) {
  // The choice of scope and backend, the configuration file, the shared-memory namespace and
  // mode: each layer asks for the snapshot, and the first asks reads it.
  ::setenv("HORUS_SHM_MODE", "0600", 1);
  const std::uint64_t before = Process::get().environment_reads();
  auto topic = horus::Topic<horus::msg::Pose2D>::open("process.read_once." + std::to_string(::getpid()));
  ASSERT_TRUE(topic) << topic.error().message();
  EXPECT_EQ(Process::get().environment_reads(), before + 1);
  auto again = horus::Topic<horus::msg::Pose2D>::open("process.read_once_again." + std::to_string(::getpid()));
  ASSERT_TRUE(again) << again.error().message();
  EXPECT_EQ(Process::get().environment_reads(), before + 1);
  ::unsetenv("HORUS_SHM_MODE");
}

// What the handlers below did, in order: letters, no allocation (they run around a fork).
std::array<char, 32> g_trace{};
std::atomic<int> g_traced{0};
void trace(char c) {
  const int i = g_traced.fetch_add(1);
  if (i < static_cast<int>(g_trace.size()) - 1) g_trace[static_cast<std::size_t>(i)] = c;
}

TEST(Process, ForkHandlersRunInPthreadAtforkOrderAndAChildKnowsItsPidAndGeneration) {
  Process::get().at_fork({[] { trace('A'); }, [] { trace('a'); }, [] { trace('1'); }});
  Process::get().at_fork({[] { trace('B'); }, [] { trace('b'); }, [] { trace('2'); }});
  const std::uint32_t generation = horus::detail::fork_generation();
  const int parent = horus::detail::current_pid();
  EXPECT_EQ(parent, static_cast<int>(::getpid()));
  g_traced = 0;
  g_trace.fill('\0');
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // Prepare in reverse order of registration, then the child's handlers in order; the pid and
    // the generation were right before they ran.
    const bool order = std::string(g_trace.data()) == "BA12";
    const bool pid = horus::detail::current_pid() == static_cast<int>(::getpid()) && ::getpid() != parent;
    const bool gen = horus::detail::fork_generation() == generation + 1;
    ::_exit((order ? 0 : 1) | (pid ? 0 : 2) | (gen ? 0 : 4));
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status) & 1, 0) << "the child's handlers ran out of order";
  EXPECT_EQ(WEXITSTATUS(status) & 2, 0) << "the child's current_pid() was not its own";
  EXPECT_EQ(WEXITSTATUS(status) & 4, 0) << "the child's fork generation was not the parent's + 1";
  EXPECT_EQ(std::string(g_trace.data()), "BAab") << "prepare in reverse order, then the parent's in order";
  EXPECT_EQ(horus::detail::current_pid(), parent);
  EXPECT_EQ(horus::detail::fork_generation(), generation);
}

}  // namespace

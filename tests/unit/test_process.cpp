// The process context (core/include/horus/detail/process.hpp): the settings snapshot is read once
// and again only when the environment changed; the fork rules run the layers' handlers in
// pthread_atfork's order, and a forked child knows its own pid and fork generation; the parts are
// one per name, end at exit in the reverse order of their making (or never), and are the ones
// docs/ARCHITECTURE.md lists.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <optional>
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
  // The open takes the settings once (horus::Settings::current()) and passes them to the choice
  // of scope and backend, the placement (namespace, mode) and the fleet layer: one read.
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

// Parts a test makes: each writes its letter into the pipe when it ends.
int g_part_pipe = -1;
template <char Letter, horus::detail::PartLifetime Lifetime>
struct TestPart {
  static constexpr char kName[] = {'t', 'e', 's', 't', ' ', Letter, '\0'};
  static constexpr horus::detail::PartSpec kPart{kName, Lifetime, "a test's"};
  int value = 0;
  ~TestPart() {
    const char letter = Letter;
    if (g_part_pipe >= 0) (void)!::write(g_part_pipe, &letter, 1);
  }
};
using PartA = TestPart<'A', horus::detail::PartLifetime::UntilExit>;
using PartB = TestPart<'B', horus::detail::PartLifetime::UntilExit>;
using PartC = TestPart<'C', horus::detail::PartLifetime::Process>;

TEST(Process, APartIsOnePerNameMadeOnFirstUseAndEndsAtExitInTheReverseOrderOfItsMaking) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(fds[0]);
    g_part_pipe = fds[1];
    const std::size_t before = Process::get().parts().size();
    Process::part<PartA>().value = 1;
    Process::part<PartC>().value = 3;
    Process::part<PartB>().value = 2;
    const auto parts = Process::get().parts();
    const bool one = Process::part<PartA>().value == 1 && &Process::part<PartA>() == &Process::part<PartA>();
    const bool listed = parts.size() == before + 3 && parts[before].spec.name == "test A" &&
                        parts[before + 1].spec.name == "test C" && parts[before + 2].spec.name == "test B" &&
                        parts[before + 1].spec.lifetime == horus::detail::PartLifetime::Process;
    std::exit((one ? 0 : 1) | (listed ? 0 : 2));  // ends B, then A; never C
  }
  ::close(fds[1]);
  std::string ended;
  char c = 0;
  while (::read(fds[0], &c, 1) == 1) ended += c;
  ::close(fds[0]);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status) & 1, 0) << "part<T>() did not return the one object of its name";
  EXPECT_EQ(WEXITSTATUS(status) & 2, 0) << "parts() did not list the parts in the order of their making";
  EXPECT_EQ(ended, "BA") << "the parts that end at exit end in the reverse order of their making; the others never";
}

// Every part the library makes is in docs/ARCHITECTURE.md's table of parts, with its lifetime.
TEST(Process, EveryPartTheLibraryMakesIsListedInArchitectureMdWithItsLifetime) {
  ::setenv("HORUS_NAMESPACE", ("pp" + std::to_string(::getpid())).c_str(), 1);
  auto host = horus::Topic<horus::msg::Point3>::open("process.parts.host");
  ASSERT_TRUE(host) << host.error().message();
  std::optional<horus::Topic<horus::msg::Point3>> fleet;
  if (horus::backend_available(horus::Backend::Lcm)) {
    const int port = 20000 + static_cast<int>((::getpid() * 13 + 5) % 40000);
    ::setenv("HORUS_LCM_URL", ("udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0").c_str(), 1);
    horus::TopicOptions o;
    o.backend = horus::Backend::Lcm;
    if (auto f = horus::Topic<horus::msg::Point3>::open("process.parts.fleet", o)) fleet.emplace(std::move(*f));
  }
  std::ifstream in(HORUS_ARCHITECTURE_MD);
  ASSERT_TRUE(in) << HORUS_ARCHITECTURE_MD;
  std::stringstream text;
  text << in.rdbuf();
  // The table of parts: from its header to the first line that is not a row.
  const std::string all = text.str();
  const auto table = all.find("| part | layer | ends | why |");
  ASSERT_NE(table, std::string::npos) << "docs/ARCHITECTURE.md has no table of parts";
  const auto table_end = all.find("\n\n", table);
  const std::string doc = all.substr(table, table_end - table);
  const auto parts = Process::get().parts();
  EXPECT_GE(parts.size(), 3u);
  for (const auto& p : parts) {
    if (p.spec.name.starts_with("test ")) continue;
    const std::string lifetime = p.spec.lifetime == horus::detail::PartLifetime::UntilExit ? "at exit" : "never";
    const std::string row = "| " + std::string(p.spec.name) + " | ";
    const auto at = doc.find(row);
    ASSERT_NE(at, std::string::npos) << "docs/ARCHITECTURE.md has no row \"" << row << "...\" for the part '"
                                     << p.spec.name << "'";
    const std::string line = doc.substr(at, doc.find('\n', at) - at);
    EXPECT_NE(line.find("| " + lifetime), std::string::npos)
        << "docs/ARCHITECTURE.md's row of '" << p.spec.name << "' does not say it ends " << lifetime << ": " << line;
  }
}

}  // namespace

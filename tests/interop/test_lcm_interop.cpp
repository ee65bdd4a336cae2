// Third-party LCM programs against horus, on loopback (udpm, ttl=0, a port per test process):
//  - lcm_echo, a plain C program built at test time from `lcm-gen -c` output of horus-idlgen's
//    .lcm files (tests/interop/build_peers.cmake), decodes every message type horus sends with
//    the generated code and sends it back encoded by that code: both directions, every
//    catalogue message and the test types that use every construct;
//  - lcm-logger records horus traffic; the log holds horus's bytes; lcm-logplayer replays it
//    into a horus subscriber.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <lcm/eventlog.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "dds_support.hpp"
#include "horus/msg/all.hpp"
#include "process_support.hpp"
#include "horus/wire/lcm.hpp"
#include "test_support.hpp"
#include "wire_test_types.hpp"

extern char** environ;

namespace {

using horus::Backend;
using namespace std::chrono_literals;

std::string test_url() {
  return "udpm://239.255.76.67:" + std::to_string(20000 + (::getpid() * 7 + 3) % 20000) +
         "?ttl=0&recv_buf_size=4194304";
}

std::string tool(const char* name) {
  for (const char* dir : {"/usr/bin/", "/usr/local/bin/"}) {
    const std::string p = std::string(dir) + name;
    if (::access(p.c_str(), X_OK) == 0) return p;
  }
  return {};
}

// A child process with the test's environment; stopped with a signal, waited with a deadline.
class Child {
 public:
  explicit Child(std::vector<std::string> args) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    EXPECT_EQ(::posix_spawn(&pid_, argv[0], &fa, nullptr, argv.data(), environ), 0) << args[0];
    posix_spawn_file_actions_destroy(&fa);
  }
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  // Sends `sig` (0: none) and waits at most `timeout`; the exit code, or -1 on timeout (killed).
  int stop(int sig, std::chrono::seconds timeout) {
    if (sig != 0) ::kill(pid_, sig);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    int st = 0;
    while (::waitpid(pid_, &st, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > deadline) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, &st, 0);
        pid_ = -1;
        return -1;
      }
      std::this_thread::sleep_for(10ms);
    }
    pid_ = -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  }

 private:
  pid_t pid_ = -1;
};

class LcmInterop : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!horus::backend_available(Backend::Lcm)) GTEST_SKIP() << "this build has no lcm backend";
    ::setenv("HORUS_LCM_URL", test_url().c_str(), 1);
  }
};

TEST_F(LcmInterop, AnLcmGenProgramEchoesEveryMessageTypeFieldByField) {
  const std::string program = std::string(INTEROP_WORK_DIR) + "/lcm_echo";
  if (::access(program.c_str(), X_OK) != 0) {
    std::ifstream why(program + ".why");
    std::stringstream ss;
    ss << why.rdbuf();
    GTEST_SKIP() << "lcm_echo was not built: " << (ss.str().empty() ? "see interop.BuildThirdPartyPeers" : ss.str());
  }
  const std::string prefix = horus_test::unique_name("lcmi");
  horus_test::Peer peer(program, Backend::Lcm, {prefix, "120"});
  ASSERT_TRUE(peer.ready()) << "lcm_echo did not start";
  for (const auto& f : horus_test::round_trip_all(Backend::Lcm, prefix, horus_test::standard_and_wire_test_types())) ADD_FAILURE() << f;
  EXPECT_EQ(peer.stop(), 0) << "lcm_echo could not decode or re-encode a message (its stderr says which)";
}

// An lcm-gen program beside two horus processes of the same host: each message once in both
// directions (LCM loops the host's own multicast back; the bridge drops its own echo only).
TEST_F(LcmInterop, OnAHostWithTwoHorusProcessesEachMessageGoesOnceEachWay) {
  const std::string program = std::string(INTEROP_WORK_DIR) + "/lcm_echo";
  if (::access(program.c_str(), X_OK) != 0) GTEST_SKIP() << "lcm_echo was not built";
  const std::string prefix = horus_test::unique_name("lcmh");
  horus_test::Peer peer(program, Backend::Lcm, {prefix, "60"});
  ASSERT_TRUE(peer.ready()) << "lcm_echo did not start";
  for (const auto& f : horus_test::same_host_exactly_once(Backend::Lcm, prefix)) ADD_FAILURE() << f;
  EXPECT_EQ(peer.stop(), 0);
}

TEST_F(LcmInterop, LcmLoggerRecordsHorusTrafficAndLogplayerReplaysItIntoHorus) {
  const std::string logger = tool("lcm-logger"), player = tool("lcm-logplayer");
  if (logger.empty() || player.empty()) GTEST_SKIP() << "lcm-logger / lcm-logplayer are not installed (Debian: liblcm-bin)";
  const std::string prefix = horus_test::unique_name("log");
  const std::string channel = prefix + ".pose";
  const std::string log = "/tmp/horus-" + prefix + ".lcmlog";
  std::string regex;
  for (char c : prefix) regex += (c == '.' ? "\\." : std::string(1, c));
  auto pub = horus::Topic<horus::msg::Pose2D>::open(channel, horus_test::on(Backend::Lcm));
  auto probe = horus::Topic<horus::msg::CmdVel>::open(prefix + ".probe", horus_test::on(Backend::Lcm));
  ASSERT_TRUE(pub && probe) << (!pub ? pub.error() : probe.error()).message();

  Child rec({logger, "--lcm-url=" + test_url(), "-c", regex + "\\..*", "-f", "-q", log});
  // lcm-logger has no "ready": send probes until the log file has something in it.
  horus_test::Deadline up(15s);
  struct stat st {};
  while (!up.expired() && (::stat(log.c_str(), &st) != 0 || st.st_size == 0)) {
    probe->send(horus::msg::CmdVel{});
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_GT(st.st_size, 0) << "lcm-logger recorded nothing in 15 s";
  constexpr int kN = 20;
  for (int i = 0; i < kN; ++i) {
    pub->send(horus::msg::Pose2D{static_cast<double>(i), 0.5, 0.25, static_cast<std::uint64_t>(i)});
    std::this_thread::sleep_for(5ms);
  }
  // The log holds horus's bytes, as any LCM tool sees them (the logger writes each event as it
  // arrives: read until all are there, then stop it).
  auto read_log = [&] {
    std::vector<double> xs;
    if (lcm_eventlog_t* l = lcm_eventlog_create(log.c_str(), "r")) {
      while (lcm_eventlog_event_t* e = lcm_eventlog_read_next_event(l)) {
        if (std::string(e->channel, static_cast<std::size_t>(e->channellen)) == channel) {
          auto m = horus::lcm::decode<horus::msg::Pose2D>(
              std::span(static_cast<const std::byte*>(e->data), static_cast<std::size_t>(e->datalen)));
          EXPECT_TRUE(m) << m.error();
          if (m) xs.push_back(m->x);
        }
        lcm_eventlog_free_event(e);
      }
      lcm_eventlog_destroy(l);
    }
    return xs;
  };
  horus_test::Deadline written(10s);
  while (!written.expired() && read_log().size() < static_cast<std::size_t>(kN)) std::this_thread::sleep_for(20ms);
  EXPECT_EQ(rec.stop(SIGINT, 10s), 0) << "lcm-logger did not exit cleanly on SIGINT";
  const std::vector<double> logged = read_log();
  ASSERT_EQ(logged.size(), static_cast<std::size_t>(kN)) << "lcm-logger did not record every message";
  for (int i = 0; i < kN; ++i) EXPECT_EQ(logged[static_cast<std::size_t>(i)], i);

  // Replayed by lcm-logplayer (it exits at the end of the log), into a horus subscriber.
  while (pub->recv()) {
  }
  Child play({player, "-l", test_url(), "-s", "4", log});
  std::vector<double> replayed;
  horus_test::Deadline deadline(30s);
  auto quiet_since = std::chrono::steady_clock::now();
  int player_rc = -2;
  while (!deadline.expired()) {
    while (auto m = pub->recv()) {
      replayed.push_back(m->x);
      quiet_since = std::chrono::steady_clock::now();
    }
    // The whole log arrived: the player must be exiting on its own.
    if (player_rc == -2 && replayed.size() >= static_cast<std::size_t>(kN)) player_rc = play.stop(0, 10s);
    if (replayed.size() >= static_cast<std::size_t>(kN) && std::chrono::steady_clock::now() - quiet_since > 300ms) break;
    std::this_thread::sleep_for(2ms);
  }
  EXPECT_EQ(player_rc, 0) << "lcm-logplayer did not exit cleanly at the end of the log";
  ASSERT_EQ(replayed.size(), static_cast<std::size_t>(kN)) << "lcm-logplayer's replay did not all arrive";
  for (int i = 0; i < kN; ++i) EXPECT_EQ(replayed[static_cast<std::size_t>(i)], i);

  // horus play reads lcm-logger's log too: the channel's messages into a horus topic (the type
  // found from the LCM fingerprint), in order, with nothing else.
  auto into = horus::Topic<horus::msg::Pose2D>::open(prefix + ".replayed");
  ASSERT_TRUE(into) << into.error().message();
  std::string out;
  ASSERT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " play " + log + " --rate 0 --topics '" + channel +
                                        "' --remap '" + channel + "=" + prefix + ".replayed'",
                                    out),
            0)
      << out;
  std::vector<double> played;
  while (auto m = into->recv()) played.push_back(m->x);
  ASSERT_EQ(played.size(), static_cast<std::size_t>(kN)) << out;
  for (int i = 0; i < kN; ++i) EXPECT_EQ(played[static_cast<std::size_t>(i)], i);
  std::remove(log.c_str());
}

// horus record --format lcm writes the log lcm-logger writes: liblcm's own reader reads it, and
// lcm-logplayer replays it into horus.
TEST_F(LcmInterop, HorusRecordsAnLcmLogThatLiblcmReadsAndLcmLogplayerReplays) {
  const std::string player = tool("lcm-logplayer");
  if (player.empty()) GTEST_SKIP() << "lcm-logplayer is not installed (Debian: liblcm-bin)";
  const std::string prefix = horus_test::unique_name("hlog");
  const std::string channel = prefix + ".pose";
  const std::string log = "/tmp/horus-" + prefix + ".lcmlog", out_file = log + ".out";
  auto pub = horus::Topic<horus::msg::Pose2D>::open(channel, horus_test::on(Backend::Lcm));
  ASSERT_TRUE(pub) << pub.error().message();
  pub->publish_only();  // sub_count() then counts the recorder alone
  // The recorder subscribes to the fleet topic on this host (shared memory).
  const pid_t rec = horus_test::spawn([&] {
    const std::string cmd = std::string(HORUS_CLI) + " record --format lcm -o " + log + " --topics '" + prefix +
                            ".**' --duration 4 > " + out_file + " 2>&1";
    return std::system(cmd.c_str()) == 0 ? 0 : 1;
  });
  horus_test::Deadline up(15s);
  while (!up.expired() && pub->sub_count() < 1) std::this_thread::sleep_for(10ms);
  constexpr int kN = 30;
  for (int i = 0; i < kN; ++i) {
    pub->send(horus::msg::Pose2D{static_cast<double>(i), -1.0, 0.5, static_cast<std::uint64_t>(i)});
    std::this_thread::sleep_for(5ms);
  }
  ASSERT_EQ(horus_test::wait_for(rec, 30s), 0) << std::ifstream(out_file).rdbuf();
  // liblcm reads every event: the channel, the bytes of lcm-gen's encoding, timestamps in order.
  std::vector<double> logged;
  std::int64_t last_ts = 0;
  lcm_eventlog_t* l = lcm_eventlog_create(log.c_str(), "r");
  ASSERT_NE(l, nullptr);
  while (lcm_eventlog_event_t* e = lcm_eventlog_read_next_event(l)) {
    EXPECT_EQ(std::string(e->channel, static_cast<std::size_t>(e->channellen)), channel);
    EXPECT_EQ(e->eventnum, static_cast<std::int64_t>(logged.size()));
    EXPECT_GE(e->timestamp, last_ts);
    last_ts = e->timestamp;
    auto m = horus::lcm::decode<horus::msg::Pose2D>(
        std::span(static_cast<const std::byte*>(e->data), static_cast<std::size_t>(e->datalen)));
    EXPECT_TRUE(m) << m.error();
    if (m) logged.push_back(m->x);
    lcm_eventlog_free_event(e);
  }
  lcm_eventlog_destroy(l);
  ASSERT_EQ(logged.size(), static_cast<std::size_t>(kN));
  for (int i = 0; i < kN; ++i) EXPECT_EQ(logged[static_cast<std::size_t>(i)], i);
  // lcm-logplayer replays it over LCM, into horus.
  auto sub = horus::Topic<horus::msg::Pose2D>::open(channel, horus_test::on(Backend::Lcm));
  ASSERT_TRUE(sub) << sub.error().message();
  Child play({player, "-l", test_url(), "-s", "4", log});
  std::vector<double> replayed;
  horus_test::Deadline deadline(30s);
  while (!deadline.expired() && replayed.size() < static_cast<std::size_t>(kN)) {
    while (auto m = sub->recv()) replayed.push_back(m->x);
    std::this_thread::sleep_for(2ms);
  }
  EXPECT_EQ(play.stop(0, 10s), 0);
  ASSERT_EQ(replayed.size(), static_cast<std::size_t>(kN));
  for (int i = 0; i < kN; ++i) EXPECT_EQ(replayed[static_cast<std::size_t>(i)], i);
  for (const auto& f : {log, out_file}) std::remove(f.c_str());
}

}  // namespace

// A fleet under DDS-Security (security/README.md) on namespace hosts (netns.hpp: each host its
// own network, /dev/shm and hostname). The keystores are made with the `horus security` CLI, as
// an operator would: fleet keystore K with hosts a, b (sec.** and robot2.**) and c (may publish
// robot1.** only); another keystore K2 (another CA) with host x.
//   - a and b, each enforcing with its identity, exchange a fleet topic; a host without security
//     and a host of the other CA, both publishing on it too, neither read a's messages nor get
//     theirs to b (Cyclone DDS and Fast DDS);
//   - c's publications on robot2.cmd_vel never reach b (its permissions allow robot1.**), while
//     a's do, and c's log says why;
//   - an expired certificate, and LCM under enforce, are refused with a clear error;
//   - on b under enforce, `horus record` and `horus bench` work with b's identity;
//   - Cyclone DDS and Fast DDS authenticate each other only when the Cyclone participant begins
//     the handshake (the one with the lower GUID, from its certificate's subject): of the two
//     ways to pair a's and b's identities across the libraries, exactly one works.
// Skips when not root or without `ip netns`.
#include <gtest/gtest.h>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include "horus/backend.hpp"
#include "netns.hpp"

namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using horus_test::HostProcess;
using horus_test::NetnsLan;

long long unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// The two keystores, made once for the test program with the CLI.
class Keystores {
 public:
  static const Keystores& get() {
    static const Keystores k;
    return k;
  }
  std::string why;  // non-empty: could not be made
  fs::path fleet, other;

 private:
  Keystores() {
    const fs::path dir = fs::temp_directory_path() / ("horus_test_keystores_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fleet = dir / "fleet";
    other = dir / "other";
    const std::string k = fleet.string(), k2 = other.string();
    const std::vector<std::vector<std::string>> steps = {
        {HORUS_CLI, "security", "keystore", "init", k},
        {HORUS_CLI, "security", "host", "create", k, "a"},
        {HORUS_CLI, "security", "host", "create", k, "b"},
        {HORUS_CLI, "security", "host", "create", k, "c"},
        {HORUS_CLI, "security", "host", "create", k, "old", "--not-before", "2020-01-01", "--not-after", "2020-06-01"},
        {HORUS_CLI, "security", "permissions", k, "a", "--publish", "sec.**", "robot2.**", "--subscribe", "sec.**", "robot2.**"},
        {HORUS_CLI, "security", "permissions", k, "b", "--publish", "sec.**", "--subscribe", "sec.**", "robot2.**"},
        {HORUS_CLI, "security", "permissions", k, "c", "--publish", "robot1.**", "--subscribe", "**"},
        {HORUS_CLI, "security", "permissions", k, "old", "--publish", "sec.**", "--subscribe", "sec.**"},
        {HORUS_CLI, "security", "keystore", "init", k2},
        {HORUS_CLI, "security", "host", "create", k2, "x"},
        {HORUS_CLI, "security", "permissions", k2, "x", "--publish", "sec.**", "--subscribe", "sec.**"},
    };
    for (const auto& step : steps) {
      if (horus_test::run_command(step) != 0) {
        why = "could not make the test keystores: this failed:";
        for (const auto& a : step) why += " " + a;
        return;
      }
    }
  }
};

// The environment of a process on a namespace host: its backend, and its identity in `keystore`
// under enforce (none: no security).
std::vector<std::string> env(std::string_view backend, const std::string& identity = "", const fs::path& keystore = {}) {
  std::vector<std::string> e = {"HORUS_BACKEND=" + std::string(backend), "HORUS_DOMAIN_ID=0", "HORUS_FLEET_HEARTBEAT_MS=100"};
  if (!identity.empty()) {
    e.push_back("HORUS_SECURITY=enforce");
    e.push_back("HORUS_SECURITY_KEYSTORE=" + keystore.string());
    e.push_back("HORUS_SECURITY_IDENTITY=" + identity);
  }
  return e;
}

// The fleet_member arguments of a publisher (`id` > 0) or a subscriber expecting `publishers`.
std::vector<std::string> member(const std::string& topic, int id, long long start, int publishers, int seconds,
                                std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {FLEET_MEMBER,          topic, "fleet", std::to_string(id), "50", std::to_string(start),
                                   std::to_string(publishers), std::to_string(seconds)};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

class SecureFleet : public ::testing::TestWithParam<horus::Backend> {
 protected:
  void SetUp() override {
    if (!horus::backend_available(GetParam())) GTEST_SKIP() << backend() << " is not in this build";
    if (!Keystores::get().why.empty()) FAIL() << Keystores::get().why;
  }
  std::string backend() const { return std::string(horus::to_string(GetParam())); }
};

// Fast DDS 2.9's security manager matches a discovered participant's handshake endpoints through
// one scratch ReaderProxyData shared by its receive threads, unlocked (fixed in 2.10:
// eProsima/Fast-DDS#3362, "Replaced SecurityManager temporary ProxyDatas with ProxyPools"). When
// two participants are discovered at the same instant on its multicast and unicast threads, one
// thread's copy of the other's half-written locator list trips an assertion of Debian's build
// (asserts are on) and the process aborts; or, without the assertion, the handshake writer keeps
// a participant's reader with the other's locators (its warning "Attempting to add existing
// reader" is the second match of that participant), and the two never authenticate (CI,
// 2026-12-07: b never heard a). True when one of `outputs` shows the abort, or the warning when
// the scenario `failed`: the scenario is then run once more, and the run says so.
bool fastdds_discovery_race(std::initializer_list<const std::string*> outputs, bool failed) {
  return std::any_of(outputs.begin(), outputs.end(), [&](const std::string* output) {
    const bool aborted = output->find("ResourceLimitedVector.hpp") != std::string::npos &&
                         output->find("size() == other.size()") != std::string::npos;
    const bool rematched = output->find("RTPS_WRITER: Attempting to add existing reader") != std::string::npos;
    return aborted || (failed && rematched);
  });
}

// Runs a scenario, and once more when a process of it aborted in that race (saying so).
template <class Run>
auto run_once_more_after_the_race(Run run) {
  auto r = run();
  if (r.upstream_race()) {
    std::cout << "[ note ] a process met Fast DDS 2.9's discovery race (eProsima/Fast-DDS#3362): it aborted, "
                 "or matched a handshake reader twice and its scenario failed; running the scenario once more\n";
    r = run();
  }
  return r;
}

// The scenario of AuthenticatedHostsExchangeAndOthersNeitherReadNorInject: a and b under enforce,
// a plain host and a host of another CA publishing too, and b's view of the fleet.
struct Exchange {
  int sub_exit = -1, view_exit = -1;
  bool view_saw_a = false;
  std::string pub, sub, plain, foreign, view;
  bool upstream_race() const {
    const bool failed = sub_exit != 0 || sub.find("received 50 from 1 publishers") == std::string::npos || !view_saw_a;
    return fastdds_discovery_race({&pub, &sub, &plain, &foreign, &view}, failed);
  }
};

Exchange run_exchange(NetnsLan& lan, const std::string& backend) {
  const Keystores& k = Keystores::get();
  const std::string topic = "sec.pose";
  const long long start = unix_ms() + 3000;
  Exchange r;
  // a publishes once b's reader matched (on a loaded machine Fast DDS's authentication took more
  // than the 4 s after the start that a 7 s stay left: CI, 2026-11-29), then stays (publishers
  // -1) until b's view below saw it, at most 45 s: the view's own participant authenticates in
  // its own time (CI, 2026-12-07: not within a's former 12 s stay).
  auto pub = lan.spawn(0, member(topic, 1, start, -1, 45, {"await-reader"}), env(backend, "a", k.fleet));
  auto sub = lan.spawn(1, member(topic, 0, start, 1, 15), env(backend, "b", k.fleet));
  // The intruders publish too (20 ms apart, overlapping a's messages) and expect two publishers.
  auto plain = lan.spawn(2, member(topic, 2, start, 2, 5, {"period=20"}), env(backend));
  auto foreign = lan.spawn(3, member(topic, 3, start, 2, 5, {"period=20"}), env(backend, "x", k.other));
  // b's view of the fleet, a table a second until a appears in it (below), at most 40 s: a
  // appears, authenticated; neither intruder ever does. The fleet layer's own participant
  // authenticates on its own time: on a loaded machine Fast DDS took more than 7 s (CI,
  // 2026-12-07: a fixed 7 s view never saw a).
  auto view = lan.spawn(1, {HORUS_CLI, "fleet", "--duration", "45"}, env(backend, "b", k.fleet));
  const auto view_started = std::chrono::steady_clock::now();
  r.sub_exit = sub.wait(30s);
  (void)plain.wait(20s);
  (void)foreign.wait(20s);
  r.view_saw_a = view.wait_for_output("\n" + lan.host(0) + " ", 40s);
  // A window in which an intruder may not appear: the view watches at least 12 s in all (the
  // intruders lived the first 5), whenever a appeared.
  const auto window = view_started + 12s - std::chrono::steady_clock::now();
  if (window > 0s)
    (void)view.wait_for_output("\n" + lan.host(2) + " ", std::chrono::duration_cast<std::chrono::milliseconds>(window));
  view.terminate();
  r.view_exit = view.wait(20s);
  pub.terminate();
  (void)pub.wait(20s);
  r.pub = pub.output();
  r.sub = sub.output();
  r.plain = plain.output();
  r.foreign = foreign.output();
  r.view = view.output();
  return r;
}

TEST_P(SecureFleet, AuthenticatedHostsExchangeAndOthersNeitherReadNorInject) {
  NetnsLan lan(4);
  if (!lan.ok()) GTEST_SKIP() << lan.why();
  const Exchange r = run_once_more_after_the_race([&] { return run_exchange(lan, backend()); });
  EXPECT_EQ(r.sub_exit, 0) << "b:\n" << r.sub << "\na:\n" << r.pub;
  EXPECT_NE(r.sub.find("received 50 from 1 publishers"), std::string::npos) << r.sub;
  // Each intruder received its own 50 only: nothing of a's.
  EXPECT_NE(r.plain.find("received 50 from 1 publishers"), std::string::npos) << r.plain;
  EXPECT_NE(r.foreign.find("received 50 from 1 publishers"), std::string::npos) << r.foreign;
  ASSERT_EQ(r.view_exit, 0) << r.view;
  const std::string& out = r.view;
  EXPECT_TRUE(r.view_saw_a) << "b's fleet view never listed a (" << lan.host(0) << "); a said:\n" << r.pub;
  EXPECT_NE(out.find("security: enforce, this host is b (CN=b,O=horus)"), std::string::npos) << out;
  const std::size_t line = out.find("\n" + lan.host(0) + " ");
  ASSERT_NE(line, std::string::npos) << out;
  const std::string row = out.substr(line + 1, out.find('\n', line + 1) - line - 1);
  EXPECT_TRUE(row.ends_with("yes")) << row;
  EXPECT_EQ(out.find(lan.host(2)), std::string::npos) << out;
  EXPECT_EQ(out.find(lan.host(3)), std::string::npos) << out;
}

// The scenario of AHostMayPublishOnlyWhatItsPermissionsAllow.
struct Permissions {
  int sub_exit = -1, echo_exit = -1;
  std::string allowed, sub, denied, echo;
  bool upstream_race() const {
    const bool failed = sub_exit != 0 || sub.find("received 50 from 1 publishers") == std::string::npos || echo_exit != 0;
    return fastdds_discovery_race({&allowed, &sub, &denied, &echo}, failed);
  }
};

Permissions run_permissions(NetnsLan& lan, const std::string& backend) {
  const Keystores& k = Keystores::get();
  const std::string topic = "robot2.cmd_vel";
  const long long start = unix_ms() + 3000;
  Permissions r;
  // a publishes once both readers' hosts matched it (b and c: under enforce each authenticates in
  // its own time; CI, 2026-12-07: c's matched first and b's after a's 50 were sent).
  auto allowed = lan.spawn(0, member(topic, 1, start, 1, 15, {"await-readers=2"}), env(backend, "a", k.fleet));
  auto sub = lan.spawn(1, member(topic, 0, start, 1, 15), env(backend, "b", k.fleet));
  auto denied = lan.spawn(2, member(topic, 3, start, 1, 7, {"period=20"}), env(backend, "c", k.fleet));
  // The CLI under enforce, with b's identity: it prints a's messages only (x is the publisher's id).
  auto echo = lan.spawn(1, {HORUS_CLI, "topic", "echo", topic, "-n", "20", "--json", "--timeout", "15"},
                        env(backend, "b", k.fleet));
  r.sub_exit = sub.wait(30s);
  (void)allowed.wait(20s);
  (void)denied.wait(20s);
  r.echo_exit = echo.wait(20s);
  r.allowed = allowed.output();
  r.sub = sub.output();
  r.denied = denied.output();
  r.echo = echo.output();
  return r;
}

TEST_P(SecureFleet, AHostMayPublishOnlyWhatItsPermissionsAllow) {
  NetnsLan lan(3);
  if (!lan.ok()) GTEST_SKIP() << lan.why();
  const Permissions r = run_once_more_after_the_race([&] { return run_permissions(lan, backend()); });
  EXPECT_EQ(r.sub_exit, 0) << "b:\n" << r.sub << "\na:\n" << r.allowed << "\nc:\n" << r.denied;
  EXPECT_NE(r.sub.find("received 50 from 1 publishers"), std::string::npos) << r.sub;
  EXPECT_NE(r.denied.find("identity 'c' may not publish this topic"), std::string::npos) << r.denied;
  EXPECT_EQ(r.echo_exit, 0) << r.echo;
  EXPECT_NE(r.echo.find("\"x\":1.0"), std::string::npos) << r.echo;
  EXPECT_EQ(r.echo.find("\"x\":3.0"), std::string::npos) << r.echo;
}

INSTANTIATE_TEST_SUITE_P(Dds, SecureFleet,
                         ::testing::Values(horus::Backend::CycloneDds, horus::Backend::FastDds),
                         [](const auto& param_info) { return std::string(horus::to_string(param_info.param)); });

// No network needed: the identity is checked before anything is sent.
TEST(SecureFleetRefusals, AnExpiredCertificateAndLcmUnderEnforceAreRefusedClearly) {
  if (!Keystores::get().why.empty()) FAIL() << Keystores::get().why;
  const Keystores& k = Keystores::get();
  // A process of `backend` with `identity` that opens a fleet topic, in a shared-memory namespace
  // of its own (another run of this test may be using the same topic).
  const auto open = [&](const std::string& backend, const std::string& identity, const fs::path& keystore,
                        const std::string& extra) {
    std::vector<std::string> args = {"env"};
    for (const std::string& e : env(backend, identity, keystore)) args.push_back(e);
    args.push_back(extra);
    args.push_back("HORUS_NAMESPACE=secref" + std::to_string(::getpid()) + backend);
    for (const std::string& a : {std::string(FLEET_MEMBER), std::string("sec.pose"), std::string("fleet"), std::string("1"),
                                 std::string("10"), std::to_string(unix_ms()), std::string("1"), std::string("5")})
      args.push_back(a);
    auto p = horus_test::start_logged(
        args, (fs::temp_directory_path() / ("horus_test_refused_" + std::to_string(::getpid()) + backend)).string());
    EXPECT_EQ(p.wait(20s), 3) << backend << ":\n" << p.output();  // the topic does not open
    return p.output();
  };
  for (const char* backend : {"cyclonedds", "fastdds"}) {
    if (!horus::backend_available(horus::Backend::network(backend))) continue;
    const std::string out = open(backend, "old", k.fleet, "HORUS_DDS_LOCALHOST=1");
    EXPECT_NE(out.find((k.fleet / "hosts" / "old" / "cert.pem").string() + "' expired on 2020-06-01"), std::string::npos)
        << backend << ":\n" << out;
  }
  if (horus::backend_available(horus::Backend::Lcm)) {
    const std::string out = open("lcm", "a", k.fleet, "HORUS_LCM_URL=udpm://239.255.76.67:7667?ttl=0");
    EXPECT_NE(out.find("environment variable HORUS_SECURITY is enforce, but LCM has no security"), std::string::npos) << out;
  }
}

// The CLI under enforce, with the host's identity (on Cyclone DDS; the transport is the one the
// tests above check on both libraries): on b, `horus record` records a's fleet topic, found
// through the secured fleet layer, and `horus bench ping` measures round trips to a pong on a.
TEST(SecureFleetCli, RecordAndBenchWorkWithTheHostsIdentity) {
  if (!horus::backend_available(horus::Backend::CycloneDds)) GTEST_SKIP() << "cyclonedds is not in this build";
  if (!Keystores::get().why.empty()) FAIL() << Keystores::get().why;
  const Keystores& k = Keystores::get();
  NetnsLan lan(2);
  if (!lan.ok()) GTEST_SKIP() << lan.why();
  const std::string tag = std::to_string(::getpid());
  const std::string file = (fs::temp_directory_path() / ("horus_test_secure_" + tag + ".mcap")).string();
  const std::string json = (fs::temp_directory_path() / ("horus_test_secure_" + tag + ".json")).string();
  const auto a = env("cyclonedds", "a", k.fleet), b = env("cyclonedds", "b", k.fleet);
  auto rec = lan.spawn(1, {HORUS_CLI, "record", "-o", file, "--topics", "sec.rec", "--duration", "9"}, b);
  auto pub = lan.spawn(0, member("sec.rec", 1, unix_ms() + 3000, 1, 9, {"await-reader", "period=20"}), a);
  auto pong = lan.spawn(0, {HORUS_CLI, "bench", "pong", "--topic-prefix", "sec.bench", "--once"}, a);
  auto ping = lan.spawn(1, {HORUS_CLI, "bench", "ping", "--topic-prefix", "sec.bench", "--remote", "--type", "Pose2D",
                            "--rate", "100", "--count", "200", "--warmup", "4", "--json", json, "-q"},
                        b);
  EXPECT_EQ(ping.wait(40s), 0) << ping.output() << "\npong:\n" << pong.output();
  EXPECT_EQ(pong.wait(15s), 0) << pong.output();
  std::ifstream summary(json);
  const auto j = nlohmann::json::parse(summary, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << ping.output();
  EXPECT_EQ(j.value("received", 0), 200) << j.dump();
  EXPECT_EQ(rec.wait(30s), 0) << rec.output();
  (void)pub.wait(20s);
  auto info = lan.spawn(1, {HORUS_CLI, "record", "info", "--json", file}, b);
  ASSERT_EQ(info.wait(20s), 0) << info.output();
  const std::string out = info.output();
  const auto recorded = nlohmann::json::parse(out.substr(std::min(out.find('{'), out.size())), nullptr, false);
  ASSERT_FALSE(recorded.is_discarded()) << out;
  int messages = -1;
  for (const auto& t : recorded.value("topics", nlohmann::json::array()))
    if (t.value("topic", "") == "sec.rec") messages = t.value("messages", 0);
  EXPECT_EQ(messages, 50) << out << "\nrecord:\n" << rec.output() << "\npublisher:\n" << pub.output();
  fs::remove(file);
  fs::remove(json);
}

// Cyclone DDS 0.10 and Fast DDS 2.9: the pairing in which the Cyclone participant begins the
// handshake delivers; the other never authenticates (Fast DDS proposes a key agreement Cyclone
// cannot read; eProsima/Fast-DDS#3802). Both pairings run at once, on two LANs.
TEST(SecureFleetInterop, CycloneAndFastDdsAuthenticateWhenCycloneBeginsTheHandshake) {
  if (!horus::backend_available(horus::Backend::CycloneDds) || !horus::backend_available(horus::Backend::FastDds))
    GTEST_SKIP() << "needs both DDS backends";
  if (!Keystores::get().why.empty()) FAIL() << Keystores::get().why;
  const Keystores& k = Keystores::get();
  NetnsLan one(2, "a"), two(2, "b");
  if (!one.ok()) GTEST_SKIP() << one.why();
  if (!two.ok()) GTEST_SKIP() << two.why();
  const long long start = unix_ms() + 3000;
  // One: a on Cyclone publishes to b on Fast DDS. Two: a on Fast DDS publishes to b on Cyclone.
  auto pub1 = one.spawn(0, member("sec.mixed", 1, start, 1, 8, {"await-reader"}), env("cyclonedds", "a", k.fleet));
  auto sub1 = one.spawn(1, member("sec.mixed", 0, start, 1, 8), env("fastdds", "b", k.fleet));
  auto pub2 = two.spawn(0, member("sec.mixed", 1, start, 1, 8, {"await-reader"}), env("fastdds", "a", k.fleet));
  auto sub2 = two.spawn(1, member("sec.mixed", 0, start, 1, 8), env("cyclonedds", "b", k.fleet));
  const int rc1 = sub1.wait(30s), rc2 = sub2.wait(30s);
  (void)pub1.wait(20s);
  (void)pub2.wait(20s);
  EXPECT_NE(rc1 == 0, rc2 == 0) << "exactly one pairing should authenticate:\nCyclone a -> Fast DDS b:\n"
                                << sub1.output() << "\nFast DDS a -> Cyclone b:\n"
                                << sub2.output();
  const std::string worked = rc1 == 0 ? sub1.output() : sub2.output();
  EXPECT_NE(worked.find("received 50 from 1 publishers"), std::string::npos) << worked;
  std::printf("secure Cyclone <-> Fast DDS: %s\n", rc1 == 0 ? "Cyclone a (begins) -> Fast DDS b delivers; Fast DDS a -> Cyclone b does not"
                                                            : "Fast DDS a -> Cyclone b (begins) delivers; Cyclone a -> Fast DDS b does not");
}

}  // namespace

// Shared memory that only its owner uses (backend_shm foreign_file): on a namespace host (its own
// /dev/shm), local users made with useradd plant the segment file of a root topic (empty, random
// bytes, mode 0666 or 0600) or of another user's topic; the victim's `horus topic pub` refuses
// it with an error naming the file, its owner and mode, and never writes into it. Two users of a
// group that shares topics with HORUS_SHM_MODE=0660 and one HORUS_NAMESPACE exchange messages;
// root, not in that group, refuses their files. Needs root (namespaces, useradd); skips otherwise.
#include <gtest/gtest.h>

#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "netns.hpp"

namespace {

using namespace std::chrono_literals;

// Users and a group for this test only; deleted at the end.
class LocalUsers {
 public:
  explicit LocalUsers(const std::string& tag) : group_("hxg" + tag) {
    ok_ = horus_test::run_command({"groupadd", group_}) == 0;
    for (const char* who : {"a", "b", "m"}) {
      const std::string name = "hx" + tag + who;
      // m (mallory) is not in the group; a and b share it.
      std::vector<std::string> args = {"useradd", "-M", "-N", "-s", "/bin/sh"};
      if (std::string(who) != "m") args.insert(args.end(), {"-G", group_});
      args.push_back(name);
      if (horus_test::run_command(args) != 0) ok_ = false;
      names_.push_back(name);
    }
  }
  ~LocalUsers() {
    for (const auto& n : names_) horus_test::run_command({"userdel", n});
    horus_test::run_command({"groupdel", group_});
  }
  bool ok() const { return ok_; }
  const std::string& a() const { return names_[0]; }
  const std::string& b() const { return names_[1]; }
  const std::string& mallory() const { return names_[2]; }
  const std::string& group() const { return group_; }

 private:
  std::string group_;
  std::vector<std::string> names_;
  bool ok_ = false;
};

std::string uid_of(const std::string& user) {
  const passwd* pw = ::getpwnam(user.c_str());
  return pw == nullptr ? std::string("?") : std::to_string(pw->pw_uid);
}

class ShmOwnership : public ::testing::Test {
 protected:
  void SetUp() override {
    if (::geteuid() != 0) GTEST_SKIP() << "needs root (namespace hosts and useradd)";
    lan_ = std::make_unique<horus_test::NetnsLan>(1);
    if (!lan_->ok()) GTEST_SKIP() << "no namespace hosts: " << lan_->why();
    users_ = std::make_unique<LocalUsers>(std::to_string(::getpid() % 100000));
    if (!users_->ok()) GTEST_SKIP() << "useradd/groupadd failed: cannot make local users";
    if (run_as(users_->mallory(), {"test", "-x", HORUS_CLI}).wait(30s) != 0)
      GTEST_SKIP() << "an unprivileged user cannot run " << HORUS_CLI << " (a directory on its path is not "
                   << "searchable by others)";
  }
  void TearDown() override {
    lan_.reset();  // its processes end before the users go
    users_.reset();
  }
  // Runs argv on the namespace host as `user` ("" : root).
  horus_test::HostProcess run_as(const std::string& user, std::vector<std::string> argv,
                                 const std::vector<std::string>& env = {}) {
    if (!user.empty()) argv.insert(argv.begin(), {"runuser", "-u", user, "--"});
    return lan_->spawn(0, argv, env);
  }
  // `stat -c "%U %a %s"` of a file on the namespace host.
  std::string stat_of(const std::string& path) {
    auto p = run_as("", {"stat", "-c", "%U %a %s", path});
    (void)p.wait(30s);
    std::string out = p.output();
    while (!out.empty() && out.back() == '\n') out.pop_back();
    return out;
  }
  std::unique_ptr<horus_test::NetnsLan> lan_;
  std::unique_ptr<LocalUsers> users_;
};

const std::vector<std::string> kShm = {"HORUS_BACKEND=shm", "HORUS_CONFIG="};

TEST_F(ShmOwnership, ASegmentFilePlantedByAnotherUserIsRefusedAndLeftAlone) {
  struct Plant {
    const char* what;
    std::string command;  // run by mallory
    std::string after;    // `stat` of the file afterwards: owner, mode, size
  };
  const std::string file = "/dev/shm/horus.u0.sec.cmd";
  const std::vector<Plant> plants = {
      {"empty, 0666", "touch " + file + " && chmod 666 " + file, users_->mallory() + " 666 0"},
      {"random bytes, 0666", "head -c 2101248 /dev/urandom > " + file + " && chmod 666 " + file,
       users_->mallory() + " 666 2101248"},
      {"random bytes, 0600", "head -c 8192 /dev/urandom > " + file + " && chmod 600 " + file,
       users_->mallory() + " 600 8192"},
  };
  for (const auto& plant : plants) {
    SCOPED_TRACE(plant.what);
    ASSERT_EQ(run_as(users_->mallory(), {"sh", "-c", plant.command}).wait(30s), 0);
    auto pub = run_as("", {HORUS_CLI, "topic", "pub", "sec.cmd", "Pose2D", "{\"x\": 1}", "-n", "2000", "-r", "100000"}, kShm);
    const int rc = pub.wait(60s);
    const std::string out = pub.output();
    EXPECT_NE(rc, 0) << out;
    EXPECT_NE(out.find("shared-memory file " + file + " belongs to uid " + uid_of(users_->mallory()) + " (" +
                       users_->mallory() + ")"),
              std::string::npos)
        << out;
    EXPECT_NE(out.find("not to this process's user"), std::string::npos) << out;
    EXPECT_EQ(stat_of(file), plant.after) << "root wrote into or resized the planted file";
    ASSERT_EQ(run_as("", {"rm", "-f", file}).wait(30s), 0);
  }
  // An unprivileged victim: user a's own topic, planted by mallory with mode 0666.
  const std::string a_file = "/dev/shm/horus.u" + uid_of(users_->a()) + ".nav.goal";
  ASSERT_EQ(run_as(users_->mallory(), {"sh", "-c", "touch " + a_file + " && chmod 666 " + a_file}).wait(30s), 0);
  auto pub = run_as(users_->a(), {HORUS_CLI, "topic", "pub", "nav.goal", "Pose2D", "{\"x\": 1}", "-n", "10"}, kShm);
  EXPECT_NE(pub.wait(60s), 0) << pub.output();
  EXPECT_NE(pub.output().find("belongs to uid " + uid_of(users_->mallory())), std::string::npos) << pub.output();
  EXPECT_EQ(stat_of(a_file), users_->mallory() + " 666 0");
  // With nothing planted, the same command works (the refusals above were not something else).
  ASSERT_EQ(run_as("", {"rm", "-f", a_file}).wait(30s), 0);
  auto fine = run_as(users_->a(), {HORUS_CLI, "topic", "pub", "nav.goal", "Pose2D", "{\"x\": 1}", "-n", "10"}, kShm);
  EXPECT_EQ(fine.wait(60s), 0) << fine.output();
}

TEST_F(ShmOwnership, AGroupWithHorusShmMode0660SharesTopicsAndRootRefusesItsFiles) {
  std::vector<std::string> env = kShm;
  env.insert(env.end(), {"HORUS_NAMESPACE=team", "HORUS_SHM_MODE=0660"});
  // a publishes with the group as its group (sg): the segment file is a's, mode 0660, group hxg.
  auto pub = run_as(users_->a(), {"sg", users_->group(), "-c",
                                  std::string(HORUS_CLI) + " topic pub team.pose Pose2D '{\"x\": 7}' -r 50 -n 250"},
                    env);
  // b echoes once a's topic exists: each attempt before fails at once ("no topic").
  auto echo = run_as(users_->b(),
                     {"timeout", "20", "sh", "-c",
                      "until " + std::string(HORUS_CLI) + " topic echo team.pose -n 1 --timeout 10; do :; done"},
                     env);
  const int echo_rc = echo.wait(60s);
  EXPECT_EQ(echo_rc, 0) << echo.output() << "\npublisher:\n" << pub.output();
  EXPECT_NE(echo.output().find('7'), std::string::npos) << echo.output();
  EXPECT_EQ(stat_of("/dev/shm/horus.team.team.pose").substr(0, users_->a().size() + 4), users_->a() + " 660")
      << pub.output();
  // Root is not in the group: the group's file is another user's to it.
  auto root = run_as("", {HORUS_CLI, "topic", "pub", "team.pose", "Pose2D", "{\"x\": 1}", "-n", "1"}, env);
  EXPECT_NE(root.wait(60s), 0) << root.output();
  EXPECT_NE(root.output().find("belongs to uid " + uid_of(users_->a())), std::string::npos) << root.output();
  (void)pub.wait(30s);
}

}  // namespace

// README.md says what horus does; these tests hold it to it (readme_doc.hpp has the directives):
// - every C++ block and every CLI sample carries a directive (a new one cannot go unchecked);
// - the C++ blocks compile (readme_blocks has one translation unit per block, with
//   <horus/horus.hpp> and the includes the block shows), and the `run` ones run and print what
//   the README says, with the exit status it says;
// - the CLI samples run beside their fixture and print what the README shows, figures aside
//   (every number matches any number; a "..." line matches any lines).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "process_support.hpp"
#include "readme_doc.hpp"

namespace {

std::vector<readme::Block> blocks() { return readme::parse(readme::read_file(HORUS_README)); }

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Runs `cmd` with sh in `dir`, a horus namespace of its own and no network backend (plus `env`),
// at most 60 s; its output (stdout and stderr) in `out`.
int run(const std::string& cmd, const std::string& dir, const std::string& ns, const std::vector<std::string>& env,
        std::string& out) {
  std::string line = "cd " + shell_quote(dir) + " && env -u HORUS_BACKEND -u HORUS_CONFIG -u HORUS_PEERS HORUS_NAMESPACE=" +
                     ns + " PATH=" + shell_quote(std::filesystem::path(HORUS_CLI).parent_path().string() + ":" +
                                                 std::getenv("PATH"));
  for (const auto& e : env) line += " " + shell_quote(e);
  line += " timeout -k 5 60 sh -c " + shell_quote(cmd);
  return horus_test::run_command(line, out);
}

std::string scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("horus_readme_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

TEST(Readme, EveryCppBlockAndCliSampleSaysHowItIsChecked) {
  int cpp = 0, cli = 0;
  for (const auto& b : blocks()) {
    const auto& d = b.directive;
    if (b.is_cpp()) {
      ++cpp;
      EXPECT_TRUE(d.mode == "run" || d.mode == "compile" || d.mode == "top" || d.mode == "skip")
          << b.where() << ": a C++ block needs <!-- readme-test: run|compile|top|skip ... --> above it, got '"
          << d.mode << "'";
    } else if (b.lang == "python") {
      EXPECT_TRUE(d.mode == "python" || d.mode == "skip")
          << b.where() << ": a Python block needs <!-- readme-test: python --> (python/tests/test_readme.py runs it) or "
          << "skip above it, got '" << d.mode << "'";
    } else if (b.is_cli_sample()) {
      ++cli;
      EXPECT_TRUE(d.mode == "cli" || d.mode == "skip")
          << b.where() << ": a CLI sample needs <!-- readme-test: cli FIXTURE --> or skip above it, got '" << d.mode
          << "'";
    }
    if (d.mode == "skip") {
      EXPECT_FALSE(d.arg.empty()) << b.where() << ": skip says why";
    }
  }
  EXPECT_GE(cpp, 5) << "README.md's C++ blocks were not found";
  EXPECT_GE(cli, 1) << "README.md's CLI samples were not found";
}

TEST(Readme, ToolsReadmeHoldsNoSampleThisTestWouldMiss) {
  // The runner compiles and runs README.md's blocks; tools/README.md documents the CLI in a table
  // (test_cli_docs.cpp holds it to --help). A C++ block or a "$ command" sample there would go
  // unchecked: move it to README.md or teach this test to run it.
  for (const auto& b : readme::parse(readme::read_file(HORUS_TOOLS_README))) {
    EXPECT_FALSE(b.is_cpp()) << b.where("tools/README.md") << ": a C++ block that nothing compiles";
    EXPECT_FALSE(b.is_cli_sample()) << b.where("tools/README.md") << ": a CLI sample that nothing runs";
  }
}

TEST(Readme, EveryCppBlockIsCompiledInReadmeBlocks) {
  std::string listing;
  ASSERT_EQ(horus_test::run_command(std::string(HORUS_README_BLOCKS) + " --list", listing), 0) << listing;
  std::map<int, std::string> compiled;
  std::istringstream in(listing);
  for (std::string line; std::getline(in, line);) {
    const auto sp = line.find(' ');
    compiled[std::stoi(line.substr(0, sp))] = sp == std::string::npos ? "" : line.substr(sp + 1);
  }
  for (const auto& b : blocks()) {
    if (!b.is_cpp()) continue;
    ASSERT_TRUE(compiled.contains(b.line)) << b.where() << " is not in readme_blocks: build it again";
    EXPECT_EQ(compiled[b.line], b.directive.mode) << b.where() << ": readme_blocks was built from another README";
  }
}

TEST(Readme, RunBlocksPrintWhatTheReadmeSays) {
  int ran = 0;
  for (const auto& b : blocks()) {
    if (!b.is_cpp() || b.directive.mode != "run") continue;
    SCOPED_TRACE(b.where());
    ++ran;
    const std::string dir = scratch_dir(std::to_string(b.line));
    std::string out;
    const int rc = run(std::string(HORUS_README_BLOCKS) + " " + std::to_string(b.line), dir,
                       "readme" + std::to_string(::getpid()) + "_" + std::to_string(b.line), b.directive.env, out);
    EXPECT_EQ(rc, b.directive.exit_code.value_or(0)) << b.where() << " exited with " << rc << ", printing:\n" << out;
    for (const auto& text : readme::expected_output(b))
      EXPECT_NE(out.find(text), std::string::npos)
          << b.where() << " should print \"" << text << "\"; it printed:\n" << out;
    std::filesystem::remove_all(dir);
  }
  EXPECT_GE(ran, 3);
}

// ---------------------------------------------------------------------------
// CLI samples.

// A line as a pattern: spaces collapsed, every number (sign, decimals, exponent) as '#'.
std::string shape(const std::string& line) {
  static const std::regex number(R"([-+]?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?)");
  static const std::regex spaces(R"([ \t]+)");
  return readme::trim(std::regex_replace(std::regex_replace(line, number, "#"), spaces, " "));
}

// Whether `actual` has the shape of `expected`, where a "..." line stands for any lines.
bool matches(const std::vector<std::string>& expected, std::size_t e, const std::vector<std::string>& actual,
             std::size_t a) {
  if (e == expected.size()) return a == actual.size();
  if (readme::trim(expected[e]) == "...") {
    for (std::size_t skip = a; skip <= actual.size(); ++skip)
      if (matches(expected, e + 1, actual, skip)) return true;
    return false;
  }
  return a < actual.size() && shape(expected[e]) == shape(actual[a]) && matches(expected, e + 1, actual, a + 1);
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

// A fixture: the processes a sample needs, stopped when it goes.
class Fixture {
 public:
  Fixture(const std::string& name, const std::string& ns) {
    if (name == "robot") {  // one robot of the fleet demo: fleet.robot_1.{pose,tf,heartbeat} on shared memory
      pid_ = ::fork();
      if (pid_ == 0) {
        ::setenv("HORUS_NAMESPACE", ns.c_str(), 1);
        ::unsetenv("HORUS_BACKEND");
        ::unsetenv("HORUS_CONFIG");
        ::execl(HORUS_FLEET_DEMO, HORUS_FLEET_DEMO, "--role", "robot", "--id", "1", static_cast<char*>(nullptr));
        ::_exit(127);
      }
      std::string out;  // ready once its pose topic has a message (echo waits for the topic to appear)
      ready_ = run("horus topic echo fleet.robot_1.pose -n 1 --timeout 20", ".", ns, {}, out) == 0;
      if (!ready_) problem_ = "the robot's pose never came: " + out;
    } else if (name == "none") {  // nothing runs beside the sample (it works in its scratch directory)
      ready_ = true;
    } else {
      problem_ = "unknown fixture '" + name + "' (robot, none)";
    }
  }
  ~Fixture() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      (void)horus_test::wait_for(pid_, std::chrono::seconds(10));
    }
  }
  Fixture(const Fixture&) = delete;
  Fixture& operator=(const Fixture&) = delete;
  bool ready() const { return ready_; }
  const std::string& problem() const { return problem_; }

 private:
  pid_t pid_ = -1;
  bool ready_ = false;
  std::string problem_;
};

TEST(Readme, CliSamplesPrintWhatTheReadmeShows) {
  int ran = 0;
  for (const auto& b : blocks()) {
    if (!b.is_cli_sample() || b.directive.mode != "cli") continue;
    SCOPED_TRACE(b.where());
    const std::string ns = "readme" + std::to_string(::getpid()) + "_" + std::to_string(b.line);
    Fixture fixture(b.directive.arg, ns);
    ASSERT_TRUE(fixture.ready()) << b.where() << ": " << fixture.problem();
    const std::string dir = scratch_dir(std::to_string(b.line));
    for (std::size_t i = 0; i < b.lines.size();) {
      std::string cmd = b.lines[i].substr(2);
      const int cmd_line = b.line + 1 + static_cast<int>(i);
      if (const auto comment = cmd.find("  #"); comment != std::string::npos) cmd = cmd.substr(0, comment);
      // Commands written as run from the source tree use this build.
      for (std::size_t p = 0; (p = cmd.find("build/default/", p)) != std::string::npos;) {
        cmd.replace(p, 14, std::string(HORUS_BUILD_DIR) + "/");
        p += std::string(HORUS_BUILD_DIR).size() + 1;
      }
      std::vector<std::string> expected;
      for (++i; i < b.lines.size() && !b.lines[i].starts_with("$ "); ++i) expected.push_back(b.lines[i]);
      std::string out;
      const int rc = run(cmd, dir, ns, b.directive.env, out);
      ++ran;
      EXPECT_EQ(rc, 0) << "README.md:" << cmd_line << ": " << cmd << "\n" << out;
      EXPECT_TRUE(matches(expected, 0, lines_of(out), 0))
          << "README.md:" << cmd_line << ": " << cmd << "\nthe README shows:\n"
          << [&] {
               std::string s;
               for (const auto& l : expected) s += l + "\n";
               return s;
             }()
          << "it printed:\n"
          << out;
    }
    std::filesystem::remove_all(dir);
  }
  EXPECT_GE(ran, 1);
}

TEST(Readme, SamplePatternsMatchFiguresOnly) {
  // The matcher itself: numbers and spacing may differ, words may not, "..." spans lines.
  EXPECT_TRUE(matches({"received 24 messages"}, 0, {"received 31 messages"}, 0));
  EXPECT_TRUE(matches({"min: 0.049790s max: 0.050176s"}, 0, {"min:  0.1s   max: -2e-3s"}, 0));
  EXPECT_FALSE(matches({"received 24 messages"}, 0, {"received 24 message"}, 0));
  EXPECT_FALSE(matches({"a", "b"}, 0, {"a"}, 0));
  EXPECT_FALSE(matches({"a"}, 0, {"a", "b"}, 0));
  EXPECT_TRUE(matches({"a", "...", "z 1"}, 0, {"a", "b", "c", "z 2"}, 0));
  EXPECT_TRUE(matches({"a", "...", "z"}, 0, {"a", "z"}, 0));
  EXPECT_FALSE(matches({"a", "...", "z"}, 0, {"a", "b"}, 0));
}

}  // namespace

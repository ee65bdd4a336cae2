// tools/README.md documents every option `horus ... --help` shows: for each command, the README
// row of that command names each of its options.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "horus/ros2/interface.hpp"
#include "process_support.hpp"

namespace {

// The commands, as tools/README.md's table names them ("`horus topic list [--json] ...`").
const std::vector<std::string> kCommands = {
    "topic list", "topic info",  "topic echo",     "topic hz", "topic bw",   "topic pub",   "fleet",
    "record",     "record info", "record recover", "play",     "bench pong", "bench ping", "bench local",
    "clean",      "config check", "config explain", "security keystore init", "security host create",
    "security permissions", "security governance", "security check", "security dds-config", "idl"};

// The options of one command's --help: "-n,--count INT  ..." gives "-n" and "--count".
std::vector<std::vector<std::string>> options_of(const std::string& help) {
  std::vector<std::vector<std::string>> out;
  std::istringstream in(help);
  std::string line;
  bool in_options = false;
  while (std::getline(in, line)) {
    if (line.starts_with("Options:")) {
      in_options = true;
      continue;
    }
    if (!line.empty() && line[0] != ' ') in_options = false;
    if (!in_options) continue;
    std::istringstream words(line);
    std::string first;
    words >> first;
    if (!first.starts_with("-")) continue;
    std::vector<std::string> names;
    std::stringstream parts(first);
    for (std::string name; std::getline(parts, name, ',');)
      if (!name.empty()) names.push_back(name);
    if (std::find(names.begin(), names.end(), "--help") == names.end()) out.push_back(names);
  }
  return out;
}

// README rows by command: the words after "horus" up to the first that is not a subcommand.
std::map<std::string, std::string> readme_rows() {
  std::ifstream in(HORUS_TOOLS_README);
  std::map<std::string, std::string> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.starts_with("| `horus ")) continue;
    const auto end = line.find("` |");
    std::istringstream words(line.substr(9, end - 9));
    std::string command, word;
    while (words >> word) {
      if (word.starts_with("[") || word.starts_with("-") || std::isupper(static_cast<unsigned char>(word[0]))) break;
      command += (command.empty() ? "" : " ") + word;
    }
    rows[command] = line;
  }
  return rows;
}

TEST(CliDocs, ToolsReadmeNamesEveryOptionEachCommandsHelpShows) {
  const auto rows = readme_rows();
  ASSERT_FALSE(rows.empty()) << "no command rows in " << HORUS_TOOLS_README;
  std::string missing;
  std::size_t parsed = 0;
  for (const auto& command : kCommands) {
    std::string help;
    ASSERT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " " + command + " --help", help), 0) << help;
    const auto options = options_of(help);
    parsed += options.size();
    const auto row = rows.find(command);
    if (row == rows.end()) {
      missing += "\n  no row for `horus " + command + "`";
      continue;
    }
    for (const auto& names : options) {
      bool named = false;
      for (const auto& n : names) {
        // The name as a whole word of the row: "--window" is not named by "--window-s".
        for (auto at = row->second.find(n); at != std::string::npos && !named; at = row->second.find(n, at + 1)) {
          const char after = at + n.size() < row->second.size() ? row->second[at + n.size()] : ' ';
          named = !(std::isalnum(static_cast<unsigned char>(after)) || after == '-' || after == '_');
        }
      }
      if (!named) missing += "\n  `horus " + command + "`: " + names.back();
    }
  }
  EXPECT_GT(parsed, 60u) << "the options of --help were not parsed";  // 70 today
  EXPECT_TRUE(missing.empty()) << "tools/README.md does not name these options that --help shows:" << missing;
}

// horus idl --ros2 DIR writes the package and prints each type's hash, the one its .msg gives.
TEST(CliIdl, WritesTheRos2PackageAndPrintsEachTypesHash) {
  const std::string dir = "/tmp/horus_test_idl_" + std::to_string(::getpid());
  std::string out;
  ASSERT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " idl --ros2 " + dir, out), 0) << out;
  std::ifstream msg(dir + "/msg/Pose2D.msg");
  ASSERT_TRUE(msg) << "no msg/Pose2D.msg in " << dir << ":\n" << out;
  std::stringstream text;
  text << msg.rdbuf();
  horus::ros2::Interfaces one;
  ASSERT_TRUE(one.add("horus_msgs/msg/Pose2D", text.str()));
  const std::string hash = one.type_hash("horus_msgs/msg/Pose2D").value();
  EXPECT_NE(out.find("horus_msgs/msg/Pose2D " + hash + "\n"), std::string::npos) << out;
  EXPECT_TRUE(std::ifstream(dir + "/package.xml").good());
  EXPECT_TRUE(std::ifstream(dir + "/CMakeLists.txt").good());
  EXPECT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " idl --ros2 " + dir + " --package Not-A-Package", out), 1)
      << out;
  EXPECT_NE(out.find("'Not-A-Package' is not a ROS 2 package name"), std::string::npos) << out;
  std::string ignored;
  (void)horus_test::run_command("rm -rf " + dir, ignored);
}

}  // namespace

// README.md as the README test sees it: its fenced blocks, each with the directive written in an
// HTML comment just above it (invisible once rendered):
//
//   <!-- readme-test: run            the C++ block runs (wrapped in a function); also: compile
//        given: horus::Topic<horus::msg::Imu> imu("imu");    code placed before the block
//        after: ex.stop();                                   code placed after it
//        expect: a text the block must print (stdout or stderr); several allowed
//        exit: 1                                             its exit status (default 0)
//        env: HORUS_BACKEND=lcm                              set for its run
//        file-scope: 3                                       its first 3 lines are declarations
//   -->
//   <!-- readme-test: top -->        C++ at file scope (declarations), compiled
//   <!-- readme-test: cli robot -->  a CLI sample ("$ command" lines, then what it prints) run
//                                    beside a fixture, its output matched as a pattern
//   <!-- readme-test: skip WHY -->   not run, for the reason given
//
// A `fmt::print(...);  // TEXT` line of a run block expects TEXT, as the README promises.
// Shared by the generator (readme_extract.cpp) and the test (test_readme.cpp); header-only.
#pragma once

#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace readme {

struct Directive {
  std::string mode;                  // run, compile, top, cli, skip; empty: none written
  std::string arg;                   // the rest of the first line (skip's reason, cli's fixture)
  std::vector<std::string> given, after, expect, env;
  std::optional<int> exit_code;
  std::size_t file_scope = 0;        // how many of the block's first lines are at file scope
  int line = 0;                      // where the comment starts (1-based)
};

struct Block {
  int line = 0;                      // the opening fence's line (1-based)
  std::string lang;                  // "cpp", "sh", "" ...
  std::vector<std::string> lines;    // the content, the fence's indentation removed
  Directive directive;

  bool is_cpp() const { return lang == "cpp" || lang == "c++"; }
  /// A CLI sample: a fence without a language whose first line is a "$ " command.
  bool is_cli_sample() const { return lang.empty() && !lines.empty() && lines.front().starts_with("$ "); }
  /// The block's name in test output: "README.md:66".
  std::string where(std::string_view file = "README.md") const { return std::string(file) + ":" + std::to_string(line); }
};

inline std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return std::string(s.substr(b, e - b + 1));
}

namespace detail {
// The directive comment that ends on lines[end] (its first line has "<!-- readme-test:").
inline Directive parse_directive(const std::vector<std::string>& lines, std::size_t end) {
  Directive d;
  std::size_t begin = end;
  for (;;) {
    if (lines[begin].find("<!--") != std::string::npos) break;
    if (begin == 0 || end - begin > 40) return d;
    --begin;
  }
  const std::string& first = lines[begin];
  const auto key = first.find("readme-test:");
  if (key == std::string::npos) return d;
  std::vector<std::string> body;
  body.push_back(first.substr(key + 12));
  for (std::size_t i = begin + 1; i <= end; ++i) body.push_back(lines[i]);
  auto& last = body.back();
  last = last.substr(0, last.rfind("-->"));
  d.line = static_cast<int>(begin) + 1;
  const std::string head = trim(body.front());
  const auto sp = head.find(' ');
  d.mode = head.substr(0, sp);
  d.arg = sp == std::string::npos ? "" : trim(head.substr(sp + 1));
  for (std::size_t i = 1; i < body.size(); ++i) {
    const std::string t = trim(body[i]);
    if (t.empty()) continue;
    const auto colon = t.find(':');
    if (colon == std::string::npos) throw std::runtime_error("README.md:" + std::to_string(begin + 1 + i) +
                                                             ": a directive line is 'key: value', got '" + t + "'");
    const std::string k = t.substr(0, colon);
    const std::string v = trim(t.substr(colon + 1));
    if (k == "given") d.given.push_back(v);
    else if (k == "after") d.after.push_back(v);
    else if (k == "expect") d.expect.push_back(v);
    else if (k == "env") d.env.push_back(v);
    else if (k == "exit") d.exit_code = std::stoi(v);
    else if (k == "file-scope") d.file_scope = std::stoul(v);
    else
      throw std::runtime_error("README.md:" + std::to_string(begin + 1 + i) + ": unknown directive key '" + k +
                               "' (given, after, expect, exit, env, file-scope)");
  }
  return d;
}
}  // namespace detail

/// The fenced blocks of a Markdown text, with their directives.
inline std::vector<Block> parse(std::string_view text) {
  std::vector<std::string> lines;
  std::istringstream in{std::string(text)};
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  std::vector<Block> blocks;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const auto indent = lines[i].find_first_not_of(' ');
    if (indent == std::string::npos || lines[i].compare(indent, 3, "```") != 0) continue;
    Block b;
    b.line = static_cast<int>(i) + 1;
    b.lang = trim(std::string_view(lines[i]).substr(indent + 3));
    std::size_t j = i + 1;
    for (; j < lines.size(); ++j) {
      if (trim(lines[j]) == "```") break;
      const auto& l = lines[j];
      b.lines.push_back(l.substr(std::min(indent, l.find_first_not_of(' ') == std::string::npos ? l.size()
                                                                                                 : l.find_first_not_of(' '))));
    }
    // The directive: the comment that ends on the last non-blank line above the fence.
    std::size_t k = i;
    while (k > 0 && trim(lines[k - 1]).empty()) --k;
    if (k > 0 && trim(lines[k - 1]).ends_with("-->")) b.directive = detail::parse_directive(lines, k - 1);
    blocks.push_back(std::move(b));
    i = j;
  }
  return blocks;
}

inline std::string read_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read " + path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// The texts a run block promises to print: its directive's `expect:` lines, and the comment of
/// every `fmt::print(...);  // TEXT` line.
inline std::vector<std::string> expected_output(const Block& b) {
  std::vector<std::string> out = b.directive.expect;
  for (const auto& l : b.lines) {
    const auto print = l.find("fmt::print(");
    const auto comment = l.find(" //", print == std::string::npos ? l.size() : print);
    if (print != std::string::npos && comment != std::string::npos) out.push_back(trim(l.substr(comment + 3)));
  }
  return out;
}

}  // namespace readme

// readme_blocks: the C++ blocks of README.md, one translation unit each (readme_extract writes
// them), in one program.
//   readme_blocks --list    every block: its README line and directive mode
//   readme_blocks LINE      runs the block at that line; its return value is the exit status
// An exception that leaves a block is printed and exits with 3.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <string>
#include <utility>

#include "readme_prelude.hpp"

namespace {
std::map<int, std::pair<std::string, int (*)()>>& registry() {
  static std::map<int, std::pair<std::string, int (*)()>> r;
  return r;
}
}  // namespace

readme::Registration::Registration(int line, const char* mode, int (*run)()) { registry()[line] = {mode, run}; }

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: readme_blocks --list | LINE\n");
    return 2;
  }
  const std::string arg = argv[1];
  if (arg == "--list") {
    for (const auto& [line, entry] : registry()) std::printf("%d %s\n", line, entry.first.c_str());
    return 0;
  }
  const auto it = registry().find(std::atoi(argv[1]));
  if (it == registry().end()) {
    std::fprintf(stderr, "readme_blocks: no block starts at README.md:%s (see --list)\n", argv[1]);
    return 2;
  }
  try {
    const int rc = it->second.second();
    std::fflush(stdout);
    return rc;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "readme_blocks: README.md:%d threw: %s\n", it->first, e.what());
    return 3;
  }
}

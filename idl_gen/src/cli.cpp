#include "horus/idlgen/cli.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

namespace horus::idlgen {
namespace {

struct Lock {
  int version = -1;
  std::map<std::string, std::pair<std::string, std::uint64_t>> types;  // type -> (file, fingerprint)
};

bool read_text(const std::filesystem::path& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream ss;
  ss << in.rdbuf();
  out = ss.str();
  return true;
}

bool write_text(const std::filesystem::path& path, const std::string& text) {
  std::string old;
  if (read_text(path, old) && old == text) return true;  // unchanged: keep the timestamp
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  return static_cast<bool>(out);
}

// Parses a lock file; an error names the line.
bool parse_lock(const std::string& text, const std::string& path, Lock& lock) {
  std::istringstream in(text);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::string a, b, c;
    ls >> a >> b >> c;
    if (a == "version" && c.empty()) {
      try {
        lock.version = std::stoi(b);
        continue;
      } catch (const std::exception&) {
      }
    } else if (!a.empty() && !b.empty() && c.starts_with("0x")) {
      try {
        lock.types[a] = {b, std::stoull(c.substr(2), nullptr, 16)};
        continue;
      } catch (const std::exception&) {
      }
    }
    std::fprintf(stderr, "horus-idlgen: %s:%d: '%s' is not a lock line; expected 'version N' or '<type> <file> 0x<fingerprint>'\n",
                 path.c_str(), n, line.c_str());
    return false;
  }
  if (lock.version < 0) {
    std::fprintf(stderr, "horus-idlgen: %s has no 'version N' line\n", path.c_str());
    return false;
  }
  return true;
}

std::string lock_text(const std::vector<Definition>& defs) {
  std::string out =
      "# horus-idlgen lock: the fingerprint of every emitted interface type. Third-party programs build\n"
      "# against these definitions, so the lock test fails when one changes. To change a type on\n"
      "# purpose, bump kInterfaceVersion (idl_gen/include/horus/idlgen/emit.hpp) and run\n"
      "#   horus-idlgen --update-lock <this file>\n";
  out += "version " + std::to_string(kInterfaceVersion) + "\n";
  char buf[32];
  for (const auto& d : defs) {
    std::snprintf(buf, sizeof(buf), "0x%016llx", static_cast<unsigned long long>(fingerprint(d.text)));
    out += d.type + " " + d.file + " " + buf + "\n";
  }
  return out;
}

// Differences between the lock and what is emitted now, one line each.
std::vector<std::string> compare(const Lock& lock, const std::vector<Definition>& defs, bool& changed) {
  std::vector<std::string> out;
  changed = false;
  std::map<std::string, int> seen;
  for (const auto& d : defs) {
    seen[d.type] = 1;
    auto it = lock.types.find(d.type);
    if (it == lock.types.end()) {
      out.push_back("new type " + d.type + " (" + d.file + ") is not in the lock");
    } else if (it->second.second != fingerprint(d.text) || it->second.first != d.file) {
      changed = true;
      out.push_back("type " + d.type + " (" + d.file + ") changed since the lock (interface version " +
                    std::to_string(lock.version) + ")");
    }
  }
  for (const auto& [type, v] : lock.types)
    if (!seen.contains(type)) {
      changed = true;
      out.push_back("type " + type + " (" + v.first + ") is in the lock but no longer emitted");
    }
  return out;
}

int usage() {
  std::fprintf(stderr,
               "usage: horus-idlgen --out DIR | --lcm-out DIR | --ros2-out DIR | --print FILE | --list | "
               "--check-lock LOCK | --update-lock LOCK\n"
               "  --out DIR       write the .idl files (DDS)\n"
               "  --lcm-out DIR   write the .lcm files (LCM)\n"
               "  --ros2-out DIR  write the ROS 2 interface package horus_msgs (package.xml, CMakeLists.txt, msg/)\n"
               "  --print FILE   print one file (geometry.idl, geometry.lcm)\n");
  return 2;
}

// Every emitted file, .idl then .lcm.
std::vector<OutputFile> all_files(const Model& model, const IdlOptions& options) {
  auto out = emit_idl(model, options);
  for (auto& f : emit_lcm(model, options)) out.push_back(std::move(f));
  return out;
}

// Every emitted definition (IDL types by their C++ name, LCM types by pkg.Name).
std::vector<Definition> all_definitions(const Model& model, const IdlOptions& options) {
  auto out = idl_definitions(model, options);
  for (auto& d : lcm_definitions(model, options)) out.push_back(std::move(d));
  return out;
}

int write_files(const std::string& dir, const std::vector<OutputFile>& files) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "horus-idlgen: cannot create %s: %s\n", dir.c_str(), ec.message().c_str());
    return 1;
  }
  for (const auto& f : files) {
    const auto path = std::filesystem::path(dir) / f.name;
    std::filesystem::create_directories(path.parent_path(), ec);
    if (!write_text(path, f.text)) {
      std::fprintf(stderr, "horus-idlgen: cannot write %s/%s\n", dir.c_str(), f.name.c_str());
      return 1;
    }
  }
  return 0;
}

// --lcm-out DIR: the LCM types, with a warning for each type left out (the DDS interfaces still
// have them).
int write_lcm(const Model& model, const std::string& dir, const IdlOptions& options) {
  const auto files = emit_lcm(model, options);
  for (const auto& f : files) {  // types left out: warn (the DDS interfaces still have them)
    std::size_t pos = 0;
    while ((pos = f.text.find("\n// no LCM type: ", pos)) != std::string::npos) {
      const auto end = f.text.find('\n', pos + 1);
      std::fprintf(stderr, "horus-idlgen: warning: %s: %s\n", f.name.c_str(),
                   f.text.substr(pos + 4, end - pos - 4).c_str());
      pos = end;
    }
  }
  return write_files(dir, files);
}

// --print FILE.
int print_file(const Model& model, const std::string& arg, const IdlOptions& options) {
  for (const auto& f : all_files(model, options))
    if (f.name == arg || f.name == arg + ".idl") {
      std::fputs(f.text.c_str(), stdout);
      return 0;
    }
  std::fprintf(stderr, "horus-idlgen: no file '%s'; --list shows them\n", arg.c_str());
  return 1;
}

// --check-lock FILE: 0 when the emitted interfaces are the lock file's.
int check_lock(const Lock& lock, const std::vector<Definition>& defs, const std::string& arg) {
  bool changed = false;
  const auto diffs = compare(lock, defs, changed);
  if (lock.version != kInterfaceVersion)
    std::fprintf(stderr, "horus-idlgen: %s is for interface version %d, the generator is version %d\n",
                 arg.c_str(), lock.version, kInterfaceVersion);
  for (const auto& d : diffs) std::fprintf(stderr, "horus-idlgen: %s\n", d.c_str());
  if (diffs.empty() && lock.version == kInterfaceVersion) return 0;
  std::fprintf(stderr, "horus-idlgen: the emitted interfaces differ from %s.%s Run: horus-idlgen --update-lock %s\n",
               arg.c_str(),
               changed && lock.version == kInterfaceVersion
                   ? " A type changed: bump kInterfaceVersion (idl_gen/include/horus/idlgen/emit.hpp) first."
                   : "",
               arg.c_str());
  return 1;
}

// --update-lock FILE: refused when existing types changed within one interface version.
int update_lock(const Lock& lock, bool exists, const std::vector<Definition>& defs, const std::string& arg) {
  if (exists) {
    bool changed = false;
    const auto diffs = compare(lock, defs, changed);
    if (changed && lock.version == kInterfaceVersion) {
      for (const auto& d : diffs) std::fprintf(stderr, "horus-idlgen: %s\n", d.c_str());
      std::fprintf(stderr,
                   "horus-idlgen: refusing to update %s: existing types changed but kInterfaceVersion is still %d; "
                   "bump it (idl_gen/include/horus/idlgen/emit.hpp) so peers can tell the versions apart\n",
                   arg.c_str(), kInterfaceVersion);
      return 1;
    }
  }
  if (!write_text(arg, lock_text(defs))) {
    std::fprintf(stderr, "horus-idlgen: cannot write %s\n", arg.c_str());
    return 1;
  }
  return 0;
}

// --check-lock FILE or --update-lock FILE (`cmd`).
int lock_command(const Model& model, const std::string& cmd, const std::string& arg, const IdlOptions& options) {
  const auto defs = all_definitions(model, options);
  std::string text;
  Lock lock;
  const bool exists = read_text(arg, text);
  if (exists && !parse_lock(text, arg, lock)) return 1;
  if (cmd == "--check-lock") {
    if (!exists) {
      std::fprintf(stderr, "horus-idlgen: cannot read lock file %s\n", arg.c_str());
      return 1;
    }
    return check_lock(lock, defs, arg);
  }
  return update_lock(lock, exists, defs, arg);
}

}  // namespace

int run_cli(const Model& model, int argc, char** argv, const IdlOptions& options) {
  if (argc != 2 && argc != 3) return usage();
  const std::string cmd = argv[1];
  const std::string arg = argc == 3 ? argv[2] : "";
  try {
    if (cmd == "--list" && argc == 2) {
      for (const auto& d : all_definitions(model, options)) std::printf("%s %s\n", d.file.c_str(), d.type.c_str());
      return 0;
    }
    if (argc != 3) return usage();
    if (cmd == "--out") return write_files(arg, emit_idl(model, options));
    if (cmd == "--lcm-out") return write_lcm(model, arg, options);
    if (cmd == "--ros2-out") return write_files(arg, emit_ros2(model));
    if (cmd == "--print") return print_file(model, arg, options);
    if (cmd == "--check-lock" || cmd == "--update-lock") return lock_command(model, cmd, arg, options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return usage();
}

}  // namespace horus::idlgen

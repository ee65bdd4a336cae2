// horus-fanout's probes of the machine and of itself (fanout_probes.hpp).
#include "fanout_probes.hpp"

#include <dirent.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>

namespace horus::bench::fanout {

long rss_kib() {
  std::ifstream in("/proc/self/statm");
  long size = 0, resident = 0;
  in >> size >> resident;
  return resident * (::sysconf(_SC_PAGESIZE) / 1024);
}

std::pair<std::uint64_t, std::uint64_t> segment_bytes(const std::string& topic) {
  std::pair<std::uint64_t, std::uint64_t> r{0, 0};
  DIR* d = ::opendir("/dev/shm");
  if (d == nullptr) return r;
  const std::string suffix = "." + topic;
  while (dirent* e = ::readdir(d)) {
    const std::string n = e->d_name;
    if (n.rfind("horus.", 0) != 0 || n.size() < suffix.size() ||
        n.compare(n.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    struct stat st {};
    if (::stat(("/dev/shm/" + n).c_str(), &st) == 0) {
      r.first += static_cast<std::uint64_t>(st.st_size);
      r.second += static_cast<std::uint64_t>(st.st_blocks) * 512;
    }
  }
  ::closedir(d);
  return r;
}

bool tsc_is_invariant() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("flags", 0) == 0)
      return line.find(" constant_tsc") != std::string::npos && line.find(" nonstop_tsc") != std::string::npos;
  return false;
}

void raise_fd_limit() {
  rlimit r{};
  if (::getrlimit(RLIMIT_NOFILE, &r) == 0 && r.rlim_cur < r.rlim_max) {
    r.rlim_cur = r.rlim_max;
    ::setrlimit(RLIMIT_NOFILE, &r);
  }
}

}  // namespace horus::bench::fanout

// Whether a process is alive, told apart from a later process with the same pid by its start
// time (horus/shm/shm_segment.hpp: process_start_time, process_alive): what reclaims the lanes,
// entries and segments of processes that died.
#include <signal.h>

#include <cerrno>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#include "horus/shm/shm_segment.hpp"

namespace horus::shm {

namespace {
// Field 3 (state) and field 22 (start time) of /proc/<pid>/stat; false when unreadable.
bool read_stat(pid_t pid, char& state, std::uint64_t& start) noexcept {
  try {
    std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
    if (!in) return false;
    std::string line;
    std::getline(in, line);
    // The command name (field 2) may hold spaces and ')': fields resume after the last ')'.
    const auto close = line.rfind(')');
    if (close == std::string::npos || close + 2 >= line.size()) return false;
    std::istringstream rest(line.substr(close + 2));
    std::string field;
    rest >> state;
    for (int i = 4; i < 22; ++i)
      if (!(rest >> field)) return false;
    rest >> start;
    return static_cast<bool>(rest);
  } catch (...) {
    return false;
  }
}
}  // namespace

std::uint64_t process_start_time(pid_t pid) noexcept {
  char state = 0;
  std::uint64_t start = 0;
  return read_stat(pid, state, start) ? start : 0;
}

bool process_alive(pid_t pid, std::uint64_t start_time) noexcept {
  if (pid <= 0) return false;
  if (::kill(pid, 0) != 0 && errno == ESRCH) return false;
  char state = 0;
  std::uint64_t start = 0;
  // Unreadable /proc entry (no /proc, hidepid, another user's process): kill() found it, so
  // it may well be alive. Never reap what cannot be proven dead; the next look decides.
  if (!read_stat(pid, state, start)) return true;
  if (state == 'Z' || state == 'X') return false;  // exited, not yet reaped by its parent
  return start_time == 0 || start == start_time;
}

}  // namespace horus::shm

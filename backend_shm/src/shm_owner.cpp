// Who may use a shared-memory file (shm_segment.hpp: foreign_file): its owner, and the group a
// HORUS_SHM_MODE that shares segments admits.
#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "horus/shm/shm_segment.hpp"

namespace horus::shm {

namespace {
std::string user_name(uid_t uid) {
  struct passwd pw{}, *found = nullptr;
  char buf[1024];
  if (::getpwuid_r(uid, &pw, buf, sizeof buf, &found) == 0 && found != nullptr) return found->pw_name;
  return "no name";
}

bool in_group(gid_t gid) {
  if (gid == ::getegid()) return true;
  gid_t groups[256];
  const int n = ::getgroups(256, groups);
  return std::find(groups, groups + std::max(n, 0), gid) != groups + std::max(n, 0);
}
}  // namespace

std::optional<std::string> foreign_file(int fd, mode_t mode, const std::string& name) {
  struct stat st{};
  if (::fstat(fd, &st) != 0) return "cannot stat /dev/shm" + name + ": " + std::strerror(errno);
  const unsigned perms = st.st_mode & 0777u;
  const uid_t me = ::geteuid();
  const bool beyond = (perms & 0022u & ~static_cast<unsigned>(mode)) != 0;
  const bool shared = (mode & 0060u) != 0 && in_group(st.st_gid) && (perms & ~static_cast<unsigned>(mode)) == 0;
  if (st.st_uid == me && !beyond) return std::nullopt;
  if (st.st_uid != me && shared) return std::nullopt;
  return fmt::format("shared-memory file /dev/shm{} belongs to uid {} ({}) with mode {:04o}, {}; this process "
                     "(uid {}, HORUS_SHM_MODE {:04o}) does not use it: another user could read or forge its messages "
                     "or shrink it. Remove it (rm /dev/shm{} as its owner or root) and find out who made it; "
                     "users who share topics set the same HORUS_NAMESPACE and HORUS_SHM_MODE=0660 and a common group",
                     name, st.st_uid, user_name(st.st_uid), perms,
                     st.st_uid != me ? std::string("not to this process's user")
                                     : fmt::format("which lets others than HORUS_SHM_MODE write it"),
                     me, static_cast<unsigned>(mode), name);
}

}  // namespace horus::shm

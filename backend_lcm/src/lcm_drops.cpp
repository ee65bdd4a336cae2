// Kernel drop counting for the LCM transport: LCM's udpm receive socket is found among this
// process's sockets (/proc/self/fd) in /proc/self/net/udp, whose `drops` column counts the
// datagrams the kernel dropped on it (a full receive buffer). Linux only; nothing is counted
// when /proc cannot be read.
#include <dirent.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "lcm_internal.hpp"

namespace horus::lcm::detail {
namespace {

// Inodes of this process's sockets (/proc/self/fd/N -> "socket:[inode]").
std::vector<std::uint64_t> own_socket_inodes() {
  std::vector<std::uint64_t> out;
  DIR* dir = ::opendir("/proc/self/fd");
  if (dir == nullptr) return out;
  while (const dirent* entry = ::readdir(dir)) {
    if (entry->d_name[0] == '.') continue;
    char link[64];
    const ssize_t n = ::readlinkat(::dirfd(dir), entry->d_name, link, sizeof link - 1);
    if (n <= 0) continue;
    const std::string_view target(link, static_cast<std::size_t>(n));
    constexpr std::string_view kPrefix = "socket:[";
    if (!target.starts_with(kPrefix) || !target.ends_with(']')) continue;
    const std::string_view digits = target.substr(kPrefix.size(), target.size() - kPrefix.size() - 1);
    if (const auto v = parse_decimal(digits, UINT64_MAX)) out.push_back(*v);
  }
  ::closedir(dir);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

// The whole of a (small, /proc) file; false when it cannot be read.
bool read_whole_file(const char* path, std::string& out) {
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  out.clear();
  char buffer[8192];
  bool ok = true;
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      ok = false;
      break;
    }
    out.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return ok;
}

void for_each_udp_row(const std::string& table, const std::function<void(const UdpRow&)>& f) {
  std::string_view rest(table);
  bool header = true;
  while (!rest.empty()) {
    const std::size_t nl = rest.find('\n');
    const std::string_view line = rest.substr(0, nl);
    rest.remove_prefix(nl == std::string_view::npos ? rest.size() : nl + 1);
    if (header) {
      header = false;
      continue;
    }
    // sl local rem st tx:rx tr:when retrnsmt uid timeout inode ref pointer drops
    std::array<std::string_view, 13> field{};
    std::size_t count = 0;
    std::string_view l = line;
    while (count < field.size()) {
      const std::size_t start = l.find_first_not_of(' ');
      if (start == std::string_view::npos) break;
      l.remove_prefix(start);
      const std::size_t end = l.find(' ');
      field[count++] = l.substr(0, end);
      l.remove_prefix(end == std::string_view::npos ? l.size() : end);
    }
    if (count < field.size()) continue;
    UdpRow row;
    const std::string_view local = field[1];
    const std::size_t colon = local.find(':');
    if (colon == std::string_view::npos) continue;
    unsigned port = 0;
    const char* pb = local.data() + colon + 1;
    if (std::from_chars(pb, local.data() + local.size(), port, 16).ec != std::errc() || port > 65535) continue;
    row.local_port = static_cast<std::uint16_t>(port);
    row.unconnected = field[2] == "00000000:0000";
    if (std::from_chars(field[9].data(), field[9].data() + field[9].size(), row.inode).ec != std::errc()) continue;
    if (std::from_chars(field[12].data(), field[12].data() + field[12].size(), row.drops).ec != std::errc()) continue;
    f(row);
  }
}

std::vector<std::uint64_t> udp_sockets_on_port(std::uint16_t port) {
  std::vector<std::uint64_t> out;
  const std::vector<std::uint64_t> mine = own_socket_inodes();
  std::string table;
  if (mine.empty() || !read_whole_file("/proc/self/net/udp", table)) return out;
  for_each_udp_row(table, [&](const UdpRow& row) {
    if (row.local_port == port && row.unconnected && std::binary_search(mine.begin(), mine.end(), row.inode))
      out.push_back(row.inode);
  });
  std::sort(out.begin(), out.end());
  return out;
}


std::optional<std::uint32_t> socket_drops(std::uint64_t inode, std::string& table) {
  std::optional<std::uint32_t> drops;
  if (!read_whole_file("/proc/self/net/udp", table)) return drops;
  for_each_udp_row(table, [&](const UdpRow& row) {
    if (row.inode == inode) drops = row.drops;
  });
  return drops;
}

}  // namespace horus::lcm::detail

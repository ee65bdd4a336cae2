// The LCM (liblcm 1.3.1, C API) backend of horus::net: see horus/network.hpp (the contract)
// and horus/lcm/transport.hpp.
//
// One LcmTransport per URL and process: an lcm_t and one receive thread (Engine::run) that
// polls {the lcm fd, an eventfd that stops it} and calls lcm_handle(), which runs the handlers
// of one message in that thread. Every listener call is made by that thread, while it holds
// Engine::handle_mutex_.
//
// Subscribing and unsubscribing. liblcm 1.3.1 cannot unsubscribe safely while another thread is
// inside lcm_handle(): lcm_dispatch_handlers() walks the channel's handler array by index with
// LCM's lock released around each callback, and lcm_unsubscribe() reorders that array
// (g_ptr_array_remove_fast), so a handler can be skipped or called twice. So every
// lcm_subscribe/lcm_unsubscribe runs under handle_mutex_ too, i.e. never concurrently with
// lcm_handle. Threads that need it announce themselves first (waiting_) and the receive thread
// gives way before its next lcm_handle, so open() and ~LcmEndpoint wait for at most the message
// being dispatched, never for the poll timeout. When ~LcmEndpoint or open() runs on the receive
// thread itself (from a listener callback), the lock is already held: subscribing is done at once
// (LCM allows it in a handler), unsubscribing is deferred until lcm_handle() returns, and the
// subscription's `closed` flag stops its callbacks at once.
#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <climits>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <exception>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include <lcm/lcm.h>

#include "horus/lcm/transport.hpp"
#include "horus/names.hpp"
#include "horus/transport_registry.hpp"

namespace horus::lcm {
namespace {

static_assert(kMaxChannelLength == LCM_MAX_CHANNEL_NAME_LENGTH);
static_assert(kMaxMessageSize == LCM_MAX_MESSAGE_SIZE);

constexpr int kPollTimeoutMs = 100;
constexpr auto kDropCheckPeriod = std::chrono::milliseconds(100);
// write() keeps a per-thread buffer for the body; above this size it is released after use.
constexpr std::size_t kKeepBufferLimit = std::size_t{16} << 20;

// ---------------------------------------------------------------------------- URL checks

enum class Provider { Udpm, Memq, File, Tcpq };

struct UrlInfo {
  Provider provider = Provider::Udpm;
  std::uint16_t port = 0;  // udpm
  bool file_read = true;   // file: mode r (the default)
};

constexpr std::string_view kUdpmExpected =
    "udpm://<IPv4 224.0.0.0-239.255.255.255>:<port>[?ttl=0..255&recv_buf_size=N]";
constexpr std::string_view kUdpmOptionsExpected =
    "udpm options ttl=0..255, recv_buf_size=<bytes, at least 1> and transmit_only=true|false, separated by '&'";
constexpr std::string_view kFileExpected = "file://<path>[?mode=r|w|a&speed=<number>&start_timestamp=<integer>]";
constexpr std::string_view kTcpqExpected = "tcpq://[<host>[:<port 1..65535>]] with no options";
constexpr std::string_view kSchemesExpected = "udpm://..., memq://, file://... or tcpq://...";

std::string url_error(std::string_view url, std::string_view problem, std::string_view expected) {
  std::string m = "LCM URL '";
  m += url;
  m += "': ";
  m += problem;
  m += "; expected ";
  m += expected;
  m += " (the default is ";
  m += kDefaultUrl;
  m += ")";
  return m;
}

std::string quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

bool all_digits(std::string_view s) noexcept {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// A decimal number 0..max, digits only.
std::optional<std::uint64_t> parse_decimal(std::string_view s, std::uint64_t max) noexcept {
  if (!all_digits(s) || s.size() > 19) return std::nullopt;
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || v > max) return std::nullopt;
  return v;
}

// Dotted-quad IPv4, decimal octets 0..255 without leading zeros (inet_aton would read "010"
// as octal and "1.2" as a short form: both are refused).
std::optional<std::array<std::uint8_t, 4>> parse_ipv4(std::string_view s) noexcept {
  std::array<std::uint8_t, 4> out{};
  for (std::size_t i = 0; i < 4; i++) {
    const std::size_t dot = s.find('.');
    const std::string_view part = i < 3 ? s.substr(0, dot) : s;
    if (i < 3 && dot == std::string_view::npos) return std::nullopt;
    if (part.size() > 3 || (part.size() > 1 && part[0] == '0')) return std::nullopt;
    const auto v = parse_decimal(part, 255);
    if (!v) return std::nullopt;
    out[i] = static_cast<std::uint8_t>(*v);
    if (i < 3) s.remove_prefix(dot + 1);
  }
  return out;
}

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  for (;;) {
    const std::size_t at = s.find(sep);
    out.push_back(s.substr(0, at));
    if (at == std::string_view::npos) return out;
    s.remove_prefix(at + 1);
  }
}

// Splits "k=v&k=v" into pairs; problems are reported with `expected`.
Result<std::vector<std::pair<std::string_view, std::string_view>>> parse_options(std::string_view url,
                                                                                 std::string_view options,
                                                                                 std::string_view expected) {
  std::vector<std::pair<std::string_view, std::string_view>> out;
  if (options.empty()) return fail(Errc::Config, url_error(url, "'?' is followed by no option", expected));
  for (std::string_view item : split(options, '&')) {
    if (item.empty()) return fail(Errc::Config, url_error(url, "an empty option (a stray '&')", expected));
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0)
      return fail(Errc::Config, url_error(url, "option " + quoted(item) + " is not of the form name=value", expected));
    const std::string_view key = item.substr(0, eq);
    for (const auto& [k, v] : out)
      if (k == key) return fail(Errc::Config, url_error(url, "option '" + std::string(key) + "' is given twice", expected));
    out.emplace_back(key, item.substr(eq + 1));
  }
  return out;
}

Result<UrlInfo> check_udpm(std::string_view url, std::string_view rest) {
  UrlInfo info;
  info.provider = Provider::Udpm;
  const std::size_t q = rest.find('?');
  const std::string_view host = rest.substr(0, q);
  if (host.empty()) return fail(Errc::Config, url_error(url, "no multicast address and port", kUdpmExpected));
  const std::size_t colon = host.rfind(':');
  const std::string_view addr = host.substr(0, colon);
  if (addr.empty()) return fail(Errc::Config, url_error(url, "no multicast address", kUdpmExpected));
  const auto ip = parse_ipv4(addr);
  if (!ip) return fail(Errc::Config, url_error(url, quoted(addr) + " is not an IPv4 address", kUdpmExpected));
  if ((*ip)[0] < 224 || (*ip)[0] > 239)
    return fail(Errc::Config, url_error(url, std::string(addr) + " is not a multicast address", kUdpmExpected));
  if (colon == std::string_view::npos || colon + 1 == host.size())
    return fail(Errc::Config, url_error(url, "the port is missing (liblcm would start but never receive)", kUdpmExpected));
  const std::string_view port = host.substr(colon + 1);
  if (!all_digits(port)) return fail(Errc::Config, url_error(url, "port " + quoted(port) + " is not a decimal number", kUdpmExpected));
  const auto p = parse_decimal(port, 65535);
  if (!p || *p == 0) return fail(Errc::Config, url_error(url, "port " + std::string(port) + " is out of range 1..65535", kUdpmExpected));
  info.port = static_cast<std::uint16_t>(*p);
  if (q == std::string_view::npos) return info;

  auto options = parse_options(url, rest.substr(q + 1), kUdpmOptionsExpected);
  if (!options) return std::unexpected(std::move(options.error()));
  for (const auto& [key, value] : *options) {
    if (key == "ttl") {
      if (!parse_decimal(value, 255))
        return fail(Errc::Config, url_error(url, "ttl=" + std::string(value) + " is not an integer 0..255", kUdpmOptionsExpected));
    } else if (key == "recv_buf_size") {
      const auto v = parse_decimal(value, static_cast<std::uint64_t>(INT_MAX));
      if (!v || *v == 0)
        return fail(Errc::Config, url_error(url, "recv_buf_size=" + std::string(value) + " is not a positive integer (bytes, at most " +
                                                     std::to_string(INT_MAX) + ")",
                                            kUdpmOptionsExpected));
    } else if (key == "transmit_only") {
      if (value != "true" && value != "false")
        return fail(Errc::Config, url_error(url, "transmit_only=" + std::string(value) + " is neither true nor false", kUdpmOptionsExpected));
    } else {
      return fail(Errc::Config, url_error(url, "unknown udpm option '" + std::string(key) + "'", kUdpmOptionsExpected));
    }
  }
  return info;
}

Result<UrlInfo> check_file(std::string_view url, std::string_view rest) {
  UrlInfo info;
  info.provider = Provider::File;
  const std::size_t q = rest.find('?');
  if (rest.substr(0, q).empty()) return fail(Errc::Config, url_error(url, "no file path", kFileExpected));
  if (q == std::string_view::npos) return info;
  auto options = parse_options(url, rest.substr(q + 1), kFileExpected);
  if (!options) return std::unexpected(std::move(options.error()));
  for (const auto& [key, value] : *options) {
    if (key == "mode") {
      if (value != "r" && value != "w" && value != "a")
        return fail(Errc::Config, url_error(url, "mode=" + std::string(value) + " is not r, w or a", kFileExpected));
      info.file_read = value == "r";
    } else if (key == "speed") {
      double v = 0;
      const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
      if (value.empty() || ec != std::errc() || end != value.data() + value.size() || !std::isfinite(v))
        return fail(Errc::Config, url_error(url, "speed=" + std::string(value) + " is not a number", kFileExpected));
    } else if (key == "start_timestamp") {
      std::int64_t v = 0;
      const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
      if (value.empty() || ec != std::errc() || end != value.data() + value.size())
        return fail(Errc::Config,
                    url_error(url, "start_timestamp=" + std::string(value) + " is not an integer (microseconds)", kFileExpected));
    } else {
      return fail(Errc::Config, url_error(url, "unknown file option '" + std::string(key) + "'", kFileExpected));
    }
  }
  return info;
}

Result<UrlInfo> check_tcpq(std::string_view url, std::string_view rest) {
  UrlInfo info;
  info.provider = Provider::Tcpq;
  if (rest.find('?') != std::string_view::npos)
    return fail(Errc::Config, url_error(url, "tcpq takes no options", kTcpqExpected));
  if (rest.empty()) return info;  // liblcm's default, 127.0.0.1:7700
  const std::size_t colon = rest.find(':');
  const std::string_view host = rest.substr(0, colon);
  const bool host_ok = !host.empty() && std::all_of(host.begin(), host.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '-';
  });
  if (!host_ok) return fail(Errc::Config, url_error(url, quoted(host) + " is not a host name or IPv4 address", kTcpqExpected));
  if (colon != std::string_view::npos) {
    const std::string_view port = rest.substr(colon + 1);
    const auto p = parse_decimal(port, 65535);
    if (!p || *p == 0) return fail(Errc::Config, url_error(url, "port " + quoted(port) + " is not a number 1..65535", kTcpqExpected));
  }
  return info;
}

Result<UrlInfo> parse_url(std::string_view url) {
  if (url.empty()) return fail(Errc::Config, url_error(url, "the URL is empty", kSchemesExpected));
  if (url.find('\0') != std::string_view::npos)
    return fail(Errc::Config, url_error(url, "the URL contains a NUL byte", kSchemesExpected));
  const std::size_t sep = url.find("://");
  if (sep == std::string_view::npos || sep == 0)
    return fail(Errc::Config, url_error(url, "no '<scheme>://' at the start", kSchemesExpected));
  const std::string_view scheme = url.substr(0, sep);
  const std::string_view rest = url.substr(sep + 3);
  if (scheme == "udpm") return check_udpm(url, rest);
  if (scheme == "file") return check_file(url, rest);
  if (scheme == "tcpq") return check_tcpq(url, rest);
  if (scheme == "memq") {
    if (!rest.empty()) return fail(Errc::Config, url_error(url, "memq takes no host part and no options", "memq://"));
    UrlInfo info;
    info.provider = Provider::Memq;
    return info;
  }
  return fail(Errc::Config, url_error(url, "unknown scheme '" + std::string(scheme) + "'", kSchemesExpected));
}

// ---------------------------------------------------------------------------- helpers

// A channel as an exact GLib regex: LCM subscribes to "^<channel>$".
std::string regex_escape(std::string_view channel) {
  static constexpr std::string_view kMeta = ".[]()*+?{}|^$\\";
  std::string out;
  out.reserve(channel.size() * 2);
  for (char c : channel) {
    if (kMeta.find(c) != std::string_view::npos) out += '\\';
    out += c;
  }
  return out;
}

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

// One row of /proc/net/udp.
struct UdpRow {
  std::uint16_t local_port = 0;
  bool unconnected = false;  // rem_address 00000000:0000
  std::uint64_t inode = 0;
  std::uint32_t drops = 0;
};

template <class F>
void for_each_udp_row(const std::string& table, F&& f) {
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

// This process's unconnected UDP sockets bound to `port` (LCM's receive socket binds
// INADDR_ANY:port; its send socket is connected to the group).
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

// ---------------------------------------------------------------------------- Engine

// One open endpoint as the receive thread sees it (the `user` pointer of its LCM subscription).
struct Subscription {
  Subscription(net::Listener& l, std::string lbl) : listener(l), label(std::move(lbl)) {}
  net::Listener& listener;
  const std::string label;
  lcm_subscription_t* handle = nullptr;  // guarded by the engine's handle lock
  std::atomic<bool> closed{false};       // set first by ~LcmEndpoint: no listener call after
  std::atomic<bool> paused{false};       // set_receiving(false): samples are not delivered

  void report(std::string_view message) noexcept {
    if (closed.load(std::memory_order_acquire)) return;
    try {
      listener.on_error(message);
    } catch (...) {  // nothing to do with it on the receive thread
    }
  }
};

class Engine;
thread_local const Engine* tl_receive_engine = nullptr;  // set on each engine's receive thread

void on_message(const lcm_recv_buf_t* rb, const char* /*channel*/, void* user) {
  auto* sub = static_cast<Subscription*>(user);
  if (sub->closed.load(std::memory_order_acquire) || sub->paused.load(std::memory_order_acquire)) return;
  try {
    const std::span<const std::byte> body(static_cast<const std::byte*>(rb->data), rb->data_size);
    sub->listener.on_sample(net::Sample{body, false});  // LCM encodes big-endian
  } catch (const std::exception& e) {
    sub->report(sub->label + ": the sample handler failed: " + e.what());
  } catch (...) {
    sub->report(sub->label + ": the sample handler failed");
  }
}

// What the receive thread owns: the lcm_t (destroyed last, by whichever thread releases the
// engine last: the transport, or the receive thread when it was detached).
class Engine {
 public:
  Engine(std::string url, const UrlInfo& info, lcm_t* lcm, int event_fd, int lcm_fd) noexcept
      : url_(std::move(url)), info_(info), lcm_(lcm), event_fd_(event_fd), lcm_fd_(lcm_fd) {}
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;
  ~Engine() {
    lcm_destroy(lcm_);  // unsubscribes what is left, stops LCM's own threads
    ::close(event_fd_);
  }

  const std::string& url() const noexcept { return url_; }
  const UrlInfo& info() const noexcept { return info_; }
  bool on_receive_thread() const noexcept { return tl_receive_engine == this; }

  // Drop accounting: the LCM receive socket's inode and its drops counter at creation.
  void set_drop_socket(std::uint64_t inode, std::uint32_t drops) noexcept {
    drop_inode_ = inode;
    last_drops_ = drops;
  }

  static void run(std::shared_ptr<Engine> self) { self->loop(); }

  void request_stop() noexcept {
    stop_.store(true, std::memory_order_release);
    const std::uint64_t one = 1;
    while (::write(event_fd_, &one, sizeof one) < 0 && errno == EINTR) {
    }
  }

  int publish(const char* channel, const void* data, unsigned size) noexcept {
    return lcm_publish(lcm_, channel, data, size);  // internally locked in every provider
  }

  Result<void> subscribe(const std::shared_ptr<Subscription>& sub, const std::string& channel) {
    const std::string pattern = regex_escape(channel);
    HandleLock lock(*this);
    subs_.reserve(subs_.size() + 1);  // so that push_back below cannot throw after subscribing
    lcm_subscription_t* handle = lcm_subscribe(lcm_, pattern.c_str(), &on_message, sub.get());
    if (handle == nullptr)
      return fail(Errc::Io, sub->label + ": liblcm refused the subscription (it printed the reason on stderr)");
    lcm_subscription_set_queue_capacity(handle, 0);  // unlimited: the topic's ring bounds it
    sub->handle = handle;
    subs_.push_back(sub);
    return {};
  }

  // Stops or resumes the LCM subscription of an open endpoint (Endpoint::set_receiving): while
  // it is off, LCM's reader drops the channel's datagrams before queueing them.
  void set_receiving(const std::shared_ptr<Subscription>& sub, const std::string& channel, bool on) noexcept {
    sub->paused.store(!on, std::memory_order_release);
    HandleLock lock(*this);
    if (sub->closed.load(std::memory_order_acquire)) return;
    if (on) {
      std::erase(deferred_, sub);  // an unsubscribe still waiting for lcm_handle to return
      if (sub->handle != nullptr) return;
      try {
        lcm_subscription_t* handle = lcm_subscribe(lcm_, regex_escape(channel).c_str(), &on_message, sub.get());
        if (handle == nullptr) {
          sub->report(sub->label + ": liblcm refused to subscribe again (it printed the reason on stderr); "
                                   "nothing more arrives on this channel");
          return;
        }
        lcm_subscription_set_queue_capacity(handle, 0);
        sub->handle = handle;
      } catch (...) {
      }
      return;
    }
    if (sub->handle == nullptr) return;
    if (lock.on_receive_thread()) {
      try {
        deferred_.push_back(sub);
      } catch (...) {  // stays subscribed; paused keeps its samples out
      }
      return;
    }
    lcm_unsubscribe(lcm_, sub->handle);
    sub->handle = nullptr;
  }

  // After this returns, `sub` gets no more callbacks.
  void unsubscribe(const std::shared_ptr<Subscription>& sub) noexcept {
    sub->closed.store(true, std::memory_order_release);
    HandleLock lock(*this);
    std::erase(subs_, sub);
    if (sub->handle == nullptr) return;
    if (lock.on_receive_thread()) {
      // Inside lcm_handle (a listener closed an endpoint): unsubscribe once it returns.
      try {
        deferred_.push_back(sub);
        return;
      } catch (...) {  // no memory: LCM allows unsubscribing from a handler (closed stops it)
      }
    }
    lcm_unsubscribe(lcm_, sub->handle);
    sub->handle = nullptr;
  }

 private:
  // Holds handle_mutex_, ahead of the receive thread; a no-op on the receive thread, which
  // holds it whenever it runs listener code.
  class HandleLock {
   public:
    explicit HandleLock(Engine& e) : engine_(e), on_thread_(e.on_receive_thread()) {
      if (on_thread_) return;
      engine_.waiting_.fetch_add(1, std::memory_order_acq_rel);
      lock_ = std::unique_lock(engine_.handle_mutex_);
    }
    HandleLock(const HandleLock&) = delete;
    HandleLock& operator=(const HandleLock&) = delete;
    ~HandleLock() {
      if (on_thread_) return;
      engine_.waiting_.fetch_sub(1, std::memory_order_acq_rel);
      lock_.unlock();
      engine_.handle_cv_.notify_all();
    }
    bool on_receive_thread() const noexcept { return on_thread_; }

   private:
    Engine& engine_;
    const bool on_thread_;
    std::unique_lock<std::mutex> lock_;
  };

  std::unique_lock<std::mutex> lock_for_dispatch() {
    std::unique_lock lock(handle_mutex_);
    handle_cv_.wait(lock, [this] { return waiting_.load(std::memory_order_acquire) == 0; });
    return lock;
  }

  // Called with handle_mutex_ held, outside lcm_handle.
  void run_deferred_locked() noexcept {
    for (const auto& sub : deferred_) {
      if (sub->handle != nullptr) lcm_unsubscribe(lcm_, sub->handle);
      sub->handle = nullptr;
    }
    deferred_.clear();
  }

  // Called with handle_mutex_ held. Listener code may open or close endpoints meanwhile.
  template <class MakeMessage>
  void report_all_locked(MakeMessage make_message) noexcept {
    std::vector<std::shared_ptr<Subscription>> subs;
    std::string message;
    try {
      subs = subs_;
      message = make_message();
    } catch (...) {
      return;
    }
    for (const auto& sub : subs) sub->report(message);
  }

  void loop() noexcept {
    tl_receive_engine = this;
    bool lcm_open = lcm_fd_ >= 0;
    last_drop_check_ = std::chrono::steady_clock::now();
    while (!stop_.load(std::memory_order_acquire)) {
      pollfd fds[2] = {{event_fd_, POLLIN, 0}, {lcm_fd_, POLLIN, 0}};
      const int n = ::poll(fds, lcm_open ? 2 : 1, kPollTimeoutMs);
      if (n < 0 && errno != EINTR) {
        const int err = errno;
        std::unique_lock lock = lock_for_dispatch();
        report_all_locked([&] {
          return "LCM URL '" + url_ + "': the receive thread stopped: poll() failed: " + std::strerror(err) +
                 "; no more samples will arrive";
        });
        break;
      }
      if (n > 0 && (fds[0].revents & POLLIN) != 0) {
        std::uint64_t value = 0;
        [[maybe_unused]] const ssize_t r = ::read(event_fd_, &value, sizeof value);
      }
      if (stop_.load(std::memory_order_acquire)) break;
      if (n > 0 && lcm_open && (fds[1].revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
        std::unique_lock lock = lock_for_dispatch();
        const int rc = lcm_handle(lcm_);  // dispatches one message; the fd said one is queued
        if (rc != 0) {
          lcm_open = false;  // do not spin on a descriptor that stays readable
          // A log read to its end (file://, mode r) is not an error.
          if (!(info_.provider == Provider::File && info_.file_read))
            report_all_locked([&] {
              return "LCM URL '" + url_ + "': lcm_handle() failed (liblcm printed the reason on stderr); " +
                     "no more samples will arrive through this transport";
            });
        }
        run_deferred_locked();
      }
      account_drops();
    }
    {
      std::unique_lock lock(handle_mutex_);
      run_deferred_locked();
    }
    tl_receive_engine = nullptr;
  }

  // Reads the kernel's drops counter of the LCM receive socket; reports increases.
  void account_drops() noexcept {
    if (drop_inode_ == 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_drop_check_ < kDropCheckPeriod) return;
    last_drop_check_ = now;
    std::optional<std::uint32_t> drops;
    try {
      if (!read_whole_file("/proc/self/net/udp", udp_table_)) return;
      for_each_udp_row(udp_table_, [&](const UdpRow& row) {
        if (row.inode == drop_inode_) drops = row.drops;
      });
    } catch (...) {
      return;
    }
    if (!drops) return;
    const std::uint32_t delta = *drops - last_drops_;  // the counter is 32-bit and wraps
    last_drops_ = *drops;
    if (delta == 0) return;
    std::unique_lock lock = lock_for_dispatch();
    std::vector<std::shared_ptr<Subscription>> subs;
    try {
      subs = subs_;
    } catch (...) {
      return;
    }
    for (const auto& sub : subs) {
      // A paused endpoint (nobody in the process reads it) loses nothing it wanted.
      if (sub->closed.load(std::memory_order_acquire) || sub->paused.load(std::memory_order_acquire)) continue;
      try {
        sub->listener.on_lost(delta);
      } catch (...) {
      }
    }
    run_deferred_locked();
  }

  const std::string url_;
  const UrlInfo info_;
  lcm_t* const lcm_;
  const int event_fd_;
  const int lcm_fd_;
  std::atomic<bool> stop_{false};

  std::mutex handle_mutex_;  // held by the receive thread around lcm_handle and listener calls
  std::condition_variable handle_cv_;
  std::atomic<int> waiting_{0};                         // threads waiting for handle_mutex_
  std::vector<std::shared_ptr<Subscription>> subs_;     // open endpoints; guarded by handle_mutex_
  std::vector<std::shared_ptr<Subscription>> deferred_;  // to unsubscribe; guarded by handle_mutex_

  // Receive thread only (set before it starts).
  std::uint64_t drop_inode_ = 0;
  std::uint32_t last_drops_ = 0;
  std::chrono::steady_clock::time_point last_drop_check_{};
  std::string udp_table_;
};

// ---------------------------------------------------------------------------- registry

class LcmTransport;

struct Registry {
  struct Entry {
    std::weak_ptr<LcmTransport> transport;
    const LcmTransport* owner;
  };
  std::mutex mutex;
  std::map<std::string, Entry, std::less<>> transports;
};

Registry& registry() {
  static Registry* const instance = new Registry();  // never destroyed: transports may outlive statics
  return *instance;
}

// ---------------------------------------------------------------------------- LcmEndpoint

class LcmEndpoint final : public net::Endpoint {
 public:
  LcmEndpoint(std::shared_ptr<net::Transport> transport, std::shared_ptr<Engine> engine, std::string channel,
              std::shared_ptr<Subscription> sub)
      : transport_(std::move(transport)), engine_(std::move(engine)), channel_(std::move(channel)), sub_(std::move(sub)) {}
  LcmEndpoint(const LcmEndpoint&) = delete;
  LcmEndpoint& operator=(const LcmEndpoint&) = delete;

  ~LcmEndpoint() override { engine_->unsubscribe(sub_); }

  Result<void> write(std::size_t body_size, const net::BodyWriter& writer) override {
    if (body_size > kMaxMessageSize)
      return fail(Errc::MessageTooLarge, sub_->label + ": a body of " + std::to_string(body_size) +
                                             " bytes exceeds LCM's largest message (" + std::to_string(kMaxMessageSize) +
                                             " bytes, LCM_MAX_MESSAGE_SIZE)");
    thread_local std::vector<std::byte> buffer;
    try {
      if (buffer.size() < body_size || buffer.empty()) buffer.resize(std::max<std::size_t>(body_size, 64));
    } catch (const std::bad_alloc&) {
      return fail(Errc::Io, sub_->label + ": out of memory for a body of " + std::to_string(body_size) + " bytes");
    }
    writer.fill(writer.context, std::span<std::byte>(buffer.data(), body_size));
    const int rc = engine_->publish(channel_.c_str(), buffer.data(), static_cast<unsigned>(body_size));
    if (buffer.size() > kKeepBufferLimit) std::vector<std::byte>().swap(buffer);
    if (rc == 0) return {};
    std::string why;
    if (engine_->info().provider == Provider::File && engine_->info().file_read)
      why = " (the URL reads a log: file:// URLs publish only with mode=w or mode=a)";
    else if (rc > 0)
      why = " (only " + std::to_string(rc) + " bytes of the datagram were sent)";
    else
      why = " (liblcm printed the reason on stderr)";
    return fail(Errc::Io, sub_->label + ": lcm_publish of " + std::to_string(body_size) + " bytes to LCM URL '" +
                              engine_->url() + "' failed" + why);
  }

  void set_receiving(bool on) noexcept override { engine_->set_receiving(sub_, channel_, on); }

  std::uint32_t matched_publishers() const override { return 0; }   // LCM has no discovery
  std::uint32_t matched_subscribers() const override { return 0; }  // LCM has no discovery

 private:
  std::shared_ptr<net::Transport> transport_;  // keeps the transport (and its thread) alive
  std::shared_ptr<Engine> engine_;
  const std::string channel_;
  std::shared_ptr<Subscription> sub_;
};

// ---------------------------------------------------------------------------- LcmTransport

class LcmTransport final : public net::Transport, public std::enable_shared_from_this<LcmTransport> {
  struct Private {};

 public:
  LcmTransport(Private, std::shared_ptr<Engine> engine) : engine_(std::move(engine)) {}
  LcmTransport(const LcmTransport&) = delete;
  LcmTransport& operator=(const LcmTransport&) = delete;

  // Called with the registry locked.
  static Result<std::shared_ptr<LcmTransport>> create(const std::string& url, const UrlInfo& info);

  ~LcmTransport() override {
    engine_->request_stop();
    if (thread_.joinable()) {
      // The last endpoint may be closed by a listener, on the receive thread itself: that
      // thread then ends on its own and releases the engine.
      if (engine_->on_receive_thread())
        thread_.detach();
      else
        thread_.join();
    }
    if (registered_) {
      Registry& reg = registry();
      std::lock_guard lock(reg.mutex);
      auto it = reg.transports.find(engine_->url());
      if (it != reg.transports.end() && it->second.owner == this) reg.transports.erase(it);
    }
  }

  std::string_view name() const noexcept override { return "lcm"; }

  // udpm loops multicast back (IP_MULTICAST_LOOP), memq and the tcpq server deliver to every
  // subscriber; a log file does not.
  bool delivers_own_samples() const noexcept override { return engine_->info().provider != Provider::File; }

  Result<std::unique_ptr<net::Endpoint>> open(const net::EndpointSpec& spec, net::Listener& listener) override {
    std::string label = "topic '" + spec.topic + "' (LCM channel '" + spec.wire_topic + "')";
    auto channel = check_channel(spec.wire_topic);
    if (!channel) return fail(Errc::InvalidName, label + ": " + channel.error().message());
    auto sub = std::make_shared<Subscription>(listener, std::move(label));
    if (auto done = engine_->subscribe(sub, *channel); !done) return std::unexpected(std::move(done.error()));
    try {
      return std::unique_ptr<net::Endpoint>(
          std::make_unique<LcmEndpoint>(shared_from_this(), engine_, std::move(*channel), sub));
    } catch (...) {
      engine_->unsubscribe(sub);
      throw;
    }
  }

  void mark_registered() noexcept { registered_ = true; }

 private:
  std::shared_ptr<Engine> engine_;
  std::thread thread_;
  bool registered_ = false;
};

std::string provider_hint(const std::string& url, const UrlInfo& info) {
  switch (info.provider) {
    case Provider::Udpm:
      return "; for udpm the usual cause is a host with no multicast route: add one with "
             "`ip route add 224.0.0.0/4 dev <interface>` (or `dev lo` for one host)";
    case Provider::File:
      return info.file_read ? "; check that the log file exists, is readable and holds at least one event"
                            : "; check that the log file's directory exists and is writable";
    case Provider::Tcpq:
      return "; check that an LCM TCP queue server listens at " +
             (url.size() > 7 ? url.substr(7) : std::string("127.0.0.1:7700"));
    case Provider::Memq: break;
  }
  return "";
}

Result<std::shared_ptr<LcmTransport>> LcmTransport::create(const std::string& url, const UrlInfo& info) {
  // The LCM receive socket is created by lcm_get_fileno(); the sockets on its port that appear
  // meanwhile are ours (creations are serialized by the registry lock).
  std::vector<std::uint64_t> before;
  if (info.provider == Provider::Udpm) before = udp_sockets_on_port(info.port);

  lcm_t* lcm = lcm_create(url.c_str());
  if (lcm == nullptr)
    return fail(Errc::Io, "LCM could not start provider for URL '" + url + "' (liblcm printed the reason on stderr)" +
                              provider_hint(url, info));
  const int lcm_fd = lcm_get_fileno(lcm);
  if (lcm_fd < 0) {
    lcm_destroy(lcm);
    std::string what = "LCM could not start the receive side for URL '" + url + "' (liblcm printed the reason on stderr";
    if (info.provider == Provider::Udpm) what += "; its self test, a message sent to itself, did not come back";
    return fail(Errc::Io, what + ")" + provider_hint(url, info));
  }
  const int event_fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (event_fd < 0) {
    const int err = errno;
    lcm_destroy(lcm);
    return fail(Errc::Io, "LCM URL '" + url + "': eventfd() failed: " + std::strerror(err));
  }
  std::shared_ptr<Engine> engine;
  try {
    engine = std::make_shared<Engine>(url, info, lcm, event_fd, lcm_fd);
  } catch (...) {
    lcm_destroy(lcm);
    ::close(event_fd);
    throw;
  }

  if (info.provider == Provider::Udpm) {
    std::vector<std::uint64_t> added;
    const std::vector<std::uint64_t> after = udp_sockets_on_port(info.port);
    std::set_difference(after.begin(), after.end(), before.begin(), before.end(), std::back_inserter(added));
    if (added.size() == 1) {
      std::string table;
      if (read_whole_file("/proc/self/net/udp", table)) {
        for_each_udp_row(table, [&](const UdpRow& row) {
          if (row.inode == added[0]) engine->set_drop_socket(row.inode, row.drops);
        });
      }
    }
  }

  auto t = std::make_shared<LcmTransport>(Private{}, engine);
  try {
    t->thread_ = std::thread(&Engine::run, engine);
  } catch (const std::system_error& e) {
    return fail(Errc::Io, "LCM URL '" + url + "': cannot start the receive thread: " + e.what());
  }
  return t;
}

}  // namespace

// ---------------------------------------------------------------------------- public API

Result<void> check_url(std::string_view url) {
  auto info = parse_url(url);
  if (!info) return std::unexpected(std::move(info.error()));
  return {};
}

Result<std::string> url_from_environment() {
  for (const char* name : {"HORUS_LCM_URL", "LCM_DEFAULT_URL"}) {
    const char* value = std::getenv(name);
    if (value == nullptr || *value == '\0') continue;
    if (auto ok = check_url(value); !ok)
      return fail(Errc::Config, "environment variable " + std::string(name) + ": " + ok.error().message());
    return std::string(value);
  }
  return std::string(kDefaultUrl);
}

Result<std::string> check_channel(std::string_view channel) {
  if (channel.empty())
    return fail(Errc::InvalidName, "empty LCM channel name; expected 1.." + std::to_string(kMaxChannelLength) +
                                       " bytes, e.g. 'horus/fleet/robot_1/pose'");
  if (channel.size() > kMaxChannelLength)
    return fail(Errc::InvalidName, "LCM channel '" + std::string(channel) + "' is " + std::to_string(channel.size()) +
                                       " bytes; LCM channel names are at most " + std::to_string(kMaxChannelLength) +
                                       " bytes (a longer one is neither sent nor received)");
  for (std::size_t i = 0; i < channel.size(); i++) {
    const auto c = static_cast<unsigned char>(channel[i]);
    if (c < 0x20 || c >= 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", c);
      std::string shown(channel);
      std::replace_if(shown.begin(), shown.end(), [](char ch) { return ch == '\0'; }, '?');
      return fail(Errc::InvalidName, "LCM channel '" + shown + "' has byte " + hex + " at offset " + std::to_string(i) +
                                         "; expected printable ASCII (liblcm matches channels as UTF-8 regexes "
                                         "and C strings)");
    }
  }
  return std::string(channel);
}

Result<std::shared_ptr<net::Transport>> lcm_transport(std::string_view url) {
  auto info = parse_url(url);
  if (!info) return std::unexpected(std::move(info.error()));
  Registry& reg = registry();
  std::shared_ptr<LcmTransport> existing;  // declared before the lock: released after it
  std::lock_guard lock(reg.mutex);
  if (auto it = reg.transports.find(url); it != reg.transports.end()) {
    existing = it->second.transport.lock();
    if (existing) return std::shared_ptr<net::Transport>(existing);
  }
  std::string key(url);
  auto created = LcmTransport::create(key, *info);
  if (!created) return std::unexpected(std::move(created.error()));
  reg.transports.insert_or_assign(std::move(key), Registry::Entry{*created, created->get()});
  (*created)->mark_registered();
  return std::shared_ptr<net::Transport>(std::move(*created));
}

Result<std::string> channel_name(std::string_view topic) {
  if (auto ok = validate_topic_name(topic); !ok) return std::unexpected(std::move(ok.error()));
  if (topic.size() > kMaxChannelLength)
    return fail(Errc::InvalidName,
                "topic '" + std::string(topic) + "': " + std::to_string(topic.size()) +
                    " characters is too long for an LCM channel (the channel is the topic name, and LCM channels "
                    "are at most " + std::to_string(kMaxChannelLength) + " bytes); use a name of at most " +
                    std::to_string(kMaxChannelLength) + " characters on the lcm backend");
  return std::string(topic);
}

void register_lcm() {
  (void)net::register_transport(
      {"lcm", net::WireFormat::Lcm, &channel_name, []() -> Result<std::shared_ptr<net::Transport>> {
         auto url = url_from_environment();
         if (!url) return std::unexpected(std::move(url.error()));
         return lcm_transport(*url);
       }});
}

}  // namespace horus::lcm

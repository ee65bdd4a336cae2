// Hosts made of network namespaces, for tests that need a real network between processes:
//
//   horus_test::NetnsLan lan(3);              // hosts 10.213.<n>.1 .. .3 on one bridge
//   if (!lan.ok()) GTEST_SKIP() << lan.why();
//   auto p = lan.spawn(0, {"/path/prog", "arg"}, {"HORUS_BACKEND=cyclonedds"});
//
// Each host is a namespace with its loopback up and one veth (eth0) plugged into a bridge that
// lives in a namespace of its own, so the machine's own interfaces are never touched. eth0 has
// an address on a private /24 and a multicast route (DDS and LCM discovery use multicast).
// A host is a whole host: besides its network namespace it has its own mount namespace with a
// private tmpfs on /dev/shm (so two hosts never meet in shared memory) and its own hostname
// (UTS namespace). A holder process (`sleep infinity`) keeps them; every process of the host
// enters all three (nsenter). Everything is deleted by the destructor, and namespaces left by
// a test process that died (their name holds its pid) are deleted by the next one.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <poll.h>
#include <spawn.h>
#include <sys/inotify.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <utility>
#include <vector>

extern char** environ;

namespace horus_test {

/// The state, kernel wait channel and kernel stack of a process (what /proc says; root reads the
/// stack), for a message about a process that does not end.
inline std::string proc_state(pid_t pid) {
  std::string text;
  for (const char* f : {"stat", "wchan", "stack"}) {
    if (FILE* in = std::fopen(("/proc/" + std::to_string(pid) + "/" + f).c_str(), "r")) {
      char buf[2048];
      const std::size_t n = std::fread(buf, 1, sizeof(buf) - 1, in);
      std::fclose(in);
      text += std::string(f) + ": " + std::string(buf, n) + "\n";
    }
  }
  return text;
}

/// SIGKILLs `pid` (a child) and reaps it, waiting at most 20 s: a process the kernel holds
/// (uninterruptible sleep) is reported on stderr with its state and left, never waited for
/// without bound. True when it was reaped.
inline bool reap_killed(pid_t pid, const std::string& what, int* status = nullptr) {
  int st = 0;
  // The pidfd is readable once the process has ended: poll waits for that, 20 s at most.
  const int fd = static_cast<int>(::syscall(SYS_pidfd_open, pid, 0));
  ::kill(pid, SIGKILL);
  bool reaped = false;
  if (fd >= 0) {
    pollfd p{fd, POLLIN, 0};
    (void)::poll(&p, 1, 20'000);
    ::close(fd);
    reaped = ::waitpid(pid, &st, WNOHANG) == pid;
  } else {  // no pidfd (a kernel before 5.3): look every 5 ms, 20 s at most
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (!(reaped = ::waitpid(pid, &st, WNOHANG) == pid) && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (!reaped) {
    std::fprintf(stderr, "horus_test: pid %d (%s) did not end 20 s after SIGKILL; left behind:\n%s\n",
                 static_cast<int>(pid), what.c_str(), proc_state(pid).c_str());
    return false;
  }
  if (status != nullptr) *status = st;
  return true;
}

/// Runs argv (no shell), waits at most `timeout`; its exit status, or -1.
inline int run_command(const std::vector<std::string>& args, std::chrono::seconds timeout = std::chrono::seconds(30)) {
  std::vector<char*> argv;
  std::vector<std::string> copy = args;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int rc = ::posix_spawnp(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return -1;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      std::string cmd;
      for (const auto& a : args) cmd += a + " ";
      std::fprintf(stderr, "horus_test: '%s' did not end within %lld s; killed\n", cmd.c_str(),
                   static_cast<long long>(timeout.count()));
      (void)reap_killed(pid, cmd);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// A process started in a namespace host; killed (SIGTERM, then SIGKILL) if still running at
/// destruction. Its stdout goes to a file the test can read; its stdin is a pipe that stays
/// open while this object lives (programs that stop when stdin closes keep running).
class HostProcess {
 public:
  HostProcess() = default;
  HostProcess(pid_t pid, std::string out, int stdin_fd) : pid_(pid), out_(std::move(out)), stdin_(stdin_fd) {}
  HostProcess(HostProcess&& o) noexcept : pid_(o.pid_), out_(std::move(o.out_)), stdin_(o.stdin_) {
    o.pid_ = -1;
    o.stdin_ = -1;
  }
  HostProcess& operator=(HostProcess&&) = delete;
  ~HostProcess() {
    if (stdin_ >= 0) ::close(stdin_);
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      (void)wait(std::chrono::seconds(5));
    }
    if (!out_.empty()) std::remove(out_.c_str());
  }
  /// Waits at most `timeout` (then kills it); the exit status, 128 + signal, or -1.
  int wait(std::chrono::seconds timeout) {
    if (pid_ <= 0) return -1;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    int status = 0;
    while (::waitpid(pid_, &status, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > deadline) {
        // Said at once (a test that hangs later still shows it): what it was doing.
        std::fprintf(stderr, "horus_test: pid %d (%s) did not end within %lld s; killed. Its state:\n%s\n",
                     static_cast<int>(pid_), out_.c_str(), static_cast<long long>(timeout.count()),
                     (proc_state(pid_) + stacks()).c_str());
        (void)reap_killed(pid_, out_);
        pid_ = -1;
        return -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ended_ms_ = std::chrono::duration_cast<std::chrono::milliseconds>(
                    std::chrono::system_clock::now().time_since_epoch())
                    .count();
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  /// True once it ended (looks without waiting; records when, as wait() does).
  bool ended() {
    if (pid_ <= 0) return true;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) != pid_) return false;
    ended_ms_ = std::chrono::duration_cast<std::chrono::milliseconds>(
                    std::chrono::system_clock::now().time_since_epoch())
                    .count();
    pid_ = -1;
    return true;
  }
  /// When wait() or ended() saw it end (Unix time in ms, within 5 ms); -1 when it has not (or was killed).
  long long ended_unix_ms() const noexcept { return ended_ms_; }
  /// Gives up the process (not killed, its output file kept); its pid.
  pid_t release() noexcept {
    out_.clear();
    return std::exchange(pid_, -1);
  }
  /// Closes its standard input (a peer that ends at EOF, as the interop peers do, then ends
  /// cleanly and flushes what it writes); wait() for it.
  void close_stdin() {
    if (stdin_ >= 0) ::close(std::exchange(stdin_, -1));
  }
  /// Asks it to end (SIGTERM); wait() for it.
  void terminate() const {
    if (pid_ > 0) ::kill(pid_, SIGTERM);
  }
  /// Its pid (nsenter and env exec the program: the program's own pid); -1 once it ended.
  pid_t pid() const noexcept { return pid_; }
  /// What a shell command printed (stdout and what it sends there).
  static std::string command_output(const std::string& cmd) {
    std::string text;
    if (FILE* p = ::popen(cmd.c_str(), "r")) {
      char buf[4096];
      std::size_t n;
      while ((n = std::fread(buf, 1, sizeof(buf), p)) > 0) text.append(buf, n);
      ::pclose(p);
    }
    return text;
  }
  /// What each of its threads is doing, for a failure message about a process that does not
  /// end: gdb's backtraces when gdb is installed, else each thread's name, state and kernel wait
  /// channel from /proc. Empty once it ended.
  std::string stacks() const {
    if (pid_ <= 0) return {};
    const std::string pid = std::to_string(pid_);
    if (::access("/usr/bin/gdb", X_OK) == 0) {
      const std::string cmd = "timeout 20 /usr/bin/gdb -p " + pid +
                              " -batch -nx -ex 'set pagination off' -ex 'thread apply all bt 30' 2>&1";
      return "--- threads of pid " + pid + " (gdb):\n" + command_output(cmd);
    }
    const std::string cmd = "cd /proc/" + pid + "/task 2>/dev/null && for t in *; do "
                            "printf '%s %s %s %s\\n' \"$t\" \"$(cat $t/comm)\" "
                            "\"$(cut -d' ' -f3 $t/stat)\" \"$(cat $t/wchan)\"; done";
    return "--- threads of pid " + pid + " (tid name state wait channel; no gdb):\n" + command_output(cmd);
  }
  /// What it printed on stdout and stderr so far.
  std::string output() const {
    std::string text;
    if (FILE* f = std::fopen(out_.c_str(), "r")) {
      char buf[4096];
      std::size_t n;
      while ((n = std::fread(buf, 1, sizeof(buf), f)) > 0) text.append(buf, n);
      std::fclose(f);
    }
    return text;
  }
  /// Waits until its output contains `text` (woken by each write to its output file), at most
  /// `timeout`; true when it does.
  bool wait_for_output(const std::string& text, std::chrono::milliseconds timeout) const {
    const int fd = ::inotify_init1(IN_CLOEXEC);
    if (fd < 0) return output().find(text) != std::string::npos;
    (void)::inotify_add_watch(fd, out_.c_str(), IN_MODIFY | IN_CLOSE_WRITE);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    bool found = false;
    while (!(found = output().find(text) != std::string::npos)) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) break;
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1000))) > 0) {
        char events[4096];
        (void)!::read(fd, events, sizeof events);
      }
    }
    ::close(fd);
    return found;
  }

 private:
  pid_t pid_ = -1;
  std::string out_;
  int stdin_ = -1;
  long long ended_ms_ = -1;
};

/// Starts argv (found on PATH) with its stdout and stderr written to `out`, its stdin `stdin_fd`
/// (-1: /dev/null); the running process, or one with pid -1 when it could not start.
inline HostProcess start_logged(std::vector<std::string> args, const std::string& out, int stdin_fd = -1) {
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  if (stdin_fd >= 0) posix_spawn_file_actions_adddup2(&fa, stdin_fd, 0);
  else posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  pid_t pid = -1;
  if (::posix_spawnp(&pid, argv[0], &fa, nullptr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  return HostProcess(pid, out, -1);
}

class NetnsLan {
 public:
  /// `tag` (a lower-case letter or empty) tells apart the LANs of one test process.
  explicit NetnsLan(int hosts, const std::string& tag = "") {
    if (::geteuid() != 0) {
      why_ = "needs root to create network namespaces (ip netns)";
      return;
    }
    if (run_command({"ip", "netns", "list"}) != 0) {
      why_ = "'ip netns' is not available (Debian: iproute2)";
      return;
    }
    const auto began = std::chrono::steady_clock::now();
    remove_stale();
    prefix_ = "hx" + std::to_string(::getpid()) + tag;
    subnet_ = "10.213." + std::to_string(::getpid() % 250 + 1);
    bridge_ns_ = prefix_ + "b";
    if (!sh({"ip", "netns", "add", bridge_ns_}) ||
        !sh({"ip", "-n", bridge_ns_, "link", "add", "br0", "type", "bridge", "mcast_snooping", "0"}) ||
        !sh({"ip", "-n", bridge_ns_, "link", "set", "br0", "up"})) {
      why_ = "could not create the bridge namespace";
      return;
    }
    for (int i = 1; i <= hosts; ++i) {
      const std::string ns = prefix_ + "h" + std::to_string(i);
      const std::string veth = prefix_ + "v" + std::to_string(i);
      const std::string peer = prefix_ + "p" + std::to_string(i);
      const std::string addr = subnet_ + "." + std::to_string(i) + "/24";
      const bool ok = sh({"ip", "netns", "add", ns}) && (hosts_.push_back(ns), true) &&
                      sh({"ip", "link", "add", veth, "type", "veth", "peer", "name", peer}) &&
                      sh({"ip", "link", "set", veth, "netns", ns}) &&
                      sh({"ip", "link", "set", peer, "netns", bridge_ns_}) &&
                      sh({"ip", "-n", ns, "link", "set", veth, "name", "eth0"}) &&
                      sh({"ip", "-n", ns, "addr", "add", addr, "dev", "eth0"}) &&
                      sh({"ip", "-n", ns, "link", "set", "eth0", "up"}) &&
                      sh({"ip", "-n", ns, "link", "set", "lo", "up"}) &&
                      sh({"ip", "-n", ns, "route", "add", "224.0.0.0/4", "dev", "eth0"}) &&
                      sh({"ip", "-n", bridge_ns_, "link", "set", peer, "master", "br0"}) &&
                      sh({"ip", "-n", bridge_ns_, "link", "set", peer, "up"});
      if (!ok) {
        why_ = "could not create host " + ns + " (veth, address or route)";
        return;
      }
    }
    for (const auto& ns : hosts_) {
      const pid_t holder = start_holder(ns);
      if (holder <= 0) {
        why_ = "could not give host " + ns + " its own /dev/shm and hostname (unshare --mount --uts)";
        return;
      }
      holders_.push_back(holder);
    }
    ok_ = true;
    const auto took = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - began);
    if (took > std::chrono::seconds(5))  // it takes ~1 s; a loaded kernel's namespace work shows here
      std::fprintf(stderr, "horus_test: the %d namespace hosts took %lld ms to make\n", hosts,
                   static_cast<long long>(took.count()));
  }
  ~NetnsLan() {
    for (const pid_t h : holders_) (void)reap_killed(h, "a namespace holder");
    for (const auto& ns : hosts_) run_command({"ip", "netns", "del", ns});
    if (!bridge_ns_.empty()) run_command({"ip", "netns", "del", bridge_ns_});
  }
  NetnsLan(const NetnsLan&) = delete;
  NetnsLan& operator=(const NetnsLan&) = delete;

  bool ok() const noexcept { return ok_; }
  const std::string& why() const noexcept { return why_; }
  /// The namespace and address of host i (0-based).
  const std::string& host(int i) const { return hosts_.at(static_cast<std::size_t>(i)); }
  std::string address(int i) const { return subnet_ + "." + std::to_string(i + 1); }

  /// Deletes the LAN itself (the bridge's namespace): every host's eth0 goes with its veth peer,
  /// as when a host's network adapter is pulled. True when it was deleted.
  bool remove_lan() {
    if (bridge_ns_.empty() || !sh({"ip", "netns", "del", bridge_ns_})) return false;
    bridge_ns_.clear();
    return true;
  }

  /// The pid of the process that holds host i's namespaces.
  pid_t holder(int i) const { return holders_.at(static_cast<std::size_t>(i)); }

  /// Starts argv on host i (its network, mount and UTS namespaces) with extra environment
  /// entries ("NAME=value").
  HostProcess spawn(int i, const std::vector<std::string>& args, const std::vector<std::string>& env_extra) const {
    std::vector<std::string> full = {"nsenter", "-t", std::to_string(holder(i)), "-n", "-m", "-u", "--", "env"};
    full.insert(full.end(), env_extra.begin(), env_extra.end());
    full.insert(full.end(), args.begin(), args.end());
    const std::string out = "/tmp/" + prefix_ + "_" + std::to_string(counter_++) + ".log";
    int in[2] = {-1, -1};
    if (::pipe2(in, O_CLOEXEC) != 0) return HostProcess();
    HostProcess p = start_logged(std::move(full), out, in[0]);
    ::close(in[0]);
    return HostProcess(p.release(), out, in[1]);
  }

 private:
  static bool sh(const std::vector<std::string>& args) { return run_command(args) == 0; }

  // The holder of host `ns`: in its network namespace, a new mount namespace with a private
  // tmpfs on /dev/shm and a new UTS namespace named after the host; then it sleeps. Returns its
  // pid once it is ready (it execs all the way down, so the pid is the sleeper's), or -1.
  static pid_t start_holder(const std::string& ns) {
    const std::string script = "mount -t tmpfs -o mode=1777,size=4g tmpfs /dev/shm && hostname " + ns +
                               " && exec sleep infinity";
    std::vector<std::string> args = {"ip", "netns", "exec", ns, "unshare", "--mount", "--uts",
                                     "--propagation", "private", "sh", "-c", script};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    pid_t pid = -1;
    const int rc = ::posix_spawnp(&pid, "ip", &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) return -1;
    // Ready when the pid runs `sleep` (after the mount and the hostname).
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < deadline) {
      if (::waitpid(pid, nullptr, WNOHANG) == pid) return -1;  // it failed
      if (FILE* f = std::fopen(("/proc/" + std::to_string(pid) + "/comm").c_str(), "r")) {
        char comm[64] = {};
        const bool sleeping = std::fgets(comm, sizeof(comm), f) != nullptr && std::string(comm) == "sleep\n";
        std::fclose(f);
        if (sleeping) return pid;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    (void)reap_killed(pid, "the holder of " + ns);
    return -1;
  }

  // Namespaces of test processes that died without cleaning up: "hx<pid>..." with <pid> gone.
  static void remove_stale() {
    FILE* p = ::popen("timeout 30 ip netns list 2>/dev/null", "r");
    if (p == nullptr) return;
    char line[256];
    std::vector<std::string> stale;
    while (std::fgets(line, sizeof(line), p) != nullptr) {
      std::string name(line);
      name = name.substr(0, name.find_first_of(" \n"));
      if (name.rfind("hx", 0) != 0) continue;
      const long pid = std::strtol(name.c_str() + 2, nullptr, 10);
      if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0) stale.push_back(name);
    }
    ::pclose(p);
    for (const auto& ns : stale) run_command({"ip", "netns", "del", ns});
  }

  bool ok_ = false;
  std::string why_;
  std::string prefix_;
  std::string subnet_;
  std::string bridge_ns_;
  std::vector<std::string> hosts_;
  std::vector<pid_t> holders_;
  mutable int counter_ = 0;
};

}  // namespace horus_test

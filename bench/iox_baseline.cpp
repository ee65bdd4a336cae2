#include "iox_baseline.hpp"

#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <new>
#include <thread>

#include "iceoryx_hoofs/log/logmanager.hpp"
#include "iceoryx_posh/popo/untyped_publisher.hpp"
#include "iceoryx_posh/popo/untyped_subscriber.hpp"
#include "iceoryx_posh/popo/wait_set.hpp"
#include "iceoryx_posh/runtime/posh_runtime.hpp"

extern char** environ;

namespace horus::bench::iox {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

void set_why(std::string* why, std::string s) {
  if (why) *why = std::move(s);
}

pid_t spawn(const std::vector<std::string>& args, posix_spawn_file_actions_t* fa, int* err) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  *err = ::posix_spawnp(&pid, argv[0], fa, nullptr, argv.data(), environ);
  return *err == 0 ? pid : -1;
}

// Waits for pid until the deadline, then SIGKILLs it; returns the wait status.
int reap(pid_t pid, Clock::time_point deadline) {
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (Clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(1ms);
  }
  return status;
}

std::string describe(int status) {
  if (WIFEXITED(status)) return "exit code " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return "signal " + std::to_string(WTERMSIG(status));
  return "status " + std::to_string(status);
}

std::string read_log(const std::string& path) {  // without ANSI colour codes
  std::ifstream in(path);
  std::string out;
  bool esc = false;
  for (auto it = std::istreambuf_iterator<char>(in); it != std::istreambuf_iterator<char>(); ++it) {
    const char c = *it;
    if (c == '\x1b') esc = true;
    else if (esc) esc = (c != 'm');
    else out += c;
  }
  return out;
}

void init_runtime(const char* role) {
  ::iox::log::LogManager::GetLogManager().SetDefaultLogLevel(::iox::log::LogLevel::kWarn,
                                                             ::iox::log::LogLevelOutput::kHideLogLevel);
  const std::string name = "horus-bench-" + std::string(role) + "-" + std::to_string(::getpid());
  ::iox::runtime::PoshRuntime::initRuntime(::iox::RuntimeName_t(::iox::cxx::TruncateToCapacity, name.c_str()));
}

::iox::capro::ServiceDescription service(const char* event, std::size_t bytes) {
  auto id = [](const std::string& s) { return ::iox::capro::IdString_t(::iox::cxx::TruncateToCapacity, s.c_str(), s.size()); };
  return {id("horus-bench"), id(event), id(std::to_string(bytes))};
}

// The exchange is lock-step (one sample in flight per direction); blocking policies as a guard.
::iox::popo::PublisherOptions pub_options() {
  ::iox::popo::PublisherOptions o;
  o.subscriberTooSlowPolicy = ::iox::popo::ConsumerTooSlowPolicy::WAIT_FOR_CONSUMER;
  return o;
}
::iox::popo::SubscriberOptions sub_options() {
  ::iox::popo::SubscriberOptions o;
  o.queueCapacity = 4;
  o.queueFullPolicy = ::iox::popo::QueueFullPolicy::BLOCK_PRODUCER;
  return o;
}

// Busy-polls take() until a sample with sequence number `seq` arrives (false at the deadline).
bool await(::iox::popo::UntypedSubscriber& sub, std::uint64_t seq, Clock::time_point deadline) {
  for (std::uint32_t spins = 0;; ++spins) {
    auto r = sub.take();
    if (!r.has_error()) {
      std::uint64_t got = 0;
      std::memcpy(&got, r.value(), sizeof got);
      sub.release(r.value());
      if (got == seq) return true;
    } else if ((spins & 1023u) == 0 && Clock::now() > deadline) {
      return false;
    }
  }
}

// Loans payload_bytes, writes only the sequence number and publishes.
bool send(::iox::popo::UntypedPublisher& pub, std::size_t bytes, std::uint64_t seq) {
  auto l = pub.loan(static_cast<std::uint32_t>(bytes));
  if (l.has_error()) {
    std::fprintf(stderr, "iox: loan(%zu) failed, AllocationError %d\n", bytes, static_cast<int>(l.get_error()));
    return false;
  }
  std::memcpy(l.value(), &seq, sizeof seq);
  pub.publish(l.value());
  return true;
}

// The fan-out's shared file (mapped by the tool and every helper): counters, then the ticks.
constexpr int kFanMax = 64;
struct FanControl {
  std::atomic<std::uint64_t> ready{0};  // subscribers connected
  std::atomic<std::uint64_t> stop{0};   // the publisher is done
  std::atomic<std::uint64_t> got[kFanMax];  // per subscriber: samples received
};
std::size_t fan_bytes(std::uint64_t messages) {
  return sizeof(FanControl) + static_cast<std::size_t>(kFanMax) * messages * sizeof(std::uint64_t);
}
FanControl* fan_map(const char* path, std::uint64_t messages) {
  const int fd = ::open(path, O_RDWR | O_CLOEXEC);
  if (fd < 0) return nullptr;
  void* p = ::mmap(nullptr, fan_bytes(messages), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  return p == MAP_FAILED ? nullptr : static_cast<FanControl*>(p);
}
std::uint64_t* fan_ticks(FanControl* c, int sub, std::uint64_t messages) {
  return reinterpret_cast<std::uint64_t*>(c + 1) + static_cast<std::size_t>(sub) * messages;
}

int fan_sub_main(const char* path, int idx, std::uint64_t messages) {
  FanControl* c = fan_map(path, messages);
  if (c == nullptr || idx < 0 || idx >= kFanMax) return 2;
  init_runtime("fansub");
  ::iox::popo::SubscriberOptions o;
  o.queueCapacity = 16;
  ::iox::popo::UntypedSubscriber sub(service("fan", 16), o);
  const auto deadline = Clock::now() + 20s;
  while (sub.getSubscriptionState() != ::iox::SubscribeState::SUBSCRIBED) {
    if (Clock::now() > deadline) return std::fputs("iox-fan-sub: not subscribed in 20 s\n", stderr), 3;
    std::this_thread::sleep_for(1ms);
  }
  ::iox::popo::WaitSet<> waitset;
  if (waitset.attachState(sub, ::iox::popo::SubscriberState::HAS_DATA).has_error()) return 4;
  c->ready.fetch_add(1, std::memory_order_acq_rel);
  std::uint64_t* out = fan_ticks(c, idx, messages);
  std::uint64_t got = 0;
  while (got < messages && c->stop.load(std::memory_order_acquire) == 0) {
    (void)waitset.timedWait(::iox::units::Duration::fromMilliseconds(200));
    for (auto r = sub.take(); !r.has_error(); r = sub.take()) {
      const std::uint64_t now = TscClock::now();
      std::uint64_t m[2];
      std::memcpy(m, r.value(), sizeof m);
      sub.release(r.value());
      if (m[0] < messages) out[m[0]] = now - m[1];
      c->got[idx].store(++got, std::memory_order_release);
    }
  }
  waitset.detachState(sub, ::iox::popo::SubscriberState::HAS_DATA);
  return 0;
}

int fan_pub_main(const char* path, int n, std::uint64_t messages, std::uint64_t gap_us) {
  FanControl* c = fan_map(path, messages);
  if (c == nullptr || n <= 0 || n > kFanMax) return 2;
  init_runtime("fanpub");
  ::iox::popo::UntypedPublisher pub(service("fan", 16));
  const auto deadline = Clock::now() + 30s;
  while (c->ready.load(std::memory_order_acquire) < static_cast<std::uint64_t>(n) || !pub.hasSubscribers()) {
    if (Clock::now() > deadline) return std::fputs("iox-fan-pub: subscribers did not connect in 30 s\n", stderr), 3;
    std::this_thread::sleep_for(1ms);
  }
  // As horus-fanout's publisher: the next sample once every subscriber has this one (or 100 ms),
  // polling asleep every 20 us, then the gap.
  for (std::uint64_t k = 0; k < messages; ++k) {
    auto l = pub.loan(16);
    if (l.has_error()) return std::fputs("iox-fan-pub: loan failed\n", stderr), 4;
    const std::uint64_t m[2] = {k, TscClock::now()};
    std::memcpy(l.value(), m, sizeof m);
    pub.publish(l.value());
    const auto until = Clock::now() + 100ms;
    for (int i = 0; i < n && Clock::now() < until;) {
      if (c->got[i].load(std::memory_order_acquire) > k) ++i;
      else std::this_thread::sleep_for(20us);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(gap_us));
  }
  c->stop.store(1, std::memory_order_release);
  return 0;
}

}  // namespace

std::vector<std::vector<std::uint64_t>> fanout(int n, std::uint64_t messages, std::uint64_t gap_us,
                                               const std::string& self_exe, std::string* why) {
  using Ticks = std::vector<std::vector<std::uint64_t>>;
  if (n <= 0 || n > kFanMax || messages == 0) return set_why(why, "1..64 subscribers, messages > 0"), Ticks{};
  char path[] = "/dev/shm/horus-iox-fan-XXXXXX";
  const int fd = ::mkstemp(path);
  if (fd < 0) return set_why(why, "mkstemp in /dev/shm failed"), Ticks{};
  const bool sized = ::ftruncate(fd, static_cast<off_t>(fan_bytes(messages))) == 0;
  ::close(fd);
  FanControl* c = sized ? fan_map(path, messages) : nullptr;
  if (c == nullptr) {
    ::unlink(path);
    return set_why(why, "cannot map the fan-out file"), Ticks{};
  }
  new (c) FanControl{};
  const std::string m = std::to_string(messages);
  std::vector<pid_t> subs;
  int err = 0;
  for (int i = 0; i < n && err == 0; ++i) {
    const pid_t p = spawn({self_exe, "--iox-fan-sub", path, std::to_string(i), m}, nullptr, &err);
    if (p > 0) subs.push_back(p);
  }
  const pid_t pub =
      err == 0 ? spawn({self_exe, "--iox-fan-pub", path, std::to_string(n), m, std::to_string(gap_us)}, nullptr, &err)
               : -1;
  const auto limit = Clock::now() + 40s + std::chrono::microseconds((gap_us + 2000) * messages);
  const int pub_status = pub > 0 ? reap(pub, limit) : -1;
  c->stop.store(1, std::memory_order_release);  // subscribers leave within 200 ms
  bool subs_ok = true;
  for (pid_t p : subs) subs_ok = reap(p, Clock::now() + 5s) == 0 && subs_ok;
  Ticks out;
  if (pub > 0 && pub_status == 0 && subs_ok && static_cast<int>(subs.size()) == n) {
    for (int i = 0; i < n; ++i) out.emplace_back(fan_ticks(c, i, messages), fan_ticks(c, i, messages) + messages);
  } else {
    set_why(why, pub <= 0 || static_cast<int>(subs.size()) != n
                     ? "posix_spawn(" + self_exe + "): " + std::strerror(err)
                     : "iceoryx fan-out failed: publisher " + describe(pub_status) +
                           (subs_ok ? "" : ", a subscriber failed"));
  }
  ::munmap(c, fan_bytes(messages));
  ::unlink(path);
  return out;
}

std::optional<Roudi> Roudi::start(std::string* why) {
  char tmpl[] = "/tmp/horus-iox-XXXXXX";
  if (!::mkdtemp(tmpl)) return set_why(why, "mkdtemp failed"), std::nullopt;
  Roudi r(-1, tmpl);  // from here on the destructor removes the directory
  const std::string cfg = r.dir_ + "/roudi.toml", log = r.dir_ + "/roudi.log";
  {  // chunk = 40-byte ChunkHeader + payload; mempool sizes must be multiples of 8
    std::ofstream out(cfg);
    out << "[general]\nversion = 1\n\n[[segment]]\n";
    const std::pair<int, int> pools[] = {{128, 256}, {1088, 256}, {6220800 + 64, 8}};  // {size, count}
    for (auto [size, count] : pools)
      out << "\n[[segment.mempool]]\nsize = " << size << "\ncount = " << count << "\n";
  }
  posix_spawn_file_actions_t fa;
  ::posix_spawn_file_actions_init(&fa);
  ::posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ::posix_spawn_file_actions_adddup2(&fa, 1, 2);
  int err = 0;  // -k 2: RouDi's own SIGKILL of stale clients comes before our 5 s bound
  const pid_t pid = spawn({"iox-roudi", "-c", cfg, "-k", "2"}, &fa, &err);
  ::posix_spawn_file_actions_destroy(&fa);
  if (pid < 0)
    return set_why(why, err == ENOENT ? "iox-roudi not found in PATH" : "posix_spawn(iox-roudi): " +
                                                                             std::string(std::strerror(err))),
           std::nullopt;
  const auto deadline = Clock::now() + 5s;
  for (;;) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid)
      return set_why(why, "iox-roudi exited (" + describe(status) + ") before it was ready (another RouDi "
                              "running?):\n" + read_log(log)),
             std::nullopt;
    if (read_log(log).find("RouDi is ready for clients") != std::string::npos) break;
    if (Clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
      return set_why(why, "iox-roudi not ready after 5 s:\n" + read_log(log)), std::nullopt;
    }
    std::this_thread::sleep_for(5ms);
  }
  r.pid_ = pid;
  return r;
}

Roudi::Roudi(Roudi&& o) noexcept : pid_(std::exchange(o.pid_, -1)), dir_(std::exchange(o.dir_, {})) {}

Roudi::~Roudi() {
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    const int status = reap(pid_, Clock::now() + 5s);
    if (WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) {  // RouDi could not clean up: do it
      ::shm_unlink("iceoryx_mgmt");
      if (const group* g = ::getgrgid(::getegid())) ::shm_unlink(g->gr_name);
      for (const char* f : {"/tmp/roudi", "/tmp/roudi.lock", "/tmp/iox-unique-roudi.lock"}) ::unlink(f);
    }
  }
  if (!dir_.empty()) {
    for (const char* f : {"/roudi.toml", "/roudi.log"}) ::unlink((dir_ + f).c_str());
    ::rmdir(dir_.c_str());
  }
}

int pong_main(std::size_t bytes, std::uint64_t rounds) {
  init_runtime("pong");
  ::iox::popo::UntypedSubscriber sub(service("ping", bytes), sub_options());
  ::iox::popo::UntypedPublisher pub(service("pong", bytes), pub_options());
  for (std::uint64_t k = 0; k < rounds; ++k) {  // 15 s for the first ping, then 5 s per round
    if (!await(sub, k, Clock::now() + (k == 0 ? 15s : 5s))) {
      std::fprintf(stderr, "iox-pong: no ping %llu\n", static_cast<unsigned long long>(k));
      return 2;
    }
    if (!send(pub, bytes, k)) return 3;
  }
  return 0;
}

int ping_main(std::size_t bytes, std::uint64_t rounds, int out_fd) {
  init_runtime("ping");
  ::iox::popo::UntypedPublisher pub(service("ping", bytes), pub_options());
  ::iox::popo::UntypedSubscriber sub(service("pong", bytes), sub_options());
  const auto hs_deadline = Clock::now() + 10s;  // both directions connected before the first ping
  while (!pub.hasSubscribers() || sub.getSubscriptionState() != ::iox::SubscribeState::SUBSCRIBED) {
    if (Clock::now() > hs_deadline) return std::fputs("iox-ping: pong did not connect in 10 s\n", stderr), 2;
    std::this_thread::sleep_for(1ms);
  }
  std::vector<std::uint64_t> ticks(rounds);
  for (std::uint64_t k = 0; k < rounds; ++k) {
    const std::uint64_t t0 = TscClock::now();
    if (!send(pub, bytes, k)) return 3;
    if (!await(sub, k, Clock::now() + 5s))
      return std::fprintf(stderr, "iox-ping: no pong %llu\n", static_cast<unsigned long long>(k)), 4;
    ticks[k] = TscClock::now() - t0;
  }
  const char* p = reinterpret_cast<const char*>(ticks.data());
  for (std::size_t left = ticks.size() * sizeof(std::uint64_t); left > 0;) {
    const ssize_t n = ::write(out_fd, p, left);
    if (n <= 0) return 5;
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return 0;
}

std::optional<int> child_main(int argc, char** argv) {
  if (argc < 4) return std::nullopt;
  const std::string mode = argv[1];
  if (mode == "--iox-fan-sub" && argc >= 5)
    return fan_sub_main(argv[2], std::atoi(argv[3]), std::strtoull(argv[4], nullptr, 10));
  if (mode == "--iox-fan-pub" && argc >= 6)
    return fan_pub_main(argv[2], std::atoi(argv[3]), std::strtoull(argv[4], nullptr, 10),
                        std::strtoull(argv[5], nullptr, 10));
  const auto bytes = std::strtoull(argv[2], nullptr, 10), rounds = std::strtoull(argv[3], nullptr, 10);
  if (mode == "--iox-pong") return pong_main(bytes, rounds);
  if (mode == "--iox-ping" && argc >= 5) return ping_main(bytes, rounds, std::atoi(argv[4]));
  return std::nullopt;
}

std::vector<double> pingpong(std::size_t bytes, std::uint64_t rounds, int child_cpu, const TscClock& tsc,
                             const std::string& self_exe, std::string* why) {
  if (bytes < sizeof(std::uint64_t) || bytes > 6220800 || rounds == 0)
    return set_why(why, "payload must be 8..6220800 bytes, rounds > 0"), std::vector<double>{};
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return set_why(why, "pipe2 failed"), std::vector<double>{};
  const std::string b = std::to_string(bytes), n = std::to_string(rounds);
  int err = 0;
  const pid_t pong = spawn({self_exe, "--iox-pong", b, n}, nullptr, &err);
  if (pong > 0) {  // exec has happened, the runtime's threads not yet: they inherit this mask
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(child_cpu, &set);
    ::sched_setaffinity(pong, sizeof set, &set);
  }
  posix_spawn_file_actions_t fa;  // the ping helper writes its RTTs (TSC ticks) to fd 3
  ::posix_spawn_file_actions_init(&fa);
  ::posix_spawn_file_actions_adddup2(&fa, fds[1], 3);
  const pid_t ping = pong > 0 ? spawn({self_exe, "--iox-ping", b, n, "3"}, &fa, &err) : -1;
  ::posix_spawn_file_actions_destroy(&fa);
  ::close(fds[1]);
  std::vector<std::uint64_t> ticks(rounds);
  std::size_t got = 0;
  const std::size_t want = rounds * sizeof(std::uint64_t);
  const auto deadline = Clock::now() + 30s + std::chrono::microseconds(100 * rounds);
  while (ping > 0 && got < want && Clock::now() < deadline) {
    pollfd p{fds[0], POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const ssize_t r = ::read(fds[0], reinterpret_cast<char*>(ticks.data()) + got, want - got);
    if (r <= 0) break;  // EOF: the ping helper exited early
    got += static_cast<std::size_t>(r);
  }
  ::close(fds[0]);
  // After a timeout both get 1 s more; otherwise they are about to exit on their own.
  const auto reap_by = Clock::now() + (got == want ? 5s : 1s);
  const int ping_status = ping > 0 ? reap(ping, reap_by) : 0, pong_status = pong > 0 ? reap(pong, reap_by) : 0;
  if (pong < 0 || ping < 0)
    return set_why(why, "posix_spawn(" + self_exe + "): " + std::strerror(err)), std::vector<double>{};
  if (got != want || ping_status != 0 || pong_status != 0)
    return set_why(why, "iceoryx ping-pong failed: got " + std::to_string(got / 8) + "/" + n + " rounds, ping " +
                            describe(ping_status) + ", pong " + describe(pong_status)),
           std::vector<double>{};
  std::vector<double> out;
  out.reserve(rounds);
  for (std::uint64_t t : ticks) out.push_back(tsc.to_ns(t) / 2.0);
  return out;
}

}  // namespace horus::bench::iox

// horus-fleet-cost: what fleet topics cost a process that sits idle, per backend and number of
// topics: the threads horus adds, the CPU time and context switches per second at rest, and the
// time to open them. Each (backend, N) runs in a fresh process (this program re-executed) that
// opens N fleet topics of CmdVel, one publishing and one subscribing handle each, publishes one
// message on each (so every bridge has exported and imported once), then sleeps for --idle
// seconds while getrusage() counts what the whole process spent (horus's threads and the
// transport library's). A row of N host topics (shared memory only) is the reference.
//
//   horus-fleet-cost [--backends cyclonedds,fastdds,lcm] [--topics 1,100,1000] [--idle 5] [--json FILE]
//
// Network traffic stays on this machine: DDS on loopback only (HORUS_DDS_LOCALHOST=1), LCM with
// ttl=0, unless the environment says otherwise (bench/fleet/fleet_cost.sh runs it in a network
// namespace of its own).
#include <dirent.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "horus/discovery/registry.hpp"
#include "horus/horus.hpp"
#include "horus/shm/shm_segment.hpp"

namespace {

using Clock = std::chrono::steady_clock;

int thread_count() {
  int n = 0;
  if (DIR* d = ::opendir("/proc/self/task")) {
    while (dirent* e = ::readdir(d))
      if (e->d_name[0] != '.') ++n;
    ::closedir(d);
  }
  return n;
}

struct Usage {
  double cpu_s;
  long switches;
};

// CPU ticks per thread (name -> utime + stime, summed over threads of that name).
std::map<std::string, long> thread_ticks() {
  std::map<std::string, long> out;
  DIR* d = ::opendir("/proc/self/task");
  if (d == nullptr) return out;
  while (dirent* e = ::readdir(d)) {
    if (e->d_name[0] == '.') continue;
    std::ifstream in(std::string("/proc/self/task/") + e->d_name + "/stat");
    std::string line;
    std::getline(in, line);
    const auto open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos) continue;
    const std::string name = line.substr(open + 1, close - open - 1);
    std::istringstream rest(line.substr(close + 2));
    std::string field;
    long ut = 0, st = 0;
    for (int i = 3; i <= 15; ++i) {
      rest >> field;
      if (i == 14) ut = std::stol(field);
      if (i == 15) st = std::stol(field);
    }
    out[name] += ut + st;
  }
  ::closedir(d);
  return out;
}

Usage usage() {
  rusage ru{};
  ::getrusage(RUSAGE_SELF, &ru);
  const double cpu = static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
                     static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) / 1e6;
  return Usage{cpu, ru.ru_nvcsw + ru.ru_nivcsw};
}

// The child: opens the topics, idles, prints one line "RESULT backend n threads_before
// threads_after open_s cpu_ms_per_s switches_per_s".
int child(const std::string& backend, int topics, double idle_s) {
  const int before = thread_count();
  horus::TopicOptions o;
  o.backend = backend == "shm" ? horus::Backend::SharedMemory : horus::Backend::network(backend);
  std::vector<horus::Topic<horus::msg::CmdVel>> pubs, subs;
  pubs.reserve(static_cast<std::size_t>(topics));
  subs.reserve(static_cast<std::size_t>(topics));
  const std::string prefix = fmt::format("bench.cost{}.t", ::getpid());
  const auto t0 = Clock::now();
  for (int i = 0; i < topics; ++i) {
    auto p = horus::Topic<horus::msg::CmdVel>::open(prefix + std::to_string(i), o);
    auto s = horus::Topic<horus::msg::CmdVel>::open(prefix + std::to_string(i), o);
    if (!p || !s) {
      std::fprintf(stderr, "horus-fleet-cost: %s\n", (!p ? p.error() : s.error()).message().c_str());
      return 1;
    }
    pubs.push_back(std::move(*p));
    subs.push_back(std::move(*s));
  }
  const double open_s = std::chrono::duration<double>(Clock::now() - t0).count();
  for (auto& p : pubs) {  // paced: a burst of 1000 would overflow a socket buffer
    p.send(horus::msg::CmdVel{});
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  for (auto& s : subs) (void)s.recv();
  // Let discovery and the first announcements settle before measuring rest (a benchmark's
  // warm-up, not a wait for a condition: what it measures is the process at rest).
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const int after = thread_count();
  const auto t_before = thread_ticks();
  const Usage u0 = usage();
  const auto i0 = Clock::now();
  std::this_thread::sleep_for(std::chrono::duration<double>(idle_s));  // the measured window itself
  const Usage u1 = usage();
  const auto t_after = thread_ticks();
  // Where the CPU went, by thread name (stderr: the parent prints it under the row).
  const double tick_ms = 1000.0 / static_cast<double>(::sysconf(_SC_CLK_TCK));
  std::string threads;
  for (const auto& [name, ticks] : t_after) {
    const auto it = t_before.find(name);
    const long d = ticks - (it == t_before.end() ? 0 : it->second);
    if (d > 0) threads += fmt::format(" {}={:.1f}", name, static_cast<double>(d) * tick_ms / idle_s);
  }
  const double secs = std::chrono::duration<double>(Clock::now() - i0).count();
  // What one look at the host's topics costs (the fleet layer's announcer makes one every
  // announce period): a warm scan of the namespace, its segments already mapped.
  {
    horus::discovery::Scanner scanner(horus::shm::shm_namespace().value_or(""));
    (void)scanner.scan();
    constexpr int kScans = 5;
    const auto s0 = Clock::now();
    std::size_t seen = 0;
    for (int i = 0; i < kScans; ++i) seen += scanner.scan().size();
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - s0).count() / kScans;
    threads += fmt::format(" | one scan of {} topics {:.2f} ms", seen / kScans, ms);
  }
  std::printf("RESULT %s %d %d %d %.3f %.3f %.1f\n", backend.c_str(), topics, before, after, open_s,
              (u1.cpu_s - u0.cpu_s) * 1000.0 / secs, static_cast<double>(u1.switches - u0.switches) / secs);
  std::printf("THREADS%s\n", threads.c_str());
  std::fflush(stdout);
  return 0;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"horus-fleet-cost: threads, idle CPU and context switches of N fleet topics in one process"};
  std::string backends = "cyclonedds,fastdds,lcm";
  std::string counts = "1,100,1000";
  double idle = 5;
  std::string json;
  std::string child_backend;
  int child_topics = 0;
  app.add_option("--backends", backends, "comma-separated backends");
  app.add_option("--topics", counts, "comma-separated numbers of topics");
  app.add_option("--idle", idle, "seconds at rest measured");
  app.add_option("--json", json, "also write the rows as JSON");
  app.add_option("--child-backend", child_backend)->group("");
  app.add_option("--child-topics", child_topics)->group("");
  CLI11_PARSE(app, argc, argv);
  if (!child_backend.empty()) return child(child_backend, child_topics, idle);

  ::setenv("HORUS_DDS_LOCALHOST", "1", 0);
  ::setenv("HORUS_LCM_URL", fmt::format("udpm://239.255.76.{}:{}?ttl=0&recv_buf_size=8388608", 100 + ::getpid() % 100, 20000 + ::getpid() % 20000).c_str(), 0);
  ::setenv("HORUS_DOMAIN_ID", std::to_string(::getpid() % 200 + 1).c_str(), 0);
  std::vector<std::string> rows;
  std::printf("%-11s %6s %8s %9s %9s %14s %12s\n", "backend", "topics", "threads", "added", "open s",
              "idle CPU ms/s", "switches/s");
  auto run = [&](const std::string& backend, int n) {
    const std::string cmd = fmt::format("'{}' --child-backend {} --child-topics {} --idle {}", argv[0], backend, n, idle);
    FILE* p = ::popen(cmd.c_str(), "r");
    if (p == nullptr) return;
    char line[512];
    bool pending_threads = false;
    while (std::fgets(line, sizeof line, p) != nullptr) {
      if (pending_threads && std::strncmp(line, "THREADS", 7) == 0) {
        std::printf("%-11s   CPU ms/s by thread:%s", "", line + 7);
        pending_threads = false;
        continue;
      }
      char name[64];
      int topics = 0, before = 0, after = 0;
      double open_s = 0, cpu = 0, sw = 0;
      if (std::sscanf(line, "RESULT %63s %d %d %d %lf %lf %lf", name, &topics, &before, &after, &open_s, &cpu, &sw) ==
          7) {
        std::printf("%-11s %6d %8d %9d %9.3f %14.2f %12.0f\n", name, topics, after, after - before, open_s, cpu, sw);
        std::fflush(stdout);
        pending_threads = true;
        rows.push_back(fmt::format("{{\"backend\":\"{}\",\"topics\":{},\"threads\":{},\"threads_added\":{},"
                                   "\"open_s\":{:.4f},\"idle_cpu_ms_per_s\":{:.3f},\"switches_per_s\":{:.1f}}}",
                                   name, topics, after, after - before, open_s, cpu, sw));
      }
    }
    if (const int rc = ::pclose(p); rc != 0)
      std::printf("%-11s %6d   (failed, status %d)\n", backend.c_str(), n, WEXITSTATUS(rc));
  };
  for (const auto& b : split(backends))
    for (const auto& n : split(counts)) run(b, std::stoi(n));
  const auto all = split(counts);
  if (!all.empty()) run("shm", std::stoi(all.back()));  // the reference: host topics
  if (!json.empty()) {
    std::ofstream out(json);
    out << "[";
    for (std::size_t i = 0; i < rows.size(); ++i) out << (i ? ",\n " : "") << rows[i];
    out << "]\n";
  }
  return 0;
}

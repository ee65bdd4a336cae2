// horus_fleet_watch: one host's view of the fleet, for the multi-host tests (test_fleet.cpp).
//
//   horus_fleet_watch <seconds> [--publish TOPIC START_UNIX_MS HZ] [--subscribe TOPIC]
//                     [--user-type TOPIC] [--garbage N] [--forge-heartbeats N] [--memory]
//
// Opens a horus::Fleet on the backend of HORUS_BACKEND and prints, one line each, as they happen:
//   start <unix_ms>
//   event <joined|lost|rejoined|changed> <host> <unix_ms>
// --publish sends Pose2D{x = seq, y = planned send time in unix ms} on a reliable fleet topic at
// HZ from START_UNIX_MS on; --subscribe counts what arrives and prints at the end
//   received <n> first <seq> last <seq> missing <m>: <seq> <seq> ...
// --user-type publishes a type horus's tools are not compiled with (watch::Battery) at 20 Hz.
// --garbage sends N samples of raw bytes that are no Announcement on horus.fleet.announce (its
// own endpoint, not horus's), then N Announcements whose type signature does not hash to its
// type (host "forged"): every other host must count and ignore all 2N. --garbage-readers R: it
// starts once R readers match its writer (10 s at most; a host's
// bridge holder reads for all of its processes).
// --forge-heartbeats sends N heartbeats, each from another forged host id (host "forged-<i>"),
// 20 000 a second, then prints "forged sent <n>".
// --memory prints every 500 ms "memory <ms since start> rss_kb <n> hosts <n> malformed <n>".
// At the end (after <seconds>, or at SIGTERM or SIGINT) it prints each host it knows:
//   host <name> <state> rejoins <n> rtt_us <n|-> processes <n> topics <n> announced <0|1>
// and "malformed <n>".
#include <fmt/format.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <thread>

#include "horus/fleet_messages.hpp"
#include "horus/executor.hpp"
#include "horus/network.hpp"
#include "horus/transport_registry.hpp"
#include "horus/fleet.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/topic.hpp"

namespace watch {
enum class Chemistry : std::uint8_t { LiIon, LiFePo4, Lead };
HORUS_REFLECT_ENUM(Chemistry, LiIon, LiFePo4, Lead)
struct Cell {
  float volts{};
  std::int16_t temp_dc{};
};
HORUS_REFLECT(Cell, volts, temp_dc)
struct Battery {
  std::string label;
  Chemistry chemistry{};
  std::array<Cell, 3> cells{};
  std::vector<std::uint16_t> history;
  std::array<char, 8> tag{};
  double charge{};
};
HORUS_REFLECT(Battery, label, chemistry, cells, history, tag, charge)
}  // namespace watch

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_stop(int) { g_stop = 1; }

std::int64_t unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::mutex g_print;
void line(const std::string& s) {
  std::lock_guard lock(g_print);
  std::fputs((s + "\n").c_str(), stdout);
  std::fflush(stdout);
}

struct Quiet final : horus::net::Listener {
  void on_sample(const horus::net::Sample&) override {}
  void on_error(std::string_view) override {}
};

int send_garbage(int n, std::uint32_t readers) {
  const auto backend = horus::backend_from_environment();
  if (!backend || !horus::is_network(*backend)) return 4;
  const auto* info = horus::net::find_transport(backend->transport());
  const auto config = horus::net::config_from_environment();
  if (!config) return 4;
  // Where the fleet layer's own topics travel (its control instance: LCM's next port).
  auto transport = info->open_for(horus::fleet::kAnnounceTopic, *config);
  auto wire = horus::wire_name(*backend, horus::fleet::kAnnounceTopic);
  if (!transport || !wire) return 4;
  horus::net::EndpointSpec spec;
  spec.topic = horus::fleet::kAnnounceTopic;
  spec.wire_topic = *wire;
  spec.type_name = std::string(horus::type_name<horus::fleet::Announcement>());
  spec.type_hash = horus::type_hash<horus::fleet::Announcement>;
  spec.qos.reliability = horus::net::Reliability::Reliable;
  Quiet quiet;
  auto ep = (*transport)->open(spec, quiet);
  if (!ep) {
    std::fprintf(stderr, "%s\n", ep.error().message().c_str());
    return 4;
  }
  // A reliable, volatile reader that matches after a write never gets it: wait for every reader
  // the test names (on DDS; LCM has no discovery and reports none: then 3 s).
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(readers > 1 ? 10 : 3);
  while ((*ep)->matched_subscribers() < readers && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  line(fmt::format("garbage readers {}", (*ep)->matched_subscribers()));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  for (int i = 0; i < n; ++i) {
    auto ok = (*ep)->write(16, horus::net::BodyWriter{[](void*, std::span<std::byte> b) {
                                                        std::memset(b.data(), 0xff, b.size());
                                                      },
                                                      nullptr});
    if (!ok) std::fprintf(stderr, "raw write: %s\n", ok.error().message().c_str());
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  horus::TopicOptions o;
  o.backend = *backend;
  o.slot_size = 256 * 1024;
  o.capacity = 4;
  o.reliability = horus::net::Reliability::Reliable;
  auto forged = horus::Topic<horus::fleet::Announcement>::open(horus::fleet::kAnnounceTopic, o);
  if (!forged) {
    std::fprintf(stderr, "%s\n", forged.error().message().c_str());
    return 4;
  }
  for (int i = 0; i < n; ++i) {
    horus::fleet::Announcement a;
    a.host_id = 12345;
    a.host = "forged";
    a.version = 1;
    a.types.push_back({1, "X{u8 a;}"});  // its hash is not 1
    if (auto ok = forged->send_blocking(a, std::chrono::seconds(1)); !ok)
      std::fprintf(stderr, "forged send: %s\n", ok.error().message().c_str());
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  line(fmt::format("garbage sent {}", n));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // reliable writers deliver before they go
  return 0;
}

// A flood of heartbeats from hosts that do not exist: the fleet layer must keep its tables bounded.
int forge_heartbeats(int n) {
  const auto backend = horus::backend_from_environment();
  if (!backend || !horus::is_network(*backend)) return 4;
  horus::TopicOptions o;
  o.backend = *backend;
  o.capacity = 16;
  o.slot_size = 16 * 1024;
  o.reliability = horus::net::Reliability::BestEffort;
  auto hb = horus::Topic<horus::fleet::Heartbeat>::open(horus::fleet::kHeartbeatTopic, o);
  if (!hb) {
    std::fprintf(stderr, "%s\n", hb.error().message().c_str());
    return 4;
  }
  hb->publish_only();
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < n; ++i) {
    horus::fleet::Heartbeat h;
    h.host_id = 0x5eed000000000000ULL + static_cast<std::uint64_t>(i) + 1;
    h.host = "forged-" + std::to_string(i);
    h.seq = 1;
    h.period_ms = 100;
    hb->send(h);
    if (i % 100 == 99) std::this_thread::sleep_until(start + std::chrono::microseconds((i + 1) * 50));
  }
  line(fmt::format("forged sent {}", n));
  return 0;
}

long rss_kb() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return -1;
  char buf[256];
  long kb = -1;
  while (std::fgets(buf, sizeof buf, f) != nullptr)
    if (std::strncmp(buf, "VmRSS:", 6) == 0) kb = std::atol(buf + 6);
  std::fclose(f);
  return kb;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s <seconds> [--publish TOPIC START_UNIX_MS HZ] [--subscribe TOPIC] [--user-type TOPIC]\n",
                 argv[0]);
    return 2;
  }
  const int seconds = std::atoi(argv[1]);
  std::string pub_topic, sub_topic, user_topic;
  std::int64_t pub_start = 0;
  double pub_hz = 0;
  int garbage = 0, forge = 0;
  std::uint32_t garbage_readers = 1;
  bool memory = false;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--publish" && i + 3 < argc) {
      pub_topic = argv[++i];
      pub_start = std::atoll(argv[++i]);
      pub_hz = std::atof(argv[++i]);
    } else if (a == "--subscribe" && i + 1 < argc) {
      sub_topic = argv[++i];
    } else if (a == "--user-type" && i + 1 < argc) {
      user_topic = argv[++i];
    } else if (a == "--garbage" && i + 1 < argc) {
      garbage = std::atoi(argv[++i]);
    } else if (a == "--garbage-readers" && i + 1 < argc) {
      garbage_readers = static_cast<std::uint32_t>(std::atoi(argv[++i]));
    } else if (a == "--forge-heartbeats" && i + 1 < argc) {
      forge = std::atoi(argv[++i]);
    } else if (a == "--memory") {
      memory = true;
    } else {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  line(fmt::format("start {}", unix_ms()));
  // Callbacks on our executor, spun once they are registered: no event is missed.
  horus::Executor executor;
  auto fleet = horus::Fleet::open(executor);
  if (!fleet) {
    std::fprintf(stderr, "fleet: %s\n", fleet.error().message().c_str());
    return 3;
  }
  (*fleet)->on_change([](const horus::FleetEvent& e) {
    line(fmt::format("event {} {} {}", horus::to_string(e.kind), e.host.name, unix_ms()));
  });
  std::thread spinner([&] { executor.spin(); });
  horus::TopicOptions reliable;
  reliable.reliability = horus::net::Reliability::Reliable;
  std::optional<horus::Topic<horus::msg::Pose2D>> pub, sub;
  std::optional<horus::Topic<watch::Battery>> user;
  for (auto [name, slot] : {std::pair{&pub_topic, &pub}, std::pair{&sub_topic, &sub}}) {
    if (name->empty()) continue;
    auto t = horus::Topic<horus::msg::Pose2D>::open(*name, reliable);
    if (!t) {
      std::fprintf(stderr, "%s\n", t.error().message().c_str());
      return 3;
    }
    slot->emplace(std::move(*t));
  }
  if (!user_topic.empty()) user.emplace(horus::Topic<watch::Battery>(user_topic));
  if (garbage > 0) {
    if (const int rc = send_garbage(garbage, garbage_readers); rc != 0) return rc;
  }
  if (forge > 0) {
    if (const int rc = forge_heartbeats(forge); rc != 0) return rc;
  }

  std::signal(SIGTERM, on_stop);
  std::signal(SIGINT, on_stop);
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  std::set<std::int64_t> got;
  std::int64_t seq = 0;
  auto next_user = std::chrono::steady_clock::now();
  const auto started = std::chrono::steady_clock::now();
  auto next_memory = started;
  while (std::chrono::steady_clock::now() < end && g_stop == 0) {
    if (memory && std::chrono::steady_clock::now() >= next_memory) {
      line(fmt::format("memory {} rss_kb {} hosts {} malformed {}",
                       std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - started).count(),
                       rss_kb(), (*fleet)->hosts().size(), (*fleet)->malformed()));
      next_memory += std::chrono::milliseconds(500);
    }
    if (pub) {
      // Message seq is due at start + seq / hz.
      const std::int64_t now = unix_ms();
      while (now >= pub_start + static_cast<std::int64_t>(static_cast<double>(seq) * 1000.0 / pub_hz)) {
        horus::msg::Pose2D m{};
        m.x = static_cast<double>(seq);
        m.y = static_cast<double>(pub_start + static_cast<std::int64_t>(static_cast<double>(seq) * 1000.0 / pub_hz));
        if (!pub->send_blocking(m, std::chrono::milliseconds(200))) break;
        ++seq;
      }
    }
    if (user && std::chrono::steady_clock::now() >= next_user) {
      watch::Battery b;
      b.label = "pack-" + std::to_string(seq);
      b.chemistry = watch::Chemistry::LiFePo4;
      b.cells = {watch::Cell{3.25f, 215}, watch::Cell{3.5f, -12}, watch::Cell{3.0f, 300}};
      b.history = {100, 99, 65535};
      std::strncpy(b.tag.data(), "rack7", b.tag.size() - 1);
      b.charge = 0.875;
      user->send(b);
      next_user += std::chrono::milliseconds(50);
    }
    if (sub) {
      while (auto m = sub->recv()) got.insert(static_cast<std::int64_t>(m->x));
      (void)sub->wait_for(std::chrono::milliseconds(2));
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  if (sub) {
    std::string missing;
    std::size_t n_missing = 0;
    if (!got.empty()) {
      for (std::int64_t s = *got.begin(); s <= *got.rbegin(); ++s)
        if (!got.contains(s)) {
          ++n_missing;
          if (n_missing <= 2000) missing += " " + std::to_string(s);
        }
    }
    line(fmt::format("received {} first {} last {} missing {}:{}", got.size(), got.empty() ? -1 : *got.begin(),
                     got.empty() ? -1 : *got.rbegin(), n_missing, missing));
  }
  if (pub) line(fmt::format("sent {}", seq));
  for (const auto& h : (*fleet)->hosts())
    line(fmt::format("host {} {} rejoins {} rtt_us {} processes {} topics {} announced {}", h.name,
                     horus::to_string(h.state), h.rejoins, h.rtt ? std::to_string(h.rtt->count()) : "-",
                     h.processes.size(), h.topics.size(), h.announced ? 1 : 0));
  line(fmt::format("malformed {}", (*fleet)->malformed()));
  executor.stop();
  spinner.join();
  return 0;
}

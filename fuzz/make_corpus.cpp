// Writes the seed corpora of the fuzz targets (fuzz/corpus/<target>/) from real messages,
// recordings and segments, as horus itself makes them:
//
//   build/fuzz/fuzz/fuzz_make_corpus fuzz/corpus
//
// local, xcdr1, lcm: each message type of fuzz_common.hpp encoded by its codec, the selector
// byte first (xcdr1 with the encapsulation header, lcm with the mode byte); dynamic: a type's
// signature, NUL, its XCDR1 body; announcement: an encapsulated Announcement; mcap: recordings
// with each compression; lcm_log: an event log; config: configuration files (one with a
// security: section and protection: rules); shm: the segment file of a topic of each kind as it
// is created, the kind byte first.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "fuzz_common.hpp"
#include "horus/record/lcm_log.hpp"
#include "horus/record/mcap.hpp"
#include "horus/msg/generic_value.hpp"
#include "horus/reflect.hpp"
#include "horus/shm/ring.hpp"
#include "horus/shm/shm_segment.hpp"
#include "horus/transport/encapsulation.hpp"
#include "horus/wire/lcm.hpp"
#include "horus/wire/local.hpp"
#include "horus/wire/xcdr1.hpp"

namespace fs = std::filesystem;
using namespace horus;

namespace {

fs::path root;

void put(const std::string& target, const std::string& name, const std::vector<std::byte>& bytes) {
  const fs::path dir = root / target;
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                    static_cast<std::streamsize>(bytes.size()));
}

std::vector<std::byte> text(std::string_view s) {
  const auto* p = reinterpret_cast<const std::byte*>(s.data());
  return {p, p + s.size()};
}

std::vector<std::byte> prefixed(std::initializer_list<std::uint8_t> head, const std::vector<std::byte>& body) {
  std::vector<std::byte> out;
  for (auto b : head) out.push_back(static_cast<std::byte>(b));
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

std::vector<std::byte> encapsulated(const std::vector<std::byte>& body) {
  std::vector<std::byte> out(net::encapsulation::serialized_size(body.size()));
  net::encapsulation::write_header_and_padding(out, body.size());
  std::copy(body.begin(), body.end(), out.begin() + net::encapsulation::kHeaderSize);
  return out;
}

void set(std::array<char, 32>& a, std::string_view s) { std::copy_n(s.data(), std::min<std::size_t>(s.size(), 31), a.data()); }

// One realistic value of each type (what the targets' selector bytes 0..9 pick).
template <class T>
T sample() {
  T m{};
  if constexpr (std::is_same_v<T, msg::Pose2D>) {
    m.x = 1.5;
    m.y = -2.25;
    m.theta = 0.7;
  } else if constexpr (std::is_same_v<T, msg::LaserScan>) {
    for (std::size_t i = 0; i < m.ranges.size(); ++i) m.ranges[i] = 0.5f + 0.01f * static_cast<float>(i);
    m.angle_max = 3.14f;
    m.range_max = 12.f;
  } else if constexpr (std::is_same_v<T, msg::JointState>) {
    m.joint_count = 2;
    set(m.names[0], "shoulder");
    set(m.names[1], "elbow");
    m.positions[0] = 0.3;
  } else if constexpr (std::is_same_v<T, msg::Path>) {
    m.waypoint_count = 3;
    set(m.frame_id, "map");
  } else if constexpr (std::is_same_v<T, msg::OccupancyGrid>) {
    m.width = 4;
    m.height = 4;
    m.data.assign(16, 0);
    m.data[5] = 100;
    m.data[6] = -1;
    set(m.frame_id, "map");
  } else if constexpr (std::is_same_v<T, msg::CompressedImage>) {
    // the defaults: an empty image of the default format
  } else if constexpr (std::is_same_v<T, msg::GenericMessage>) {
    m = *msg::GenericMessage::from_value(std::map<std::string, std::string>{{"op", "hello"}, {"run", "42"}});
  } else if constexpr (std::is_same_v<T, fleet::Heartbeat>) {
    m.host_id = 0x1234;
    m.host = "robot-a";
    m.seq = 7;
    m.period_ms = 100;
    m.echoes.push_back({0x5678, 123456789, 2000});
  } else if constexpr (std::is_same_v<T, fleet::Announcement>) {
    m.host_id = 0x1234;
    m.host = "robot-a";
    m.shm_namespace = "u0";
    m.heartbeat_ms = 100;
    m.processes.push_back({4242, "planner", 1});
    m.topics.push_back({"fleet.pose", std::string(type_name<msg::Pose2D>()), type_hash<msg::Pose2D>, "fleet", "lcm", 1, 2,
                        50.0, 100, 0, 32});
    m.types.push_back({type_hash<msg::Pose2D>, reflect::type_signature<msg::Pose2D>()});
  } else if constexpr (std::is_same_v<T, fleet::FleetView>) {
    m.host_id = 0x1234;
    m.version = 3;
    fleet::ViewedHost h;
    h.host_id = 0x5678;
    h.host = "robot-b";
    h.period_ms = 100;
    h.state = 1;
    m.hosts.push_back(h);
  }
  return m;
}

// The dynamic target's seed: the type's signature, a NUL, then its XCDR1 body (no header).
template <class T>
std::vector<std::byte> signed_body(const std::vector<std::byte>& body) {
  auto out = text(reflect::type_signature<T>());
  out.push_back(std::byte{0});
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

// The seeds of message type T (selector `sel`), one file named after the type in each codec's
// target: local, xcdr1 (encapsulated), dynamic, lcm when T has an LCM form; the Announcement is
// also the announcement target's one seed.
template <class T>
void type_seeds(std::uint8_t sel) {
  const T m = sample<T>();
  const std::string name(type_name<T>().substr(type_name<T>().rfind(':') + 1));
  put("local", name, prefixed({sel}, codec::encode(m)));
  const auto body = cdr::encode(m);
  put("xcdr1", name, prefixed({sel}, encapsulated(body)));
  put("dynamic", name, signed_body<T>(body));
  if constexpr (lcm::expressible<T>) put("lcm", name, prefixed({0, sel}, lcm::encode(m)));
  if constexpr (std::is_same_v<T, fleet::Announcement>) put("announcement", "announcement", encapsulated(body));
}

// The lcm target's provider URLs (mode byte 1), each named after a hash of its text.
void lcm_url_seeds() {
  static constexpr const char* kUrls[] = {
      "udpm://239.255.76.67:7667?ttl=1",
      "udpm://239.255.76.68:20000?ttl=0&recv_buf_size=2097152",
      "memq://",
      "file:///tmp/x.log?mode=w",
      "tcpq://localhost:7700",
      "udpm://239.255.76.67:7667?transmit_only=true",
  };
  for (const char* url : kUrls)
    put("lcm", std::string("url_") + std::to_string(std::hash<std::string>{}(url) % 100000),
        prefixed({1}, text(url)));
}

void codecs() {
  for (std::uint8_t sel = 0; sel < 10; ++sel) fuzz::with_type(sel, [&]<class T>() { type_seeds<T>(sel); });
  lcm_url_seeds();
}

void recordings() {
  const std::string tmp = "/tmp/horus_corpus_" + std::to_string(::getpid());
  for (const auto c : {mcap::Compression::None, mcap::Compression::Zstd, mcap::Compression::Lz4}) {
    mcap::WriterOptions o;
    o.compression = c;
    o.chunk_size = 2048;
    auto w = mcap::Writer::create(tmp, o);
    if (!w) continue;
    const auto sig = reflect::type_signature<msg::Pose2D>();
    auto schema = (*w)->add_schema("horus::msg::Pose2D", "horus-signature",
                                   std::span(reinterpret_cast<const std::byte*>(sig.data()), sig.size()));
    auto channel = (*w)->add_channel(*schema, "robot.pose", "xcdr1", {{"scope", "fleet"}});
    for (std::uint32_t i = 0; i < 40; ++i) {
      auto m = sample<msg::Pose2D>();
      m.x = i;
      const auto body = cdr::encode(m);
      (void)(*w)->write(mcap::Message{*channel, i, 1'000'000'000ULL + i * 1000, 1'000'000'000ULL + i * 1000, body});
    }
    (void)(*w)->close();
    w->reset();
    std::ifstream in(tmp, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto* p = reinterpret_cast<const std::byte*>(bytes.data());
    put("mcap", c == mcap::Compression::None ? "none" : c == mcap::Compression::Zstd ? "zstd" : "lz4", {p, p + bytes.size()});
  }
  if (auto w = lcmlog::Writer::create(tmp)) {
    for (int i = 0; i < 10; ++i) (void)(*w)->write("ROBOT_POSE", 1000 + i, lcm::encode(sample<msg::Pose2D>()));
    w->reset();
    std::ifstream in(tmp, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto* p = reinterpret_cast<const std::byte*>(bytes.data());
    put("lcm_log", "pose", {p, p + bytes.size()});
  }
  std::remove(tmp.c_str());
}

void configs() {
  put("config", "full", text(R"(network:
  backend: cyclonedds
  domain_id: 3
  localhost_only: false
  lcm_url: "udpm://239.255.76.67:7667?ttl=1"
  peers: [10.0.0.2, robot-3]
  max_bandwidth: "2 MB/s"
fleet:
  announce: true
  heartbeat_ms: 100
  misses: 3
  max_hosts: 256
  forget_after: 10min
topics:
  - match: "fleet.camera.**"
    scope: fleet
    backend: lcm
    reliability: best_effort
    max_rate_hz: 10
    max_bandwidth: "1.5 MB/s"
    priority: low
  - match: "robot.*.cmd_vel"
    scope: fleet
    reliability: reliable
    durability: transient_local
    capacity: 64
    deadline: 100ms
    lifespan: 300ms
    priority: high
  - match: "**"
    scope: host
)"));
  put("config", "bad", text("topics:\n  - match: a.**\n    scop: host\n"));
  put("config", "secure", text(R"(security:
  mode: enforce
  keystore: keys
  identity: robot1
topics:
  - match: horus.fleet.heartbeat
    scope: fleet
    protection: sign
  - match: "robot1.*"
    scope: fleet
    backend: fastdds
    protection: encrypt
)"));
}

void segments() {
  const std::string ns = "corpus" + std::to_string(::getpid());
  for (std::uint8_t kind = 0; kind < 3; ++kind) {
    shm::SegmentSpec spec;
    spec.type_name = kind == 0 ? "fuzz::Fixed" : kind == 1 ? "fuzz::Bytes" : "fuzz::Large";
    spec.type_hash = 0x1234u + kind;
    spec.serialized = kind != 0;
    spec.payload_size = kind == 0 ? 40 : 8 + 1024;
    spec.capacity = 4;
    if (kind == 2) {
      spec.pool_slot_bytes = 4096;
      spec.pool_slots_per_lane = 2;
    }
    auto seg = shm::ShmSegment::open(ns, "t", spec);
    if (!seg) continue;
    const std::string file = "/dev/shm" + shm::segment_name(ns, "t");
    std::ifstream in(file, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto* p = reinterpret_cast<const std::byte*>(bytes.data());
    put("shm", "kind" + std::to_string(kind), prefixed({kind}, {p, p + bytes.size()}));
    ::unlink(file.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR (fuzz/corpus)\n", argv[0]);
    return 2;
  }
  root = argv[1];
  codecs();
  recordings();
  configs();
  segments();
  std::printf("corpora written under %s\n", argv[1]);
  return 0;
}

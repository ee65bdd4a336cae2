// raw_fastdds_pingpong: the raw Fast DDS baseline of the DDS latency benchmark. A plain Fast DDS
// 2.9 (DDS API) program over what fastddsgen generates from horus's .idl files (geometry.idl,
// vision.idl, horus_bench.idl); no horus code. Its twin is raw_cyclone_pingpong.c: same
// command line, topics, QoS and loop, so the two (and horus) are compared like for like.
//
//   raw-fastdds-pingpong pong <domain> <type> <seconds>
//   raw-fastdds-pingpong ping <domain> <type> <round_trips> <warmup>
//   raw-fastdds-pingpong sink <domain> <type> <seconds>      throughput: counts what arrives on
//   raw-fastdds-pingpong source <domain> <type> <seconds>    horus/bench/<type>/tput, sent back to back
//     type: cmdvel | kilobyte | image   (image: 1920x1080 RGB8, 6,220,800 bytes of data)
//
// pong takes every sample of horus/bench/<type>/ping and writes that same sample back on
// horus/bench/<type>/pong. It prints "ready" once its endpoints exist and stops after
// <seconds>, when its stdin (a pipe) reaches EOF, or on a sample whose seq is UINT64_MAX.
// ping waits for both matches (30 s), runs <warmup> then <round_trips> round trips, stops the
// pong and prints one line:
//   RESULT impl=raw-fastdds type=<type> n=<round_trips> p50_ns= p99_ns= p999_ns= mean_ns= [lost=<k>]
// with the one-way latency (RTT/2). A round trip with no answer within 2 s is lost.
//
// sink prints "ready", counts the samples of horus/bench/<type>/tput until one whose seq is
// UINT64_MAX (or <seconds>, or EOF on its stdin pipe), and prints
//   RESULT impl=raw-fastdds type=<type> mode=tput received=<n> seconds=<s> rate=<msgs/s> mbps=<MB/s> lost=<gaps> qos=<history> wait=..
// timed from the first to the last counted sample; MB are payload bytes (cmdvel 16, kilobyte
// 1024, image 6,220,800 a sample), as horus-dds-pingpong counts them. source waits for a
// matched reader (30 s), writes back to back for <seconds>, then the stop sample 3 times.
//
// Receiving: a WaitSet on a ReadCondition by default; BENCH_POLL=1: take_next_sample in a loop
// with std::this_thread::yield() between empty takes, as horus-dds-pingpong receives (its recv()
// does not block). Both RESULT lines end in wait=waitset or wait=poll.
//
// UDPv4 only (no shared-memory transport, no data sharing), XCDR1, synchronous publishing;
// BENCH_LOCALHOST=1: loopback only, unicast discovery. Exit: 0 ok, 2 usage, 3 setup failure.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <fastdds/dds/core/condition/GuardCondition.hpp>
#include <fastdds/dds/core/condition/StatusCondition.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/log/StdoutErrConsumer.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/ReadCondition.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include "geometryPubSubTypes.h"
#include "horus_benchPubSubTypes.h"
#include "visionPubSubTypes.h"

namespace {

namespace fd = eprosima::fastdds::dds;
using eprosima::fastrtps::Duration_t;
using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;

constexpr std::uint32_t kImageWidth = 1920;
constexpr std::uint32_t kImageHeight = 1080;
constexpr std::uint32_t kImageStep = kImageWidth * 3;
constexpr std::size_t kImageBytes = std::size_t{kImageStep} * kImageHeight;
constexpr std::uint64_t kStopSeq = UINT64_MAX;
constexpr std::uint64_t kLostAfterNs = 2'000'000'000ull;
constexpr auto kMatchDeadline = std::chrono::seconds(30);
constexpr std::uint32_t kSocketBuffer = 4u << 20;
constexpr std::uint32_t kInitialPeersRange = 32;

enum class Role { kPing, kPong, kSink, kSource };

// BENCH_POLL=1: receive by polling take_next_sample (yield between empty takes), no WaitSet.
bool g_poll = false;

const char* wait_name() { return g_poll ? "poll" : "waitset"; }

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
          .count());
}

Duration_t duration_of(std::uint64_t ns) {
  return Duration_t(static_cast<std::int32_t>(ns / 1'000'000'000ull), static_cast<std::uint32_t>(ns % 1'000'000'000ull));
}

int usage() {
  std::fprintf(stderr,
               "usage: raw-fastdds-pingpong pong <domain> <type> <seconds>\n"
               "       raw-fastdds-pingpong ping <domain> <type> <round_trips> <warmup>\n"
               "       raw-fastdds-pingpong sink <domain> <type> <seconds>\n"
               "       raw-fastdds-pingpong source <domain> <type> <seconds>\n"
               "  type: cmdvel | kilobyte | image\n"
               "  BENCH_LOCALHOST=1: loopback only; BENCH_POLL=1: receive by polling, not a WaitSet\n");
  return 2;
}

bool parse_u64(const char* s, std::uint64_t& out) {
  if (s == nullptr || *s == '\0' || *s == '-') return false;
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(s, &end, 10);
  if (errno != 0 || *end != '\0') return false;
  out = v;
  return true;
}

// The sequence-number field of each type (the stop signal is UINT64_MAX there).
std::uint64_t& seq_field(horus::msg::CmdVel& m) { return m.stamp_nanos(); }
std::uint64_t& seq_field(horus_bench::Kilobyte& m) { return m.seq(); }
std::uint64_t& seq_field(horus::msg::Image& m) { return m.timestamp_ns(); }

// The constant payload, prepared once (the image's 6 MB buffer is filled here and reused).
void fill(horus::msg::CmdVel& m) {
  m.linear(0.5f);
  m.angular(-0.25f);
}
void fill(horus_bench::Kilobyte& m) {
  for (std::size_t i = 0; i < m.payload().size(); ++i) m.payload()[i] = static_cast<std::uint8_t>(i);
}
void fill(horus::msg::Image& m) {
  m.width(kImageWidth);
  m.height(kImageHeight);
  m.encoding(horus::msg::ImageEncoding_Rgb8);
  m.step(kImageStep);
  std::array<char, 32> frame{};
  std::memcpy(frame.data(), "camera", 6);
  m.frame_id(frame);
  m.data().resize(kImageBytes);
  for (std::size_t i = 0; i < kImageBytes; ++i) m.data()[i] = static_cast<std::uint8_t>(i * 7u);
}

// Payload bytes a sample carries, as horus-dds-pingpong counts them for its MB/s.
constexpr std::uint64_t payload_bytes(const horus::msg::CmdVel*) { return 16; }
constexpr std::uint64_t payload_bytes(const horus_bench::Kilobyte*) { return 1024; }
constexpr std::uint64_t payload_bytes(const horus::msg::Image*) { return kImageBytes; }

// ---- stdin watcher: a guard condition raised when the parent closes our stdin pipe ----------

// Never destroyed: the detached watcher thread may still be blocked in read() at exit.
fd::GuardCondition* const g_stdin_guard = new fd::GuardCondition();

// Only a pipe or socket is watched: /dev/null or a file would end at once, and reading a
// terminal from a background job would stop the process (SIGTTIN).
bool stdin_is_pipe() {
  struct stat st {};
  if (fstat(STDIN_FILENO, &st) != 0) return false;
  return S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode);
}

void stdin_watch() {
  char buf[256];
  for (;;) {
    const ssize_t n = read(STDIN_FILENO, buf, sizeof buf);
    if (n > 0) continue;
    if (n < 0 && errno == EINTR) continue;
    break;  // EOF or error: the parent is gone
  }
  g_stdin_guard->set_trigger_value(true);
}

bool stdin_closed() { return g_stdin_guard->get_trigger_value(); }

// ---- setup ----------------------------------------------------------------------------------

struct Endpoints {
  fd::DomainParticipant* participant = nullptr;
  fd::DataWriter* writer = nullptr;
  fd::DataReader* reader = nullptr;
  fd::WaitSet waitset;
  fd::Condition* data_cond = nullptr;  // the reader's ReadCondition (or its data_available status)
  fd::ReadCondition* read_cond = nullptr;

  ~Endpoints() {
    if (participant == nullptr) return;
    if (data_cond != nullptr) waitset.detach_condition(*data_cond);
    waitset.detach_condition(*g_stdin_guard);
    if (read_cond != nullptr) reader->delete_readcondition(read_cond);
    participant->delete_contained_entities();
    fd::DomainParticipantFactory::get_instance()->delete_participant(participant);
  }
};

// The participant of `role` on `domain`, in ep.participant; false (said on stderr) if refused.
// The default participant profile of FASTRTPS_DEFAULT_PROFILES_FILE, when set, under this
// program's own settings: how a Fast DDS user adds DDS-Security (run_dds_bench.sh --secure
// gives the profile `horus security dds-config --for fastdds` writes).
bool create_participant(Endpoints& ep, std::uint32_t domain, Role role) {
  const char* env = std::getenv("BENCH_LOCALHOST");
  const bool localhost = env != nullptr && env[0] != '\0' && std::strcmp(env, "0") != 0;
  auto* factory = fd::DomainParticipantFactory::get_instance();
  factory->load_profiles();
  fd::DomainParticipantQos pq = factory->get_default_participant_qos();
  pq.name(role == Role::kPing    ? "raw-fastdds-ping"
          : role == Role::kPong  ? "raw-fastdds-pong"
          : role == Role::kSink  ? "raw-fastdds-sink"
                                 : "raw-fastdds-source");
  pq.transport().use_builtin_transports = false;  // no default UDPv4 + shared-memory pair
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->sendBufferSize = kSocketBuffer;
  udp->receiveBufferSize = kSocketBuffer;
  udp->maxInitialPeersRange = kInitialPeersRange;
  if (localhost) {
    udp->interfaceWhiteList.emplace_back("127.0.0.1");
    eprosima::fastrtps::rtps::Locator_t loopback;
    loopback.kind = LOCATOR_KIND_UDPv4;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(loopback, 127, 0, 0, 1);
    loopback.port = 0;  // 0: the well-known ports of the domain and participant index
    pq.wire_protocol().builtin.metatrafficUnicastLocatorList.push_back(loopback);
    pq.wire_protocol().builtin.initialPeersList.push_back(loopback);
    pq.wire_protocol().default_unicast_locator_list.push_back(loopback);
  }
  pq.transport().user_transports.push_back(udp);

  ep.participant = factory->create_participant(
      static_cast<fd::DomainId_t>(domain), pq, nullptr, fd::StatusMask::none());
  if (ep.participant == nullptr) {
    std::fprintf(stderr, "raw-fastdds: could not create a participant on domain %u\n", domain);
    return false;
  }
  return true;
}

// BENCH_KEEP_ALL=1: the QoS of horus's reliable fleet topics (KEEP_ALL within 16 samples, a
// 100 ms heartbeat): a writer whose history is full waits for acknowledgements.
// BENCH_KEEP_ALL_DEPTH=N: that many samples instead of 16. 0: KEEP_LAST 16, the default.
int keep_all_depth_from_env() {
  const char* keep_all_env = std::getenv("BENCH_KEEP_ALL");
  const char* depth_env = std::getenv("BENCH_KEEP_ALL_DEPTH");
  const bool keep_all = keep_all_env != nullptr && std::string_view(keep_all_env) == "1";
  if (!keep_all) return 0;
  return depth_env != nullptr ? std::max(1, std::atoi(depth_env)) : 16;
}

// The history the run uses, for the RESULT line: keep_last16 or keep_all<N>.
const char* qos_name() {
  static const std::string name = [] {
    const int d = keep_all_depth_from_env();
    return d == 0 ? std::string("keep_last16") : "keep_all" + std::to_string(d);
  }();
  return name.c_str();
}

// Reliable, volatile, KEEP_LAST 16 (or KEEP_ALL within `keep_all_depth` samples when not 0),
// XCDR1, no data sharing, written synchronously.
fd::DataWriterQos writer_qos(fd::Publisher* pub, int keep_all_depth) {
  const Duration_t max_blocking(1, 0);
  fd::DataWriterQos wq = pub->get_default_datawriter_qos();
  wq.reliability().kind = fd::RELIABLE_RELIABILITY_QOS;
  wq.reliability().max_blocking_time = max_blocking;
  wq.durability().kind = fd::VOLATILE_DURABILITY_QOS;
  wq.history().kind = fd::KEEP_LAST_HISTORY_QOS;
  wq.history().depth = 16;
  wq.data_sharing().off();
  wq.representation().m_value = {fd::XCDR_DATA_REPRESENTATION};
  wq.publish_mode().kind = fd::SYNCHRONOUS_PUBLISH_MODE;
  if (keep_all_depth != 0) {
    wq.history().kind = fd::KEEP_ALL_HISTORY_QOS;
    wq.resource_limits().max_instances = 1;
    wq.resource_limits().max_samples_per_instance = keep_all_depth;
    wq.resource_limits().max_samples = keep_all_depth;
    wq.reliable_writer_qos().times.heartbeatPeriod = Duration_t(0, 100000000u);
  }
  return wq;
}

// The writer's twin; with KEEP_ALL the reader holds as many samples as horus's reader buffer.
fd::DataReaderQos reader_qos(fd::Subscriber* sub, int keep_all_depth) {
  const Duration_t max_blocking(1, 0);
  fd::DataReaderQos rq = sub->get_default_datareader_qos();
  rq.reliability().kind = fd::RELIABLE_RELIABILITY_QOS;
  rq.reliability().max_blocking_time = max_blocking;
  rq.durability().kind = fd::VOLATILE_DURABILITY_QOS;
  rq.history().kind = fd::KEEP_LAST_HISTORY_QOS;
  rq.history().depth = 16;
  if (keep_all_depth != 0) {
    rq.history().kind = fd::KEEP_ALL_HISTORY_QOS;
    rq.resource_limits().max_instances = 1;
    rq.resource_limits().max_samples_per_instance = 4096;  // horus's reader buffer (kReaderSamples)
    rq.resource_limits().max_samples = 4096;
  }
  rq.data_sharing().off();
  rq.type_consistency().representation.m_value = {fd::XCDR_DATA_REPRESENTATION};
  return rq;
}

// The WaitSet the reader is waited on with: a ReadCondition on any sample, as the Cyclone twin;
// the data_available status if refused.
bool attach_reader(Endpoints& ep) {
  ep.read_cond = ep.reader->create_readcondition(fd::ANY_SAMPLE_STATE, fd::ANY_VIEW_STATE, fd::ANY_INSTANCE_STATE);
  ep.data_cond = ep.read_cond;
  if (ep.data_cond == nullptr) {
    fd::StatusCondition& sc = ep.reader->get_statuscondition();
    sc.set_enabled_statuses(fd::StatusMask::data_available());
    ep.data_cond = &sc;
  }
  if (ep.waitset.attach_condition(*ep.data_cond) != ReturnCode_t::RETCODE_OK) {
    std::fprintf(stderr, "raw-fastdds: could not attach the reader's condition to the WaitSet\n");
    return false;
  }
  return true;
}

// ping: writer on .../ping, reader on .../pong; pong the reverse; sink: a reader on .../tput;
// source: a writer on .../tput. The ReadCondition and WaitSet only when waiting on them.
bool setup(Endpoints& ep, std::uint32_t domain, fd::TypeSupport type, const std::string& type_name, Role role) {
  const bool is_ping = role == Role::kPing;
  const bool tput = role == Role::kSink || role == Role::kSource;
  if (!create_participant(ep, domain, role)) return false;
  if (type.register_type(ep.participant) != ReturnCode_t::RETCODE_OK) {
    std::fprintf(stderr, "raw-fastdds: could not register the type\n");
    return false;
  }
  const std::string prefix = "horus/bench/" + type_name;
  // sink/source: ping_topic is .../tput and there is no pong topic.
  fd::Topic* ping_topic =
      ep.participant->create_topic(prefix + (tput ? "/tput" : "/ping"), type.get_type_name(), fd::TOPIC_QOS_DEFAULT);
  fd::Topic* pong_topic =
      tput ? ping_topic : ep.participant->create_topic(prefix + "/pong", type.get_type_name(), fd::TOPIC_QOS_DEFAULT);
  fd::Publisher* pub = ep.participant->create_publisher(fd::PUBLISHER_QOS_DEFAULT);
  fd::Subscriber* sub = ep.participant->create_subscriber(fd::SUBSCRIBER_QOS_DEFAULT);
  if (ping_topic == nullptr || pong_topic == nullptr || pub == nullptr || sub == nullptr) {
    std::fprintf(stderr, "raw-fastdds: could not create the topics, publisher or subscriber\n");
    return false;
  }
  const int keep_all_depth = keep_all_depth_from_env();
  const fd::DataWriterQos wq = writer_qos(pub, keep_all_depth);
  const fd::DataReaderQos rq = reader_qos(sub, keep_all_depth);
  if (role != Role::kSource)
    ep.reader = sub->create_datareader(is_ping ? pong_topic : ping_topic, rq, nullptr, fd::StatusMask::none());
  if (role != Role::kSink)
    ep.writer = pub->create_datawriter(role == Role::kPong ? pong_topic : ping_topic, wq, nullptr, fd::StatusMask::none());
  if ((role != Role::kSource && ep.reader == nullptr) || (role != Role::kSink && ep.writer == nullptr)) {
    std::fprintf(stderr, "raw-fastdds: could not create the DataReader/DataWriter\n");
    return false;
  }
  if (role == Role::kSource || g_poll) return true;
  return attach_reader(ep);
}

// ---- pong -----------------------------------------------------------------------------------

// Watches stdin (when a pipe) from a detached thread; its guard joins the WaitSet, if waiting.
bool watch_stdin(Endpoints& ep) {
  if (!g_poll && ep.waitset.attach_condition(*g_stdin_guard) != ReturnCode_t::RETCODE_OK) {
    std::fprintf(stderr, "raw-fastdds: could not attach the guard condition\n");
    return false;
  }
  if (stdin_is_pipe()) std::thread(stdin_watch).detach();
  return true;
}

template <class T>
int run_pong(Endpoints& ep, std::uint64_t seconds) {
  if (!watch_stdin(ep)) return 3;
  auto sample = std::make_unique<T>();
  fd::SampleInfo info;
  fd::ConditionSeq active;
  active.reserve(4);
  std::printf("ready\n");
  std::fflush(stdout);

  const std::uint64_t end = now_ns() + seconds * 1'000'000'000ull;
  bool stop = false;
  while (g_poll && !stop) {
    if (ep.reader->take_next_sample(sample.get(), &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      if (seq_field(*sample) == kStopSeq) break;
      ep.writer->write(sample.get());
      continue;
    }
    if (now_ns() >= end || stdin_closed()) break;
    std::this_thread::yield();
  }
  while (!g_poll && !stop) {
    const std::uint64_t now = now_ns();
    if (now >= end) break;
    ep.waitset.wait(active, duration_of(end - now));
    if (g_stdin_guard->get_trigger_value()) break;
    while (ep.reader->take_next_sample(sample.get(), &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      if (seq_field(*sample) == kStopSeq) {
        stop = true;
        break;
      }
      ep.writer->write(sample.get());
    }
  }
  return 0;
}

// ---- ping -----------------------------------------------------------------------------------

bool wait_matched(Endpoints& ep) {
  const auto deadline = std::chrono::steady_clock::now() + kMatchDeadline;
  for (;;) {
    fd::PublicationMatchedStatus pm;
    fd::SubscriptionMatchedStatus sm;
    if (ep.writer->get_publication_matched_status(pm) == ReturnCode_t::RETCODE_OK &&
        ep.reader->get_subscription_matched_status(sm) == ReturnCode_t::RETCODE_OK && pm.current_count > 0 &&
        sm.current_count > 0)
      return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

// One round trip: write seq, wait for the pong sample with that seq (older ones are skipped).
// Returns the RTT in ns, or 0 when nothing came back within 2 s.
template <class T>
std::uint64_t round_trip(Endpoints& ep, T& out, T& in, fd::SampleInfo& info, fd::ConditionSeq& active,
                         std::uint64_t seq) {
  seq_field(out) = seq;
  const std::uint64_t t0 = now_ns();
  ep.writer->write(&out);
  const std::uint64_t deadline = t0 + kLostAfterNs;
  for (;;) {
    while (ep.reader->take_next_sample(&in, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data && seq_field(in) == seq) return now_ns() - t0;
    }
    const std::uint64_t now = now_ns();
    if (now >= deadline) return 0;
    if (g_poll)
      std::this_thread::yield();
    else
      ep.waitset.wait(active, duration_of(deadline - now));
  }
}

// Nearest rank: the ceil(p * n)-th smallest.
std::uint64_t percentile(const std::vector<std::uint64_t>& sorted, double p) {
  const auto n = sorted.size();
  if (n == 0) return 0;
  auto rank = static_cast<std::size_t>(p * static_cast<double>(n));
  if (static_cast<double>(rank) < p * static_cast<double>(n)) ++rank;
  rank = std::clamp<std::size_t>(rank, 1, n);
  return sorted[rank - 1];
}

template <class T>
int run_ping(Endpoints& ep, const std::string& type_name, std::uint64_t round_trips, std::uint64_t warmup) {
  auto out = std::make_unique<T>();
  auto in = std::make_unique<T>();
  fill(*out);
  std::vector<std::uint64_t> rtt;
  rtt.reserve(round_trips);
  fd::SampleInfo info;
  fd::ConditionSeq active;
  active.reserve(4);

  if (!wait_matched(ep)) {
    std::fprintf(stderr, "raw-fastdds: no pong matched on horus/bench/%s/{ping,pong} within 30 s\n",
                 type_name.c_str());
    return 3;
  }

  std::uint64_t seq = 0;
  for (std::uint64_t i = 0; i < warmup; ++i) (void)round_trip(ep, *out, *in, info, active, seq++);
  std::uint64_t lost = 0;
  for (std::uint64_t i = 0; i < round_trips; ++i) {
    const std::uint64_t r = round_trip(ep, *out, *in, info, active, seq++);
    if (r == 0)
      ++lost;
    else
      rtt.push_back(r);  // capacity reserved: no allocation
  }

  // Stop the pong; let the sample be acknowledged before the participant goes.
  seq_field(*out) = kStopSeq;
  ep.writer->write(out.get());
  ep.writer->wait_for_acknowledgments(Duration_t(2, 0));

  std::sort(rtt.begin(), rtt.end());
  long double sum = 0;
  for (const auto r : rtt) sum += static_cast<long double>(r);
  const std::uint64_t mean =
      rtt.empty() ? 0 : static_cast<std::uint64_t>(sum / static_cast<long double>(rtt.size()) / 2.0L + 0.5L);
  std::printf("RESULT impl=raw-fastdds type=%s n=%" PRIu64 " p50_ns=%" PRIu64 " p99_ns=%" PRIu64 " p999_ns=%" PRIu64
              " mean_ns=%" PRIu64,
              type_name.c_str(), round_trips, percentile(rtt, 0.50) / 2, percentile(rtt, 0.99) / 2,
              percentile(rtt, 0.999) / 2, mean);
  if (lost > 0) std::printf(" lost=%" PRIu64, lost);
  std::printf(" wait=%s\n", wait_name());
  std::fflush(stdout);
  return 0;
}

// ---- sink / source (throughput) -------------------------------------------------------------

// The sink's loss accounting, as horus's sink reports its dropped count: the sequence numbers
// between the first and the last sample received that never came (the source numbers them 1, 2, ...).
struct SeqGaps {
  std::uint64_t lo = UINT64_MAX, hi = 0;
  void add(std::uint64_t seq) noexcept {
    lo = std::min(lo, seq);
    hi = std::max(hi, seq);
  }
  std::uint64_t lost(std::uint64_t received) const noexcept {
    return received == 0 || hi - lo + 1 < received ? 0 : hi - lo + 1 - received;
  }
};

template <class T>
int run_sink(Endpoints& ep, const std::string& type_name, std::uint64_t seconds) {
  if (!watch_stdin(ep)) return 3;
  auto sample = std::make_unique<T>();
  fd::SampleInfo info;
  fd::ConditionSeq active;
  active.reserve(4);
  std::printf("ready\n");
  std::fflush(stdout);

  const std::uint64_t end = now_ns() + seconds * 1'000'000'000ull;
  std::uint64_t received = 0, first = 0, last = 0;
  SeqGaps gaps;
  while (g_poll) {
    if (ep.reader->take_next_sample(sample.get(), &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      if (seq_field(*sample) == kStopSeq) break;
      gaps.add(seq_field(*sample));
      last = now_ns();
      if (received++ == 0) first = last;
      continue;
    }
    if (now_ns() >= end || stdin_closed()) break;
    std::this_thread::yield();
  }
  bool stop = false;
  while (!g_poll && !stop) {
    const std::uint64_t now = now_ns();
    if (now >= end) break;
    ep.waitset.wait(active, duration_of(end - now));
    if (stdin_closed()) break;
    while (ep.reader->take_next_sample(sample.get(), &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      if (seq_field(*sample) == kStopSeq) {
        stop = true;
        break;
      }
      gaps.add(seq_field(*sample));
      last = now_ns();
      if (received++ == 0) first = last;
    }
  }

  const double s = static_cast<double>(last - first) / 1e9;
  const double bytes = static_cast<double>(received) * static_cast<double>(payload_bytes(sample.get()));
  std::printf("RESULT impl=raw-fastdds type=%s mode=tput received=%" PRIu64
              " seconds=%.3f rate=%.0f mbps=%.1f lost=%" PRIu64 " qos=%s wait=%s\n",
              type_name.c_str(), received, s, s > 0 ? static_cast<double>(received) / s : 0.0,
              s > 0 ? bytes / s / 1e6 : 0.0, gaps.lost(received), qos_name(), wait_name());
  std::fflush(stdout);
  return received > 0 ? 0 : 1;
}

template <class T>
int run_source(Endpoints& ep, const std::string& type_name, std::uint64_t seconds) {
  auto out = std::make_unique<T>();
  fill(*out);
  const auto deadline = std::chrono::steady_clock::now() + kMatchDeadline;
  for (;;) {
    fd::PublicationMatchedStatus pm;
    if (ep.writer->get_publication_matched_status(pm) == ReturnCode_t::RETCODE_OK && pm.current_count > 0) break;
    if (std::chrono::steady_clock::now() >= deadline) {
      std::fprintf(stderr, "raw-fastdds: no sink matched on horus/bench/%s/tput within 30 s\n", type_name.c_str());
      return 3;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));

  const std::uint64_t end = now_ns() + seconds * 1'000'000'000ull;
  for (std::uint64_t seq = 1; now_ns() < end; ++seq) {
    seq_field(*out) = seq;
    ep.writer->write(out.get());
  }
  seq_field(*out) = kStopSeq;
  for (int i = 0; i < 3; ++i) {
    ep.writer->write(out.get());
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ep.writer->wait_for_acknowledgments(Duration_t(2, 0));
  return 0;
}

template <class T, class PubSub>
int run(Role role, std::uint32_t domain, const std::string& type_name, std::uint64_t a, std::uint64_t b) {
  Endpoints ep;
  if (!setup(ep, domain, fd::TypeSupport(new PubSub()), type_name, role)) return 3;
  switch (role) {
    case Role::kPing: return run_ping<T>(ep, type_name, a, b);
    case Role::kPong: return run_pong<T>(ep, a);
    case Role::kSink: return run_sink<T>(ep, type_name, a);
    case Role::kSource: return run_source<T>(ep, type_name, a);
  }
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return usage();
  Role role;
  if (std::strcmp(argv[1], "ping") == 0)
    role = Role::kPing;
  else if (std::strcmp(argv[1], "pong") == 0)
    role = Role::kPong;
  else if (std::strcmp(argv[1], "sink") == 0)
    role = Role::kSink;
  else if (std::strcmp(argv[1], "source") == 0)
    role = Role::kSource;
  else
    return usage();
  const bool is_ping = role == Role::kPing;
  if (argc != (is_ping ? 6 : 5)) return usage();
  const char* poll_env = std::getenv("BENCH_POLL");
  g_poll = poll_env != nullptr && poll_env[0] != '\0' && std::strcmp(poll_env, "0") != 0;
  std::uint64_t domain = 0, a = 0, b = 0;
  if (!parse_u64(argv[2], domain) || domain > 232 || !parse_u64(argv[4], a) || (is_ping && !parse_u64(argv[5], b)))
    return usage();
  const std::string type = argv[3];
  if (type != "cmdvel" && type != "kilobyte" && type != "image") return usage();

  // The library must not print on stdout (the RESULT line is parsed): errors only, on stderr (the
  // warnings are interop noise at teardown, e.g. Cyclone's key-only dispose messages).
  fd::Log::ClearConsumers();
  fd::Log::RegisterConsumer(std::unique_ptr<fd::LogConsumer>(new fd::StdoutErrConsumer()));
  fd::Log::SetVerbosity(fd::Log::Kind::Error);

  const auto d = static_cast<std::uint32_t>(domain);
  int rc;
  if (type == "cmdvel")
    rc = run<horus::msg::CmdVel, horus::msg::CmdVelPubSubType>(role, d, type, a, b);
  else if (type == "kilobyte")
    rc = run<horus_bench::Kilobyte, horus_bench::KilobytePubSubType>(role, d, type, a, b);
  else
    rc = run<horus::msg::Image, horus::msg::ImagePubSubType>(role, d, type, a, b);
  fd::Log::Flush();
  return rc;
}

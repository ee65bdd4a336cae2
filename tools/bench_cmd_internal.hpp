// What the files of `horus bench` share, internal to tools/: bench_cmd.cpp (the handshake, the
// choices, the argument checks, the pong side), bench_ping.cpp (the ping side), bench_output.cpp (its outputs),
// bench_local.cpp (`horus bench local`). The commands themselves are in bench_cmd.hpp.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench_cmd.hpp"
#include "bench_peer.hpp"
#include "bench_stats.hpp"
#include "horus/config.hpp"
#include "horus/fleet.hpp"
#include "horus/msg/generic_value.hpp"
#include "horus/topic.hpp"

namespace horus::tools::bench_detail {

using Fields = std::map<std::string, std::string>;

// -- bench_cmd.cpp ----------------------------------------------------------------------------

// The host as the fleet layer names and tells it apart (hostname, boot, /dev/shm, namespace):
// a namespace host is a host of its own, and robots cloned from one image with one hostname differ.
std::string host_name();
std::string host_id();

// Pins the calling thread to `cpu` (nothing when it is negative).
void pin_to_cpu(int cpu);

// "PREFIX.SIDE.TYPE" or, for a sized payload, "PREFIX.SIDE.TYPE_SIZE".
std::string data_topic(const std::string& prefix, const char* side, const std::string& qualified, std::uint64_t size);

// Where a topic's messages go, in words: "fleet (cyclonedds, domain 3)", "host (shared memory)".
std::string where_text(const Backend& b);

// Where the choice of a topic's backend came from, for errors.
std::string choice_origin(const TopicChoice& c);

// The control topic, PREFIX.control.
class Control {
 public:
  static Result<Control> open(const std::string& prefix, const std::optional<Backend>& backend) {
    TopicOptions o;
    o.backend = backend;
    auto t = Topic<msg::GenericMessage>::open(prefix + ".control", o);
    if (!t) return std::unexpected(t.error());
    return Control(std::move(*t));
  }
  void send(const Fields& f) {
    auto m = msg::GenericMessage::from_value(f);
    if (m) topic_.send(*m);
  }
  // The next well-formed control message (others are skipped: another tool's traffic).
  std::optional<Fields> recv() {
    while (auto m = topic_.recv()) {
      auto f = static_cast<const msg::GenericMessage&>(*m).to_value<Fields>();
      if (f && f->contains("op") && f->contains("run")) return *f;
    }
    return std::nullopt;
  }
  bool wait(std::chrono::nanoseconds t) { return topic_.wait_for(t); }
  Backend backend() const { return topic_.backend(); }
  std::string name() const { return std::string(topic_.name()); }

 private:
  explicit Control(Topic<msg::GenericMessage> t) : topic_(std::move(t)) {}
  Topic<msg::GenericMessage> topic_;
};

// A control message's field `k` (empty when it has none).
std::string get(const Fields& f, const std::string& k);

// Echo times (the ping asks for them with stamps=1 in its start): the pong notes, at most once
// a millisecond, a message's tag and when it echoed it on its host's fleet clock
// (fleet::host_clock_unix_ns, the clock the fleet's heartbeats compare), and sends them on the
// control topic: {op: stamps, run, t0: the first time (Unix ns), d: "TAG:DT,..." (hex; DT: ns
// after t0), last: 1 on the last answer to the ping's {op: flush, run}}, a message per
// kStampsPerMessageBytes of text.
constexpr std::size_t kStampsPerMessageBytes = 3000;
// This host's fleet clock minus bench_now_ns() (the pair of readings closest in time of five).
std::int64_t clock_base();
void send_stamps(Control& control, const std::string& run, const std::vector<BenchPeer::EchoStamp>& stamps,
                 bool last);
// The stamps of a control message (`at`: Unix ns of the pong's fleet clock); nothing when it is
// malformed.
std::optional<std::vector<BenchPeer::EchoStamp>> parse_stamps(const Fields& f);

// Checks the arguments and, when `backend` is given, parses --backend into it; prints what is
// wrong and returns false otherwise.
bool check_args(const BenchArgs& a, const char* cmd, std::optional<Backend>* backend = nullptr);

// Answers pings until `stop` (or, with --once, after one run); sets `ready_flag` once it listens.
int run_pong(const BenchArgs& a, const std::optional<Backend>& backend, const std::atomic<bool>& stop,
             std::atomic<bool>* ready_flag);

// -- bench_ping.cpp ---------------------------------------------------------------------------

struct PingResult {
  bool ok = false;
  int exit_code = 0;
  std::string error;
  std::string type, payload, tag, ping_topic, pong_topic, control_topic, where, backend;
  std::string host, pong_host, pong_pid;
  std::uint64_t message_bytes = 0;
  std::uint64_t sent = 0, received = 0, lost = 0, late = 0, reordered = 0, duplicates = 0, refused = 0, dropped = 0;
  double measured_s = 0, warmup_s = 0;
  std::uint32_t window = 0;
  LatencyHistogram one_way;
  std::int64_t start_unix_ns = 0;
  // One-way latencies by clock, each way, from the pong's echo times (fleet topics): the pong's
  // clock minus ours from `source` ("same host", "synced": --clocks-synced, "fleet": the
  // heartbeats' NTP-style offset; "none": not measured, `why`).
  std::string pong_hostid;
  std::string clock_source = "none", clock_why;
  std::int64_t clock_offset_ns = 0, clock_uncertainty_ns = 0;
  std::uint64_t clock_below_zero = 0;  // samples below 0 each way (the offset's error exceeds them): counted as 0
  LatencyHistogram forward, back;      // ping -> pong, pong -> ping
};

// -- the ping's books (bench_ping.cpp; ClockSamples: bench_clock.cpp) ------------------------

// The ping's book of messages in flight, indexed by sequence number modulo its size.
class Ledger {
 public:
  static constexpr std::size_t kSize = std::size_t{1} << 20;
  Ledger() : slots_(kSize) {}
  void sent(std::uint64_t seq, std::int64_t t) {
    auto& s = slots_[seq & (kSize - 1)];
    if (s.state == kOut) --outstanding_;  // overwritten while still out: it is lost
    s = Slot{seq, t, kOut};
    ++outstanding_;
  }
  enum class Echo { OnTime, Late, Duplicate, Unknown };
  // Marks seq received; `sent_at` is its send time when it came back within the timeout.
  Echo received(std::uint64_t seq, std::int64_t& sent_at) {
    auto& s = slots_[seq & (kSize - 1)];
    if (s.seq != seq || s.state == kNone) return Echo::Unknown;
    if (s.state == kDone) return Echo::Duplicate;
    const bool late = s.state == kLate;
    if (s.state == kOut) --outstanding_;
    s.state = kDone;
    sent_at = s.t;
    return late ? Echo::Late : Echo::OnTime;
  }
  // Messages out longer than `timeout` stop counting against the window.
  void expire(std::uint64_t next_seq, std::int64_t now, std::int64_t timeout) {
    while (oldest_ < next_seq) {
      auto& s = slots_[oldest_ & (kSize - 1)];
      if (s.seq == oldest_ && s.state == kOut) {
        if (now - s.t <= timeout) break;
        s.state = kLate;
        --outstanding_;
      }
      ++oldest_;
    }
  }
  std::uint64_t outstanding() const { return outstanding_; }

 private:
  enum State : std::uint8_t { kNone, kOut, kLate, kDone };
  struct Slot {
    std::uint64_t seq = 0;
    std::int64_t t = 0;
    State state = kNone;
  };
  std::vector<Slot> slots_;
  std::uint64_t oldest_ = 0, outstanding_ = 0;
};

// The ping's side of one-way by clock: the send and receive times of measured echoes (a ring by
// sequence number), matched with the pong's echo times as they arrive on the control topic.
class ClockSamples {
 public:
  static constexpr std::size_t kSize = std::size_t{1} << 16;
  static constexpr std::size_t kMaxMatched = std::size_t{1} << 22;
  ClockSamples() : ring_(kSize) {}
  void echoed(std::uint64_t seq, std::int64_t sent, std::int64_t received) {
    ring_[seq & (kSize - 1)] = Entry{seq, sent, received};
  }
  // The pong echoed `seq` at `pong_unix` (its fleet clock); ignored unless `seq` was measured.
  void stamped(std::uint64_t seq, std::int64_t pong_unix) {
    const auto& e = ring_[seq & (kSize - 1)];
    if (e.seq != seq || matched_.size() >= kMaxMatched) return;
    matched_.push_back(Match{e.sent, pong_unix, e.received});
  }
  std::size_t size() const { return matched_.size(); }
  // Each way's latency with the pong's clock taken as ours + `offset`; `base`: our fleet clock
  // minus bench_now_ns().
  void resolve(std::int64_t base, std::int64_t offset, PingResult& r) const;

 private:
  struct Entry {
    std::uint64_t seq = UINT64_MAX;
    std::int64_t sent = 0, received = 0;
  };
  struct Match {
    std::int64_t sent, pong, received;
  };
  std::vector<Entry> ring_;
  std::vector<Match> matched_;
};

// The pong's clock against ours, for one-way by clock: r.clock_* (from the fleet's offset of
// r.pong_hostid's host, none on one host or with --clocks-synced; `fleet` may be null).
void choose_clock(const BenchArgs& a, const std::string& hostid, Fleet* fleet, PingResult& r);

// One ping run: the handshake with a pong, the warm-up, the measurement and the drain.
PingResult run_ping(const BenchArgs& a, const std::optional<Backend>& backend, const std::atomic<bool>& stop);

// -- bench_output.cpp: the ping's outputs -----------------------------------------------------

double msgs_per_s(const PingResult& r);

// Writes `text` to `file` ("-": stdout), appending or truncating; false with `error` set when it cannot.
bool write_text(const std::string& file, const std::string& text, bool append, std::string& error);

// The human summary, on `out` (stderr when the JSON or CSV goes to stdout).
void print_result(std::FILE* out, const BenchArgs& a, const PingResult& r);

// --json, --csv and --plot; false, with the error printed, when one cannot be written.
bool write_outputs(const BenchArgs& a, const PingResult& r);

}  // namespace horus::tools::bench_detail

// horus record and horus play between real processes, and the files they write read by
// independent readers:
//  - every standard message type recorded from shared memory by `horus record`, played back by
//    `horus play` into other topics, and compared field by field with what was sent;
//  - the same recording read by Foxglove's own libraries (@mcap/core, @foxglove/omgidl-parser,
//    @foxglove/omgidl-serialization; tests/interop/mcap_js), each message compared with
//    horus::to_json of what was sent;
//  - a recorder killed with SIGKILL: its file reads up to its last chunk, `record recover` makes
//    it whole, `play` plays it;
//  - bad files and bad arguments: clear errors, never a crash.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "horus/msg/all.hpp"
#include "horus/record/mcap.hpp"
#include "horus/record/player.hpp"
#include "horus/record/recorder.hpp"
#include "horus/topic.hpp"
#include "horus/wire/dynamic.hpp"
#include "foxglove_compare.hpp"
#include "message_trips.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

extern char** environ;

namespace {

using namespace std::chrono_literals;
using nlohmann::json;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::size_t count_lines_starting(const std::string& text, const std::string& start) {
  std::size_t n = 0;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) n += line.starts_with(start) ? 1 : 0;
  return n;
}

// A child process (the test's environment) whose standard output and error go to a file.
class Proc {
 public:
  Proc(std::vector<std::string> args, const std::string& log) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    EXPECT_EQ(::posix_spawn(&pid_, argv[0], &fa, nullptr, argv.data(), environ), 0) << args[0];
    posix_spawn_file_actions_destroy(&fa);
  }
  ~Proc() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  Proc(const Proc&) = delete;
  Proc& operator=(const Proc&) = delete;
  /// Sends `sig` (0: none) and waits at most `timeout`: the exit code, 128+signal, or -1 (killed on timeout).
  int stop(int sig, std::chrono::seconds timeout) {
    if (pid_ <= 0) return -1;
    if (sig != 0) ::kill(pid_, sig);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    int st = 0;
    while (::waitpid(pid_, &st, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > deadline) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, &st, 0);
        pid_ = -1;
        return -1;
      }
      std::this_thread::sleep_for(10ms);
    }
    pid_ = -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  }

 private:
  pid_t pid_ = -1;
};

std::string quote(const std::string& s) { return "'" + s + "'"; }

struct Recording {
  std::string prefix, file, log;
  std::vector<horus_test::MessageType> types;
  std::vector<std::unique_ptr<horus_test::Trip>> trips;
};

// Opens a Trip of every standard type on shared memory, records <prefix>.* with `horus record`
// while each sends its sample once, and stops the recorder with SIGINT.
void record_every_type(Recording& r, const std::string& base) {
  r.prefix = horus_test::unique_name(base);
  r.file = "/tmp/horus-" + r.prefix + ".mcap";
  r.log = "/tmp/horus-" + r.prefix + ".log";
  r.types = horus_test::standard_types();
  for (const auto& t : r.types) {
    r.trips.push_back(t.trip());
    ASSERT_EQ(r.trips.back()->open(horus::Backend::SharedMemory, r.prefix), "") << t.name;
  }
  Proc rec({HORUS_CLI, "record", "-o", r.file, "--topics", r.prefix + ".*"}, r.log);
  horus_test::Deadline up(30s);
  while (!up.expired() && count_lines_starting(slurp(r.log), "+ ") < r.types.size()) std::this_thread::sleep_for(20ms);
  ASSERT_EQ(count_lines_starting(slurp(r.log), "+ "), r.types.size()) << "the recorder did not find every topic:\n"
                                                                      << slurp(r.log);
  for (auto& t : r.trips) t->send();
  // The recorder takes what the topics still hold when it stops.
  ASSERT_EQ(rec.stop(SIGINT, 30s), 0) << slurp(r.log);
}

TEST(Record, EveryStandardTypeIsRecordedAndPlayedBackFieldForField) {
  Recording r;
  ASSERT_NO_FATAL_FAILURE(record_every_type(r, "rec"));
  // record info: every topic, one message each.
  std::string out;
  ASSERT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " record info --json " + r.file, out), 0) << out;
  const auto info = json::parse(out.substr(out.find('{')));
  ASSERT_EQ(info["topics"].size(), r.types.size()) << out;
  for (const auto& t : info["topics"]) EXPECT_EQ(t["messages"], 1) << t.dump();
  EXPECT_EQ(info["messages"], r.types.size());
  // play, each recorded topic into the Trip's echo topic.
  std::string cmd = std::string(HORUS_CLI) + " play " + r.file + " --rate 0";
  for (const auto& t : r.types)
    cmd += " --remap " + quote(r.prefix + "." + std::string(t.name) + "=" + r.prefix + "." + std::string(t.name) + ".echo");
  ASSERT_EQ(horus_test::run_command(cmd, out), 0) << out;
  EXPECT_NE(out.find("published " + std::to_string(r.types.size()) + " messages"), std::string::npos) << out;
  for (std::size_t i = 0; i < r.types.size(); ++i) {
    horus_test::Deadline back(10s);
    bool got = false;
    while (!(got = r.trips[i]->poll()) && !back.expired()) std::this_thread::sleep_for(5ms);
    EXPECT_TRUE(got) << r.types[i].name << " was not played back";
    EXPECT_EQ(r.trips[i]->failure(), "") << r.types[i].name;
  }
  std::remove(r.file.c_str());
  std::remove(r.log.c_str());
}

// -- Foxglove's readers ------------------------------------------------------------------------

std::string find_tool(const char* name) {
  for (const char* dir : {"/usr/bin/", "/usr/local/bin/"}) {
    const std::string p = std::string(dir) + name;
    if (::access(p.c_str(), X_OK) == 0) return p;
  }
  return {};
}

TEST(Record, FoxglovesReadersDecodeEveryRecordedMessageAsSent) {
  const std::string node = find_tool("node");
  const std::string dir = MCAP_JS_DIR;
  if (node.empty()) GTEST_SKIP() << "node is not installed (scripts/install-deps.sh installs Debian's nodejs)";
  if (::access((dir + "/node_modules/@mcap/core").c_str(), F_OK) != 0)
    GTEST_SKIP() << "the npm packages are not installed in " << dir << " (scripts/install-deps.sh runs npm ci there)";
  Recording r;
  ASSERT_NO_FATAL_FAILURE(record_every_type(r, "fox"));
  std::string out;
  const int rc = horus_test::run_command(node + " " + dir + "/read_mcap.mjs " + r.file, out);
  ASSERT_EQ(rc, 0) << out;
  std::map<std::string, const horus_test::MessageType*> by_topic;
  for (const auto& t : r.types) by_topic[r.prefix + "." + std::string(t.name)] = &t;
  std::set<std::string> seen;
  std::size_t schemas = 0;
  json summary;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    if (!line.starts_with('{')) continue;
    const auto j = json::parse(line);
    if (j.contains("schema") && !j.contains("topic")) ++schemas;
    if (j.contains("summary")) summary = j["summary"];
    if (!j.contains("topic")) continue;
    const auto it = by_topic.find(j["topic"]);
    ASSERT_NE(it, by_topic.end()) << line;
    const auto& type = *it->second;
    seen.insert(it->first);
    auto dyn = horus::wire::parse_signature(type.signature());
    ASSERT_TRUE(dyn) << dyn.error();
    EXPECT_EQ(j["schema"], dyn->name);
    EXPECT_EQ(j["metadata"]["horus.signature"], type.signature());
    EXPECT_EQ(horus_test::compare(*dyn, json::parse(type.sample_json()), j["value"], std::string(type.name)), "");
  }
  EXPECT_EQ(seen.size(), r.types.size()) << out.substr(0, 2000);
  EXPECT_EQ(schemas, r.types.size());
  EXPECT_EQ(summary["messages"], r.types.size()) << summary.dump();
  EXPECT_EQ(summary["statistics_messages"], std::to_string(r.types.size())) << summary.dump();
  std::remove(r.file.c_str());
  std::remove(r.log.c_str());
}

// -- a killed recorder ---------------------------------------------------------------------------

TEST(Record, ARecorderKilledMidWriteLeavesAFileThatReadsToItsLastChunk) {
  const std::string prefix = horus_test::unique_name("kill");
  const std::string file = "/tmp/horus-" + prefix + ".mcap", log = file + ".log";
  auto pub = horus::Topic<horus::msg::Pose2D>::open(prefix + ".pose");
  ASSERT_TRUE(pub) << pub.error().message();
  Proc rec({HORUS_CLI, "record", "-o", file, "--topics", prefix + ".**", "--compression", "lz4"}, log);
  horus_test::Deadline up(20s);
  while (!up.expired() && pub->sub_count() == 0) std::this_thread::sleep_for(10ms);
  ASSERT_GE(pub->sub_count(), 1u) << slurp(log);
  // 2.5 s at 1 kHz: the recorder writes a chunk at least every second, then dies mid-chunk.
  std::uint64_t sent = 0;
  const auto end = std::chrono::steady_clock::now() + 2500ms;
  while (std::chrono::steady_clock::now() < end) {
    pub->send(horus::msg::Pose2D{static_cast<double>(sent), 1.0, 2.0, sent});
    ++sent;
    std::this_thread::sleep_for(1ms);
  }
  EXPECT_EQ(rec.stop(SIGKILL, 10s), 128 + SIGKILL);

  // Without recover: a clear error about the missing end, naming the file.
  auto whole = horus::mcap::Reader::open(file);
  ASSERT_FALSE(whole);
  EXPECT_EQ(whole.error().code(), horus::Errc::Corrupt) << whole.error().message();
  EXPECT_NE(whole.error().message().find(file), std::string::npos) << whole.error().message();
  // With recover: the messages of the complete chunks, in order, from the first one recorded.
  horus::mcap::ReadOptions ro;
  ro.recover = true;
  auto cut = horus::mcap::Reader::open(file, ro);
  ASSERT_TRUE(cut) << cut.error().message();
  std::vector<double> xs;
  auto read = (*cut)->read_messages([&](const horus::mcap::Channel&, const horus::mcap::Schema*, const horus::mcap::Message& m) {
    auto s = horus::net::encapsulation::parse(m.data);
    EXPECT_TRUE(std::holds_alternative<horus::net::Sample>(s));
    auto p = horus::cdr::decode<horus::msg::Pose2D>(std::get<horus::net::Sample>(s).body);
    EXPECT_TRUE(p) << p.error();
    if (p) xs.push_back(p->x);
    return true;
  });
  ASSERT_TRUE(read) << read.error().message();
  EXPECT_TRUE((*cut)->truncated());
  ASSERT_GE(xs.size(), 500u) << "at least the first second's chunk";
  EXPECT_LT(xs.size(), sent);
  for (std::size_t i = 1; i < xs.size(); ++i) ASSERT_EQ(xs[i], xs[i - 1] + 1) << "a gap at " << i;

  // record info says so; record recover makes a whole file that reads without recover.
  std::string out;
  EXPECT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " record info " + file, out), 0) << out;
  EXPECT_NE(out.find("ends early"), std::string::npos) << out;
  EXPECT_NE(out.find(std::to_string(xs.size()) + " msgs"), std::string::npos) << out;
  const std::string fixed = "/tmp/horus-" + prefix + ".fixed.mcap";
  ASSERT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " record recover " + file + " -o " + fixed, out), 0) << out;
  auto player = horus::Player::open(fixed);
  ASSERT_TRUE(player) << player.error().message();
  EXPECT_FALSE((*player)->truncated());
  ASSERT_EQ((*player)->channels().size(), 1u);
  EXPECT_EQ((*player)->channels()[0].messages, xs.size());
  EXPECT_EQ((*player)->channels()[0].type, "horus::msg::Pose2D");
  // And the library plays it back, in order, into a topic of its own.
  auto back = horus::Topic<horus::msg::Pose2D>::open(prefix + ".back");
  ASSERT_TRUE(back);
  auto bound = (*player)->bind<horus::msg::Pose2D>(prefix + ".pose", prefix + ".back");
  ASSERT_TRUE(bound) << bound.error().message();
  horus::PlayOptions po;
  po.rate = 0;
  std::vector<double> played;
  std::thread drain([&] {
    horus_test::Deadline d(20s);
    while (played.size() < xs.size() && !d.expired())
      if (auto m = back->recv_for(50ms)) played.push_back(m->x);
  });
  auto stats = (*player)->play(po);
  drain.join();
  ASSERT_TRUE(stats) << stats.error().message();
  EXPECT_EQ(stats->published, xs.size());
  EXPECT_EQ(played, xs);

  // Playing from past the end, or looping over nothing, is an error at once (it spun a core).
  {
    auto again = horus::Player::open(fixed);
    ASSERT_TRUE(again) << again.error().message();
    ASSERT_TRUE((*again)->bind<horus::msg::Pose2D>(prefix + ".pose", prefix + ".back"));
    horus::PlayOptions past;
    past.start_s = 10;
    past.loop = true;
    auto r = (*again)->play(past);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message().find("past the end of the recording"), std::string::npos) << r.error().message();
    horus::PlayOptions none;
    none.loop = true;
    none.rate = 0;
    none.topics = {prefix + ".nothing"};
    r = (*again)->play(none);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message().find("nothing to play"), std::string::npos) << r.error().message();
  }
  EXPECT_EQ(horus_test::run_command("timeout 20 " + std::string(HORUS_CLI) + " play " + fixed + " --start 10 --loop", out), 1)
      << out;
  EXPECT_NE(out.find("past the end of the recording"), std::string::npos) << out;
  for (const auto& f : {file, fixed, log}) std::remove(f.c_str());
}

// -- the library and bad input --------------------------------------------------------------------

TEST(Record, TheLibraryRecordsItsOwnTopicsAndRefusesWhatItCannotRecord) {
  const std::string prefix = horus_test::unique_name("lib");
  const std::string file = "/tmp/horus-" + prefix + ".mcap";
  auto rec = horus::Recorder::open(file);
  ASSERT_TRUE(rec) << rec.error().message();
  ASSERT_TRUE((*rec)->add<horus::msg::Imu>(prefix + ".imu"));
  ASSERT_TRUE((*rec)->add<horus::msg::Image>(prefix + ".camera"));
  auto again = (*rec)->add<horus::msg::Imu>(prefix + ".imu");
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().message().find("recorded already"), std::string::npos);
  auto wrong = (*rec)->add<horus::msg::Pose2D>(prefix + ".imu2");
  ASSERT_TRUE(wrong);  // another name: fine
  auto imu = horus::Topic<horus::msg::Imu>::open(prefix + ".imu");
  auto cam = horus::Topic<horus::msg::Image>::open(prefix + ".camera");
  ASSERT_TRUE(imu && cam);
  horus::msg::Image img(48, 64, horus::msg::ImageEncoding::Rgb8);
  auto pixels = img.data_mut();
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint8_t>(i * 7);
  const auto stamp = static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                                   std::chrono::system_clock::now().time_since_epoch())
                                                   .count()) -
                     1'000'000'000ULL;
  for (int i = 0; i < 100; ++i) {
    horus::msg::Imu m{};
    m.timestamp_ns = stamp + static_cast<std::uint64_t>(i);  // a wall-clock stamp
    m.linear_acceleration[0] = i;
    imu->send(m);
    if (i % 10 == 0) cam->send(img);
    std::this_thread::sleep_for(1ms);
  }
  ASSERT_TRUE((*rec)->close());
  const auto stats = (*rec)->stats();
  ASSERT_EQ(stats.topics.size(), 3u);
  EXPECT_EQ(stats.topics[0].messages, 100u);
  EXPECT_EQ(stats.topics[1].messages, 10u);
  EXPECT_EQ(stats.topics[0].dropped + stats.topics[1].dropped, 0u);

  auto reader = horus::mcap::Reader::open(file);
  ASSERT_TRUE(reader) << reader.error().message();
  std::size_t images = 0;
  auto ok = (*reader)->read_messages([&](const horus::mcap::Channel& ch, const horus::mcap::Schema* s, const horus::mcap::Message& m) {
    EXPECT_NE(s, nullptr);
    if (s) {
      EXPECT_EQ(s->encoding, "omgidl");
    }
    EXPECT_EQ(ch.message_encoding, "cdr");
    if (ch.topic == prefix + ".camera") {
      auto sample = std::get<horus::net::Sample>(horus::net::encapsulation::parse(m.data));
      auto back = horus::cdr::decode<horus::msg::Image>(sample.body);
      EXPECT_TRUE(back) << back.error();
      if (back) {
        EXPECT_EQ(back->width(), 64u);
        EXPECT_TRUE(std::ranges::equal(back->data(), img.data())) << "the image's bytes are in the file";
      }
      ++images;
    } else if (ch.topic == prefix + ".imu") {
      // A plausible wall-clock stamp is the publish time.
      EXPECT_GE(m.publish_time, stamp);
      EXPECT_LT(m.publish_time, stamp + 100);
      EXPECT_GT(m.log_time, m.publish_time);
    }
    return true;
  });
  ASSERT_TRUE(ok) << ok.error().message();
  EXPECT_EQ(images, 10u);

  // A type LCM cannot carry is refused for an LCM log, naming it.
  auto lcm_rec = horus::Recorder::open(file + ".lcm", {.format = horus::RecordFormat::Lcm});
  ASSERT_TRUE(lcm_rec);
  auto refused = (*lcm_rec)->add<horus::msg::Pose2D>(prefix + ".a.very.long.name.that.is.longer.than.an.lcm.channel.may.be.x");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message().find("LCM channel"), std::string::npos) << refused.error().message();
  ASSERT_TRUE((*lcm_rec)->close());

  // Player: a type mismatch is named.
  auto player = horus::Player::open(file);
  ASSERT_TRUE(player);
  auto mismatch = (*player)->bind<horus::msg::Pose2D>(prefix + ".imu");
  ASSERT_FALSE(mismatch);
  EXPECT_EQ(mismatch.error().code(), horus::Errc::TypeMismatch);
  EXPECT_NE(mismatch.error().message().find("horus::msg::Imu"), std::string::npos) << mismatch.error().message();
  auto unknown = (*player)->bind<horus::msg::Imu>("no.such.topic");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message().find("no.such.topic"), std::string::npos);
  for (const auto& f : {file, file + ".lcm"}) std::remove(f.c_str());
}

// A recorder of an idle topic sleeps: the library's thread makes a handful of rounds a second
// (its 200 ms tick), not millions (a fired trigger once kept every wait from sleeping), and
// `horus record` of an idle topic uses a small part of a core. The bounds are upper bounds on
// counts and CPU, never on how fast anything ran.
TEST(Record, AnIdleRecorderSleepsInsteadOfSpinning) {
  const std::string prefix = horus_test::unique_name("idle");
  const std::string file = "/tmp/horus-" + prefix + ".mcap";
  auto pub = horus::Topic<horus::msg::Pose2D>::open(prefix + ".pose");
  ASSERT_TRUE(pub) << pub.error().message();
  auto rec = horus::Recorder::open(file);
  ASSERT_TRUE(rec) << rec.error().message();
  ASSERT_TRUE((*rec)->add<horus::msg::Pose2D>(prefix + ".pose"));
  pub->send(horus::msg::Pose2D{1.0, 2.0, 3.0, 4});
  horus_test::Deadline took(10s);
  while (!took.expired() && (*rec)->stats().messages == 0) std::this_thread::sleep_for(5ms);
  ASSERT_EQ((*rec)->stats().messages, 1u);
  const auto before = (*rec)->stats().rounds;
  const auto t0 = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(1s);
  const auto rounds = (*rec)->stats().rounds - before;
  const double idle_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // One round per 200 ms tick, and a few for the message's gather and the flush.
  EXPECT_LE(static_cast<double>(rounds), 5.0 * idle_s + 4.0) << rounds << " rounds in " << idle_s << " s idle";
  EXPECT_GE(rounds, 1u) << "the tick still runs (flushes, splits)";
  ASSERT_TRUE((*rec)->close());
  EXPECT_EQ((*rec)->stats().topics.at(0).messages, 1u);

  // The command line: 3 s of an idle topic.
  rusage r0{}, r1{};
  ::getrusage(RUSAGE_CHILDREN, &r0);
  std::string out;
  const std::string cli = HORUS_CLI;
  ASSERT_EQ(horus_test::run_command(cli + " record --overwrite -o " + file + " --topics '" + prefix + ".**' --duration 3", out), 0)
      << out;
  ::getrusage(RUSAGE_CHILDREN, &r1);
  const auto cpu_s = [](const rusage& r) {
    return static_cast<double>(r.ru_utime.tv_sec + r.ru_stime.tv_sec) +
           static_cast<double>(r.ru_utime.tv_usec + r.ru_stime.tv_usec) / 1e6;
  };
  EXPECT_LT(cpu_s(r1) - cpu_s(r0), 0.6) << "horus record of an idle topic for 3 s used " << cpu_s(r1) - cpu_s(r0)
                                        << " s of CPU\n" << out;
  EXPECT_NE(out.find("+ " + prefix + ".pose"), std::string::npos) << out;
  std::remove(file.c_str());
}

// `horus record -o FILE` never replaces a recording unless told to, and says when no topic
// matched (it once replaced a recording with an empty one when the pattern matched nothing).
TEST(Record, AnExistingRecordingIsKeptAndNoMatchIsSaid) {
  const std::string prefix = horus_test::unique_name("keep");
  const std::string file = "/tmp/horus-" + prefix + ".mcap";
  const std::string cli = HORUS_CLI;
  std::ofstream(file, std::ios::binary) << "an earlier recording";
  std::string out;
  EXPECT_EQ(horus_test::run_command(cli + " record -o " + file + " --topics '" + prefix + ".**' --duration 1", out), 1)
      << out;
  EXPECT_NE(out.find(file + " exists already"), std::string::npos) << out;
  EXPECT_NE(out.find("--overwrite"), std::string::npos) << out;
  EXPECT_EQ(slurp(file), "an earlier recording") << "the file is untouched";
  // A split that would reach an existing file stops the recording, naming it.
  std::remove(file.c_str());
  const std::string second = "/tmp/horus-" + prefix + "_1.mcap";
  std::ofstream(second, std::ios::binary) << "kept";
  {
    auto rec = horus::Recorder::open(file, {.split_size = 1, .overwrite = false});
    ASSERT_TRUE(rec) << rec.error().message();
    ASSERT_TRUE((*rec)->add<horus::msg::Pose2D>(prefix + ".split"));
    auto pub = horus::Topic<horus::msg::Pose2D>::open(prefix + ".split");
    ASSERT_TRUE(pub);
    pub->send(horus::msg::Pose2D{});
    horus_test::Deadline stopped(10s);
    while (!stopped.expired() && !(*rec)->error()) std::this_thread::sleep_for(5ms);
    ASSERT_TRUE((*rec)->error()) << "the split reached " << second;
    EXPECT_NE((*rec)->error()->message().find(second + " exists already"), std::string::npos)
        << (*rec)->error()->message();
  }
  EXPECT_EQ(slurp(second), "kept");
  std::remove(second.c_str());
  // --overwrite replaces it; a pattern that matches nothing is said at the start and at the end.
  std::ofstream(file, std::ios::binary) << "an earlier recording";
  EXPECT_EQ(
      horus_test::run_command(cli + " record --overwrite -o " + file + " --topics '" + prefix + ".none' --duration 1", out), 1)
      << out;
  EXPECT_NE(out.find("no topic matches --topics '" + prefix + ".none' yet"), std::string::npos) << out;
  EXPECT_NE(out.find("no topic matched --topics '" + prefix + ".none'"), std::string::npos) << out;
  EXPECT_NE(out.find("holds no messages"), std::string::npos) << out;
  EXPECT_NE(slurp(file), "an earlier recording") << "--overwrite replaced it";
  std::remove(file.c_str());
}

TEST(Record, BadFilesAndArgumentsGetClearErrors) {
  const std::string prefix = horus_test::unique_name("bad");
  const std::string dir = "/tmp/horus-" + prefix;
  ::mkdir(dir.c_str(), 0755);
  const auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir + "/" + name, std::ios::binary) << bytes;
    return dir + "/" + name;
  };
  std::string out;
  const std::string cli = HORUS_CLI;
  // Not a recording at all.
  const auto junk = write("junk.mcap", "this is not a recording");
  EXPECT_EQ(horus_test::run_command(cli + " record info " + junk, out), 1) << out;
  EXPECT_NE(out.find("magic"), std::string::npos) << out;
  // An LCM log: a bad sync word in the second event, a negative length, an event cut short.
  std::string event;
  const auto be = [](std::uint64_t v, int n) {
    std::string s;
    for (int i = n - 1; i >= 0; --i) s += static_cast<char>((v >> (8 * i)) & 0xff);
    return s;
  };
  event = be(0xEDA1DA01u, 4) + be(0, 8) + be(1'700'000'000'000'000ULL, 8) + be(3, 4) + be(2, 4) + "abc" + "xy";
  const auto bad_sync = write("sync.lcmlog", event + be(0x12345678u, 4) + std::string(30, '\0'));
  EXPECT_EQ(horus_test::run_command(cli + " record info " + bad_sync, out), 1) << out;
  EXPECT_NE(out.find("offset 33"), std::string::npos) << out;
  EXPECT_NE(out.find("sync word"), std::string::npos) << out;
  const auto negative = write("neg.lcmlog", be(0xEDA1DA01u, 4) + be(0, 8) + be(0, 8) + be(3, 4) + be(0xFFFFFFF0u, 4) + "abc");
  EXPECT_EQ(horus_test::run_command(cli + " record info " + negative, out), 1) << out;
  EXPECT_NE(out.find("data length is -16"), std::string::npos) << out;
  const auto cut = write("cut.lcmlog", event + event.substr(0, 20));
  EXPECT_EQ(horus_test::run_command(cli + " record info " + cut, out), 0) << out;
  EXPECT_NE(out.find("1 msgs"), std::string::npos) << out;
  // An MCAP whose channel is of a ROS 2 type horus does not convert from: named, not played.
  const std::string foreign = dir + "/foreign.mcap";
  {
    auto w = horus::mcap::Writer::create(foreign);
    ASSERT_TRUE(w);
    const std::string text = "string data";
    auto sid = (*w)->add_schema("std_msgs/String", "ros2msg", std::as_bytes(std::span(text.data(), text.size())));
    ASSERT_TRUE(sid);
    auto cid = (*w)->add_channel(*sid, "/chatter", "cdr");
    ASSERT_TRUE(cid);
    const std::array<std::byte, 12> body{};
    ASSERT_TRUE((*w)->write({*cid, 0, 1, 1, body}));
    ASSERT_TRUE((*w)->close());
  }
  EXPECT_EQ(horus_test::run_command(cli + " play " + foreign, out), 1) << out;
  EXPECT_NE(out.find("std_msgs/msg/String"), std::string::npos) << out;
  EXPECT_NE(out.find("no horus message converts from"), std::string::npos) << out;
  // Arguments.
  EXPECT_EQ(horus_test::run_command(cli + " record -o " + dir + "/x.mcap", out), 2) << out;
  EXPECT_NE(out.find("--all"), std::string::npos) << out;
  EXPECT_EQ(horus_test::run_command(cli + " record -o " + dir + "/x.mcap --all --compression brotli", out), 2) << out;
  EXPECT_NE(out.find("zstd"), std::string::npos) << out;
  EXPECT_EQ(horus_test::run_command(cli + " record -o " + dir + "/x.mcap --topics 'a..b'", out), 2) << out;
  EXPECT_EQ(horus_test::run_command(cli + " play " + foreign + " --remap nonsense", out), 2) << out;
  EXPECT_NE(out.find("OLD=NEW"), std::string::npos) << out;
  EXPECT_EQ(horus_test::run_command(cli + " record -o " + dir + "/x.mcap --all --duration 0", out), 105) << out;
  EXPECT_NE(out.find("--duration"), std::string::npos) << out;
  EXPECT_EQ(horus_test::run_command(cli + " record -o /nonexistent/dir/x.mcap --all", out), 1) << out;
  EXPECT_NE(out.find("/nonexistent/dir/x.mcap"), std::string::npos) << out;
  std::filesystem::remove_all(dir);
}

}  // namespace

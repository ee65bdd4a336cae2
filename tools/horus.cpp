// horus: the command line. This file sets up CLI11 and dispatches; each command family has its
// own file: topic_cmd.cpp, fleet_cmd.cpp, config_cmd.cpp, record_cmd.cpp, bench_cmd.cpp.
//
//   horus topic list [--json] [-v] [--local]  every topic on this host (HORUS_NAMESPACE) and, when
//                                         a network backend is configured (HORUS_BACKEND, the
//                                         file's network.backend, --backend), on the fleet's hosts
//   horus topic info NAME                 type, sizes, processes, counts, rate (or the hosts that
//                                         announce it)
//   horus topic echo NAME [--json] [-n N] print messages as they arrive: standard types through
//                                         the reflection; a topic of other hosts through the
//                                         type signature its host announced (any type)
//   horus topic hz NAME [--duration S]    live rate with min/max/std of the periods
//   horus topic bw NAME [--duration S]    bytes per second, mean and max message size
//   horus topic pub NAME TYPE JSON [--rate HZ] [--count N]  publish (standard types, JSON
//                                         through the reflection)
//   horus fleet [--json] [--once]         the fleet's hosts: state, heartbeat age, RTT, processes,
//                                         topics (live table; --once: one snapshot)
//   horus bench pong | ping | local       round trips between hosts through ordinary topics
//                                         (one-way latency, jitter, losses, throughput; JSON,
//                                         CSV, a plot), and the local paths beside the true
//                                         floor (bench_cmd.hpp)
//   horus foxglove [--port P] [--topics P...]  the Foxglove WebSocket protocol and a status page
//                                         of the fleet, on one port (foxglove/command.hpp)
//   horus clean                           remove segments whose processes are all gone
//   horus config check FILE               validate a configuration file (exit 1 naming the error)
//   horus security keystore init | host create | permissions | governance | check
//                                         DDS-Security's keystore (security_cmd.hpp)
//   horus config explain NAME [--file F]  which rule, scope, backend and QoS a topic gets, and
//                                         from where (code is not known here: environment,
//                                         file, default); the file is F or HORUS_CONFIG's
//   horus idl --ros2 DIR [--package P]    the standard messages as a ROS 2 interface package
//
// list/info/clean read the segments without joining them; echo, hz and bw subscribe like any
// other process (they count as a subscriber while they run); the fleet commands join the fleet
// layer (horus/fleet.hpp) for as long as they run.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <signal.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>

#include "horus/backend.hpp"
#include "horus/config.hpp"
#include "horus/discovery/registry.hpp"
#include "horus/shm/shm_segment.hpp"
#include "horus/version.hpp"
#include "bench_cmd.hpp"
#include "config_cmd.hpp"
#include "fleet_cmd.hpp"
#include "idl_cmd.hpp"
#include "foxglove/command.hpp"
#include "record_cmd.hpp"
#include "security_cmd.hpp"
#include "topic_cmd.hpp"
#include "ros2_cmd.hpp"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }

// The command line's variables (several subcommands share one: --json, NAME, --count, ...) and
// the subcommands that dispatch asks which one was given.
struct Cli {
  horus::tools::Lookup lookup;
  bool json = false, verbose = false, local_only = false, all = false, once = false, ros2 = false;
  double rate_window_s = 1.0, timeout_s = 0, duration_s = 0, window_s = 1.0, rate_hz = 0;
  long count = 0;
  int fleet_wait_ms = 1000;
  std::string name, type, message, config_file, record_file, recover_out;
  std::string idl_ros2_dir, idl_package = "horus_msgs";
  horus::tools::RecordArgs rec;
  horus::tools::FoxgloveArgs fox;
  horus::tools::PlayArgs play_args;
  horus::tools::BenchArgs bench_args;
  CLI::App *list = nullptr, *info = nullptr, *echo = nullptr, *hz = nullptr, *bw = nullptr, *pub = nullptr;
  CLI::App *fleet = nullptr, *clean = nullptr, *check = nullptr, *explain = nullptr, *settings = nullptr;
  CLI::App *record = nullptr, *record_info = nullptr, *recover = nullptr, *foxglove = nullptr, *play = nullptr;
  CLI::App *bench_pong = nullptr, *bench_ping = nullptr, *bench_local = nullptr, *idl = nullptr;
};

// horus idl --ros2 DIR.
void add_idl_command(CLI::App& app, Cli& c) {
  c.idl = app.add_subcommand("idl", "write interface files of the standard messages");
  c.idl->add_option("--ros2", c.idl_ros2_dir, "write the ROS 2 interface package (package.xml, CMakeLists.txt, msg/) "
                                              "into DIR")
      ->required();
  c.idl->add_option("--package", c.idl_package, "the ROS 2 package's name (default horus_msgs)");
}

// horus topic list | info | echo | hz | bw | pub.
void add_topic_commands(CLI::App& app, Cli& c) {
  auto* topic = app.add_subcommand("topic", "inspect and publish topics");
  topic->require_subcommand(1);
  auto fleet_flags = [&](CLI::App* s) {
    s->add_option("--backend", c.lookup.transport, "network backend of the fleet (default: HORUS_BACKEND's, else the "
                                                   "configuration file's network.backend)");
    s->add_option("--wait", c.lookup.wait_ms, "milliseconds to wait for other hosts' announcements (echo, hz, bw: "
                                              "also for a topic of this host to appear)")
        ->check(CLI::Range(0, 60000));
  };

  c.list = topic->add_subcommand("list", "list every topic on this host and the fleet's");
  c.list->add_flag("--json", c.json, "print JSON");
  c.list->add_flag("-v,--verbose", c.verbose, "show the processes of each topic");
  c.list->add_flag("--local", c.local_only, "this host's topics only");
  c.list->add_flag("--all", c.all, "also the fleet layer's own topics (horus.fleet.*)");
  c.list->add_flag("--ros2", c.ros2,
                   "the ROS 2 topics of the DDS domain instead (name, ROS 2 type, publishers, subscribers, nodes)");
  auto rate_flag = [&](CLI::App* s) {
    s->add_option("--window", c.rate_window_s, "seconds over which rates are measured (default 1; 0: no rates)")
        ->check(CLI::Range(0.0, 60.0));
  };
  rate_flag(c.list);
  fleet_flags(c.list);

  c.info = topic->add_subcommand("info", "describe one topic");
  c.info->add_option("name", c.name, "topic name")->required();
  rate_flag(c.info);
  fleet_flags(c.info);

  c.echo = topic->add_subcommand("echo", "print a topic's messages");
  c.echo->add_option("name", c.name, "topic name")->required();
  c.echo->add_flag("--json", c.json, "one JSON object per line");
  c.echo->add_option("-n,--count", c.count, "stop after N messages (exit 1 if fewer arrive before --timeout)");
  c.echo->add_option("--timeout", c.timeout_s, "stop after S seconds, waiting for the topic to appear included")
      ->check(CLI::PositiveNumber);
  fleet_flags(c.echo);

  c.hz = topic->add_subcommand("hz", "measure a topic's rate");
  c.hz->add_option("name", c.name, "topic name")->required();
  c.hz->add_option("--duration", c.duration_s, "stop after S seconds (default: until Ctrl-C)")
      ->check(CLI::PositiveNumber);
  c.hz->add_option("--window", c.window_s, "seconds between reports")->check(CLI::Range(0.05, 3600.0));
  fleet_flags(c.hz);

  c.bw = topic->add_subcommand("bw", "measure a topic's bandwidth and message sizes");
  c.bw->add_option("name", c.name, "topic name")->required();
  c.bw->add_option("--duration", c.duration_s, "stop after S seconds (default: until Ctrl-C)")
      ->check(CLI::PositiveNumber);
  c.bw->add_option("--window", c.window_s, "seconds between reports")->check(CLI::Range(0.05, 3600.0));
  fleet_flags(c.bw);

  c.pub = topic->add_subcommand("pub", "publish messages (a standard type, given as JSON)");
  c.pub->add_option("name", c.name, "topic name")->required();
  c.pub->add_option("type", c.type, "message type (Pose2D or horus::msg::Pose2D)")->required();
  c.pub->add_option("json", c.message, "the message as JSON, e.g. '{\"x\": 1.5}' (missing fields keep their defaults)")
      ->required();
  c.pub->add_option("-r,--rate", c.rate_hz, "messages per second (default: once)")->check(CLI::Range(0.0, 1e6));
  c.pub->add_option("-n,--count", c.count, "messages to send (default: 1, or until Ctrl-C with --rate)");
  fleet_flags(c.pub);
}

// horus fleet, horus clean and horus config check | explain | settings.
void add_fleet_config_commands(CLI::App& app, Cli& c) {
  c.fleet = app.add_subcommand("fleet", "the fleet's hosts: state, heartbeat age, RTT, processes, topics");
  c.fleet->add_flag("--json", c.json, "print JSON");
  c.fleet->add_flag("--once", c.once, "print one snapshot and exit");
  c.fleet->add_option("--backend", c.lookup.transport, "network backend (default: HORUS_BACKEND's, else the file's)");
  c.fleet->add_option("--wait", c.fleet_wait_ms, "milliseconds to listen before the first snapshot")
      ->check(CLI::Range(0, 60000));
  c.fleet->add_option("--duration", c.duration_s, "stop after S seconds (default: until Ctrl-C)")
      ->check(CLI::PositiveNumber);

  c.clean = app.add_subcommand("clean", "remove shared-memory segments whose processes are all gone");

  auto* config = app.add_subcommand("config", "check and explain the configuration file (HORUS_CONFIG)");
  config->require_subcommand(1);
  c.check = config->add_subcommand("check", "validate a configuration file");
  c.check->add_option("file", c.config_file, "the YAML file")->required();
  c.explain = config->add_subcommand("explain", "what a topic name gets, and from where");
  c.explain->add_option("name", c.name, "topic name")->required();
  c.explain->add_option("--file", c.config_file, "the YAML file (default: HORUS_CONFIG's)");
  c.settings = config->add_subcommand("settings", "the per-topic settings: file keys, code, examples (Markdown)");
}

// horus record (and record info | recover).
void add_record_commands(CLI::App& app, Cli& c) {
  auto& rec = c.rec;
  c.record = app.add_subcommand("record", "record topics into an MCAP file (or an LCM log)");
  auto* record = c.record;
  record->require_subcommand(0, 1);
  record->add_option("-o,--output", rec.output, "the file to write (FILE.mcap; with --split-size, FILE_1.mcap, ...)");
  record->add_option("--topics", rec.topics, "topic patterns to record ('*' one segment, '**' any): 'robot.**'");
  record->add_flag("--all", rec.all, "record every topic (not the fleet layer's own horus.fleet.*)");
  record->add_option("--duration", rec.duration_s, "stop after S seconds (default: until Ctrl-C)")
      ->check(CLI::PositiveNumber);
  record->add_option("--split-size", rec.split_mb, "start a new file every N MB");
  record->add_flag("--overwrite", rec.overwrite, "replace the output file(s) when they exist (else refused)");
  record->add_option("--compression", rec.compression, "MCAP chunk compression: zstd (default), lz4 or none");
  record->add_option("--format", rec.format, "mcap (default) or lcm (an LCM event log, as lcm-logger writes)");
  record->add_option("--profile", rec.profile,
                     "horus (default: horus's types) or ros2 (a bag as rosbag2 writes: ROS 2 names, types and CDR; "
                     "docs/ROS2.md)");
  record->add_option("--backend", rec.backend, "network backend of the fleet (default: the configuration's)");
  record->add_flag("--foxglove", rec.foxglove,
                   "also record, beside each topic Foxglove's panels draw (images, clouds, scans, poses, "
                   "transforms), TOPIC/foxglove in Foxglove's own schema");
  record->add_option("--frame", rec.frame, "with --foxglove: the frame of messages that name none (default world)");
  c.record_info = record->add_subcommand("info", "topics, types, counts, duration and size of a recording");
  c.record_info->add_option("file", c.record_file, "an MCAP file or an LCM log")->required();
  c.record_info->add_flag("--json", c.json, "print JSON");
  c.recover = record->add_subcommand("recover", "copy what a killed recorder left into a whole file");
  c.recover->add_option("file", c.record_file, "the MCAP file or LCM log")->required();
  c.recover->add_option("-o,--output", c.recover_out, "the new file (default: FILE.recovered.mcap)");
}

// horus foxglove.
void add_foxglove_command(CLI::App& app, Cli& c) {
  auto& fox = c.fox;
  c.foxglove = app.add_subcommand(
      "foxglove", "serve this host's and the fleet's topics to Foxglove (WebSocket) and a status page, on one port");
  auto* foxglove = c.foxglove;
  foxglove->add_option("--port", fox.port, "TCP port (default 8765; 0: any free one, printed)");
  foxglove->add_option("--address", fox.address,
                       "address to listen on (default 127.0.0.1; 0.0.0.0 serves every interface)");
  foxglove->add_option("--topics", fox.topics, "topic patterns served (default: every topic but horus.fleet.*)");
  foxglove->add_option("--frame", fox.frame, "the frame of converted messages that name none (default world)");
  foxglove->add_flag("--no-publish", fox.no_publish, "refuse clients' messages (clientPublish)");
  foxglove->add_option("--max-clients", fox.max_clients, "connections served at once (default 64)");
  foxglove->add_option("--backend", fox.backend, "network backend of the fleet (default: the configuration's)");
  foxglove->add_option("--duration", fox.duration_s, "stop after S seconds (default: until Ctrl-C)")
      ->check(CLI::PositiveNumber);
  foxglove->add_flag("--ros2", fox.ros2,
                     "also the ROS 2 topics of the DDS domain (any ROS 2 node's), in their ROS 2 schemas (ros2msg)");
}

// horus play.
void add_play_command(CLI::App& app, Cli& c) {
  auto& play_args = c.play_args;
  c.play = app.add_subcommand("play", "publish a recording into horus topics with its timing");
  auto* play = c.play;
  play->add_option("file", play_args.file, "an MCAP file or an LCM log (lcm-logger's too)")->required();
  play->add_option("--rate", play_args.rate, "speed factor (2: twice as fast; 0: as fast as possible)")
      ->check(CLI::Range(0.0, 1e6));
  play->add_option("--start", play_args.start_s, "skip the first S seconds")->check(CLI::Range(0.0, 1e9));
  play->add_flag("--loop", play_args.loop, "start over at the end, until Ctrl-C");
  play->add_option("--topics", play_args.topics, "topic patterns to play (default: all)");
  play->add_option("--remap", play_args.remap, "publish recorded topic OLD into topic NEW (OLD=NEW)");
  play->add_flag("--ros2", play_args.ros2,
                 "publish each topic onto the ROS 2 wire too (its ros2: mapping: the recorded ROS 2 name and type)");
}

// horus bench pong | ping | local.
void add_bench_commands(CLI::App& app, Cli& c) {
  auto& bench_args = c.bench_args;
  auto* bench = app.add_subcommand("bench", "measure latency and throughput between hosts (ping/pong) or on this one (local)");
  bench->require_subcommand(1);
  auto common_bench = [&](CLI::App* s) {
    s->add_option("--topic-prefix", bench_args.prefix, "topics PREFIX.control, PREFIX.ping.TYPE, PREFIX.pong.TYPE (default bench)");
    s->add_option("--backend", bench_args.backend, "inproc, shm or a network backend (default: what HORUS_BACKEND and HORUS_CONFIG choose)");
    s->add_flag("--spin", bench_args.spin, "poll with pause instead of sleeping in recv_for");
    s->add_flag("-q,--quiet", bench_args.quiet, "no progress line");
  };
  auto payload_bench = [&](CLI::App* s) {
    s->add_option("--type", bench_args.type, "a standard message type (Pose2D, CmdVel, Imu, Image, ...; default Pose2D)");
    s->add_option("--size", bench_args.size, "payload bytes: CompressedImage below 64 KiB, Image (the pool) from 64 KiB; with --type, that type's payload");
  };
  auto* bench_pong = c.bench_pong = bench->add_subcommand("pong", "answer pings (run it on the other host)");
  common_bench(bench_pong);
  bench_pong->add_flag("--once", bench_args.once, "exit after one ping's run");
  bench_pong->add_option("--cpu", bench_args.cpu, "pin the echo threads to this CPU");
  auto* bench_ping = c.bench_ping = bench->add_subcommand("ping", "measure round trips to a pong: one-way latency, jitter, losses, throughput");
  common_bench(bench_ping);
  payload_bench(bench_ping);
  bench_ping->add_option("--rate", bench_args.rate, "messages per second (default 1000)");
  bench_ping->add_flag("--flood", bench_args.flood, "send as fast as the window allows");
  bench_ping->add_option("--window", bench_args.window, "messages in flight with --flood (default: half the ring, at most 256)");
  bench_ping->add_option("--duration", bench_args.duration, "seconds measured (default 5)");
  bench_ping->add_option("--count", bench_args.count, "messages measured (instead of --duration)");
  bench_ping->add_option("--warmup", bench_args.warmup, "seconds before measuring; the pong must answer within them (default 2)");
  bench_ping->add_option("--timeout", bench_args.timeout, "an echo later than this many seconds counts as lost (default 1)");
  bench_ping->add_flag("--remote", bench_args.remote, "the pong must be on another host (fail at once if the configuration keeps the topics here)");
  bench_ping->add_flag("--clocks-synced", bench_args.clocks_synced, "the hosts' clocks agree (PTP): one-way by clock uses them as they are, not the fleet's measured offset");
  bench_ping->add_option("--json", bench_args.json, "write the summary as JSON to FILE ('-': stdout)");
  bench_ping->add_option("--csv", bench_args.csv, "append the summary as a CSV row to FILE (a header first in a new file; '-': stdout)");
  bench_ping->add_option("--plot", bench_args.plot, "draw the latency histogram and CDF into FILE.png (gnuplot)");
  auto* bench_local = c.bench_local = bench->add_subcommand("local", "in-process and cross-process latency and throughput beside this machine's true floor");
  payload_bench(bench_local);
  bench_local->add_option("--duration", bench_args.duration, "seconds per path (default 1)");
  bench_local->add_option("--window", bench_args.window, "messages in flight in the flood rows (default: half the ring)");
  bench_local->add_option("--json", bench_args.json, "write the table as JSON to FILE ('-': stdout)");
}

// The commands that read neither the environment nor the segments; nothing when another was given.
std::optional<int> run_offline_command(Cli& c) {
  if (*c.record_info) return horus::tools::cmd_record_info(c.record_file, c.json);
  if (*c.recover) return horus::tools::cmd_record_recover(c.record_file, c.recover_out);
  if (*c.check) return horus::tools::cmd_config_check(c.config_file);
  if (*c.idl) return horus::tools::cmd_idl_ros2(c.idl_ros2_dir, c.idl_package);
  if (*c.explain) return horus::tools::cmd_config_explain(c.name, c.config_file);
  if (*c.settings) {
    fmt::print("{}", horus::settings_table());
    return 0;
  }
  return std::nullopt;
}

// The commands that read this host's segments, in the namespace `ns`.
int run_host_command(Cli& c, const std::string& ns) {
  if (*c.clean) {
    const auto removed = horus::discovery::clean(ns);
    for (const auto& t : removed) fmt::print("removed stale topic {} (/dev/shm/horus.{}.{})\n", t, ns, t);
    fmt::print("{} stale segment{} removed from namespace '{}'\n", removed.size(), removed.size() == 1 ? "" : "s", ns);
    return 0;
  }
  if (*c.record) {
    if (c.rec.output.empty()) {
      fmt::print(stderr, "horus record: name the file to write with -o FILE.mcap\n");
      return 2;
    }
    c.rec.ns = ns;
    return horus::tools::cmd_record(c.rec, g_stop);
  }
  if (*c.foxglove) {
    c.fox.ns = ns;
    return horus::tools::cmd_foxglove(c.fox, g_stop);
  }
  if (*c.list && c.ros2) return horus::tools::cmd_list_ros2(c.json, c.lookup, g_stop);
  if (*c.list) return horus::tools::cmd_list(ns, c.json, c.verbose, c.lookup, c.local_only, c.all, g_stop);
  if (*c.info) return horus::tools::cmd_info(ns, c.name, c.lookup, g_stop);
  if (*c.echo) return horus::tools::cmd_echo(ns, c.name, c.lookup, c.json, c.count, c.timeout_s, g_stop);
  if (*c.hz) return horus::tools::cmd_hz(ns, c.name, c.lookup, c.duration_s, c.window_s, g_stop);
  if (*c.bw) return horus::tools::cmd_bw(ns, c.name, c.lookup, c.duration_s, c.window_s, g_stop);
  if (*c.pub) return horus::tools::cmd_pub(ns, c.name, c.type, c.message, c.lookup, c.rate_hz, c.count, g_stop);
  return 2;
}

// The parsed command line's command, run.
int run_command(Cli& c) {
  c.lookup.rate_window = std::chrono::milliseconds(static_cast<long long>(c.rate_window_s * 1000));
  // echo, hz and bw wait for a topic that does not exist yet (here or on another host) when asked
  // to: --wait, else echo's --timeout.
  for (const auto* s : {c.echo, c.hz, c.bw})
    if (*s && s->count("--wait") > 0) c.lookup.appear_wait = std::chrono::milliseconds(c.lookup.wait_ms);
  if (*c.echo && c.echo->count("--wait") == 0 && c.timeout_s > 0)
    c.lookup.appear_wait = std::chrono::milliseconds(static_cast<long long>(c.timeout_s * 1000));
  if (auto rc = run_offline_command(c)) return *rc;
  // The environment as programs read it: a bad HORUS_BACKEND or HORUS_CONFIG is an error here too
  // (a CLI that ignored it would show another fleet than the programs it watches see).
  if (auto b = horus::backend_from_environment(); !b) {
    fmt::print(stderr, "horus: {}\n", b.error().message());
    return 2;
  }
  if (auto e = horus::config_from_environment(); !e) {
    fmt::print(stderr, "horus: {}\n", e.error().message());
    return 2;
  }
  ::signal(SIGINT, on_signal);
  ::signal(SIGTERM, on_signal);
  if (*c.fleet)
    return horus::tools::cmd_fleet(c.lookup.transport, c.json, c.once, c.fleet_wait_ms, c.duration_s, g_stop);
  if (*c.play) return horus::tools::cmd_play(c.play_args, g_stop);
  if (*c.bench_pong) return horus::tools::cmd_bench_pong(c.bench_args, g_stop);
  if (*c.bench_ping) return horus::tools::cmd_bench_ping(c.bench_args, g_stop);
  if (*c.bench_local) {
    if (c.bench_local->count("--duration") == 0) c.bench_args.duration = 1;
    return horus::tools::cmd_bench_local(c.bench_args, g_stop);
  }

  auto ns = horus::shm::shm_namespace();
  if (!ns) {
    fmt::print(stderr, "horus: {}\n", ns.error().message);
    return 2;
  }
  return run_host_command(c, *ns);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"horus: topics on this host and the fleet"};
  app.set_version_flag("--version", "horus " + std::string(horus::version()), "print the version of this build and exit");
  app.require_subcommand(1);
  Cli cli;
  add_topic_commands(app, cli);
  add_fleet_config_commands(app, cli);
  add_record_commands(app, cli);
  add_foxglove_command(app, cli);
  add_play_command(app, cli);
  add_bench_commands(app, cli);
  add_idl_command(app, cli);
  const auto security = horus::tools::add_security_commands(app);
  CLI11_PARSE(app, argc, argv);
  if (const int rc = horus::tools::run_security(*security); rc >= 0) return rc;
  return run_command(cli);
}

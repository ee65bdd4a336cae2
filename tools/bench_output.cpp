// horus bench ping's outputs (bench_ping.cpp runs the ping): the human summary, --json, --csv
// and --plot.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "bench_cmd_internal.hpp"
#include "bench_stats.hpp"

extern char** environ;

namespace horus::tools::bench_detail {

double msgs_per_s(const PingResult& r) {
  return r.measured_s > 0 ? static_cast<double>(r.received) / r.measured_s : 0;
}

bool write_text(const std::string& file, const std::string& text, bool append, std::string& error) {
  if (file == "-") {
    fmt::print("{}", text);
    return true;
  }
  std::ofstream f(file, append ? std::ios::app : std::ios::trunc);
  if (f) f << text;
  if (!f) error = fmt::format("cannot write {}: {}", file, std::strerror(errno));
  return static_cast<bool>(f);
}

namespace {

double mb_per_s(const PingResult& r) {
  return r.measured_s > 0 ? static_cast<double>(r.received) * static_cast<double>(r.message_bytes) / r.measured_s / 1e6 : 0;
}

nlohmann::json latency_json(const LatencyHistogram& h) {
  return {{"min", h.min()},
          {"p50", h.quantile(0.5)},
          {"p90", h.quantile(0.9)},
          {"p99", h.quantile(0.99)},
          {"p99_9", h.quantile(0.999)},
          {"max", h.max()},
          {"mean", h.mean()},
          {"stddev", h.stddev()},
          {"jitter", h.jitter()}};
}

nlohmann::json result_json(const BenchArgs& a, const PingResult& r) {
  return {{"tool", "horus bench ping"},
          {"type", r.type},
          {"payload", r.payload},
          {"message_bytes", r.message_bytes},
          {"tag", r.tag},
          {"topics", {{"control", r.control_topic}, {"ping", r.ping_topic}, {"pong", r.pong_topic}}},
          {"backend", r.backend},
          {"where", r.where},
          {"host", r.host},
          {"pong_host", r.pong_host},
          {"pong_pid", r.pong_pid},
          {"mode", a.flood ? "flood" : "rate"},
          {"rate_hz", a.flood ? 0.0 : a.rate},
          {"window", r.window},
          {"spin", a.spin},
          {"warmup_s", r.warmup_s},
          {"duration_s", r.measured_s},
          {"start_unix_ns", r.start_unix_ns},
          {"sent", r.sent},
          {"received", r.received},
          {"lost", r.lost},
          {"late", r.late},
          {"reordered", r.reordered},
          {"duplicates", r.duplicates},
          {"refused", r.refused},
          {"dropped", r.dropped},
          {"one_way_ns", latency_json(r.one_way)},
          {"clock",
           {{"source", r.clock_source},
            {"why", r.clock_why},
            {"offset_ns", r.clock_offset_ns},
            {"uncertainty_ns", r.clock_uncertainty_ns}}},
          {"by_clock",
           {{"samples", r.forward.count()},
            {"below_zero", r.clock_below_zero},
            {"forward_ns", latency_json(r.forward)},
            {"return_ns", latency_json(r.back)}}},
          {"throughput", {{"msgs_per_s", msgs_per_s(r)}, {"mb_per_s", mb_per_s(r)}}}};
}

// The JSON's scalars, flattened ("one_way_ns.p50"), in a stable order.
void flatten(const nlohmann::json& j, const std::string& prefix, std::vector<std::pair<std::string, std::string>>& out) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (it->is_object()) flatten(*it, key, out);
    else out.emplace_back(key, it->is_string() ? it->get<std::string>() : it->dump());
  }
}

std::string csv_field(const std::string& v) {
  if (v.find_first_of(",\"\n") == std::string::npos) return v;
  std::string q = "\"";
  for (char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// Appends a row to FILE (a header first when the file is new or empty).
bool write_csv(const std::string& file, const nlohmann::json& j, std::string& error) {
  std::vector<std::pair<std::string, std::string>> kv;
  flatten(j, "", kv);
  std::string header, row;
  for (const auto& [k, v] : kv) {
    header += (header.empty() ? "" : ",") + k;
    row += (row.empty() ? "" : ",") + csv_field(v);
  }
  std::error_code ec;
  const bool fresh = file == "-" || !std::filesystem::exists(file, ec) || std::filesystem::file_size(file, ec) == 0;
  return write_text(file, (fresh ? header + "\n" : std::string()) + row + "\n", true, error);
}

std::string find_in_path(const std::string& exe) {
  const char* path = std::getenv("PATH");
  std::string p = path ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= p.size()) {
    const auto end = p.find(':', start);
    const std::string dir = p.substr(start, end == std::string::npos ? std::string::npos : end - start);
    const std::string full = (dir.empty() ? "." : dir) + "/" + exe;
    if (::access(full.c_str(), X_OK) == 0) return full;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return {};
}

// The one-way latency histogram (top) and CDF (bottom) as a PNG, drawn by gnuplot.
bool write_plot(const std::string& file, const PingResult& r, std::string& error) {
  const std::string gnuplot = find_in_path("gnuplot");
  if (gnuplot.empty()) {
    error = "--plot needs gnuplot, which is not on PATH (Debian: apt-get install gnuplot-nox)";
    return false;
  }
  if (r.one_way.count() == 0) {
    error = "--plot: no samples to draw";
    return false;
  }
  std::string script = (std::filesystem::temp_directory_path() / "horus_bench_XXXXXX.gp").string();
  const int fd = ::mkstemps(script.data(), 3);
  if (fd < 0) {
    error = fmt::format("--plot: cannot create a temporary file for gnuplot's script: {}", std::strerror(errno));
    return false;
  }
  ::close(fd);
  std::string text = fmt::format(
      "set terminal pngcairo size 1000,800 font 'sans,10'\nset output '{}'\nset multiplot layout 2,1 title "
      "\"horus bench ping: {} over {}\\n{} -> {}, {} samples\"\nset logscale x\nset grid\nset xlabel 'one-way "
      "latency (us)'\n",
      file, r.type, r.where, r.host, r.pong_host, r.one_way.count());
  text += "$hist << EOD\n";
  {  // 20 bins per decade (the x axis is logarithmic): messages per bin
    std::map<int, std::uint64_t> bins;
    for (const auto& b : r.one_way.buckets())
      bins[static_cast<int>(std::floor(20.0 * std::log10(std::max(1.0, static_cast<double>(b.lo)))))] += b.count;
    for (const auto& [bin, n] : bins)
      text += fmt::format("{} {} {}\n", std::pow(10.0, bin / 20.0) / 1e3, std::pow(10.0, (bin + 1) / 20.0) / 1e3, n);
  }
  text += "EOD\n$cdf << EOD\n";
  std::uint64_t seen = 0;
  for (const auto& b : r.one_way.buckets()) {
    seen += b.count;
    text += fmt::format("{} {}\n", static_cast<double>(b.hi) / 1e3, static_cast<double>(seen) / static_cast<double>(r.one_way.count()));
  }
  text += "EOD\n";
  const double p50 = static_cast<double>(r.one_way.quantile(0.5)) / 1e3, p99 = static_cast<double>(r.one_way.quantile(0.99)) / 1e3;
  text += fmt::format(
      "set ylabel 'messages'\nset style fill solid 0.5\nplot $hist using (sqrt($1*$2)):3:1:2:(0):3 with "
      "boxxyerror title 'histogram (20 bins per decade)'\nset ylabel 'fraction at or below'\nset yrange [0:1.02]\nset arrow 1 from {0},0 to {0},1.02 "
      "nohead dt 2\nset arrow 2 from {1},0 to {1},1.02 nohead dt 3\nplot $cdf using 1:2 with steps lw 2 title "
      "'CDF (p50 {2}, p99 {3})'\nunset multiplot\n",
      p50, p99, format_ns(p50 * 1e3), format_ns(p99 * 1e3));
  if (!write_text(script, text, false, error)) return false;
  std::vector<std::string> args = {gnuplot, script};
  std::vector<char*> argv;
  for (auto& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  pid_t child = -1;
  int status = 0;
  if (::posix_spawn(&child, gnuplot.c_str(), nullptr, nullptr, argv.data(), environ) != 0 ||
      ::waitpid(child, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    error = fmt::format("gnuplot failed to draw {} (script kept: {})", file, script);
    return false;
  }
  std::filesystem::remove(script);
  return true;
}

}  // namespace

// The human summary, on `out` (stderr when the JSON or CSV goes to stdout).
void print_result(std::FILE* out, const BenchArgs& a, const PingResult& r) {
  const auto& h = r.one_way;
  fmt::print(out, "horus bench ping: {}, tag in {}\n", r.payload, r.tag);
  fmt::print(out, "  topics      {} -> {} ({})\n", r.ping_topic, r.pong_topic, r.where);
  fmt::print(out, "  hosts       {} (pid {}) -> {} (pid {})\n", r.host, ::getpid(), r.pong_host, r.pong_pid);
  if (a.flood) fmt::print(out, "  traffic     flood, {} in flight, {:.3f} s after {:.2f} s warm-up\n", r.window, r.measured_s, r.warmup_s);
  else fmt::print(out, "  traffic     {} Hz, {:.3f} s after {:.2f} s warm-up\n", a.rate, r.measured_s, r.warmup_s);
  fmt::print(out, "one-way latency (round trip / 2), {} samples{}:\n", h.count(), a.spin ? ", spinning" : "");
  auto f = [](std::uint64_t v) { return format_ns(static_cast<double>(v)); };
  fmt::print(out, "  min {}   p50 {}   p90 {}   p99 {}   p99.9 {}   max {}\n", f(h.min()), f(h.quantile(0.5)),
             f(h.quantile(0.9)), f(h.quantile(0.99)), f(h.quantile(0.999)), f(h.max()));
  fmt::print(out, "  mean {}   stddev {}   jitter {} (mean change between consecutive messages)\n", format_ns(h.mean()),
             format_ns(h.stddev()), format_ns(h.jitter()));
  if (r.forward.count() > 0) {
    const std::string from =
        r.clock_source == "fleet"
            ? fmt::format("{}'s clock - ours: {:+.6f} s +- {}, from the fleet's heartbeats", r.pong_host,
                          static_cast<double>(r.clock_offset_ns) / 1e9, format_ns(static_cast<double>(r.clock_uncertainty_ns)))
        : r.clock_source == "synced" ? std::string("the clocks as they are (--clocks-synced)")
                                     : std::string("one clock: the pong runs on this host");
    fmt::print(out, "one-way latency by clock ({}), {} samples{}:\n", from, r.forward.count(),
               r.clock_below_zero ? fmt::format(", {} below 0 counted as 0 (the offset is off by more)", r.clock_below_zero)
                                  : std::string());
    for (const auto* way : {&r.forward, &r.back})
      fmt::print(out, "  {}  min {}   p50 {}   p99 {}   p99.9 {}   max {}\n", way == &r.forward ? "ping -> pong" : "pong -> ping",
                 f(way->min()), f(way->quantile(0.5)), f(way->quantile(0.99)), f(way->quantile(0.999)), f(way->max()));
  } else if (!r.clock_why.empty()) {
    fmt::print(out, "one-way latency by clock: not measured: {}\n", r.clock_why);
  }
  fmt::print(out, "messages: sent {}, received {}, lost {} ({:.3f} %{}), reordered {}, duplicates {}{}\n", r.sent,
             r.received, r.lost, r.sent ? 100.0 * static_cast<double>(r.lost) / static_cast<double>(r.sent) : 0.0,
             r.late ? fmt::format(", {} of them came back after --timeout", r.late) : std::string(), r.reordered,
             r.duplicates, r.refused ? fmt::format(", refused by the topic {}", r.refused) : std::string());
  fmt::print(out, "throughput: {:.1f} msg/s, {:.3f} MB/s each way ({} bytes per message)\n", msgs_per_s(r), mb_per_s(r),
             r.message_bytes);
  if (r.lost == 0) return;
  // Where losses come from, per backend.
  fmt::print(out, "lost: {} message(s) did not come back within --timeout {} s; this side's {} counted {} dropped on "
                  "the way back over the whole run, warm-up included (dropped_count; the pong prints its own)\n",
             r.lost, a.timeout, r.pong_topic, r.dropped);
  if (r.backend == "lcm")
    fmt::print(out, "  LCM is best effort over UDP and a {}-byte message is about {} datagram(s): losses are usually a full "
                    "receive buffer;\n  add recv_buf_size=BYTES to the LCM URL on both hosts (the kernel caps it at "
                    "net.core.rmem_max), or lower --rate\n",
               r.message_bytes, (r.message_bytes + 65000) / 65000);
  else if (r.backend == "cyclonedds" || r.backend == "fastdds")
    fmt::print(out, "  a best-effort topic loses what the network drops; a reliable one only what its history "
                    "(capacity) overwrites: see `horus config explain {}`\n",
               r.ping_topic);
  else
    fmt::print(out, "  on one host a message is lost only when a ring overwrites it: a slow pong, or --window above "
                    "the ring's capacity\n");
}

bool write_outputs(const BenchArgs& a, const PingResult& r) {
  std::string error;
  bool ok = true;
  const auto j = result_json(a, r);
  if (!a.json.empty() && !write_text(a.json, j.dump(2) + "\n", false, error)) ok = false;
  if (ok && !a.csv.empty() && !write_csv(a.csv, j, error)) ok = false;
  if (ok && !a.plot.empty() && !write_plot(a.plot, r, error)) ok = false;
  if (!ok) fmt::print(stderr, "horus bench ping: {}\n", error);
  return ok;
}

}  // namespace horus::tools::bench_detail

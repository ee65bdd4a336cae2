// The library's log lines while a LogCapture lives (a sink added to horus's logger), as
// "LEVEL TEXT": what tests of logged behaviour read (verbose topics).
#pragma once

#include <spdlog/logger.h>
#include <spdlog/sinks/ostream_sink.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "horus/log.hpp"

namespace horus_test {

class LogCapture {
 public:
  LogCapture() : sink_(std::make_shared<spdlog::sinks::ostream_sink_mt>(out_)) {
    sink_->set_pattern("%l %v");
    horus::detail::log().sinks().push_back(sink_);
  }
  ~LogCapture() {
    auto& sinks = horus::detail::log().sinks();
    sinks.erase(std::remove(sinks.begin(), sinks.end(), sink_), sinks.end());
  }
  LogCapture(const LogCapture&) = delete;
  LogCapture& operator=(const LogCapture&) = delete;

  // The lines that contain `part` (every line when empty).
  std::vector<std::string> lines(const std::string& part = "") const {
    std::vector<std::string> found;
    std::istringstream in(text());
    for (std::string line; std::getline(in, line);)
      if (line.find(part) != std::string::npos) found.push_back(line);
    return found;
  }
  // Read it once the threads that log are done (joined): the sink's lock is its own.
  std::string text() const { return out_.str(); }

 private:
  std::ostringstream out_;
  std::shared_ptr<spdlog::sinks::ostream_sink_mt> sink_;
};

// A verbose topic's traffic lines (horus/detail/traffic_log.hpp) in a capture: the lines of
// sends, the lines held back that they report, and what the topic's close reported.
struct TrafficCount {
  std::uint64_t sends = 0;
  std::uint64_t held_in_lines = 0;
  std::uint64_t held_at_close = 0;
  std::uint64_t held_in_all = 0;  // the close's "(N in all)"
  std::uint64_t closes = 0;       // close reports (one when anything was held back after the last line)
};
inline TrafficCount count_traffic(const LogCapture& log, const std::string& topic) {
  TrafficCount c;
  const std::regex in_line(R"((\d+) lines? held back before this one by log_rate_hz)");
  const std::regex at_close(R"(': (\d+) lines? of its traffic held back after the last one.*\((\d+) in all\))");
  for (const std::string& l : log.lines("topic '" + topic + "'")) {
    std::smatch m;
    if (l.find("' send #") != std::string::npos) {
      ++c.sends;
      if (std::regex_search(l, m, in_line)) c.held_in_lines += std::stoull(m[1]);
    } else if (std::regex_search(l, m, at_close)) {
      ++c.closes;
      c.held_at_close += std::stoull(m[1]);
      c.held_in_all = std::stoull(m[2]);
    }
  }
  return c;
}

}  // namespace horus_test

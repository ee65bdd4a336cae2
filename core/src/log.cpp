#include "horus/log.hpp"

#include "horus/detail/process.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <array>
#include <string>
#include <string_view>

namespace horus::detail {

namespace {
// HORUS_LOG_LEVEL's values, in the order of spdlog's levels.
constexpr std::array<std::string_view, 7> kLevelNames{"trace", "debug", "info", "warn", "error", "critical", "off"};

std::shared_ptr<spdlog::logger> make_logger() {
  auto logger = spdlog::get("horus");
  if (!logger) logger = spdlog::stderr_color_mt("horus");
  // fork() while another thread writes a line would leave the console's mutex locked in the
  // child forever (a forked child that logs would hang): fork waits for the line instead.
  horus::detail::Process::get().at_fork({[] { spdlog::details::console_mutex::mutex().lock(); },
                                  [] { spdlog::details::console_mutex::mutex().unlock(); },
                                  [] { spdlog::details::console_mutex::mutex().unlock(); }});
  logger->set_level(spdlog::level::info);
  const std::string env = horus::detail::Process::get().environment()->log_level;
  if (!env.empty()) {
    bool ok = false;
    for (std::size_t i = 0; i < kLevelNames.size(); ++i) {
      if (kLevelNames[i] == env) {
        logger->set_level(static_cast<spdlog::level::level_enum>(i));
        ok = true;
      }
    }
    if (!ok)
      logger->error("HORUS_LOG_LEVEL='{}' is not a log level; expected one of trace, debug, info, warn, error, "
                    "critical, off (using info)",
                    env);
  }
  return logger;
}
}  // namespace

spdlog::logger& log() {
  static const std::shared_ptr<spdlog::logger> logger = make_logger();
  return *logger;
}

std::string hidden_lines(spdlog::level::level_enum level) {
  if (log().should_log(level)) return {};
  const auto name = [](spdlog::level::level_enum l) { return kLevelNames.at(static_cast<std::size_t>(l)); };
  return "the library's log level (" + std::string(name(log().level())) + ", HORUS_LOG_LEVEL) hides " +
         std::string(name(level)) + " lines: set HORUS_LOG_LEVEL=" + std::string(name(level)) + " to see them";
}

}  // namespace horus::detail

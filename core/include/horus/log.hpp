// The library's logger ("horus"), level from HORUS_LOG_LEVEL. Private to horus.
#pragma once

#include <spdlog/logger.h>

#include <string>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::detail {
spdlog::logger& log();
/// Empty when the library's logger shows lines at `level`; else why not and what to set:
/// "the library's log level (info, HORUS_LOG_LEVEL) hides debug lines: set HORUS_LOG_LEVEL=debug
/// to see them" (a verbose topic at its opening, `horus config explain`).
std::string hidden_lines(spdlog::level::level_enum level);
}

HORUS_API_END

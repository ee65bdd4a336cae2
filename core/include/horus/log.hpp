// The library's logger ("horus"), level from HORUS_LOG_LEVEL. Private to horus.
#pragma once

#include <spdlog/logger.h>

namespace horus::detail {
spdlog::logger& log();
}

// Everything a horus user needs: Topic<T>, errors, metrics and the standard messages, with their
// fmt printing (horus/format.hpp: fmt::format("{}", msg), horus::to_string, horus::log_summary).
#pragma once

#include "horus/config.hpp"
#include "horus/error.hpp"
#include "horus/format.hpp"
#include "horus/messages.hpp"
#include "horus/metrics.hpp"
#include "horus/executor.hpp"
#include "horus/topic.hpp"
#include "horus/version.hpp"
#include "horus/waitset.hpp"

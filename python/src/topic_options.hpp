// Keyword arguments of horus.Topic and Executor.subscribe as TopicOptions: capacity, slot_size,
// scope, backend, reliability, durability, deadline, lifespan, max_rate_hz, max_bandwidth,
// priority, verbose, log_level, log_rate_hz. A wrong name or value raises, naming it and the
// valid ones.
#pragma once

#include <pybind11/pybind11.h>

#include "horus/backend.hpp"

namespace horus::python {

TopicOptions topic_options(const pybind11::kwargs& kw);

}  // namespace horus::python

// Keyword arguments of horus.Topic and Executor.subscribe as TopicOptions: one per setting of
// HORUS_TOPIC_SETTINGS (horus/topic_options.hpp), named as its member, and scope=. Named values
// are strs in the file's form ('reliable', 'debug'), durations seconds. A wrong name or value
// raises, naming it and the valid ones.
#pragma once

#include <pybind11/pybind11.h>

#include "horus/topic_options.hpp"

namespace horus::python {

TopicOptions topic_options(const pybind11::kwargs& kw);

}  // namespace horus::python

// horus config check / explain (config_cmd.cpp).
#pragma once

#include <string>

namespace horus::tools {

// Validates a configuration file: 0, or 1 with the error (file, line, key, what is valid).
int cmd_config_check(const std::string& file);
// The rule, scope, backend, capacity and QoS `topic` gets, each with where it came from; the
// file is `file`, or HORUS_CONFIG's when empty.
int cmd_config_explain(const std::string& topic, const std::string& file);

}  // namespace horus::tools

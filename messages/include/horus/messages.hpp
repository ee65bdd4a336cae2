// All standard horus messages (without Eigen interop: include horus/msg/eigen.hpp
// for that, and horus/json.hpp for JSON).
#pragma once

#include "horus/msg/control.hpp"
#include "horus/msg/diagnostics.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/msg/sensor.hpp"

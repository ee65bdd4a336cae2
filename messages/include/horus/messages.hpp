// All standard horus messages (without Eigen interop: include horus/msg/eigen.hpp
// for that, and horus/json.hpp for JSON).
#pragma once

#include "horus/msg/audio.hpp"
#include "horus/msg/control.hpp"
#include "horus/msg/detection.hpp"
#include "horus/msg/diagnostics.hpp"
#include "horus/msg/force.hpp"
#include "horus/msg/generic.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/msg/image.hpp"
#include "horus/msg/input.hpp"
#include "horus/msg/navigation.hpp"
#include "horus/msg/perception.hpp"
#include "horus/msg/sensor.hpp"
#include "horus/msg/tensor.hpp"
#include "horus/msg/time.hpp"
#include "horus/msg/tracking.hpp"
#include "horus/msg/vision.hpp"

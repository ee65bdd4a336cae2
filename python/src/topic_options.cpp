// topic_options.hpp
#include "topic_options.hpp"

#include <fmt/format.h>

#include <string>

#include "fields.hpp"
#include "horus/config.hpp"
#include "typed.hpp"

namespace horus::python {

namespace {

std::string text(pybind11::handle v, const char* key, const char* valid) {
  if (!pybind11::isinstance<pybind11::str>(v)) type_error(key, valid, v);
  return v.cast<std::string>();
}

[[noreturn]] void bad(const char* key, const std::string& got, const char* valid) {
  throw pybind11::value_error(fmt::format("{}: '{}' is not valid; expected {}", key, got, valid));
}

// scope='fleet' without a backend: HORUS_BACKEND when it names a network backend, else the
// configuration file's network.backend.
Backend fleet_backend() {
  auto env = backend_from_environment();
  if (!env) raise(env.error());
  if (is_network(*env)) return *env;
  auto file = config_from_environment();
  if (!file) raise(file.error());
  if (*file != nullptr && (*file)->network().backend) {
    auto b = backend_from(*(*file)->network().backend);
    if (!b) raise(b.error());
    return *b;
  }
  raise(Error(Errc::Config, "scope 'fleet' needs a network backend: pass backend='cyclonedds' (fastdds, lcm), or set "
                            "HORUS_BACKEND or the configuration file's network.backend"));
}

}  // namespace

TopicOptions topic_options(const pybind11::kwargs& kw) {
  TopicOptions o;
  std::optional<std::string> scope;
  for (const auto& [k, v] : kw) {
    const auto key = k.cast<std::string>();
    if (v.is_none()) continue;
    if (key == "capacity") {
      o.capacity = number_from<std::uint32_t>(v, "capacity");
    } else if (key == "slot_size") {
      o.slot_size = number_from<std::size_t>(v, "slot_size");
    } else if (key == "scope") {
      scope = text(v, "scope", "'process', 'host' or 'fleet'");
    } else if (key == "backend") {
      auto b = backend_from(text(v, "backend", "a str"));
      if (!b) raise(b.error());
      o.backend = *b;
    } else if (key == "reliability") {
      const auto s = text(v, "reliability", "'reliable' or 'best_effort'");
      if (s == "reliable") o.reliability = net::Reliability::Reliable;
      else if (s == "best_effort") o.reliability = net::Reliability::BestEffort;
      else bad("reliability", s, "'reliable' or 'best_effort'");
    } else if (key == "durability") {
      const auto s = text(v, "durability", "'volatile' or 'transient_local'");
      if (s == "volatile") o.durability = net::Durability::Volatile;
      else if (s == "transient_local") o.durability = net::Durability::TransientLocal;
      else bad("durability", s, "'volatile' or 'transient_local'");
    } else if (key == "deadline") {
      o.deadline = seconds(v, "deadline");
    } else if (key == "lifespan") {
      o.lifespan = seconds(v, "lifespan");
    } else if (key == "max_rate_hz") {
      o.max_rate_hz = number_from<double>(v, "max_rate_hz");
    } else if (key == "max_bandwidth") {
      o.max_bandwidth = number_from<std::uint64_t>(v, "max_bandwidth");
    } else if (key == "priority") {
      const auto s = text(v, "priority", "'low', 'normal' or 'high'");
      if (s == "low") o.priority = Priority::Low;
      else if (s == "normal") o.priority = Priority::Normal;
      else if (s == "high") o.priority = Priority::High;
      else bad("priority", s, "'low', 'normal' or 'high'");
    } else if (key == "verbose") {
      if (!pybind11::isinstance<pybind11::bool_>(v)) type_error("verbose", "a bool", v);
      o.verbose = v.cast<bool>();
    } else if (key == "log_level") {
      const auto s = text(v, "log_level", "'trace', 'debug', 'info', 'warn' or 'error'");
      const auto level = log_level_from(s);
      if (!level) bad("log_level", s, "'trace', 'debug', 'info', 'warn' or 'error'");
      o.log_level = *level;
    } else if (key == "log_rate_hz") {
      o.log_rate_hz = number_from<double>(v, "log_rate_hz");
    } else {
      throw pybind11::type_error(fmt::format(
          "unknown option '{}'; the options are capacity, slot_size, scope, backend, reliability, durability, deadline, "
          "lifespan, max_rate_hz, max_bandwidth, priority, verbose, log_level, log_rate_hz",
          key));
    }
  }
  if (scope) {
    auto clash = [&](const char* fits) {
      throw pybind11::value_error(fmt::format("scope '{}' does not go with backend '{}': {}", *scope,
                                              to_string(*o.backend), fits));
    };
    if (*scope == "process") {
      if (o.backend && *o.backend != Backend::InProcess) clash("a process topic's backend is inproc");
      o.backend = Backend::InProcess;
    } else if (*scope == "host") {
      if (o.backend && *o.backend != Backend::SharedMemory) clash("a host topic's backend is shm");
      o.backend = Backend::SharedMemory;
    } else if (*scope == "fleet") {
      if (!o.backend) o.backend = fleet_backend();
      else if (!is_network(*o.backend)) clash("a fleet topic's backend is a network one (cyclonedds, fastdds, lcm)");
    } else {
      bad("scope", *scope, "'process', 'host' or 'fleet'");
    }
  }
  return o;
}

}  // namespace horus::python

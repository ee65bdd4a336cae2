// topic_options.hpp
#include "topic_options.hpp"

#include <fmt/format.h>

#include <string>
#include <type_traits>
#include <variant>

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
  auto name = fleet_transport();
  if (!name) raise(name.error());
  if (!name->empty()) {
    auto b = backend_from(*name);
    if (!b) raise(b.error());
    return *b;
  }
  raise(Error(Errc::Config, "scope 'fleet' needs a network backend: pass backend='cyclonedds' (fastdds, lcm), or set "
                            "HORUS_BACKEND or the configuration file's network.backend"));
}

Backend value_from(setting::BackendName, pybind11::handle v, const char* key) {
  auto b = backend_from(text(v, key, "a str"));
  if (!b) raise(b.error());
  return *b;
}

// A value of each other kind of setting from Python: a str in the file's form for the named kinds,
// a number for numbers, seconds (a float) for durations, a bool for booleans.
template <class K>
typename K::type value_from(K of, pybind11::handle v, const char* key) {
  using T = typename K::type;
  if constexpr (std::is_same_v<K, setting::Duration>) {
    return seconds(v, key);
  } else if constexpr (std::is_same_v<K, setting::Boolean>) {
    if (!pybind11::isinstance<pybind11::bool_>(v)) type_error(key, "a bool", v);
    return v.cast<bool>();
  } else if constexpr (std::is_arithmetic_v<T>) {
    return number_from<T>(v, key);
  } else if constexpr (std::is_same_v<K, setting::Ros2>) {
    // ros2=True, or a dict of str (name, type, frame_id, child_frame_id, qos), or the file's text.
    std::string form;
    if (pybind11::isinstance<pybind11::bool_>(v)) {
      form = v.cast<bool>() ? "true" : "false";
    } else if (pybind11::isinstance<pybind11::dict>(v)) {
      for (const auto& item : v.cast<pybind11::dict>()) {
        const pybind11::handle k = item.first, x = item.second;
        if (!pybind11::isinstance<pybind11::str>(k) || !pybind11::isinstance<pybind11::str>(x))
          type_error(key, "True, False or a dict of str (name, type, frame_id, child_frame_id, qos)", v);
        form += (form.empty() ? "" : ", ") + pybind11::cast<std::string>(k) + ": \"" + pybind11::cast<std::string>(x) + "\"";
      }
      form = "{" + form + "}";
    } else {
      form = text(v, key, "True, False or a dict");
    }
    auto value = setting::parse(of, form);
    if (const auto* why = std::get_if<std::string>(&value))
      throw pybind11::value_error(fmt::format("{}: {}", key, *why));
    return std::get<T>(value);
  } else {
    const std::string expected = setting::expected(of);
    const auto s = text(v, key, expected.c_str());
    auto value = setting::parse(of, s);
    if (std::holds_alternative<std::string>(value)) bad(key, s, expected.c_str());
    return std::get<T>(value);
  }
}

// The keywords: the settings of the table that code chooses (the backend also by scope=).
std::string keyword_list() {
  std::string out;
#define HORUS_KEYWORD(member, Kind, Rule, key, example, dflt, unset, doc) \
  if (std::string_view(#member) != "backend") out += #member ", ";
  HORUS_TOPIC_SETTINGS(HORUS_KEYWORD)
#undef HORUS_KEYWORD
  return out + "scope, backend";
}

}  // namespace

TopicOptions topic_options(const pybind11::kwargs& kw) {
  TopicOptions o;
  std::optional<std::string> scope;
  for (const auto& [k, v] : kw) {
    const auto key = k.cast<std::string>();
    if (v.is_none()) continue;
    if (key == "scope") {
      scope = text(v, "scope", "'process', 'host' or 'fleet'");
      continue;
    }
#define HORUS_KEYWORD_VALUE(member, Kind, Rule, key_, example, dflt, unset, doc) \
  if (key == #member) {                                                         \
    o.member = value_from(setting::Kind{}, v, #member);                         \
    continue;                                                                   \
  }
    HORUS_TOPIC_SETTINGS(HORUS_KEYWORD_VALUE)
#undef HORUS_KEYWORD_VALUE
    throw pybind11::type_error(fmt::format("unknown option '{}'; the options are {}", key, keyword_list()));
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

// JSON rendering of every reflected message (nlohmann::json).
//
//   horus::to_json(pose)          -> {"x":1.0,"y":2.0,"theta":0.5,"timestamp_ns":0}
//   horus::from_json<Pose2D>(j)   -> Pose2D, throws horus::JsonError naming the field
//
// Char arrays are JSON strings, other arrays and sequences JSON arrays, enums
// declared with HORUS_REFLECT_ENUM their name (else their number), nested messages objects. Non-finite floats render as null (JSON
// has no NaN) and read back as NaN. from_json() is strict: an unknown key, a
// wrong JSON type, a number out of range or a text that does not fit its field
// is an error; a missing key keeps the field's default.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// Thrown by from_json() with a message that names the offending field.
class JsonError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

namespace reflect::detail {

template <class V>
nlohmann::json value_to_json(const V& v) {
  if constexpr (std::is_same_v<V, bool>) {
    return v;
  } else if constexpr (std::is_integral_v<V>) {
    return static_cast<std::conditional_t<std::is_signed_v<V>, std::int64_t, std::uint64_t>>(v);
  } else if constexpr (std::is_floating_point_v<V>) {
    return std::isfinite(v) ? nlohmann::json(static_cast<double>(v)) : nlohmann::json(nullptr);
  } else if constexpr (ReflectedEnum<V>) {
    const std::string_view name = enum_name(v);
    if (name.empty()) return value_to_json(static_cast<std::underlying_type_t<V>>(v));
    return std::string(name);
  } else if constexpr (std::is_enum_v<V>) {
    return value_to_json(static_cast<std::underlying_type_t<V>>(v));
  } else if constexpr (std::is_same_v<V, std::string>) {
    return v;
  } else if constexpr (is_char_array<V>::value) {
    return std::string(fixed_str_view(v));
  } else if constexpr (is_std_array<V>::value || is_std_vector<V>::value) {
    auto arr = nlohmann::json::array();
    for (const auto& e : v) arr.push_back(value_to_json(e));
    return arr;
  } else {
    static_assert(Reflected<V>, "to_json: not a reflected type");
    auto obj = nlohmann::json::object();
    for_each_field(v, [&](std::string_view name, const auto& field) { obj[std::string(name)] = value_to_json(field); });
    return obj;
  }
}

[[noreturn]] inline void json_fail(const std::string& path, const std::string& what) {
  throw JsonError("JSON field '" + path + "': " + what);
}

template <class V>
void value_from_json(const nlohmann::json& j, V& v, const std::string& path);

// An integer, checked against V's range.
template <class V>
void integer_from_json(const nlohmann::json& j, V& v, const std::string& path) {
  if (!j.is_number_integer()) json_fail(path, "expected an integer, found " + j.dump());
  if constexpr (std::is_signed_v<V>) {
    if (j.is_number_unsigned() && j.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<V>::max()))
      json_fail(path, "value " + j.dump() + " is out of range");
    const auto x = j.get<std::int64_t>();
    if (x < std::numeric_limits<V>::min() || x > std::numeric_limits<V>::max())
      json_fail(path, "value " + j.dump() + " is out of range");
    v = static_cast<V>(x);
  } else {
    // nlohmann stores a parsed non-negative number as unsigned, but a C++ int
    // put into a json (j["id"] = 5) as signed: accept both when >= 0.
    if (!j.is_number_unsigned() && j.get<std::int64_t>() < 0)
      json_fail(path, "expected a non-negative integer, found " + j.dump());
    const auto x = j.get<std::uint64_t>();
    if (x > std::numeric_limits<V>::max()) json_fail(path, "value " + j.dump() + " is out of range");
    v = static_cast<V>(x);
  }
}

// A reflected enum: its name, or its underlying value.
template <class V>
void enum_from_json(const nlohmann::json& j, V& v, const std::string& path) {
  if (j.is_string()) {
    if (!enum_from_name(j.get_ref<const std::string&>(), v)) {
      std::string valid;
      for (const auto& e : enum_values<V>()) valid += (valid.empty() ? "" : ", ") + std::string(e.name);
      json_fail(path, "unknown " + std::string(type_name<V>()) + " " + j.dump() + " (expected one of: " + valid + ")");
    }
  } else {
    std::underlying_type_t<V> raw{};
    value_from_json(j, raw, path);
    v = static_cast<V>(raw);
  }
}

// A reflected struct: each key sets the field of that name; a key that names none is an error.
template <class V>
void fields_from_json(const nlohmann::json& j, V& v, const std::string& path) {
  if (!j.is_object()) json_fail(path.empty() ? std::string(type_name<V>()) : path, "expected an object, found " + j.dump());
  for (const auto& item : j.items()) {
    const std::string& key = item.key();
    const nlohmann::json& val = item.value();
    bool known = false;
    for_each_field(v, [&](std::string_view name, auto& field) {
      if (name == key) {
        known = true;
        value_from_json(val, field, path.empty() ? key : path + "." + key);
      }
    });
    if (!known) {
      std::string valid;
      for_each_field_desc<V>([&](const auto& fd) { valid += (valid.empty() ? "" : ", ") + std::string(fd.name); });
      json_fail(path.empty() ? key : path + "." + key,
                "unknown field of " + std::string(type_name<V>()) + " (fields: " + valid + ")");
    }
  }
}

template <class V>
void value_from_json(const nlohmann::json& j, V& v, const std::string& path) {
  if constexpr (std::is_same_v<V, bool>) {
    if (!j.is_boolean()) json_fail(path, "expected true or false, found " + j.dump());
    v = j.get<bool>();
  } else if constexpr (std::is_integral_v<V>) {
    integer_from_json(j, v, path);
  } else if constexpr (std::is_floating_point_v<V>) {
    if (j.is_null()) {
      v = std::numeric_limits<V>::quiet_NaN();
    } else {
      if (!j.is_number()) json_fail(path, "expected a number, found " + j.dump());
      v = static_cast<V>(j.get<double>());
    }
  } else if constexpr (ReflectedEnum<V>) {
    enum_from_json(j, v, path);
  } else if constexpr (std::is_enum_v<V>) {
    std::underlying_type_t<V> raw{};
    value_from_json(j, raw, path);
    v = static_cast<V>(raw);
  } else if constexpr (std::is_same_v<V, std::string>) {
    if (!j.is_string()) json_fail(path, "expected a string, found " + j.dump());
    v = j.get<std::string>();
  } else if constexpr (is_char_array<V>::value) {
    if (!j.is_string()) json_fail(path, "expected a string, found " + j.dump());
    const auto& s = j.get_ref<const std::string&>();
    if (!set_fixed_str(v, s))
      json_fail(path, "text of " + std::to_string(s.size()) + " characters does not fit (at most " +
                          std::to_string(std::tuple_size_v<V> - 1) + ")");
  } else if constexpr (is_std_array<V>::value) {
    if (!j.is_array()) json_fail(path, "expected an array, found " + j.dump());
    if (j.size() > v.size())
      json_fail(path, "array of " + std::to_string(j.size()) + " elements, at most " + std::to_string(v.size()));
    for (std::size_t i = 0; i < j.size(); ++i) value_from_json(j[i], v[i], path + "[" + std::to_string(i) + "]");
  } else if constexpr (is_std_vector<V>::value) {
    if (!j.is_array()) json_fail(path, "expected an array, found " + j.dump());
    v.resize(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) value_from_json(j[i], v[i], path + "[" + std::to_string(i) + "]");
  } else {
    static_assert(Reflected<V>, "from_json: not a reflected type");
    fields_from_json(j, v, path);
  }
}

}  // namespace reflect::detail

/// The JSON value of a message.
template <Reflected T>
nlohmann::json to_json(const T& msg) {
  return reflect::detail::value_to_json(msg);
}

/// Reads a message from JSON; throws JsonError naming the field that is wrong.
template <Reflected T>
T from_json(const nlohmann::json& j) {
  T msg{};
  reflect::detail::value_from_json(j, msg, "");
  return msg;
}

}  // namespace horus

HORUS_API_END

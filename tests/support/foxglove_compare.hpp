// What Foxglove's own decoder (@foxglove/omgidl-serialization, run by node in the recording and `horus foxglove` tests)
// made of a message, compared field by field with horus::to_json's text of what was sent, guided by the type's
// signature (horus/wire/dynamic.hpp).
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "horus/wire/dynamic.hpp"

namespace horus_test {

using json = nlohmann::json;

inline std::string plain_key(std::string k) {
  if (k.starts_with('_')) k.erase(0, 1);
  if (k.ends_with('_')) k.pop_back();
  return k;
}

inline std::string as_decimal(const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

// Text of a char array as Foxglove gives it (a string, or characters / codes), up to its first NUL.
inline std::string char_text(const json& v) {
  std::string s;
  if (v.is_string())
    s = v.get<std::string>();
  else if (v.is_array())
    for (const auto& c : v) s += c.is_string() ? c.get<std::string>() : std::string(1, static_cast<char>(c.get<int>()));
  return s.substr(0, s.find('\0'));
}

// Foxglove's decoding `got` against horus::to_json's `want`, guided by the type: IDL member names (escaped with '_',
// renamed with a trailing '_'), enums as their numbers, 64-bit integers as decimal text, char arrays as text. The first
// difference, or empty.
inline std::string compare(const horus::wire::DynType& t, const json& want, const json& got, const std::string& path) {
  using K = horus::wire::DynType::Kind;
  const auto cut = [](const json& v) {
    auto text = v.dump();
    return text.size() > 200 ? text.substr(0, 200) + "..." : text;
  };
  const auto differ = [&](const std::string& what) {
    return path + ": " + what + ": want " + cut(want) + ", got " + cut(got);
  };
  switch (t.kind) {
    case K::Struct: {
      if (!got.is_object() || !want.is_object()) return differ("not an object");
      if (got.size() != t.field_names.size()) return differ("another number of members");
      for (std::size_t i = 0; i < t.field_names.size(); ++i) {
        const auto& name = t.field_names[i];
        const json* g = nullptr;
        for (const auto& [k, v] : got.items())
          if (plain_key(k) == plain_key(name)) g = &v;
        if (g == nullptr || !want.contains(name)) return differ("no member " + name);
        if (auto d = compare(t.children[i], want[name], *g, path + "." + name); !d.empty()) return d;
      }
      return {};
    }
    case K::Bool:
      return got == want ? "" : differ("bool");
    case K::Char: {
      const auto code = [](const json& v) {
        return v.is_string() ? (v.get<std::string>().empty() ? 0 : v.get<std::string>()[0]) : v.get<int>();
      };
      return code(got) == code(want) ? "" : differ("char");
    }
    case K::Int:
      return as_decimal(got) == as_decimal(want) ? "" : differ("integer");
    case K::Float: {
      if (want.is_null() || got.is_null()) return want.is_null() && got.is_null() ? "" : differ("non-finite");
      const double a = want.get<double>(), b = got.get<double>();
      return a == b ? "" : differ("float");
    }
    case K::Enum: {
      if (!got.is_number_integer()) return differ("an enum that is not a number");
      if (want.is_string()) {
        const auto n = got.get<std::int64_t>();
        std::string name;
        for (std::size_t i = 0; i < t.enumerators.size(); ++i)
          if ((t.idl_enum() ? static_cast<std::int64_t>(i) : t.enumerators[i].second) == n)
            name = t.enumerators[i].first;
        return name == want.get<std::string>() ? "" : differ("enum");
      }
      return as_decimal(got) == as_decimal(want) ? "" : differ("enum");
    }
    case K::String:
      return got == want ? "" : differ("string");
    case K::Array:
    case K::Sequence: {
      if (t.char_array()) return char_text(got) == want.get<std::string>() ? "" : differ("char array");
      if (!got.is_array() || !want.is_array()) return differ("not an array");
      if (got.size() != want.size()) return differ("another length");
      for (std::size_t i = 0; i < got.size(); ++i)
        if (auto d = compare(t.children[0], want[i], got[i], path + "[" + std::to_string(i) + "]"); !d.empty())
          return d;
      return {};
    }
  }
  return differ("unknown kind");
}

}  // namespace horus_test

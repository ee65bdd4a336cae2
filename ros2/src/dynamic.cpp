// The dynamic ROS 2 CDR codec (dynamic.hpp): a walk over a type's fields as an Interfaces set
// holds them, reading with the bounded wire::Reader, writing into a vector.
#include "horus/ros2/dynamic.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <new>
#include <optional>
#include <string>
#include <utility>

#include "horus/wire/reader.hpp"

namespace horus::ros2 {
namespace {

using nlohmann::json;

static_assert(std::endian::native == std::endian::little, "encode_json writes a little-endian body");

constexpr int kDynMaxDepth = 32;  // deeper nesting: a cycle in the set
constexpr std::size_t kDynMax = std::numeric_limits<std::size_t>::max();

/// Bytes of a basic value; 0 for a string, wstring or nested type.
std::size_t dyn_size(Base b) noexcept {
  switch (b) {
    case Base::Int8:
    case Base::Uint8:
    case Base::Bool:
    case Base::Byte: return 1;
    case Base::Int16:
    case Base::Uint16: return 2;
    case Base::Int32:
    case Base::Uint32:
    case Base::Float32: return 4;
    case Base::Int64:
    case Base::Uint64:
    case Base::Float64: return 8;
    default: return 0;
  }
}

std::size_t dyn_mul(std::size_t a, std::size_t b) noexcept { return a != 0 && b > kDynMax / a ? kDynMax : a * b; }
std::size_t dyn_add(std::size_t a, std::size_t b) noexcept { return b > kDynMax - a ? kDynMax : a + b; }

// -- UTF-16 (wstring) <-> UTF-8 (JSON text); what is not well formed becomes U+FFFD ----------------

void dyn_put_utf8(std::string& out, std::uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}
std::string dyn_utf8(const std::vector<std::uint16_t>& units) {
  std::string out;
  for (std::size_t i = 0; i < units.size(); ++i) {
    std::uint32_t cp = units[i];
    if (cp >= 0xD800 && cp < 0xDC00 && i + 1 < units.size() && units[i + 1] >= 0xDC00 && units[i + 1] < 0xE000) {
      cp = 0x10000 + ((cp - 0xD800) << 10) + (units[i + 1] - 0xDC00u);
      ++i;
    } else if (cp >= 0xD800 && cp < 0xE000) {
      cp = 0xFFFD;
    }
    dyn_put_utf8(out, cp);
  }
  return out;
}
std::vector<std::uint16_t> dyn_utf16(std::string_view s) {
  std::vector<std::uint16_t> out;
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    const std::size_t len = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
    std::uint32_t cp = len == 1 ? b : len == 2 ? (b & 0x1Fu) : len == 3 ? (b & 0x0Fu) : (b & 0x07u);
    bool ok = len != 0 && i + len <= s.size();
    for (std::size_t k = 1; ok && k < len; ++k) {
      const auto c = static_cast<unsigned char>(s[i + k]);
      ok = (c & 0xC0) == 0x80;
      cp = (cp << 6) | (c & 0x3Fu);
    }
    if (!ok || cp > 0x10FFFF || (cp >= 0xD800 && cp < 0xE000)) cp = 0xFFFD;
    i += ok ? len : 1;
    if (cp >= 0x10000) {
      out.push_back(static_cast<std::uint16_t>(0xD800 + ((cp - 0x10000) >> 10)));
      out.push_back(static_cast<std::uint16_t>(0xDC00 + ((cp - 0x10000) & 0x3FF)));
    } else {
      out.push_back(static_cast<std::uint16_t>(cp));
    }
  }
  return out;
}

// -- what decoding and encoding share ---------------------------------------------------------------

/// A walk over a type: the path to the value at hand (field names and element indices from the
/// root type, as text only on failure) and the first error.
class DynWalk {
 public:
  DynWalk(const Interfaces& types, std::string_view root) : types_(types), root_(root) {}
  Errc code = Errc::Corrupt;
  std::string error;

 protected:
  bool fail(Errc c, std::string_view what) {
    code = c;
    error = path_text() + ": " + std::string(what);
    return false;
  }
  void push(std::string_view name) { parts_.emplace_back(name, 0); }
  void push(std::size_t index) { parts_.emplace_back(std::string_view{}, index); }
  void pop() { parts_.pop_back(); }
  const Message* nested(const FieldType& t, int depth) {
    if (depth >= kDynMaxDepth) {
      fail(Errc::InvalidArgument, "types nested more than " + std::to_string(kDynMaxDepth) + " deep (a cycle?)");
      return nullptr;
    }
    const Message* m = types_.find(t.nested);
    if (m == nullptr) fail(Errc::InvalidArgument, "type '" + t.nested + "' is not in the set");
    return m;
  }
  const Interfaces& types_;

 private:
  std::string path_text() const {
    std::string out(root_);
    for (const auto& [name, index] : parts_)
      out += name.empty() ? "[" + std::to_string(index) + "]" : "." + std::string(name);
    return out;
  }
  std::string root_;
  std::vector<std::pair<std::string_view, std::size_t>> parts_;
};

// -- decoding -----------------------------------------------------------------------------------------

class DynDecoder : public DynWalk {
 public:
  DynDecoder(const Interfaces& types, std::string_view root, std::span<const std::byte> body, bool swap)
      : DynWalk(types, root), r_(body, nullptr, swap) {}

  std::size_t remaining() const noexcept { return r_.remaining(); }

  bool message(const Message& m, json& out, int depth) {
    out = json::object();
    if (m.fields.empty()) {  // rosidl's uint8 structure_needs_at_least_one_member
      std::uint8_t placeholder = 0;
      return r_.take(&placeholder, 1) || truncated(1);
    }
    for (const Field& f : m.fields) {
      push(f.name);
      json v;
      if (!field(f.type, v, depth)) return false;
      out[f.name] = std::move(v);
      pop();
    }
    return true;
  }

 private:
  bool truncated(std::size_t need) {
    return fail(Errc::Corrupt, "needs " + std::to_string(need) + " bytes, " + std::to_string(r_.remaining()) +
                                   " remain (truncated sample)");
  }
  bool count(std::size_t& n, std::size_t min_bytes) {
    std::uint32_t c = 0;
    if (!r_.align(4) || !r_.number(c, r_.swap)) return truncated(4);
    if (!r_.fits(c, min_bytes))
      return fail(Errc::Corrupt, "count " + std::to_string(c) + " needs at least " +
                                     std::to_string(dyn_mul(c, std::max<std::size_t>(min_bytes, 1))) + " bytes, " +
                                     std::to_string(r_.remaining()) + " remain (corrupt or truncated sample)");
    n = c;
    return true;
  }

  bool field(const FieldType& t, json& out, int depth) {
    if (t.shape == Shape::Single) return value(t, out, depth);
    const auto min = min_size(t, depth);
    if (!min) return false;
    std::size_t n = 0;
    if (t.shape == Shape::Array) {
      n = static_cast<std::size_t>(t.capacity);
      if (!r_.fits(n, *min)) return truncated(dyn_mul(n, *min));
    } else {
      if (!count(n, *min)) return false;
      if (t.shape == Shape::BoundedSequence && n > t.capacity)
        return fail(Errc::Corrupt, std::to_string(n) + " elements, over the bound of " + std::to_string(t.capacity));
    }
    out = json::array();
    out.get_ref<json::array_t&>().reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      push(i);
      json e;
      if (!value(t, e, depth)) return false;
      out.push_back(std::move(e));
      pop();
    }
    return true;
  }

  bool value(const FieldType& t, json& out, int depth) {
    switch (t.base) {
      case Base::Nested: {
        const Message* m = nested(t, depth);
        return m != nullptr && message(*m, out, depth + 1);
      }
      case Base::String:
      case Base::BoundedString: return string(t, out);
      case Base::WString:
      case Base::BoundedWString: return wstring(t, out);
      case Base::Bool: {
        std::uint8_t b = 0;
        if (!r_.take(&b, 1)) return truncated(1);
        if (b > 1) return fail(Errc::Corrupt, "bool byte " + std::to_string(b) + ", expected 0 or 1");
        out = b == 1;
        return true;
      }
      case Base::Int8: return number<std::int8_t>(out);
      case Base::Uint8:
      case Base::Byte: return number<std::uint8_t>(out);
      case Base::Int16: return number<std::int16_t>(out);
      case Base::Uint16: return number<std::uint16_t>(out);
      case Base::Int32: return number<std::int32_t>(out);
      case Base::Uint32: return number<std::uint32_t>(out);
      case Base::Int64: return number<std::int64_t>(out);
      case Base::Uint64: return number<std::uint64_t>(out);
      case Base::Float32: return number<float>(out);
      case Base::Float64: return number<double>(out);
    }
    return fail(Errc::InvalidArgument, "a field type of id " + std::to_string(static_cast<int>(t.base)));
  }
  template <class N>
  bool number(json& out) {
    N v{};
    if (!r_.align(sizeof(N)) || !r_.number(v, r_.swap)) return truncated(sizeof(N));
    out = v;
    return true;
  }
  bool string(const FieldType& t, json& out) {
    std::size_t n = 0;
    if (!count(n, 1)) return false;
    if (n == 0) {  // some writers send an empty string as length 0
      out = "";
      return true;
    }
    const auto* p = reinterpret_cast<const char*>(r_.here());
    if (p[n - 1] != '\0') return fail(Errc::Corrupt, "a string of " + std::to_string(n) + " bytes without its NUL");
    if (t.base == Base::BoundedString && n - 1 > t.string_capacity)
      return fail(Errc::Corrupt, std::to_string(n - 1) + " characters, over the bound of " +
                                     std::to_string(t.string_capacity));
    out = std::string(p, n - 1);
    r_.skip(n);
    return true;
  }
  bool wstring(const FieldType& t, json& out) {
    std::size_t n = 0;
    if (!count(n, 2)) return false;
    if (t.base == Base::BoundedWString && n > t.string_capacity)
      return fail(Errc::Corrupt,
                  std::to_string(n) + " characters, over the bound of " + std::to_string(t.string_capacity));
    std::vector<std::uint16_t> units(n);
    if (n != 0 && (!r_.align(2) || !r_.numbers(units.data(), n, r_.swap))) return truncated(2 * n);
    out = dyn_utf8(units);
    return true;
  }

  /// The fewest bytes one value of t's base takes (alignment aside): bounds counts.
  std::optional<std::size_t> min_size(const FieldType& t, int depth) {
    if (t.base == Base::String || t.base == Base::BoundedString || t.base == Base::WString ||
        t.base == Base::BoundedWString)
      return 4;
    if (t.base != Base::Nested) return dyn_size(t.base);
    if (const auto it = min_sizes_.find(t.nested); it != min_sizes_.end()) return it->second;
    const Message* m = nested(t, depth);
    if (m == nullptr) return std::nullopt;
    std::size_t sum = m->fields.empty() ? 1 : 0;
    for (const Field& f : m->fields) {
      if (f.type.shape == Shape::BoundedSequence || f.type.shape == Shape::Sequence) {
        sum = dyn_add(sum, 4);
        continue;
      }
      const auto one = min_size(f.type, depth + 1);
      if (!one) return std::nullopt;
      const auto cap = static_cast<std::size_t>(f.type.capacity);
      sum = dyn_add(sum, f.type.shape == Shape::Array ? dyn_mul(*one, cap) : *one);
    }
    min_sizes_.emplace(t.nested, sum);
    return sum;
  }

  wire::Reader r_;
  std::map<std::string, std::size_t, std::less<>> min_sizes_;
};

// -- encoding -----------------------------------------------------------------------------------------

/// A field's default value (the .msg's text) as JSON, or nullopt (then zero, empty).
std::optional<json> dyn_default(const Field& f) {
  std::string text = f.default_value;
  const bool text_field = f.type.base == Base::String || f.type.base == Base::BoundedString ||
                          f.type.base == Base::WString || f.type.base == Base::BoundedWString;
  if (text_field && f.type.shape == Shape::Single) {
    if (text.size() >= 2 && (text.front() == '"' || text.front() == '\'') && text.back() == text.front())
      text = text.substr(1, text.size() - 2);
    return json(text);
  }
  for (const char* word : {"True", "False"})
    for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at))
      text[at] = static_cast<char>(text[at] - 'A' + 'a');
  json parsed = json::parse(text, nullptr, false);
  if (parsed.is_discarded()) return std::nullopt;
  return parsed;
}

class DynEncoder : public DynWalk {
 public:
  using DynWalk::DynWalk;
  std::vector<std::byte> out;

  bool message(const Message& m, const json* v, int depth) {
    if (v != nullptr && !v->is_object()) return wrong("an object (" + m.type_name + ")", *v);
    if (v != nullptr)
      for (const auto& item : v->items())
        if (std::none_of(m.fields.begin(), m.fields.end(), [&](const Field& f) { return f.name == item.key(); }))
          return unknown(m, item.key());
    if (m.fields.empty()) {  // rosidl's uint8 structure_needs_at_least_one_member
      put(std::uint8_t{0});
      return true;
    }
    for (const Field& f : m.fields) {
      push(f.name);
      const json* fv = nullptr;
      if (v != nullptr)
        if (const auto it = v->find(f.name); it != v->end()) fv = &*it;
      std::optional<json> preset;
      if (fv == nullptr && !f.default_value.empty() && (preset = dyn_default(f))) fv = &*preset;
      if (!field(f.type, fv, depth)) return false;
      pop();
    }
    return true;
  }

 private:
  bool wrong(std::string_view expected, const json& v) {
    std::string text = v.dump();
    if (text.size() > 40) text = text.substr(0, 40) + "...";
    return fail(Errc::InvalidArgument, "expected " + std::string(expected) + ", got " + v.type_name() + " " + text);
  }
  bool unknown(const Message& m, std::string_view key) {
    std::string names;
    for (const Field& f : m.fields) names += (names.empty() ? "" : ", ") + f.name;
    return fail(Errc::InvalidArgument, "unknown field '" + std::string(key) + "' (" + m.type_name + " has " +
                                           (names.empty() ? "no fields" : names) + ")");
  }
  void align(std::size_t a) {
    while (out.size() % a != 0) out.push_back(std::byte{0});
  }
  template <class N>
  void put(N v) {
    align(sizeof(N));
    const auto* p = reinterpret_cast<const std::byte*>(&v);
    out.insert(out.end(), p, p + sizeof(N));
  }

  bool field(const FieldType& t, const json* v, int depth) {
    if (t.shape == Shape::Single) return value(t, v, depth);
    const auto cap = static_cast<std::size_t>(t.capacity);
    if (v != nullptr && !v->is_array()) return wrong("an array", *v);
    const std::size_t n = v != nullptr ? v->size() : (t.shape == Shape::Array ? cap : 0);
    if (t.shape == Shape::Array && n != cap)
      return fail(Errc::InvalidArgument,
                  std::to_string(n) + " elements; the array holds exactly " + std::to_string(cap));
    if (t.shape == Shape::BoundedSequence && n > cap)
      return fail(Errc::InvalidArgument, std::to_string(n) + " elements, over the bound of " + std::to_string(cap));
    if (t.shape != Shape::Array) put(static_cast<std::uint32_t>(n));
    for (std::size_t i = 0; i < n; ++i) {
      push(i);
      if (!value(t, v != nullptr ? &(*v)[i] : nullptr, depth)) return false;
      pop();
    }
    return true;
  }

  bool value(const FieldType& t, const json* v, int depth) {
    switch (t.base) {
      case Base::Nested: {
        const Message* m = nested(t, depth);
        return m != nullptr && message(*m, v, depth + 1);
      }
      case Base::String:
      case Base::BoundedString:
      case Base::WString:
      case Base::BoundedWString: return string(t, v);
      case Base::Bool:
        if (v != nullptr && !v->is_boolean()) return wrong("a bool", *v);
        put(static_cast<std::uint8_t>(v != nullptr && v->get<bool>() ? 1 : 0));
        return true;
      case Base::Int8: return integer<std::int8_t>(v, "int8");
      case Base::Uint8: return integer<std::uint8_t>(v, "uint8");
      case Base::Byte: return integer<std::uint8_t>(v, "byte");
      case Base::Int16: return integer<std::int16_t>(v, "int16");
      case Base::Uint16: return integer<std::uint16_t>(v, "uint16");
      case Base::Int32: return integer<std::int32_t>(v, "int32");
      case Base::Uint32: return integer<std::uint32_t>(v, "uint32");
      case Base::Int64: return integer<std::int64_t>(v, "int64");
      case Base::Uint64: return integer<std::uint64_t>(v, "uint64");
      case Base::Float32: return floating<float>(v);
      case Base::Float64: return floating<double>(v);
    }
    return fail(Errc::InvalidArgument, "a field type of id " + std::to_string(static_cast<int>(t.base)));
  }
  template <class N>
  bool integer(const json* v, std::string_view type) {
    N x{};
    if (v != nullptr) {
      bool fits = false;
      if (v->is_number_unsigned()) {
        const auto u = v->get<std::uint64_t>();
        fits = std::in_range<N>(u);
        x = static_cast<N>(u);
      } else if (v->is_number_integer()) {
        const auto s = v->get<std::int64_t>();
        fits = std::in_range<N>(s);
        x = static_cast<N>(s);
      } else {
        return wrong("an integer (" + std::string(type) + ")", *v);
      }
      if (!fits) return fail(Errc::InvalidArgument, v->dump() + " is out of range for " + std::string(type));
    }
    put(x);
    return true;
  }
  template <class N>
  bool floating(const json* v) {
    N x{};
    if (v != nullptr && v->is_number()) {
      x = static_cast<N>(v->get<double>());
    } else if (v != nullptr && v->is_null()) {
      x = std::numeric_limits<N>::quiet_NaN();  // JSON has no NaN: null stands for it
    } else if (v != nullptr) {
      return wrong("a number", *v);
    }
    put(x);
    return true;
  }
  bool string(const FieldType& t, const json* v) {
    if (v != nullptr && !v->is_string()) return wrong("a string", *v);
    const std::string& s = v != nullptr ? v->get_ref<const std::string&>() : empty_;
    if (s.find('\0') != std::string::npos) return fail(Errc::InvalidArgument, "a string with a NUL inside");
    if (t.base == Base::WString || t.base == Base::BoundedWString) {
      const std::vector<std::uint16_t> units = dyn_utf16(s);
      if (t.base == Base::BoundedWString && units.size() > t.string_capacity)
        return fail(Errc::InvalidArgument, std::to_string(units.size()) + " characters, over the bound of " +
                                               std::to_string(t.string_capacity));
      put(static_cast<std::uint32_t>(units.size()));
      for (std::uint16_t u : units) put(u);
      return true;
    }
    if (t.base == Base::BoundedString && s.size() > t.string_capacity)
      return fail(Errc::InvalidArgument, std::to_string(s.size()) + " characters, over the bound of " +
                                             std::to_string(t.string_capacity));
    put(static_cast<std::uint32_t>(s.size() + 1));
    const auto* p = reinterpret_cast<const std::byte*>(s.data());
    out.insert(out.end(), p, p + s.size());
    out.push_back(std::byte{0});
    return true;
  }
  const std::string empty_;
};

}  // namespace

Result<nlohmann::json> decode_json(const Interfaces& types, std::string_view type_name,
                                   std::span<const std::byte> body, bool little_endian) {
  const Message* m = types.find(type_name);
  if (m == nullptr)
    return fail(Errc::InvalidArgument, "decode_json: no type '" + std::string(type_name) + "' in the set");
  DynDecoder d(types, m->type_name, body, little_endian != (std::endian::native == std::endian::little));
  json out;
  try {
    if (!d.message(*m, out, 0)) return fail(d.code, d.error);
  } catch (const std::bad_alloc&) {
    return fail(Errc::Corrupt, m->type_name + ": out of memory");
  }
  if (d.remaining() > 3)
    return fail(Errc::Corrupt, m->type_name + ": " + std::to_string(d.remaining()) +
                                   " bytes left over after the sample (another type?)");
  return out;
}

Result<std::vector<std::byte>> encode_json(const Interfaces& types, std::string_view type_name,
                                           const nlohmann::json& value) {
  const Message* m = types.find(type_name);
  if (m == nullptr)
    return fail(Errc::InvalidArgument, "encode_json: no type '" + std::string(type_name) + "' in the set");
  DynEncoder e(types, m->type_name);
  try {
    if (!e.message(*m, &value, 0)) return fail(e.code, e.error);
  } catch (const std::bad_alloc&) {
    return fail(Errc::InvalidArgument, m->type_name + ": out of memory");
  }
  return std::move(e.out);
}

}  // namespace horus::ros2

// Parsing type signatures and decoding samples without the C++ type (horus/wire/dynamic.hpp).
// The decoders mirror the typed ones (xcdr1.hpp, lcm.hpp) rule for rule: same widths,
// alignment, checks and left-over rules, so a message decodes here exactly when it decodes there.
#include "horus/wire/dynamic.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "horus/wire/reader.hpp"
#include "horus/wire/walk.hpp"  // sat_add

namespace horus::wire {
namespace {

constexpr std::size_t kMaxSignature = 1 << 20;
constexpr int kMaxDepth = 32;
constexpr std::uint64_t kMaxArray = std::numeric_limits<std::uint32_t>::max();

struct Scalar {
  std::string_view token;
  DynType::Kind kind;
  std::uint8_t size;
  bool is_signed;
};
constexpr Scalar kScalars[] = {
    {"bool", DynType::Kind::Bool, 1, false},  {"char", DynType::Kind::Char, 1, true},
    {"i8", DynType::Kind::Int, 1, true},      {"u8", DynType::Kind::Int, 1, false},
    {"i16", DynType::Kind::Int, 2, true},     {"u16", DynType::Kind::Int, 2, false},
    {"i32", DynType::Kind::Int, 4, true},     {"u32", DynType::Kind::Int, 4, false},
    {"i64", DynType::Kind::Int, 8, true},     {"u64", DynType::Kind::Int, 8, false},
    {"f32", DynType::Kind::Float, 4, true},   {"f64", DynType::Kind::Float, 8, true},
    {"string", DynType::Kind::String, 0, false},
};

bool ident_char(char c) noexcept {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

class Parser {
 public:
  explicit Parser(std::string_view text) : t_(text) {}

  bool type(DynType& out, int depth) {
    if (depth > kMaxDepth) return fail("nesting deeper than 32 levels");
    if (rest().starts_with("enum ")) return enumeration(out);
    if (rest().starts_with("seq<")) {
      pos_ += 4;
      out.kind = DynType::Kind::Sequence;
      out.children.resize(1);
      return type(out.children[0], depth + 1) && expect('>');
    }
    if (rest().starts_with("[")) {
      ++pos_;
      out.kind = DynType::Kind::Array;
      out.children.resize(1);
      if (!type(out.children[0], depth + 1) || !expect(';')) return false;
      if (!number(out.length)) return false;
      if (out.length > kMaxArray) return fail("an array of more than 2^32 - 1 elements");
      return expect(']');
    }
    if (const Scalar* s = scalar()) {
      out.kind = s->kind;
      out.size = s->size;
      out.is_signed = s->is_signed;
      pos_ += s->token.size();
      return true;
    }
    return structure(out, depth);
  }

  bool at_end() const noexcept { return pos_ == t_.size(); }
  std::size_t pos() const noexcept { return pos_; }
  std::string error;

 private:
  std::string_view rest() const noexcept { return t_.substr(pos_); }

  bool fail(std::string_view what) {
    if (error.empty()) error = "at offset " + std::to_string(pos_) + ": " + std::string(what);
    return false;
  }
  bool expect(char c) {
    if (pos_ < t_.size() && t_[pos_] == c) {
      ++pos_;
      return true;
    }
    return fail(std::string("expected '") + c + "', found " +
                (pos_ < t_.size() ? "'" + std::string(1, t_[pos_]) + "'" : std::string("the end")));
  }
  bool number(std::uint64_t& v) {
    const std::size_t start = pos_;
    v = 0;
    while (pos_ < t_.size() && t_[pos_] >= '0' && t_[pos_] <= '9') {
      const auto d = static_cast<std::uint64_t>(t_[pos_] - '0');
      if (v > (std::numeric_limits<std::uint64_t>::max() - d) / 10) return fail("a number too large");
      v = v * 10 + d;
      ++pos_;
    }
    return pos_ != start || fail("expected a number");
  }
  bool identifier(std::string& out) {
    const std::size_t start = pos_;
    while (pos_ < t_.size() && ident_char(t_[pos_])) ++pos_;
    if (pos_ == start) return fail("expected a name (letters, digits, '_')");
    out.assign(t_.substr(start, pos_ - start));
    return true;
  }
  // A scalar token followed by what may follow a type (a field's space, ';', '>', the end).
  const Scalar* scalar() const noexcept {
    for (const auto& s : kScalars) {
      if (!rest().starts_with(s.token)) continue;
      const std::size_t after = pos_ + s.token.size();
      if (after == t_.size() || t_[after] == ' ' || t_[after] == ';' || t_[after] == '>') return &s;
    }
    return nullptr;
  }
  // A qualified type name: a struct's runs up to its '{' (GCC's "{anonymous}" is part of it;
  // template arguments may hold anything else), an enum's up to the single ':' before its
  // integer type.
  bool type_name(std::string& out, bool enum_name) {
    const std::size_t start = pos_;
    while (pos_ < t_.size()) {
      const char c = t_[pos_];
      if (c == '{' && rest().starts_with("{anonymous}")) {
        pos_ += 11;
        continue;
      }
      if (enum_name && c == ':') {
        if (pos_ + 1 < t_.size() && t_[pos_ + 1] == ':') {
          pos_ += 2;
          continue;
        }
        break;
      }
      if (c == '{' || c == ';' || c == '}') break;
      ++pos_;
    }
    if (pos_ == start) return fail("expected a type name");
    out.assign(t_.substr(start, pos_ - start));
    return true;
  }
  bool enumeration(DynType& out) {
    pos_ += 5;
    out.kind = DynType::Kind::Enum;
    if (!type_name(out.name, true) || !expect(':')) return false;
    const Scalar* s = scalar_at_enum();
    if (s == nullptr || s->kind != DynType::Kind::Int) return fail("expected the enum's integer type (i8 ... u64)");
    out.size = s->size;
    out.is_signed = s->is_signed;
    pos_ += s->token.size();
    if (pos_ >= t_.size() || t_[pos_] != '{') return true;  // a plain enum: no enumerators
    ++pos_;
    out.reflected = true;
    while (pos_ < t_.size() && t_[pos_] != '}') {
      std::string name;
      if (!identifier(name) || !expect('=')) return false;
      bool negative = false;
      if (pos_ < t_.size() && t_[pos_] == '-') {
        negative = true;
        ++pos_;
      }
      std::uint64_t mag = 0;
      if (!number(mag) || !expect(';')) return false;
      if (negative && mag > (std::uint64_t{1} << 63)) return fail("an enumerator value out of range");
      // Values of a u64 enum above 2^63 keep their bits (decoding compares bits the same way).
      const auto value = negative ? static_cast<std::int64_t>(0 - mag) : static_cast<std::int64_t>(mag);
      out.enumerators.emplace_back(std::move(name), value);
      if (out.enumerators.size() > 65536) return fail("more than 65536 enumerators");
    }
    return expect('}');
  }
  const Scalar* scalar_at_enum() const noexcept {
    // After "enum Name:" the integer type may be followed by '{' too.
    for (const auto& s : kScalars) {
      if (!rest().starts_with(s.token)) continue;
      const std::size_t after = pos_ + s.token.size();
      if (after == t_.size() || t_[after] == ' ' || t_[after] == ';' || t_[after] == '>' || t_[after] == '{') return &s;
    }
    return nullptr;
  }
  bool structure(DynType& out, int depth) {
    out.kind = DynType::Kind::Struct;
    if (!type_name(out.name, false) || !expect('{')) return false;
    while (pos_ < t_.size() && t_[pos_] != '}') {
      DynType field;
      std::string name;
      if (!type(field, depth + 1) || !expect(' ') || !identifier(name) || !expect(';')) return false;
      for (const auto& n : out.field_names)
        if (n == name) return fail("field '" + name + "' appears twice");
      out.children.push_back(std::move(field));
      out.field_names.push_back(std::move(name));
      if (out.children.size() > 65536) return fail("more than 65536 fields");
    }
    return expect('}');
  }

  std::string_view t_;
  std::size_t pos_ = 0;
};

// -- decoding ---------------------------------------------------------------------------------

constexpr std::size_t sat_mul(std::uint64_t a, std::size_t b) noexcept {
  if (a != 0 && b > std::numeric_limits<std::size_t>::max() / a) return std::numeric_limits<std::size_t>::max();
  return static_cast<std::size_t>(a) * b;
}

std::int64_t sign_extend(std::uint64_t raw, std::size_t size) noexcept {
  switch (size) {
    case 1: return static_cast<std::int8_t>(raw);
    case 2: return static_cast<std::int16_t>(raw);
    case 4: return static_cast<std::int32_t>(raw);
    default: return static_cast<std::int64_t>(raw);
  }
}

class Decoder {
 public:
  Decoder(std::span<const std::byte> body, DynFormat format, bool little_endian)
      : r(body, nullptr, format == DynFormat::Lcm || !little_endian), lcm_(format == DynFormat::Lcm) {}

  bool value(const DynType& t, nlohmann::json& out, const Path& path) {
    switch (t.kind) {
      case DynType::Kind::Bool: return boolean(out, path);
      case DynType::Kind::Char: {
        std::uint8_t b = 0;
        if (!r.take(&b, 1)) return r.truncated(path, 1, noun());
        out = static_cast<std::int64_t>(static_cast<char>(b));
        return true;
      }
      case DynType::Kind::Int: {
        std::uint64_t raw = 0;
        if (!integer(t.size, t.is_signed, raw, path)) return false;
        out = t.is_signed ? nlohmann::json(sign_extend(raw, t.size)) : nlohmann::json(raw);
        return true;
      }
      case DynType::Kind::Float: return floating(t.size, out, path);
      case DynType::Kind::Enum: return enumeration(t, out, path);
      case DynType::Kind::String: {
        std::string s;
        if (!string(s, path)) return false;
        out = std::move(s);
        return true;
      }
      case DynType::Kind::Sequence: {
        std::size_t n = 0;
        if (!count(n, min_size(t.children[0]), path)) return false;
        return elements(t.children[0], n, out, path);
      }
      case DynType::Kind::Array:
        if (t.char_array()) {
          const auto n = static_cast<std::size_t>(t.length);
          if (n > r.remaining()) return r.truncated(path, n, noun());
          const auto* p = reinterpret_cast<const char*>(r.here());
          out = std::string(p, strnlen(p, n));
          r.skip(n);
          return true;
        }
        return elements(t.children[0], static_cast<std::size_t>(t.length), out, path);
      case DynType::Kind::Struct: {
        out = nlohmann::json::object();
        for (std::size_t i = 0; i < t.children.size(); ++i) {
          nlohmann::json& f = out[t.field_names[i]];
          if (!value(t.children[i], f, Path{&path, t.field_names[i]})) return false;
        }
        return true;
      }
    }
    return r.fail(path, ": unknown kind");
  }

  // Fewest encoded bytes of a value (alignment aside): bounds counts before allocating.
  std::size_t min_size(const DynType& t) const noexcept {
    switch (t.kind) {
      case DynType::Kind::Bool:
      case DynType::Kind::Char: return 1;
      case DynType::Kind::Int: return lcm_ ? lcm_width(t.size, t.is_signed) : t.size;
      case DynType::Kind::Float: return t.size;
      case DynType::Kind::Enum: return t.idl_enum() ? 4 : (lcm_ ? lcm_width(t.size, t.is_signed) : t.size);
      case DynType::Kind::String: return lcm_ ? 5 : 4;
      case DynType::Kind::Sequence: return 4;
      case DynType::Kind::Array: return sat_mul(t.length, min_size(t.children[0]));
      case DynType::Kind::Struct: {
        std::size_t n = 0;
        for (const auto& c : t.children) n = sat_add(n, min_size(c));
        return n;
      }
    }
    return 1;
  }

  Reader r;

 private:
  std::string_view noun() const noexcept { return lcm_ ? "message" : "sample"; }
  // LCM has no unsigned types: u16 travels as i32, u32 and u64 as i64.
  static std::size_t lcm_width(std::size_t size, bool is_signed) noexcept {
    if (is_signed || size == 1) return size;
    return size == 2 ? 4 : 8;
  }

  template <class N>
  bool read(N& v, const Path& path) {
    if (!lcm_ && !r.align(sizeof(N))) return r.truncated(path, sizeof(N), noun());
    if (!r.number(v, r.swap)) return r.truncated(path, sizeof(N), noun());
    return true;
  }

  bool boolean(nlohmann::json& out, const Path& path) {
    if (!lcm_) {
      bool b = false;
      if (!get_strict_bool(r, b, path, noun())) return false;
      out = b;
      return true;
    }
    std::uint8_t b = 0;
    if (!r.take(&b, 1)) return r.truncated(path, 1, noun());
    out = b != 0;  // C programs store booleans in an int8_t
    return true;
  }

  // An integer of `size` bytes (its C++ width) as raw bits; LCM's widened unsigned values are
  // range-checked as lcm.hpp does.
  bool integer(std::size_t size, bool is_signed, std::uint64_t& raw, const Path& path) {
    const std::size_t wire = lcm_ ? lcm_width(size, is_signed) : size;
    switch (wire) {
      case 1: {
        std::uint8_t v = 0;
        if (!r.take(&v, 1)) return r.truncated(path, 1, noun());
        raw = v;
        break;
      }
      case 2: {
        std::uint16_t v = 0;
        if (!read(v, path)) return false;
        raw = v;
        break;
      }
      case 4: {
        std::uint32_t v = 0;
        if (!read(v, path)) return false;
        raw = v;
        break;
      }
      default: {
        std::uint64_t v = 0;
        if (!read(v, path)) return false;
        raw = v;
        break;
      }
    }
    if (lcm_ && wire > size) {
      const std::int64_t w = sign_extend(raw, wire);
      const std::uint64_t max = size == 2 ? 0xffffU : 0xffff'ffffULL;
      if (w < 0 || static_cast<std::uint64_t>(w) > max)
        return r.fail(path, ": value ", w, " is out of range for a ", size * 8, "-bit unsigned field (expected 0..",
                      max, ")");
      raw = static_cast<std::uint64_t>(w);
    }
    return true;
  }

  bool floating(std::size_t size, nlohmann::json& out, const Path& path) {
    double d = 0;
    if (size == 4) {
      float f = 0;
      if (!read(f, path)) return false;
      d = f;
    } else if (!read(d, path)) {
      return false;
    }
    out = std::isfinite(d) ? nlohmann::json(d) : nlohmann::json(nullptr);
    return true;
  }

  bool enumeration(const DynType& t, nlohmann::json& out, const Path& path) {
    if (t.idl_enum()) {
      std::uint32_t raw = 0;
      if (!read(raw, path)) return false;
      const auto n = t.enumerators.size();
      if (lcm_ && static_cast<std::int32_t>(raw) < 0)
        return r.fail(path, ": enum value ", static_cast<std::int32_t>(raw), ", expected 0..", n - 1,
                      " (corrupt message or another version of the type)");
      if (raw >= n)
        return r.fail(path, ": enum value ", raw, ", expected 0..", n - 1, " (corrupt ", noun(),
                      " or another version of the type)");
      out = t.enumerators[raw].first;
      return true;
    }
    std::uint64_t raw = 0;
    if (!integer(t.size, t.is_signed, raw, path)) return false;
    const std::int64_t value = t.is_signed ? sign_extend(raw, t.size) : static_cast<std::int64_t>(raw);
    for (const auto& [name, v] : t.enumerators)
      if (v == value) {
        out = name;
        return true;
      }
    out = t.is_signed ? nlohmann::json(value) : nlohmann::json(raw);
    return true;
  }

  bool count(std::size_t& n, std::size_t min_bytes, const Path& path) {
    if (lcm_) {
      std::int32_t raw = 0;
      if (!r.number(raw, true)) return r.truncated(path, 4, noun());
      if (raw < 0) return r.fail(path, ": length ", raw, " is negative (corrupt message)");
      if (!r.fits(static_cast<std::uint64_t>(raw), min_bytes))
        return r.too_many(path, "length", static_cast<std::uint64_t>(raw), min_bytes, noun());
      n = static_cast<std::size_t>(raw);
      return true;
    }
    std::uint32_t raw = 0;
    if (!read(raw, path)) return false;
    if (!r.fits(raw, min_bytes)) return r.too_many(path, "count", raw, min_bytes, noun());
    n = raw;
    return true;
  }

  bool string(std::string& s, const Path& path) {
    std::size_t n = 0;
    if (!count(n, 1, path)) return false;
    if (n == 0) {
      if (lcm_) return r.fail(path, ": string length 0; LCM strings count their NUL, so the least is 1 (corrupt message)");
      s.clear();  // some DDS writers send an empty string as length 0, no NUL
      return true;
    }
    const auto* p = reinterpret_cast<const char*>(r.here());
    if (p[n - 1] != '\0')
      return r.fail(path, ": a string of ", n, " bytes without its NUL terminator (corrupt ", noun(), ")");
    if (lcm_ && std::memchr(p, '\0', n - 1) != nullptr)
      return r.fail(path, ": a string with a NUL byte inside (LCM strings end at the first NUL; corrupt message)");
    s.assign(p, n - 1);
    r.skip(n);
    return true;
  }

  bool elements(const DynType& e, std::size_t n, nlohmann::json& out, const Path& path) {
    if (!r.fits(n, min_size(e))) return r.too_many(path, "count", n, min_size(e), noun());
    out = nlohmann::json::array();
    auto& arr = out.get_ref<nlohmann::json::array_t&>();
    arr.reserve(std::min<std::size_t>(n, 1 << 16));
    for (std::size_t i = 0; i < n; ++i) {
      arr.emplace_back();
      if (!value(e, arr.back(), Path{&path, {}, i})) return false;
    }
    return true;
  }

  bool lcm_;
};

// LCM cannot express a variable-size array inside another array, nor an empty array.
bool lcm_element_ok(const DynType& t, std::string& why, const std::string& where);
bool lcm_fields_ok(const DynType& t, std::string& why, const std::string& where) {
  for (std::size_t i = 0; i < t.children.size(); ++i) {
    const DynType& f = t.children[i];
    const std::string at = where + "." + t.field_names[i];
    if (!lcm_element_ok(f.kind == DynType::Kind::Sequence ? f.children[0] : f, why, at)) return false;
  }
  return true;
}
bool lcm_element_ok(const DynType& t, std::string& why, const std::string& where) {
  if (t.kind == DynType::Kind::Sequence) {
    why = where + ": a variable-size array inside an array; LCM cannot express it";
    return false;
  }
  if (t.kind == DynType::Kind::Array) {
    if (t.length == 0) {
      why = where + ": an array of 0 elements; LCM cannot express it";
      return false;
    }
    return lcm_element_ok(t.children[0], why, where);
  }
  if (t.kind == DynType::Kind::Struct) return lcm_fields_ok(t, why, where);
  return true;
}

}  // namespace

bool DynType::idl_enum() const noexcept {
  if (kind != Kind::Enum || !reflected || enumerators.empty()) return false;
  for (std::size_t i = 0; i < enumerators.size(); ++i)
    if (enumerators[i].second != static_cast<std::int64_t>(i)) return false;
  return true;
}

std::uint64_t signature_hash(std::string_view text) noexcept {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::expected<DynType, std::string> parse_signature(std::string_view text, std::uint64_t expected_hash) {
  if (text.size() > kMaxSignature)
    return std::unexpected("type signature of " + std::to_string(text.size()) + " bytes; at most 1 MiB expected");
  if (expected_hash != 0 && signature_hash(text) != expected_hash) {
    char buf[80];
    std::snprintf(buf, sizeof buf, "hash %016llx, expected %016llx", static_cast<unsigned long long>(signature_hash(text)),
                  static_cast<unsigned long long>(expected_hash));
    return std::unexpected("type signature does not match its type hash (" + std::string(buf) +
                           "): corrupt or not this type's");
  }
  Parser p(text);
  DynType root;
  if (!p.type(root, 0)) return std::unexpected("type signature " + p.error);
  if (!p.at_end())
    return std::unexpected("type signature at offset " + std::to_string(p.pos()) + ": text after the type");
  if (root.kind != DynType::Kind::Struct) return std::unexpected(std::string("type signature: the root is not a struct"));
  return root;
}

std::expected<void, std::string> check_expressible(const DynType& type, DynFormat format) {
  if (format != DynFormat::Lcm || type.kind != DynType::Kind::Struct) return {};
  std::string why;
  if (!lcm_fields_ok(type, why, type.name)) return std::unexpected(std::move(why));
  return {};
}

std::expected<nlohmann::json, std::string> decode_json(const DynType& type, DynFormat format,
                                                       std::span<const std::byte> body, bool little_endian) {
  if (auto ok = check_expressible(type, format); !ok) return std::unexpected(std::move(ok.error()));
  Decoder d(body, format, little_endian);
  if (format == DynFormat::Lcm) {
    if (body.size() < 8)
      return std::unexpected(type.name + ": " + std::to_string(body.size()) +
                             " bytes, shorter than the 8-byte fingerprint (not an LCM message)");
    d.r.skip(8);  // the fingerprint: the announced type hash vouches for the type
  }
  nlohmann::json out;
  try {
    if (!d.value(type, out, Path{nullptr, type.name})) return std::unexpected(std::move(d.r.error));
  } catch (const std::bad_alloc&) {
    return std::unexpected(type.name + ": out of memory decoding " + std::to_string(body.size()) + " bytes");
  }
  const std::size_t padding = format == DynFormat::Lcm ? 0 : 3;
  if (d.r.remaining() > padding)
    return std::unexpected(type.name + ": " + std::to_string(d.r.remaining()) +
                           " bytes left over after the " + (format == DynFormat::Lcm ? "message" : "sample") +
                           " (another type or version on this topic, or a corrupt one)");
  return out;
}

}  // namespace horus::wire

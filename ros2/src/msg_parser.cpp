// .msg text to a Message (horus/ros2/interface.hpp), by ROS 2's rules (rosidl_adapter's .msg
// grammar): one field or constant per line, '#' starts a comment, types of the same package
// without their package.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <optional>
#include <utility>

#include "horus/ros2/interface.hpp"

namespace horus::ros2 {

namespace {

constexpr std::array<std::pair<std::string_view, Base>, 15> kPrimitives{{
    {"bool", Base::Bool},     {"byte", Base::Byte},       {"char", Base::Uint8},     {"float32", Base::Float32},
    {"float64", Base::Float64}, {"int8", Base::Int8},     {"uint8", Base::Uint8},    {"int16", Base::Int16},
    {"uint16", Base::Uint16}, {"int32", Base::Int32},     {"uint32", Base::Uint32},  {"int64", Base::Int64},
    {"uint64", Base::Uint64}, {"string", Base::String},   {"wstring", Base::WString},
}};

bool is_lower_name(std::string_view s) {  // a package or a field: a-z, 0-9, '_', a letter first
  if (s.empty() || !std::islower(static_cast<unsigned char>(s.front()))) return false;
  if (s.back() == '_' || s.find("__") != std::string_view::npos) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) || c == '_';
  });
}

bool is_type_name(std::string_view s) {  // CamelCase: a capital first, then letters and digits
  if (s.empty() || !std::isupper(static_cast<unsigned char>(s.front()))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; });
}

bool is_constant_name(std::string_view s) {  // A-Z, 0-9, '_', a letter first
  if (s.empty() || !std::isupper(static_cast<unsigned char>(s.front()))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isupper(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) || c == '_';
  });
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

std::optional<std::uint64_t> number(std::string_view s) {
  std::uint64_t v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

// One line's context for errors: "<type> line <n>".
struct Where {
  std::string_view type_name;
  std::size_t line;
  Error error(std::string_view what) const {
    return Error(Errc::InvalidArgument, fmt::format("{}, line {}: {}", type_name, line, what));
  }
};

// The array suffix of a type: "[]", "[N]", "[<=N]".
Result<void> parse_shape(std::string_view suffix, FieldType& t, const Where& at) {
  if (suffix.empty()) return {};
  if (suffix.front() != '[' || suffix.back() != ']')
    return std::unexpected(at.error(fmt::format("'{}' is not an array suffix; expected [], [N] or [<=N]", suffix)));
  std::string_view inner = suffix.substr(1, suffix.size() - 2);
  if (inner.empty()) {
    t.shape = Shape::Sequence;
    return {};
  }
  const bool bounded = inner.starts_with("<=");
  if (bounded) inner.remove_prefix(2);
  const auto n = number(inner);
  if (!n || *n == 0)
    return std::unexpected(at.error(fmt::format("'{}' is not an array size; expected a positive integer", inner)));
  t.shape = bounded ? Shape::BoundedSequence : Shape::Array;
  t.capacity = *n;
  return {};
}

// "string<=N", a primitive, "pkg/Name", "pkg/msg/Name", "Name" (of `package`), "Header".
Result<void> parse_base(std::string_view base, std::string_view package, FieldType& t, const Where& at) {
  for (const auto& [name, b] : kPrimitives)
    if (base == name) {
      t.base = b;
      return {};
    }
  for (std::string_view s : {std::string_view("string<="), std::string_view("wstring<=")}) {
    if (!base.starts_with(s)) continue;
    const auto n = number(base.substr(s.size()));
    if (!n || *n == 0) return std::unexpected(at.error(fmt::format("'{}' has no valid bound; expected {}N", base, s)));
    t.base = s.front() == 'w' ? Base::BoundedWString : Base::BoundedString;
    t.string_capacity = *n;
    return {};
  }
  t.base = Base::Nested;
  if (base == "Header") {
    t.nested = "std_msgs/msg/Header";
    return {};
  }
  if (base.find('/') == std::string_view::npos) {
    if (!is_type_name(base))
      return std::unexpected(at.error(fmt::format(
          "'{}' is not a type; expected a primitive (bool, byte, char, int8..uint64, float32, float64, string, "
          "wstring), string<=N, or a message type (Name, pkg/Name, pkg/msg/Name)",
          base)));
    t.nested = std::string(package) + "/msg/" + std::string(base);
    return {};
  }
  auto name = parse_type_name(base);
  if (!name) return std::unexpected(at.error(name.error().message()));
  t.nested = name->full();
  return {};
}

Result<FieldType> parse_type(std::string_view text, std::string_view package, const Where& at) {
  FieldType t;
  const auto bracket = text.find('[');
  const std::string_view base = text.substr(0, bracket);
  if (auto ok = parse_base(base, package, t, at); !ok) return std::unexpected(ok.error());
  if (bracket != std::string_view::npos) {
    if (auto ok = parse_shape(text.substr(bracket), t, at); !ok) return std::unexpected(ok.error());
  }
  return t;
}

// A constant's line: "TYPE NAME=value" (a string's value is the rest of the line, '#' included).
Result<Constant> parse_constant(std::string_view type, std::string_view rest, const FieldType& t, const Where& at) {
  const auto eq = rest.find('=');
  Constant c;
  c.name = std::string(trim(rest.substr(0, eq)));
  c.type = t;
  std::string_view value = rest.substr(eq + 1);
  if (t.base != Base::String && t.base != Base::BoundedString && t.base != Base::WString &&
      t.base != Base::BoundedWString)
    value = value.substr(0, value.find('#'));
  c.value = std::string(trim(value));
  if (!is_constant_name(c.name))
    return std::unexpected(at.error(fmt::format("constant '{}' is not a valid name; expected upper case letters, "
                                                "digits and '_', a letter first",
                                                c.name)));
  if (t.base == Base::Nested || t.shape != Shape::Single)
    return std::unexpected(at.error(fmt::format("constant '{}' of type '{}': a constant is a single value of a "
                                                "primitive type or a string",
                                                c.name, type)));
  if (c.value.empty()) return std::unexpected(at.error(fmt::format("constant '{}' has no value", c.name)));
  return c;
}

// One line without its comment, not empty: a field or a constant into `m`.
Result<void> parse_line(std::string_view raw, std::string_view package, Message& m, const Where& at) {
  std::string_view line = trim(raw);
  const auto space = line.find_first_of(" \t");
  if (space == std::string_view::npos)
    return std::unexpected(at.error(fmt::format("'{}' has a type and no name; expected 'type name'", line)));
  const std::string_view type = line.substr(0, space);
  std::string_view rest = trim(line.substr(space));
  auto t = parse_type(type, package, at);
  if (!t) return std::unexpected(t.error());
  // A constant when its name is followed by '=' (rosidl_adapter's rule); a string's value may hold '#'.
  const bool text_value = t->base == Base::String || t->base == Base::BoundedString || t->base == Base::WString ||
                          t->base == Base::BoundedWString;
  const std::string_view code = text_value ? rest : rest.substr(0, rest.find('#'));
  if (code.find('=') != std::string_view::npos) {
    auto c = parse_constant(type, rest, *t, at);
    if (!c) return std::unexpected(c.error());
    m.constants.push_back(std::move(*c));
    return {};
  }
  rest = trim(rest.substr(0, rest.find('#')));
  Field f;
  const auto name_end = rest.find_first_of(" \t");
  f.name = std::string(rest.substr(0, name_end));
  if (name_end != std::string_view::npos) f.default_value = std::string(trim(rest.substr(name_end)));
  f.type = std::move(*t);
  if (!is_lower_name(f.name))
    return std::unexpected(at.error(fmt::format("field '{}' is not a valid name; expected lower case letters, "
                                                "digits and '_', a letter first, no '__', no '_' at the end",
                                                f.name)));
  for (const Field& other : m.fields)
    if (other.name == f.name) return std::unexpected(at.error(fmt::format("field '{}' is declared twice", f.name)));
  m.fields.push_back(std::move(f));
  return {};
}

}  // namespace

Result<TypeName> parse_type_name(std::string_view text) {
  TypeName n;
  const auto first = text.find('/');
  const auto last = text.rfind('/');
  if (first == std::string_view::npos)
    return fail(Errc::InvalidArgument,
                fmt::format("ROS 2 type '{}' has no package; expected pkg/msg/Name or pkg/Name", text));
  const std::string_view middle = first == last ? std::string_view("msg") : text.substr(first + 1, last - first - 1);
  n.package = std::string(text.substr(0, first));
  n.name = std::string(text.substr(last + 1));
  if (middle != "msg")
    return fail(Errc::InvalidArgument,
                fmt::format("ROS 2 type '{}' is not a message type; expected pkg/msg/Name or pkg/Name", text));
  if (!is_lower_name(n.package))
    return fail(Errc::InvalidArgument, fmt::format("ROS 2 type '{}': package '{}' is not a valid name; expected lower "
                                                   "case letters, digits and '_', a letter first",
                                                   text, n.package));
  if (!is_type_name(n.name))
    return fail(Errc::InvalidArgument, fmt::format("ROS 2 type '{}': '{}' is not a valid message name; expected "
                                                   "CamelCase letters and digits, a capital first",
                                                   text, n.name));
  return n;
}

Result<Message> parse_msg(std::string_view type_name, std::string_view text) {
  auto name = parse_type_name(type_name);
  if (!name) return std::unexpected(name.error());
  Message m;
  m.type_name = name->full();
  m.text = std::string(text);
  std::size_t line_no = 0;
  for (std::size_t start = 0; start <= text.size();) {
    auto end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(start, end - start);
    ++line_no;
    start = end + 1;
    const std::string_view code = trim(line.substr(0, line.find('#')));
    if (code.empty()) continue;
    if (auto ok = parse_line(line, name->package, m, {m.type_name, line_no}); !ok) return std::unexpected(ok.error());
  }
  // rosidl gives a message without fields the one uint8 field an IDL struct needs.
  if (m.fields.empty()) {
    Field only;
    only.name = "structure_needs_at_least_one_member";
    only.type.base = Base::Uint8;
    m.fields.push_back(std::move(only));
  }
  return m;
}

}  // namespace horus::ros2

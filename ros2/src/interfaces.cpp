// Type descriptions and type hashes (horus/ros2/interface.hpp), as rosidl_generator_type_description
// makes them: the description of a type and of every type it refers to, sorted by name, as JSON
// with Python's json.dumps separators and without default values, hashed with SHA-256.
#include <fmt/format.h>
#include <openssl/evp.h>

#include <set>
#include <utility>

#include "horus/ros2/interface.hpp"

namespace horus::ros2 {

namespace {

std::string_view primitive_name(Base b) {
  switch (b) {
    case Base::Int8: return "int8";
    case Base::Uint8: return "uint8";
    case Base::Int16: return "int16";
    case Base::Uint16: return "uint16";
    case Base::Int32: return "int32";
    case Base::Uint32: return "uint32";
    case Base::Int64: return "int64";
    case Base::Uint64: return "uint64";
    case Base::Float32: return "float32";
    case Base::Float64: return "float64";
    case Base::Bool: return "bool";
    case Base::Byte: return "byte";
    case Base::String:
    case Base::BoundedString: return "string";
    case Base::WString:
    case Base::BoundedWString: return "wstring";
    case Base::Nested: break;
  }
  return "";
}

// A JSON string as Python's json.dumps(ensure_ascii=True) writes it.
void append_json_string(std::string& out, std::string_view s) {
  out += '"';
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      default:
        if (c < 0x20 || c >= 0x7f) {
          out += fmt::format("\\u{:04x}", c);
        } else {
          out += ch;
        }
    }
  }
  out += '"';
}

void append_description(std::string& out, const Message& m) {
  out += "{\"type_name\": ";
  append_json_string(out, m.type_name);
  out += ", \"fields\": [";
  for (std::size_t i = 0; i < m.fields.size(); ++i) {
    const Field& f = m.fields[i];
    if (i != 0) out += ", ";
    out += "{\"name\": ";
    append_json_string(out, f.name);
    out += fmt::format(", \"type\": {{\"type_id\": {}, \"capacity\": {}, \"string_capacity\": {}, \"nested_type_name\": ",
                       f.type.type_id(), f.type.capacity, f.type.string_capacity);
    append_json_string(out, f.type.nested);
    out += "}}";
  }
  out += "]}";
}

std::string sha256_hex(std::string_view bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  EVP_Digest(bytes.data(), bytes.size(), digest, &size, EVP_sha256(), nullptr);
  std::string hex;
  hex.reserve(size * 2);
  for (unsigned int i = 0; i < size; ++i) hex += fmt::format("{:02x}", digest[i]);
  return hex;
}

}  // namespace

int FieldType::type_id() const noexcept {
  const int base_id = static_cast<int>(base);
  switch (shape) {
    case Shape::Single: return base_id;
    case Shape::Array: return base_id + 48;
    case Shape::BoundedSequence: return base_id + 96;
    case Shape::Sequence: return base_id + 144;
  }
  return base_id;
}

std::string FieldType::to_msg() const {
  std::string out;
  if (base == Base::Nested) {
    auto n = parse_type_name(nested);
    out = n ? n->package + "/" + n->name : nested;
  } else {
    out = std::string(primitive_name(base));
    if (base == Base::BoundedString || base == Base::BoundedWString) out += fmt::format("<={}", string_capacity);
  }
  switch (shape) {
    case Shape::Single: break;
    case Shape::Array: out += fmt::format("[{}]", capacity); break;
    case Shape::BoundedSequence: out += fmt::format("[<={}]", capacity); break;
    case Shape::Sequence: out += "[]"; break;
  }
  return out;
}

Result<void> Interfaces::add(std::string_view type_name, std::string_view msg_text) {
  auto m = parse_msg(type_name, msg_text);
  if (!m) return std::unexpected(m.error());
  if (types_.contains(m->type_name))
    return fail(Errc::InvalidArgument, fmt::format("ROS 2 type '{}' is defined twice", m->type_name));
  std::string key = m->type_name;
  types_.emplace(std::move(key), std::move(*m));
  return {};
}

const Message* Interfaces::find(std::string_view type_name) const {
  auto name = parse_type_name(type_name);
  if (!name) return nullptr;
  auto it = types_.find(name->full());
  return it == types_.end() ? nullptr : &it->second;
}

std::vector<std::string> Interfaces::names() const {
  std::vector<std::string> out;
  for (const auto& [name, m] : types_) out.push_back(name);
  return out;
}

Result<std::vector<std::string>> Interfaces::references(std::string_view type_name) const {
  const Message* top = find(type_name);
  if (top == nullptr)
    return fail(Errc::InvalidArgument, fmt::format("ROS 2 type '{}' is not known (horus knows {} types; `horus idl --ros2` "
                                            "lists them)",
                                            type_name, types_.size()));
  std::set<std::string> seen;
  std::vector<const Message*> queue{top};
  while (!queue.empty()) {
    const Message* m = queue.back();
    queue.pop_back();
    for (const Field& f : m->fields) {
      if (f.type.base != Base::Nested || !seen.insert(f.type.nested).second) continue;
      const Message* next = find(f.type.nested);
      if (next == nullptr)
        return fail(Errc::InvalidArgument, fmt::format("ROS 2 type '{}' refers to '{}' (field '{}' of {}), which is not known",
                                                top->type_name, f.type.nested, f.name, m->type_name));
      queue.push_back(next);
    }
  }
  return std::vector<std::string>(seen.begin(), seen.end());
}

Result<std::string> Interfaces::hashed_description(std::string_view type_name) const {
  auto refs = references(type_name);
  if (!refs) return std::unexpected(refs.error());
  std::string out = "{\"type_description\": ";
  append_description(out, *find(type_name));
  out += ", \"referenced_type_descriptions\": [";
  for (std::size_t i = 0; i < refs->size(); ++i) {
    if (i != 0) out += ", ";
    append_description(out, *find((*refs)[i]));
  }
  out += "]}";
  return out;
}

Result<std::string> Interfaces::type_hash(std::string_view type_name) const {
  auto description = hashed_description(type_name);
  if (!description) return std::unexpected(description.error());
  return "RIHS01_" + sha256_hex(*description);
}

Result<std::string> Interfaces::message_definition(std::string_view type_name) const {
  auto refs = references(type_name);
  if (!refs) return std::unexpected(refs.error());
  std::string out = find(type_name)->text;
  // As rosbag2 (Jazzy) writes it, which Foxglove's ROS 2 parser reads: a newline after the
  // text, the separator line, "MSG: pkg/Name" (the name as fields write it, without "msg/").
  for (const std::string& r : *refs) {
    const auto t = parse_type_name(r);
    out += "\n" + std::string(80, '=') + "\nMSG: " + (t ? t->package + "/" + t->name : r) + "\n" + find(r)->text;
  }
  return out;
}

std::string user_data_of(std::string_view type_hash) { return fmt::format("typehash={};", type_hash); }

std::string type_hash_in(std::string_view user_data) {
  constexpr std::string_view kKey = "typehash=";
  for (std::size_t at = user_data.find(kKey); at != std::string_view::npos; at = user_data.find(kKey, at + 1)) {
    if (at != 0 && user_data[at - 1] != ';') continue;
    const std::string_view value = user_data.substr(at + kKey.size(), user_data.find(';', at) - at - kKey.size());
    if (value.size() == 7 + 64 && value.starts_with("RIHS01_")) return std::string(value);
  }
  return {};
}

}  // namespace horus::ros2

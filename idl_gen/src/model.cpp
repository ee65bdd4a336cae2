#include "horus/idlgen/model.hpp"

#include <cctype>
#include <memory>
#include <stdexcept>

namespace horus::idlgen {

void Model::build() const {
  // A builder may add nothing new to pending_ (nested types are built directly), so a plain loop is safe.
  auto pending = std::move(pending_);
  pending_.clear();
  for (auto& b : pending) b();
}

void Model::note_file(const std::string& file) const {
  for (const auto& f : files_)
    if (f == file) return;
  files_.push_back(file);
}

void Model::check_file_name(std::string_view file) {
  bool ok = !file.empty() && file.size() <= 64 && (std::isalpha(static_cast<unsigned char>(file[0])) != 0);
  for (char c : file) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_');
  if (!ok)
    throw std::invalid_argument("horus-idlgen: file name '" + std::string(file) +
                                "' is not valid; expected 1 to 64 letters, digits or '_', starting with a letter");
}

void Model::check_type_name(const std::string& name) {
  // Interface types need a plain qualified name: ns::ns::Name (no template arguments, no
  // anonymous or inline-namespace decorations, no leading digit in a part).
  const auto parts = module_path(name);
  bool ok = true;
  std::string_view rest = name;
  std::size_t start = 0;
  while (ok) {
    const auto end = rest.find("::", start);
    const std::string_view part = rest.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start);
    ok = !part.empty() && (std::isalpha(static_cast<unsigned char>(part[0])) != 0 || part[0] == '_');
    for (char c : part) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_');
    if (end == std::string_view::npos) break;
    start = end + 2;
  }
  if (!ok || parts.empty())
    throw std::invalid_argument("horus-idlgen: type '" + name +
                                "' has no interface name; expected a struct in a named namespace (my_robot::msgs::Foo), "
                                "not a template, a local or an anonymous-namespace type (or give it one with "
                                "HORUS_REFLECT_NAMED)");
}

void Model::add(const wire::DynType& type, std::string_view file) {
  check_file_name(file);
  if (type.kind != wire::DynType::Kind::Struct)
    throw std::invalid_argument("horus-idlgen: the root type of file '" + std::string(file) +
                                "' must be a struct, not a field type");
  check_type_name(type.name);
  build();
  if (roots_.contains(type.name)) return;
  roots_.emplace(type.name, std::string(file));
  note_file(std::string(file));
  if (!structs_index_.contains(type.name)) dynamic_struct(type, std::string(file));
}

void Model::dynamic_struct(const wire::DynType& t, const std::string& file) {
  if (building_.contains(t.name)) throw std::invalid_argument("horus-idlgen: type " + t.name + " contains itself");
  building_.emplace(t.name);
  StructDef def;
  def.name = t.name;
  def.file = file;
  for (std::size_t i = 0; i < t.children.size() && i < t.field_names.size(); ++i)
    def.fields.push_back(FieldDef{t.field_names[i], dynamic_ref(t.children[i], file)});
  building_.erase(t.name);
  note_file(file);
  structs_index_.emplace(def.name, structs_.size());
  structs_.push_back(std::move(def));
}

TypeRef Model::dynamic_ref(const wire::DynType& t, const std::string& file) {
  using K = wire::DynType::Kind;
  TypeRef r;
  switch (t.kind) {
    case K::Bool: r.prim = Prim::Bool; break;
    case K::Char: r.prim = Prim::Char; break;
    case K::Int: r.prim = integer_prim(t.size, t.is_signed); break;
    case K::Float: r.prim = t.size == 4 ? Prim::Float32 : Prim::Float64; break;
    case K::Enum:
      if (t.idl_enum()) {
        r.kind = TypeRef::Kind::Enum;
        r.name = t.name;
        check_type_name(r.name);
        if (!enums_index_.contains(r.name)) {
          EnumDef def;
          def.name = r.name;
          def.file = file;
          for (const auto& [name, value] : t.enumerators) def.enumerators.push_back(name);
          note_file(file);
          enums_index_.emplace(def.name, enums_.size());
          enums_.push_back(std::move(def));
        }
      } else {
        r.prim = integer_prim(t.size, t.is_signed);
      }
      break;
    case K::String: r.kind = TypeRef::Kind::String; break;
    case K::Array:
    case K::Sequence:
      if (t.children.size() != 1) throw std::invalid_argument("horus-idlgen: an array or sequence without an element type");
      r.kind = t.kind == K::Array ? TypeRef::Kind::Array : TypeRef::Kind::Sequence;
      r.length = static_cast<std::size_t>(t.length);
      r.element = std::make_shared<const TypeRef>(dynamic_ref(t.children[0], file));
      break;
    case K::Struct:
      r.kind = TypeRef::Kind::Struct;
      r.name = t.name;
      check_type_name(r.name);
      if (!structs_index_.contains(r.name)) {
        auto root = roots_.find(r.name);
        dynamic_struct(t, root != roots_.end() ? root->second : file);
      }
      break;
  }
  return r;
}

const StructDef* Model::find_struct(std::string_view name) const {
  build();
  auto it = structs_index_.find(name);
  return it == structs_index_.end() ? nullptr : &structs_[it->second];
}

const EnumDef* Model::find_enum(std::string_view name) const {
  build();
  auto it = enums_index_.find(name);
  return it == enums_index_.end() ? nullptr : &enums_[it->second];
}

std::vector<std::string> module_path(std::string_view qualified) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    const auto end = qualified.find("::", start);
    if (end == std::string_view::npos) break;
    parts.emplace_back(qualified.substr(start, end - start));
    start = end + 2;
  }
  return parts;
}

std::string_view short_name(std::string_view qualified) noexcept {
  const auto pos = qualified.rfind("::");
  return pos == std::string_view::npos ? qualified : qualified.substr(pos + 2);
}

}  // namespace horus::idlgen

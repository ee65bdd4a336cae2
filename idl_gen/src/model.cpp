#include "horus/idlgen/model.hpp"

#include <cctype>

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

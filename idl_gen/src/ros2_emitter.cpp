// ROS 2 interface package emitter (see emit.hpp): package.xml, CMakeLists.txt and one .msg per
// struct of the model, each field the .msg type whose CDR bytes are the field's XCDR1 bytes (so a
// ROS 2 node built with the package reads what horus writes on the DDS wire).
#include <fmt/format.h>

#include <cctype>
#include <map>
#include <set>
#include <stdexcept>

#include "horus/idlgen/emit.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/wire/dynamic.hpp"

namespace horus::idlgen {
namespace {

std::string_view msg_prim(Prim p) {
  switch (p) {
    case Prim::Bool: return "bool";
    case Prim::Char: return "char";  // a uint8 in ROS 2's IDL: one byte, as an IDL char
    case Prim::Int8: return "int8";
    case Prim::Uint8: return "uint8";
    case Prim::Int16: return "int16";
    case Prim::Uint16: return "uint16";
    case Prim::Int32: return "int32";
    case Prim::Uint32: return "uint32";
    case Prim::Int64: return "int64";
    case Prim::Uint64: return "uint64";
    case Prim::Float32: return "float32";
    case Prim::Float64: return "float64";
  }
  return "?";
}

// "DriveMode" -> "DRIVE_MODE", "Ok" -> "OK", "ImuV2" -> "IMU_V2".
std::string upper_snake(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    const bool boundary = i != 0 && std::isupper(c) && (std::islower(static_cast<unsigned char>(s[i - 1])) ||
                                                         (i + 1 < s.size() && std::islower(static_cast<unsigned char>(s[i + 1])) &&
                                                          std::isupper(static_cast<unsigned char>(s[i - 1]))));
    if (boundary && out.back() != '_') out += '_';
    out += static_cast<char>(std::toupper(c));
  }
  return out;
}

bool valid_field_name(std::string_view s) {  // ROS 2's rule for a field: [a-z][a-z0-9_]*, no "__", no '_' last
  if (s.empty() || !std::islower(static_cast<unsigned char>(s.front())) || s.back() == '_' ||
      s.find("__") != std::string_view::npos)
    return false;
  for (char c : s)
    if (!std::islower(static_cast<unsigned char>(c)) && !std::isdigit(static_cast<unsigned char>(c)) && c != '_')
      return false;
  return true;
}

class PackageEmitter {
 public:
  PackageEmitter(const Model& model, const Ros2Options& options) : model_(model), options_(options) {}

  std::vector<OutputFile> run() {
    check_package();
    for (const auto& s : model_.structs()) {
      const std::string name(short_name(s.name));
      if (auto [it, fresh] = names_.emplace(name, s.name); !fresh)
        throw std::invalid_argument("horus-idlgen: " + s.name + " and " + it->second + " would both be " +
                                    options_.package + "/msg/" + name + "; a ROS 2 package has one type per name");
    }
    std::vector<OutputFile> out;
    std::vector<std::string> msgs;
    for (const auto& s : model_.structs()) {
      if (auto why = inexpressible(s); !why.empty()) {
        skipped_.push_back(s.name + ": " + why);
        continue;
      }
      const std::string file = "msg/" + std::string(short_name(s.name)) + ".msg";
      out.push_back({file, msg_text(s)});
      msgs.push_back(file);
    }
    out.push_back({"package.xml", package_xml()});
    out.push_back({"CMakeLists.txt", cmake_lists(msgs)});
    return out;
  }

 private:
  void check_package() const {
    if (!horus::ros2::parse_type_name(options_.package + "/msg/Check"))
      throw std::invalid_argument("horus-idlgen: '" + options_.package +
                                  "' is not a ROS 2 package name; expected lower case letters, digits and '_', a "
                                  "letter first");
  }

  // Why a struct has no .msg (empty: it has one): ROS 2 has no sequence of sequences, and a
  // struct that uses a struct without a .msg has none either.
  std::string inexpressible(const StructDef& s) const {
    for (const auto& f : s.fields) {
      if (flat_length(f.type) != 0) continue;  // fixed arrays of fixed arrays of a primitive: one array
      const TypeRef* t = &f.type;
      bool in_collection = false;
      while (t->kind == TypeRef::Kind::Sequence || t->kind == TypeRef::Kind::Array) {
        if (in_collection) return "field '" + f.name + "' is a collection of collections, which a .msg cannot express";
        in_collection = true;
        t = t->element.get();
      }
      if (t->kind == TypeRef::Kind::Struct) {
        const StructDef* inner = model_.find_struct(t->name);
        if (inner != nullptr && !inexpressible(*inner).empty()) return "field '" + f.name + "' is a " + t->name + ", which has no .msg";
      }
    }
    return {};
  }

  // A fixed array of fixed arrays (of ...) of a primitive holds its values one after the other
  // in CDR, as one array of them all does: its total length, or 0 for any other type.
  static std::size_t flat_length(const TypeRef& t) {
    if (t.kind != TypeRef::Kind::Array || t.element->kind != TypeRef::Kind::Array) return 0;
    std::size_t n = 1;
    const TypeRef* e = &t;
    for (; e->kind == TypeRef::Kind::Array; e = e->element.get()) n *= e->length;
    return e->kind == TypeRef::Kind::Primitive ? n : 0;
  }
  static const TypeRef& innermost(const TypeRef& t) {
    const TypeRef* e = &t;
    while (e->kind == TypeRef::Kind::Array) e = e->element.get();
    return *e;
  }

  std::string type_text(const TypeRef& t, std::vector<std::string>& enums) const {
    if (const std::size_t n = flat_length(t); n != 0)
      return std::string(msg_prim(innermost(t).prim)) + "[" + std::to_string(n) + "]";
    switch (t.kind) {
      case TypeRef::Kind::Primitive: return std::string(msg_prim(t.prim));
      case TypeRef::Kind::String: return "string";
      case TypeRef::Kind::Enum:
        if (std::find(enums.begin(), enums.end(), t.name) == enums.end()) enums.push_back(t.name);
        return "uint32";  // an IDL enum is 4 bytes in XCDR1; its values are the .msg's constants
      case TypeRef::Kind::Struct: return std::string(short_name(t.name));
      case TypeRef::Kind::Sequence: return type_text(*t.element, enums) + "[]";
      case TypeRef::Kind::Array: return type_text(*t.element, enums) + "[" + std::to_string(t.length) + "]";
    }
    return "?";
  }

  static std::string dims_text(const TypeRef& t) {  // "16 x char[32]"
    std::string out;
    const TypeRef* e = &t;
    for (; e->element->kind == TypeRef::Kind::Array; e = e->element.get()) out += std::to_string(e->length) + " x ";
    return out + std::string(msg_prim(e->element->prim)) + "[" + std::to_string(e->element->length) + "]";
  }

  std::string msg_text(const StructDef& s) const {
    std::string fields;
    std::vector<std::string> enums;
    std::set<std::string> used;
    for (const auto& f : s.fields) used.insert(f.name);
    for (const auto& f : s.fields) {
      // A padding field (`_pad`) is `reserved_pad`: ROS 2 names start with a letter. The wire is
      // positional, so the name is only what a ROS 2 program calls the field.
      const std::string name = f.name.starts_with('_') ? "reserved" + f.name : f.name;
      if (!valid_field_name(name))
        throw std::invalid_argument("horus-idlgen: " + s.name + "." + f.name +
                                    ": not a ROS 2 field name; expected lower case letters, digits and '_', a letter "
                                    "first, no '__' and no '_' at the end");
      if (name != f.name && used.contains(name))
        throw std::invalid_argument("horus-idlgen: " + s.name + "." + f.name + " would be '" + name +
                                    "' in ROS 2, the name of another field");
      if (flat_length(f.type) != 0) fields += "# " + name + ": " + dims_text(f.type) + ", one after the other\n";
      fields += type_text(f.type, enums) + " " + name + "\n";
    }
    std::string text = "# " + s.name + " (horus), generated by horus-idlgen: do not edit.\n";
    for (const auto& e : enums) {
      const EnumDef* def = model_.find_enum(e);
      if (def == nullptr) continue;
      text += "\n# " + e + "\n";
      const std::string prefix = upper_snake(short_name(e));
      for (std::size_t i = 0; i < def->enumerators.size(); ++i)
        text += "uint32 " + prefix + "_" + upper_snake(def->enumerators[i]) + "=" + std::to_string(i) + "\n";
    }
    return text + "\n" + fields;
  }

  std::string package_xml() const {
    return "<?xml version=\"1.0\"?>\n"
           "<?xml-model href=\"http://download.ros.org/schema/package_format3.xsd\" "
           "schematypens=\"http://www.w3.org/2001/XMLSchema\"?>\n"
           "<package format=\"3\">\n"
           "  <name>" + options_.package + "</name>\n"
           "  <version>" + options_.version + "</version>\n"
           "  <description>horus messages as ROS 2 interfaces (generated by horus-idlgen; their CDR bytes are "
           "horus's on the DDS wire)</description>\n"
           "  <maintainer email=\"" + options_.maintainer_email + "\">" + options_.maintainer + "</maintainer>\n"
           "  <license>" + options_.license + "</license>\n"
           "  <buildtool_depend>ament_cmake</buildtool_depend>\n"
           "  <buildtool_depend>rosidl_default_generators</buildtool_depend>\n"
           "  <exec_depend>rosidl_default_runtime</exec_depend>\n"
           "  <member_of_group>rosidl_interface_packages</member_of_group>\n"
           "  <export>\n    <build_type>ament_cmake</build_type>\n  </export>\n"
           "</package>\n";
  }

  std::string cmake_lists(const std::vector<std::string>& msgs) const {
    std::string text = "# Generated by horus-idlgen: do not edit. Build with colcon in a ROS 2 workspace.\n";
    for (const auto& s : skipped_) text += "# No .msg: " + s + "\n";
    text += "cmake_minimum_required(VERSION 3.8)\nproject(" + options_.package +
            ")\nfind_package(ament_cmake REQUIRED)\nfind_package(rosidl_default_generators REQUIRED)\n"
            "rosidl_generate_interfaces(${PROJECT_NAME}\n";
    for (const auto& m : msgs) text += "  \"" + m + "\"\n";
    return text + ")\nament_export_dependencies(rosidl_default_runtime)\nament_package()\n";
  }

  const Model& model_;
  const Ros2Options& options_;
  std::map<std::string, std::string> names_;  // short name -> qualified
  std::vector<std::string> skipped_;
};

}  // namespace

std::vector<OutputFile> emit_ros2(const Model& model, const Ros2Options& options) {
  return PackageEmitter(model, options).run();
}

std::string ros2_type_name(std::string_view qualified, const Ros2Options& options) {
  return options.package + "/msg/" + std::string(short_name(qualified));
}

Result<Ros2Type> ros2_type_of(const wire::DynType& root, const Ros2Options& options) {
  Ros2Type out;
  out.name = ros2_type_name(root.name, options);
  std::vector<OutputFile> files;
  try {
    Model model;
    model.add(root, "types");
    files = emit_ros2(model, options);
  } catch (const std::exception& e) {
    return fail(Errc::InvalidArgument, fmt::format("{} has no ROS 2 type: {}", root.name, e.what()));
  }
  std::string skipped;
  for (const auto& f : files) {
    if (f.name == "CMakeLists.txt") {
      for (std::size_t at = f.text.find("# No .msg: "); at != std::string::npos; at = f.text.find("# No .msg: ", at + 1))
        skipped += (skipped.empty() ? "" : "; ") + f.text.substr(at + 11, f.text.find('\n', at) - at - 11);
    }
    if (!f.name.starts_with("msg/")) continue;
    if (auto ok = out.types.add(options.package + "/msg/" + f.name.substr(4, f.name.size() - 8), f.text); !ok)
      return std::unexpected(ok.error());
  }
  if (out.types.find(out.name) == nullptr)
    return fail(Errc::InvalidArgument, fmt::format("{} has no ROS 2 type in package {}: {}", root.name, options.package,
                                                   skipped.empty() ? "the package left it out" : skipped));
  auto hash = out.types.type_hash(out.name);
  if (!hash) return std::unexpected(hash.error());
  out.type_hash = *hash;
  return out;
}

Result<Ros2Mapped> ros2_mapped_type(std::string_view type_name, std::uint64_t type_hash, std::string_view signature,
                                    std::string_view requested) {
  std::string wanted;
  Ros2Options options;
  if (!requested.empty()) {
    auto t = ros2::parse_type_name(requested);
    if (!t) return std::unexpected(t.error());
    wanted = t->full();
    options.package = t->package;
  }
  Ros2Mapped out;
  const auto& standard = ros2::Interfaces::standard();
  out.conversion = ros2::find_conversion(type_hash, wanted);
  if (out.conversion != nullptr) {
    out.type = std::string(out.conversion->ros_type);
    auto hash = standard.type_hash(out.type);
    if (!hash) return std::unexpected(hash.error());
    auto definition = standard.message_definition(out.type);
    if (!definition) return std::unexpected(definition.error());
    out.type_hash = std::move(*hash);
    out.definition = std::move(*definition);
    return out;
  }
  if (!wanted.empty() && standard.find(wanted) != nullptr) {
    const std::string targets = ros2::conversion_targets(type_hash);
    return fail(Errc::Config, fmt::format("{} does not convert to {}; {}", type_name, wanted,
                                          targets.empty() ? "it has no ROS 2 equivalent (leave out `type:` to map it "
                                                            "as its own type of the horus_msgs package)"
                                                          : "it converts to " + targets));
  }
  auto dyn = wire::parse_signature(signature, type_hash);
  if (signature.empty() || !dyn)
    return fail(Errc::Config, fmt::format("{} has no ROS 2 type: its layout is not known here ({})", type_name,
                                          dyn ? "no signature" : dyn.error()));
  auto own = ros2_type_of(*dyn, options);
  if (!own) return fail(Errc::Config, own.error().message());
  if (!wanted.empty() && wanted != own->name)
    return fail(Errc::Config,
                fmt::format("{} is {} in package {}, not {}", type_name, own->name, options.package, wanted));
  auto definition = own->types.message_definition(own->name);
  if (!definition) return std::unexpected(definition.error());
  out.type = std::move(own->name);
  out.type_hash = std::move(own->type_hash);
  out.definition = std::move(*definition);
  return out;
}

}  // namespace horus::idlgen

// LCM type emitter (see emit.hpp and horus/wire/lcm_mapping.hpp).
#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>

#include "horus/idlgen/emit.hpp"
#include "horus/wire/lcm_mapping.hpp"

namespace horus::idlgen {
namespace {
namespace map = lcm;

constexpr std::size_t kMaxNameLength = 64;  // lcm-gen -c overflows a buffer near 114
constexpr std::string_view kNoLcmType = "no LCM type: ";

std::string_view lcm_prim(Prim p) {
  switch (p) {
    case Prim::Bool: return map::kBoolean;
    case Prim::Char: return map::kByte;
    case Prim::Int8: return map::integer_type(1, true);
    case Prim::Uint8: return map::integer_type(1, false);
    case Prim::Int16: return map::integer_type(2, true);
    case Prim::Uint16: return map::integer_type(2, false);
    case Prim::Int32: return map::integer_type(4, true);
    case Prim::Uint32: return map::integer_type(4, false);
    case Prim::Int64: return map::integer_type(8, true);
    case Prim::Uint64: return map::integer_type(8, false);
    case Prim::Float32: return map::kFloat;
    case Prim::Float64: return map::kDouble;
  }
  return "?";
}

// What a widened or reinterpreted field was in C++ (a comment in the .lcm file).
std::string_view cxx_note(Prim p) {
  switch (p) {
    case Prim::Char: return "char";
    case Prim::Uint8: return "uint8";
    case Prim::Uint16: return "uint16";
    case Prim::Uint32: return "uint32";
    case Prim::Uint64: return "uint64, same bits";
    default: return {};
  }
}

std::string hex(std::uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof(buf), "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// One member of an LCM struct, as emitted and as hashed.
struct Member {
  std::string name;
  std::string type;         // primitive name, or "pkg.Struct"
  bool primitive = true;
  std::string struct_name;  // qualified C++ name of a struct type
  std::vector<std::pair<bool, std::string>> dims;  // (variable, size text)
  std::string note;
};

class Lowering {
 public:
  explicit Lowering(const Model& model) : model_(model) {}

  // The members of s in LCM terms; throws std::invalid_argument for what LCM cannot express.
  std::vector<Member> members(const StructDef& s) const {
    std::vector<Member> out;
    std::set<std::string> names;
    auto add = [&](Member m) {
      if (m.name.size() > kMaxNameLength)
        throw std::invalid_argument("horus-idlgen: " + s.name + "." + m.name + ": LCM member names are kept to " +
                                    std::to_string(kMaxNameLength) + " characters (lcm-gen's C emitter fails beyond)");
      if (!names.insert(m.name).second)
        throw std::invalid_argument("horus-idlgen: " + s.name + " has two LCM members named '" + m.name +
                                    "' (a variable-size field <f> brings a length member num_<f>); rename one");
      out.push_back(std::move(m));
    };
    for (const auto& f : s.fields) {
      const auto mn = map::member_name(f.name);
      Member m;
      m.name = std::string(mn.field) + std::string(mn.suffix());
      const TypeRef* t = &f.type;
      if (t->kind == TypeRef::Kind::Sequence) {
        Member len;
        len.name = std::string(map::kLengthPrefix) + f.name;
        len.type = std::string(map::kInt32);
        len.note = "the length of " + m.name;
        add(std::move(len));
        m.dims.emplace_back(true, std::string(map::kLengthPrefix) + f.name);
        t = t->element.get();
      }
      while (t->kind == TypeRef::Kind::Array) {
        if (t->length == 0)
          throw std::invalid_argument("horus-idlgen: " + s.name + "." + f.name +
                                      ": an array of size 0; LCM array sizes must be at least 1");
        m.dims.emplace_back(false, std::to_string(t->length));
        t = t->element.get();
      }
      switch (t->kind) {
        case TypeRef::Kind::Primitive:
          m.type = std::string(lcm_prim(t->prim));
          m.note = std::string(cxx_note(t->prim));
          break;
        case TypeRef::Kind::String: m.type = std::string(map::kString); break;
        case TypeRef::Kind::Enum:
          m.type = std::string(map::kInt32);
          m.note = "enum " + lcm_type_name(t->name);
          break;
        case TypeRef::Kind::Struct:
          m.primitive = false;
          m.type = lcm_type_name(t->name);
          m.struct_name = t->name;
          break;
        case TypeRef::Kind::Sequence:
        case TypeRef::Kind::Array:
          throw std::invalid_argument("horus-idlgen: " + s.name + "." + f.name +
                                      ": a variable-size array inside an array; LCM cannot express it (its "
                                      "multi-dimensional arrays are rectangular): wrap the inner array in a struct");
      }
      add(std::move(m));
    }
    return out;
  }

  std::uint64_t fingerprint(const std::string& type) const {
    if (auto it = cache_.find(type); it != cache_.end()) return it->second;
    const StructDef* s = model_.find_struct(type);
    if (s == nullptr) throw std::invalid_argument("horus-idlgen: no struct " + type + " in the model");
    if (!on_stack_.insert(type).second) return 0;  // lcm-gen's cycle guard
    std::int64_t v = map::kHashSeed;
    std::uint64_t nested = 0;
    for (const auto& m : members(*s)) {
      v = map::hash_string(v, m.name);
      if (m.primitive) v = map::hash_string(v, m.type);
      v = map::hash_update(v, static_cast<char>(m.dims.size()));
      for (const auto& [variable, size] : m.dims) {
        v = map::hash_update(v, variable ? 1 : 0);
        v = map::hash_string(v, size);
      }
      if (!m.primitive) nested += fingerprint(m.struct_name);
    }
    on_stack_.erase(type);
    const std::uint64_t fp = map::hash_finish(v, nested);
    cache_.emplace(type, fp);
    return fp;
  }

 private:
  const Model& model_;
  mutable std::map<std::string, std::uint64_t, std::less<>> cache_;
  mutable std::set<std::string, std::less<>> on_stack_;
};

class LcmFileEmitter {
 public:
  LcmFileEmitter(const Model& model, const std::string& file, std::vector<Definition>* definitions)
      : model_(model), lowering_(model), file_(file), definitions_(definitions) {}

  std::string run() {
    std::string body;
    for (const auto& e : model_.enums())
      if (e.file == file_) body += in_package(e.name) + record(e.name, enum_text(e));
    for (const auto& s : model_.structs()) {
      if (s.file != file_) continue;
      std::string text;
      try {
        text = struct_text(s);
      } catch (const std::invalid_argument& e) {
        // Not an LCM type (the .idl still has it): said in the file, and by horus-idlgen.
        std::string why = e.what();
        if (why.rfind("horus-idlgen: ", 0) == 0) why.erase(0, 14);
        body += "\n// " + std::string(kNoLcmType) + why + "\n";
        continue;
      }
      body += in_package(s.name) + record(s.name, text);
    }
    std::string out;
    out += "// " + file_ + ".lcm: horus LCM types (interface version " + std::to_string(kInterfaceVersion) + ").\n";
    out += "// Generated by horus-idlgen from the C++ message reflection; do not edit.\n";
    out += "// LCM has no unsigned integers: uint16 travels as int32_t, uint32 as int64_t, uint64 as\n";
    out += "// int64_t (same bits); char and uint8 as byte. Enums are int32_t, their values the constants\n";
    out += "// of a struct of the enum's name. A variable-size array's length is its num_<field> member.\n";
    out += body;
    return out;
  }

 private:
  const std::string& record(const std::string& name, const std::string& text) {
    if (definitions_ != nullptr) definitions_->push_back(Definition{lcm_type_name(name), file_ + ".lcm", text});
    return text;
  }

  std::string in_package(const std::string& qualified) {
    const std::string pkg = lcm_package(qualified);
    if (pkg == package_) return "\n";
    package_ = pkg;
    if (pkg.empty())
      throw std::invalid_argument("horus-idlgen: " + qualified + " is in no namespace; LCM types need a package "
                                  "(lcm-gen -j warns without one): declare the message in a namespace");
    return "\npackage " + pkg + ";\n\n";
  }

  std::string enum_text(const EnumDef& e) {
    std::string out = "// " + e.name + ": the values of its int32_t fields.\n";
    out += "struct " + std::string(short_name(e.name)) + "\n{\n";
    for (std::size_t i = 0; i < e.enumerators.size(); ++i) {
      const auto n = map::member_name(e.enumerators[i]);
      out += "    const int32_t " + std::string(n.field) + std::string(n.suffix()) + " = " + std::to_string(i) + ";\n";
    }
    out += "}\n";
    return out;
  }

  std::string struct_text(const StructDef& s) {
    std::string out = "// " + s.name + ", fingerprint " + hex(lowering_.fingerprint(s.name)) + "\n";
    out += "struct " + std::string(short_name(s.name)) + "\n{\n";
    for (const auto& m : lowering_.members(s)) {
      std::string line = "    " + m.type + " " + m.name;
      for (const auto& d : m.dims) line += "[" + d.second + "]";
      line += ";";
      if (!m.note.empty()) line += std::string(std::max<std::size_t>(1, 44 - std::min<std::size_t>(line.size(), 44)), ' ') + "// " + m.note;
      out += line + "\n";
    }
    out += "}\n";
    return out;
  }

  const Model& model_;
  Lowering lowering_;
  const std::string& file_;
  std::string package_;
  std::vector<Definition>* definitions_;
};

}  // namespace

std::string lcm_package(std::string_view qualified) {
  std::string out;
  for (const auto& p : module_path(qualified)) out += (out.empty() ? "" : "_") + p;
  return out;
}

std::string lcm_type_name(std::string_view qualified) {
  const std::string pkg = lcm_package(qualified);
  return pkg.empty() ? std::string(short_name(qualified)) : pkg + "." + std::string(short_name(qualified));
}

std::uint64_t lcm_fingerprint(const Model& model, std::string_view type) {
  model.structs();
  return Lowering(model).fingerprint(std::string(type));
}

std::vector<OutputFile> emit_lcm(const Model& model, const IdlOptions& options) {
  std::vector<OutputFile> out;
  model.structs();
  for (const auto& file : model.files())
    if (options.wants(file)) out.push_back(OutputFile{file + ".lcm", LcmFileEmitter(model, file, nullptr).run()});
  return out;
}

std::vector<Definition> lcm_definitions(const Model& model, const IdlOptions& options) {
  std::vector<Definition> out;
  model.structs();
  for (const auto& file : model.files())
    if (options.wants(file)) LcmFileEmitter(model, file, &out).run();
  return out;
}

}  // namespace horus::idlgen

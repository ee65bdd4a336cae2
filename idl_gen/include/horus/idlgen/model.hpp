// The type tree horus-idlgen builds from the reflection: the first of its three steps
// (reflect, build this model, run one emitter per output format).
//
//   horus::idlgen::Model model;
//   model.add<horus::msg::Pose2D>("geometry");          // a root type, in file "geometry"
//   auto files = horus::idlgen::emit_idl(model);        // {"geometry.idl", text}, ...
//
// Types a root refers to (nested structs, enums) join the model too; a nested type is
// defined in the file of the first root that needs it, unless it is itself a root of
// another file. Adding the same type twice is harmless.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "horus/reflect.hpp"
#include "horus/wire/dynamic.hpp"
#include "horus/wire/mapping.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::idlgen {

/// Wire primitives (see mapping.hpp).
enum class Prim : std::uint8_t { Bool, Char, Int8, Uint8, Int16, Uint16, Int32, Uint32, Int64, Uint64, Float32, Float64 };

/// A field's type.
struct TypeRef {
  enum class Kind : std::uint8_t { Primitive, String, Sequence, Array, Enum, Struct };
  Kind kind = Kind::Primitive;
  Prim prim = Prim::Bool;                  // Primitive
  std::size_t length = 0;                  // Array
  std::shared_ptr<const TypeRef> element;  // Sequence, Array
  std::string name;                        // Enum, Struct: the qualified name ("horus::msg::Pose2D")
};

struct FieldDef {
  std::string name;
  TypeRef type;
};

struct StructDef {
  std::string name;  // qualified
  std::vector<FieldDef> fields;
  std::string file;  // the file that defines it
};

struct EnumDef {
  std::string name;  // qualified
  std::vector<std::string> enumerators;  // values 0..N-1
  std::string file;
};

/// The reflected types of one run, in definition order (a type after everything it uses).
class Model {
 public:
  /// Adds T (a reflected message) as a root of `file`, with every type it refers to.
  template <class T>
  void add(std::string_view file) {
    static_assert(Reflected<T>, "horus::idlgen::Model::add<T>: T must be a reflected message");
    check_file_name(file);
    const std::string name(type_name<T>());
    check_type_name(name);
    if (roots_.contains(name)) return;
    roots_.emplace(name, std::string(file));
    note_file(std::string(file));
    pending_.push_back([this, f = std::string(file)] {
      if (!structs_index_.contains(std::string(type_name<T>()))) build_struct<T>(f);
    });
  }

  /// Adds the struct a parsed type signature describes (horus/wire/dynamic.hpp) as a root of
  /// `file`, with every type it refers to: the same definitions add<T>() gives for the C++ type,
  /// for a type this program was not compiled with (a recording's, another host's).
  void add(const wire::DynType& type, std::string_view file);

  const std::vector<StructDef>& structs() const {
    build();
    return structs_;
  }
  const std::vector<EnumDef>& enums() const {
    build();
    return enums_;
  }
  /// The files, in the order they were first named.
  const std::vector<std::string>& files() const noexcept { return files_; }
  const StructDef* find_struct(std::string_view name) const;
  const EnumDef* find_enum(std::string_view name) const;

 private:
  template <class V>
  TypeRef ref(const std::string& file) const {
    TypeRef r;
    if constexpr (std::is_same_v<V, bool>) {
      r.prim = Prim::Bool;
    } else if constexpr (std::is_same_v<V, char>) {
      r.prim = Prim::Char;
    } else if constexpr (std::is_floating_point_v<V>) {
      static_assert(sizeof(V) == 4 || sizeof(V) == 8, "horus-idlgen: long double has no interface type");
      r.prim = sizeof(V) == 4 ? Prim::Float32 : Prim::Float64;
    } else if constexpr (std::is_integral_v<V>) {
      r.prim = integer_prim(sizeof(V), std::is_signed_v<V>);
    } else if constexpr (std::is_enum_v<V>) {
      if constexpr (is_idl_enum<V>()) {
        r.kind = TypeRef::Kind::Enum;
        r.name = std::string(type_name<V>());
        add_enum<V>(r.name, file);
      } else {
        using U = std::underlying_type_t<V>;
        r.prim = integer_prim(sizeof(U), std::is_signed_v<U>);
      }
    } else if constexpr (std::is_same_v<V, std::string>) {
      r.kind = TypeRef::Kind::String;
    } else if constexpr (reflect::detail::is_std_array<V>::value) {
      r.kind = TypeRef::Kind::Array;
      r.length = std::tuple_size_v<V>;
      r.element = std::make_shared<const TypeRef>(ref<typename V::value_type>(file));
    } else if constexpr (reflect::detail::is_std_vector<V>::value) {
      r.kind = TypeRef::Kind::Sequence;
      r.element = std::make_shared<const TypeRef>(ref<typename V::value_type>(file));
    } else {
      static_assert(Reflected<V>, "horus-idlgen: unsupported field type");
      r.kind = TypeRef::Kind::Struct;
      r.name = std::string(type_name<V>());
      check_type_name(r.name);
      if (!structs_index_.contains(r.name)) {
        auto root = roots_.find(r.name);
        build_struct<V>(root != roots_.end() ? root->second : file);
      }
    }
    return r;
  }

  template <class T>
  void build_struct(const std::string& file) const {
    const std::string name(type_name<T>());
    if (building_.contains(name)) throw std::invalid_argument("horus-idlgen: type " + name + " contains itself");
    building_.emplace(name);
    StructDef def;
    def.name = name;
    def.file = file;
    reflect::for_each_field_desc<T>([&](const auto& fd) {
      using F = typename std::remove_cvref_t<decltype(fd)>::type;
      def.fields.push_back(FieldDef{std::string(fd.name), ref<F>(file)});
    });
    building_.erase(name);
    note_file(file);
    structs_index_.emplace(name, structs_.size());
    structs_.push_back(std::move(def));
  }

  template <class E>
  void add_enum(const std::string& name, const std::string& file) const {
    if (enums_index_.contains(name)) return;
    EnumDef def;
    def.name = name;
    def.file = file;
    for (const auto& v : reflect::enum_values<E>()) def.enumerators.emplace_back(v.name);
    note_file(file);
    enums_index_.emplace(name, enums_.size());
    enums_.push_back(std::move(def));
  }

  static Prim integer_prim(std::size_t size, bool is_signed) {
    switch (size) {
      case 1: return is_signed ? Prim::Int8 : Prim::Uint8;
      case 2: return is_signed ? Prim::Int16 : Prim::Uint16;
      case 4: return is_signed ? Prim::Int32 : Prim::Uint32;
      default: return is_signed ? Prim::Int64 : Prim::Uint64;
    }
  }

  TypeRef dynamic_ref(const wire::DynType& t, const std::string& file);
  void dynamic_struct(const wire::DynType& t, const std::string& file);

  void note_file(const std::string& file) const;
  // Builds the roots added since the last call (every root is known first, so a nested type
  // that is also a root lands in its own file).
  void build() const;
  static void check_file_name(std::string_view file);
  static void check_type_name(const std::string& name);

  mutable std::vector<std::function<void()>> pending_;
  mutable std::vector<StructDef> structs_;
  mutable std::vector<EnumDef> enums_;
  mutable std::vector<std::string> files_;
  mutable std::map<std::string, std::size_t, std::less<>> structs_index_;
  mutable std::map<std::string, std::size_t, std::less<>> enums_index_;
  std::map<std::string, std::string, std::less<>> roots_;  // root type -> its file
  mutable std::set<std::string, std::less<>> building_;  // recursion guard
};

/// The module path of a qualified name: "horus::msg::Pose2D" -> {"horus", "msg"}, and its last part.
std::vector<std::string> module_path(std::string_view qualified);
std::string_view short_name(std::string_view qualified) noexcept;

}  // namespace horus::idlgen

HORUS_API_END

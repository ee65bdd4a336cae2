// The emitters of horus-idlgen: one per output format, each a function of the Model.
//
//   emit_idl(model)  OMG IDL 4 for DDS (idlc, fastddsgen): one .idl per file of the model,
//                    modules from the C++ namespaces, @final structs (XCDR1), enums, fixed
//                    arrays, unbounded sequences and strings (mapping.hpp has the table).
//   emit_lcm(model)  LCM types for lcm-gen (C, C++, Java, Python): one .lcm per file, packages
//                    from the namespaces joined by '_' (lcm_mapping.hpp has the table).
//
// The text is a contract with third-party programs: it changes only with kInterfaceVersion
// (the lock test compares it with interfaces.lock).
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "horus/error.hpp"
#include "horus/idlgen/model.hpp"
#include "horus/ros2/convert.hpp"
#include "horus/ros2/interface.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::idlgen {

/// Bumped whenever the emitted text of an existing type changes.
inline constexpr int kInterfaceVersion = 1;

struct OutputFile {
  std::string name;  // "geometry.idl"
  std::string text;
};

struct IdlOptions {
  std::string guard_prefix = "HORUS_MSG";  // include guards: <prefix>_<FILE>_IDL_
  std::vector<std::string> only_files;     // emit these files only (empty: all); the others are
                                           // known to exist (a user's messages #include horus's)
  /// Whether `file` is to be emitted.
  bool wants(const std::string& file) const {
    return only_files.empty() || std::find(only_files.begin(), only_files.end(), file) != only_files.end();
  }
};

/// One .idl per file of the model. Throws std::invalid_argument when a name cannot be
/// spelled in IDL (it names the type and field).
std::vector<OutputFile> emit_idl(const Model& model, const IdlOptions& options = {});

/// One emitted definition (a struct, an enum, with the typedefs it needs): what the lock
/// file fingerprints, type by type.
struct Definition {
  std::string type;  // qualified name
  std::string file;  // "geometry.idl"
  std::string text;
};
std::vector<Definition> idl_definitions(const Model& model, const IdlOptions& options = {});

/// The IDL of `root` (a parsed type signature) and of every type it refers to, in one text, each
/// type after those it uses, with no comment, include guard or #include: the data of an MCAP
/// schema of encoding "omgidl" named root.name (Foxglove's IDL parser reads no preprocessor
/// line). Definitions are those emit_idl() writes. Throws std::invalid_argument as emit_idl does.
std::string omgidl_schema(const wire::DynType& root);

/// One .lcm per file of the model (IdlOptions::only_files applies; guard_prefix does not).
/// A struct LCM cannot express (a vector of vectors, a member clashing with a num_<field>
/// length member, a name too long), or one that uses such a struct, is left out: the file
/// says so in a comment starting "// no LCM type: " that names the type and field.
std::vector<OutputFile> emit_lcm(const Model& model, const IdlOptions& options = {});
/// The emitted LCM structs and enum-constant structs, type by type (for the lock file); the
/// type is the LCM name ("horus_msg.Pose2D").
std::vector<Definition> lcm_definitions(const Model& model, const IdlOptions& options = {});
/// lcm-gen's fingerprint of the LCM type emitted for a struct of the model (qualified C++ name).
std::uint64_t lcm_fingerprint(const Model& model, std::string_view type);
/// "horus::msg::Pose2D" -> "horus_msg" and "horus_msg.Pose2D".
std::string lcm_package(std::string_view qualified);
std::string lcm_type_name(std::string_view qualified);

/// What a ROS 2 interface package is called and says of itself (package.xml).
struct Ros2Options {
  std::string package = "horus_msgs";
  std::string version = "0.1.0";
  std::string maintainer = "horus";
  std::string maintainer_email = "horus@localhost";
  // package.xml's <license>: horus's own is not chosen yet (packaging/copyright says so).
  std::string license = "Not chosen yet (horus packaging/copyright)";
};
/// A ROS 2 interface package of the model's structs, for colcon: package.xml, CMakeLists.txt and
/// msg/<Name>.msg per struct (the package's type <package>/msg/<Name>). Each field is the .msg
/// type whose CDR bytes are its XCDR1 bytes (char as char, an enum as uint32 with one constant per
/// enumerator), so the DDS type <package>::msg::dds_::<Name>_ reads what horus writes. A struct a
/// .msg cannot express (a collection of collections), or that uses one, is left out and named in
/// CMakeLists.txt's comments. Throws std::invalid_argument when a name cannot be a ROS 2 name
/// (it names the type and field) or two structs share a name.
std::vector<OutputFile> emit_ros2(const Model& model, const Ros2Options& options = {});
/// "horus::msg::Pose2D" -> "horus_msgs/msg/Pose2D".
std::string ros2_type_name(std::string_view qualified, const Ros2Options& options = {});

/// One struct as the ROS 2 type emit_ros2 makes of it: its name ("horus_msgs/msg/Heartbeat"),
/// the .msg types of it and of the types it uses, and its RIHS01 type hash (what a topic mapped
/// onto ROS 2 announces in USER_DATA). An error names why the struct has none (a collection of
/// collections, a name ROS 2 refuses).
struct Ros2Type {
  std::string name;
  std::string type_hash;
  ros2::Interfaces types;
};
Result<Ros2Type> ros2_type_of(const wire::DynType& root, const Ros2Options& options = {});

/// The ROS 2 type a horus message is on a ROS 2 wire or in a ROS 2 bag: the conversion of
/// ros2/convert.hpp to `requested` ("pkg/msg/Name" or "pkg/Name"; empty: the message's preferred
/// one) when it has one; else its own type in the package emit_ros2 writes (`requested`'s
/// package, or horus_msgs), whose CDR bytes are the message's XCDR1 bytes, from its layout
/// `signature` (reflect::type_signature). Errors (the caller names the topic): a type it does not
/// convert to (naming those it does), no layout, no ROS 2 type.
struct Ros2Mapped {
  std::string type;                              // "geometry_msgs/msg/Twist"
  std::string type_hash;                         // "RIHS01_..."
  const ros2::Conversion* conversion = nullptr;  // nullptr: the message's own XCDR1 bytes
  std::string definition;  // the type's ros2msg text (Interfaces::message_definition): MCAP's schema
};
Result<Ros2Mapped> ros2_mapped_type(std::string_view type_name, std::uint64_t type_hash, std::string_view signature,
                                    std::string_view requested = {});

/// IDL spelling of a name that collides with an IDL keyword (case-insensitively): "_name"
/// (an escaped identifier; generated code still calls it `name`). Others are unchanged.
std::string idl_identifier(std::string_view name);

/// 64-bit FNV-1a of a text (the lock file's fingerprint of an emitted file).
std::uint64_t fingerprint(std::string_view text) noexcept;

}  // namespace horus::idlgen

HORUS_API_END

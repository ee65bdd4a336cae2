// horus-idlgen: the type tree, the IDL text for every construct, names IDL reserves, and the
// lock that makes an interface change without a version bump fail.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "horus/idlgen/cli.hpp"
#include "horus/idlgen/emit.hpp"
#include "horus/idlgen/model.hpp"
#include "horus/msg/all.hpp"
#include "wire_test_types.hpp"

namespace {

using horus::idlgen::Model;

std::string file_text(const std::vector<horus::idlgen::OutputFile>& files, const std::string& name) {
  for (const auto& f : files)
    if (f.name == name) return f.text;
  return "<no " + name + ">";
}

TEST(IdlGen, EmitsEveryConstructAsIdl4) {
  Model model;
  model.add<wiretest::All>("wire");
  const auto text = file_text(horus::idlgen::emit_idl(model, {"WIRETEST", {}}), "wire.idl");
  const std::string body = text.substr(text.find("#define WIRETEST_WIRE_IDL_"));
  EXPECT_EQ(body,
            "#define WIRETEST_WIRE_IDL_\n"
            "\n"
            "module wiretest {\n"
            "  enum Mode {\n"
            "    Mode_Off,\n"
            "    Mode_On,\n"
            "    Mode_Auto\n"
            "  };\n"
            "\n"
            "  @final\n"
            "  struct Inner {\n"
            "    uint8 a;\n"
            "    double b;\n"
            "  };\n"
            "\n"
            "  @final\n"
            "  struct All {\n"
            "    boolean flag;\n"
            "    char c;\n"
            "    int8 i8;\n"
            "    unsigned short u16;\n"
            "    long i32;\n"
            "    unsigned long long u64;\n"
            "    float f;\n"
            "    double d;\n"
            "    wiretest::Mode mode_;\n"
            "    short raw;\n"
            "    char name[4];\n"
            "    short shorts[3];\n"
            "    string text;\n"
            "    sequence<double> values;\n"
            "    sequence<wiretest::Inner> inners;\n"
            "    sequence<string> words;\n"
            "    wiretest::Inner inner_;\n"
            "  };\n"
            "};\n"
            "\n"
            "#endif  // WIRETEST_WIRE_IDL_\n");
  EXPECT_NE(text.find("interface version " + std::to_string(horus::idlgen::kInterfaceVersion)), std::string::npos);
}

TEST(IdlGen, EscapesKeywordsAndRenamesAFieldNamedLikeItsStruct) {
  Model model;
  model.add<wiretest::Keywords>("kw");
  const auto text = file_text(horus::idlgen::emit_idl(model), "kw.idl");
  EXPECT_NE(text.find("    long _map;\n"), std::string::npos) << text;
  EXPECT_NE(text.find("    uint8 keywords_;\n"), std::string::npos) << text;
  EXPECT_NE(text.find("    float grid[3][2];\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  typedef unsigned short Keywords_pairs_element[2];\n"), std::string::npos) << text;
  EXPECT_NE(text.find("    sequence<Keywords_pairs_element> pairs;\n"), std::string::npos) << text;
}

TEST(IdlGen, PutsEachStandardDomainInItsFileWithIncludes) {
  Model model;
  horus::msg::for_each_message([&]<class T>(std::string_view domain) { model.add<T>(domain); });
  const auto files = horus::idlgen::emit_idl(model);
  EXPECT_EQ(files.size(), 14u);
  const auto nav = file_text(files, "navigation.idl");
  EXPECT_NE(nav.find("#include \"geometry.idl\""), std::string::npos);
  EXPECT_NE(nav.find("module horus {\n  module msg {\n"), std::string::npos);
  EXPECT_NE(nav.find("      horus::msg::Pose2D target_pose;\n"), std::string::npos) << nav;
  EXPECT_EQ(nav.find("struct Pose2D"), std::string::npos) << "Pose2D belongs to geometry.idl";
  // Every standard message is defined exactly once.
  std::size_t structs = 0;
  for (const auto& f : files)
    for (std::size_t p = f.text.find("struct "); p != std::string::npos; p = f.text.find("struct ", p + 1)) ++structs;
  EXPECT_EQ(structs, model.structs().size());
  EXPECT_GE(model.structs().size(), horus::msg::AllMessages::size);
}

// The definitions of a type built from its signature alone (a recording's, another host's) are
// those of its C++ type, for every standard message and every IDL construct.
template <class T>
void expect_signature_gives_the_same_idl() {
  Model typed;
  typed.add<T>("schema");
  const auto type = horus::wire::parse_signature(horus::reflect::type_signature<T>());
  ASSERT_TRUE(type) << type.error();
  Model dynamic;
  dynamic.add(*type, "schema");
  const auto a = horus::idlgen::idl_definitions(typed);
  const auto b = horus::idlgen::idl_definitions(dynamic);
  ASSERT_EQ(a.size(), b.size()) << horus::type_name<T>();
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].type, b[i].type);
    EXPECT_EQ(a[i].text, b[i].text) << a[i].type;
  }
  // The MCAP schema: every definition, nothing for a preprocessor, the root last.
  const auto schema = horus::idlgen::omgidl_schema(*type);
  EXPECT_EQ(schema.find('#'), std::string::npos) << schema;
  EXPECT_EQ(schema.find("//"), std::string::npos) << schema;
  const std::string root = "struct " + std::string(horus::idlgen::short_name(horus::type_name<T>())) + " {";
  EXPECT_NE(schema.find(root), std::string::npos) << schema;
  for (const auto& d : a)
    EXPECT_NE(schema.find(std::string(horus::idlgen::short_name(d.type)) + " {"), std::string::npos)
        << d.type << " missing from the schema of " << horus::type_name<T>() << ":\n" << schema;
}

TEST(IdlGen, ATypeFromItsSignatureHasTheIdlOfItsCppType) {
  std::size_t n = 0;
  horus::msg::for_each_message([&]<class T>(std::string_view) {
    expect_signature_gives_the_same_idl<T>();
    ++n;
  });
  EXPECT_EQ(n, horus::msg::AllMessages::size);
  expect_signature_gives_the_same_idl<wiretest::All>();
  expect_signature_gives_the_same_idl<wiretest::Keywords>();
  expect_signature_gives_the_same_idl<wiretest::Widths>();
}

TEST(IdlGen, AnOmgIdlSchemaNestsModulesAndTypesInOrder) {
  const auto type = horus::wire::parse_signature(horus::reflect::type_signature<horus::msg::Odometry>());
  ASSERT_TRUE(type) << type.error();
  const auto schema = horus::idlgen::omgidl_schema(*type);
  EXPECT_EQ(schema.rfind("module horus {\n  module msg {\n", 0), 0u) << schema;
  // Pose2D and Twist come before the struct that uses them.
  EXPECT_LT(schema.find("struct Pose2D {"), schema.find("struct Odometry {")) << schema;
  EXPECT_LT(schema.find("struct Twist {"), schema.find("struct Odometry {")) << schema;
  // Not a struct: refused with a message.
  horus::wire::DynType not_struct;
  not_struct.kind = horus::wire::DynType::Kind::String;
  EXPECT_THROW(horus::idlgen::omgidl_schema(not_struct), std::invalid_argument);
}

TEST(IdlGen, RefusesAFileNameThatIsNotAnIdentifier) {
  EXPECT_THROW(
      {
        Model m;
        m.add<wiretest::Inner>("bad-name");
      },
      std::invalid_argument);
}

class LockFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("horus_idl_lock_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    lock_ = (dir_ / "interfaces.lock").string();
    model_.add<wiretest::All>("wire");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  int run(const std::string& cmd) {
    std::string a0 = "horus-idlgen", a1 = cmd, a2 = lock_;
    char* argv[] = {a0.data(), a1.data(), a2.data(), nullptr};
    return horus::idlgen::run_cli(model_, 3, argv);
  }
  void edit(const std::string& from, const std::string& to) {
    std::ifstream in(lock_);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = ss.str();
    const auto pos = text.find(from);
    ASSERT_NE(pos, std::string::npos);
    text.replace(pos, from.size(), to);
    std::ofstream(lock_, std::ios::trunc) << text;
  }
  std::filesystem::path dir_;
  std::string lock_;
  Model model_;
};

TEST_F(LockFile, PassesWhenTheInterfacesMatch) {
  ASSERT_EQ(run("--update-lock"), 0);
  EXPECT_EQ(run("--check-lock"), 0);
}

TEST_F(LockFile, FailsWhenATypeChangedAndRefusesToUpdateWithoutAVersionBump) {
  ASSERT_EQ(run("--update-lock"), 0);
  // Another fingerprint for Inner: its line with the 16 hex digits replaced.
  {
    std::ifstream in(lock_);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    const auto pos = text.find("wiretest::Inner wire.idl 0x");
    ASSERT_NE(pos, std::string::npos);
    edit(text.substr(pos, 43), "wiretest::Inner wire.idl 0x0000000000000001");
  }
  EXPECT_EQ(run("--check-lock"), 1);
  EXPECT_EQ(run("--update-lock"), 1) << "same interface version: the update must be refused";
  edit("version " + std::to_string(horus::idlgen::kInterfaceVersion), "version 0");  // an older lock
  EXPECT_EQ(run("--check-lock"), 1);
  EXPECT_EQ(run("--update-lock"), 0) << "a new version may change types";
  EXPECT_EQ(run("--check-lock"), 0);
}

TEST_F(LockFile, FailsOnANewTypeUntilTheLockIsUpdated) {
  ASSERT_EQ(run("--update-lock"), 0);
  model_.add<wiretest::Keywords>("wire");
  EXPECT_EQ(run("--check-lock"), 1);
  EXPECT_EQ(run("--update-lock"), 0) << "adding a type changes no existing one";
  EXPECT_EQ(run("--check-lock"), 0);
}

TEST_F(LockFile, NamesAMalformedLine) {
  ASSERT_EQ(run("--update-lock"), 0);
  edit("version", "verzion");
  EXPECT_EQ(run("--check-lock"), 1);
}

}  // namespace

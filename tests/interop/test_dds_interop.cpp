// Third-party DDS programs, built at test time from idlc / fastddsgen output of horus-idlgen's
// .idl files (tests/interop/build_peers.cmake), echo what horus sends: standard messages and
// the test types that use every IDL construct (nested structs, fixed and char arrays,
// sequences, strings, enums, every integer and float width). Both horus backends against both
// peers, on loopback; and each library's peer under DDS-Security, with an identity of the
// fleet's keystore and the configuration `horus security dds-config` writes for it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dds_support.hpp"
#include "process_support.hpp"
#include "test_support.hpp"
#include "wire_test_types.hpp"

namespace {

using horus::Backend;
using namespace horus::msg;

const std::vector<horus_test::MessageType> kInteropTypes =
    horus_test::types_named({"Pose2D", "TransformStamped", "Imu", "LaserScan", "BatteryState", "JoystickInput",
                             "OccupancyGrid", "Image", "Tensor", "All", "Keywords", "Widths"});

struct Case {
  Backend horus;
  const char* peer;  // cyclone_echo or fastdds_echo
};

class Interop : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    ::setenv("HORUS_DDS_LOCALHOST", "1", 1);
    domain_ = std::to_string(1 + ::getpid() % 200);
    ::setenv("HORUS_DOMAIN_ID", domain_.c_str(), 1);
  }
  std::string domain_;
};

TEST_P(Interop, AThirdPartyProgramEchoesEveryConstructFieldByField) {
  const auto [backend, peer_name] = GetParam();
  if (!horus::backend_available(backend)) GTEST_SKIP() << "this build has no " << horus::to_string(backend) << " backend";
  const std::string program = std::string(INTEROP_WORK_DIR) + "/" + peer_name;
  if (::access(program.c_str(), X_OK) != 0) {
    std::ifstream why(program + ".why");
    std::stringstream ss;
    ss << why.rdbuf();
    GTEST_SKIP() << peer_name << " was not built: " << (ss.str().empty() ? "see interop.BuildThirdPartyPeers" : ss.str());
  }
  const std::string prefix = horus_test::unique_name("interop");
  horus_test::Peer peer(program, backend, {domain_, horus::wire_name(backend, prefix).value(), "120"});
  ASSERT_TRUE(peer.ready()) << peer_name << " did not start";
  for (const auto& f : horus_test::round_trip_all(backend, prefix, kInteropTypes)) ADD_FAILURE() << f;
  EXPECT_EQ(peer.stop(), 0);
}

// fastddsgen / idlc programs beside two horus processes of the same host: each message once
// in both directions (the host has one bridge, one writer and one reader for the topic).
TEST_P(Interop, OnAHostWithTwoHorusProcessesEachMessageGoesOnceEachWay) {
  const auto [backend, peer_name] = GetParam();
  if (!horus::backend_available(backend)) GTEST_SKIP() << "this build has no " << horus::to_string(backend) << " backend";
  const std::string program = std::string(INTEROP_WORK_DIR) + "/" + peer_name;
  if (::access(program.c_str(), X_OK) != 0) GTEST_SKIP() << peer_name << " was not built";
  const std::string prefix = horus_test::unique_name("interop.host");
  horus_test::Peer peer(program, backend, {domain_, horus::wire_name(backend, prefix).value(), "60"});
  ASSERT_TRUE(peer.ready()) << peer_name << " did not start";
  for (const auto& f : horus_test::same_host_exactly_once(backend, prefix)) ADD_FAILURE() << f;
  EXPECT_EQ(peer.stop(), 0);
}

// A third-party program of the same library as horus's backend, configured the standard way
// (CYCLONEDDS_URI, or a Fast DDS XML profile) with what `horus security dds-config` writes for its
// identity, echoes what horus sends while horus enforces DDS-Security with another identity of
// the keystore. Under enforce horus matches authenticated participants only, so a peer whose
// configuration did not take gets nothing. (Cyclone DDS against Fast DDS under security is
// tests/multihost/test_security.cpp's: they authenticate each other one way only.)
class SecureInterop : public Interop {};

TEST_P(SecureInterop, AThirdPartyProgramWithAnIdentityEchoesUnderEnforce) {
  namespace fs = std::filesystem;
  const auto [backend, peer_name] = GetParam();
  if (!horus::backend_available(backend)) GTEST_SKIP() << "this build has no " << horus::to_string(backend) << " backend";
  const std::string program = std::string(INTEROP_WORK_DIR) + "/" + peer_name;
  if (::access(program.c_str(), X_OK) != 0) GTEST_SKIP() << peer_name << " was not built";
  const fs::path keys = fs::temp_directory_path() / ("horus_interop_keys_" + std::to_string(::getpid()));
  fs::remove_all(keys);
  const bool cyclone = backend == Backend::CycloneDds;
  const fs::path peer_config = keys / "peer_dds.xml";
  const std::string cli = HORUS_CLI, k = keys.string();
  const std::string grant = " --publish 'test.**' --subscribe 'test.**'";
  const std::string make = cli + " security keystore init " + k + " && " + cli + " security host create " + k + " horus && " +
                           cli + " security host create " + k + " peer && " + cli + " security permissions " + k + " horus" +
                           grant + " && " + cli + " security permissions " + k + " peer" + grant + " && " + cli +
                           " security dds-config " + k + " peer --for " + (cyclone ? "cyclonedds" : "fastdds") + " -o " +
                           peer_config.string();
  std::string out;
  ASSERT_EQ(horus_test::run_command(make, out), 0) << make << "\n" << out;
  ::setenv("HORUS_SECURITY", "enforce", 1);
  ::setenv("HORUS_SECURITY_KEYSTORE", k.c_str(), 1);
  ::setenv("HORUS_SECURITY_IDENTITY", "horus", 1);
  const std::string how = cyclone ? "CYCLONEDDS_URI=file://" + peer_config.string()
                                  : "FASTRTPS_DEFAULT_PROFILES_FILE=" + peer_config.string();
  const std::string prefix = horus_test::unique_name("interop.secure");
  {
    horus_test::Peer peer(program, backend, {domain_, horus::wire_name(backend, prefix).value(), "120"}, {how});
    ASSERT_TRUE(peer.ready()) << peer_name << " did not start with " << how;
    for (const auto& f : horus_test::round_trip_all(backend, prefix, horus_test::types_named({"Pose2D", "Image", "All"})))
      ADD_FAILURE() << f;
    EXPECT_EQ(peer.stop(), 0);
  }
  fs::remove_all(keys);
}

INSTANTIATE_TEST_SUITE_P(Secure, SecureInterop,
                         ::testing::Values(Case{Backend::CycloneDds, "cyclone_echo"}, Case{Backend::FastDds, "fastdds_echo"}),
                         [](const auto& param_info) {
                           return std::string(horus::to_string(param_info.param.horus)) + "_with_" +
                                  param_info.param.peer;
                         });

INSTANTIATE_TEST_SUITE_P(Peers, Interop,
                         ::testing::Values(Case{Backend::CycloneDds, "cyclone_echo"},
                                           Case{Backend::CycloneDds, "fastdds_echo"},
                                           Case{Backend::FastDds, "cyclone_echo"},
                                           Case{Backend::FastDds, "fastdds_echo"}),
                         [](const auto& param_info) {
                           return std::string(horus::to_string(param_info.param.horus)) + "_with_" +
                                  param_info.param.peer;
                         });

}  // namespace

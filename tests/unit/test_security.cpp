// DDS-Security's configuration and keystore (security/): the `security:` section and its
// variables, topic patterns as DDS-Security's fnmatch expressions, the governance and permissions
// documents, and a keystore made, checked and damaged the ways a fleet's operator meets: an
// expired certificate, a document edited after signing, another host's permissions, a key others
// can read, a certificate of another CA; what another DDS program is configured with (dds-config).
// The namespace-host tests are multihost/test_security.cpp; a third-party program under security,
// interop/test_dds_interop.cpp.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "horus/config.hpp"
#include "horus/environment.hpp"
#include "horus/network.hpp"
#include "horus/security/dds_config.hpp"
#include "horus/security/keystore.hpp"
#include "horus/security/policy.hpp"
#include "horus/transport_registry.hpp"

namespace {

namespace fs = std::filesystem;
using horus::Config;
using horus::Errc;
using horus::net::Protection;
using horus::net::SecurityMode;
using namespace horus::security;
using namespace std::chrono_literals;

std::string read(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A temporary directory, removed at the end.
struct TempDir {
  fs::path path;
  TempDir() {
    static int n = 0;
    path = fs::temp_directory_path() / ("horus_test_security_" + std::to_string(::getpid()) + "_" + std::to_string(++n));
    fs::remove_all(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// ---------------------------------------------------------------------------- configuration

TEST(SecurityConfig, TheFileSectionGivesModeKeystoreAndIdentity) {
  auto c = Config::parse("security:\n  mode: permissive\n  keystore: keys\n  identity: robot1\n", "/etc/horus/fleet.yaml");
  ASSERT_TRUE(c) << c.error().message();
  EXPECT_EQ(c->security().mode, SecurityMode::Permissive);
  EXPECT_EQ(c->security().keystore, "/etc/horus/keys");  // relative to the file's directory
  EXPECT_EQ(c->security().identity, "robot1");
}

TEST(SecurityConfig, AnUnknownKeyOrModeNamesTheLineAndWhatIsValid) {
  auto c = Config::parse("network:\n  domain_id: 3\nsecurity:\n  mode: strict\n", "f.yaml");
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().code(), Errc::Config);
  EXPECT_NE(c.error().message().find("f.yaml, line 4, key 'security.mode'"), std::string::npos) << c.error().message();
  EXPECT_NE(c.error().message().find("expected enforce, permissive or off"), std::string::npos);
  auto k = Config::parse("security:\n  keystroke: x\n", "f.yaml");
  ASSERT_FALSE(k);
  EXPECT_NE(k.error().message().find("security.keystroke"), std::string::npos) << k.error().message();
  auto id = Config::parse("security:\n  identity: \"robot 1\"\n", "f.yaml");
  ASSERT_FALSE(id);
  EXPECT_NE(id.error().message().find("identity name 'robot 1' has ' '"), std::string::npos) << id.error().message();
}

TEST(SecurityConfig, ATopicRuleChoosesSignOrEncrypt) {
  auto c = Config::parse("network:\n  backend: cyclonedds\ntopics:\n  - match: horus.fleet.heartbeat\n    protection: sign\n"
                         "  - match: \"*.camera\"\n    scope: fleet\n    protection: encrypt\n",
                         "f.yaml");
  ASSERT_TRUE(c) << c.error().message();
  ASSERT_EQ(c->rules().size(), 2u);
  EXPECT_EQ(c->rules()[0].protection, Protection::Sign);
  EXPECT_EQ(c->rules()[1].protection, Protection::Encrypt);
  auto host = Config::parse("topics:\n  - match: a.b\n    scope: host\n    protection: sign\n", "f.yaml");
  ASSERT_FALSE(host);
  EXPECT_NE(host.error().message().find("protection applies to fleet topics"), std::string::npos) << host.error().message();
  auto bad = Config::parse("topics:\n  - match: a.b\n    protection: hide\n", "f.yaml");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message().find("unknown protection 'hide'"), std::string::npos) << bad.error().message();
}

TEST(SecurityConfig, VariablesOverTheFileAndAKeystoreAloneMeansEnforce) {
  horus::Environment env;
  horus::net::FileDefaults file;
  file.security_mode = SecurityMode::Permissive;
  file.security_keystore = "/etc/horus/keys";
  file.security_identity = "robot1";
  file.origin = "configuration file 'f.yaml'";
  auto c = horus::net::config_from(env, file);
  ASSERT_TRUE(c) << c.error().message();
  EXPECT_EQ(c->security.mode, SecurityMode::Permissive);
  EXPECT_NE(c->security.origin.find("f.yaml"), std::string::npos);
  env.security = "enforce";
  env.security_identity = "robot2";
  c = horus::net::config_from(env, file);
  ASSERT_TRUE(c) << c.error().message();
  EXPECT_EQ(c->security.mode, SecurityMode::Enforce);
  EXPECT_EQ(c->security.identity, "robot2");
  EXPECT_EQ(c->security.origin, "environment variable HORUS_SECURITY");

  horus::Environment only_keystore;
  only_keystore.security_keystore = "/k";
  only_keystore.security_identity = "r";
  c = horus::net::config_from(only_keystore, {});
  ASSERT_TRUE(c) << c.error().message();
  EXPECT_EQ(c->security.mode, SecurityMode::Enforce);

  horus::Environment off;
  off.security = "off";
  off.security_keystore = "/k";
  c = horus::net::config_from(off, {});
  ASSERT_TRUE(c);
  EXPECT_EQ(c->security, horus::net::Security{});
}

TEST(SecurityConfig, AModeWithoutKeystoreOrIdentityOrAnUnknownModeIsAnError) {
  horus::Environment env;
  env.security = "enforce";
  auto c = horus::net::config_from(env, {});
  ASSERT_FALSE(c);
  EXPECT_NE(c.error().message().find("environment variable HORUS_SECURITY is enforce but no keystore is given"),
            std::string::npos)
      << c.error().message();
  env.security_keystore = "/k";
  c = horus::net::config_from(env, {});
  ASSERT_FALSE(c);
  EXPECT_NE(c.error().message().find("this host's identity is not given"), std::string::npos) << c.error().message();
  env.security = "yes";
  c = horus::net::config_from(env, {});
  ASSERT_FALSE(c);
  EXPECT_NE(c.error().message().find("HORUS_SECURITY=yes: expected enforce"), std::string::npos) << c.error().message();
}

TEST(SecurityConfig, LcmRefusesEnforceAndOpensUnderPermissive) {
  const auto* lcm = horus::net::find_transport("lcm");
  if (lcm == nullptr) GTEST_SKIP() << "this build has no LCM transport";
  horus::net::Config config;
  config.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  config.security = {SecurityMode::Enforce, "/k", "robot1", "configuration file 'f.yaml', line 3, security.mode"};
  ASSERT_NE(lcm->check, nullptr);
  auto checked = lcm->check(config);
  ASSERT_FALSE(checked);
  EXPECT_EQ(checked.error().code(), Errc::Config);
  EXPECT_NE(checked.error().message().find("f.yaml', line 3, security.mode is enforce, but LCM has no security"),
            std::string::npos)
      << checked.error().message();
  config.security.mode = SecurityMode::Permissive;
  EXPECT_TRUE(lcm->check(config));
}

// ---------------------------------------------------------------------------- policy

TEST(SecurityPolicy, DoubleStarMapsExactlyToFnmatchExpressions) {
  auto e = dds_topic_expressions("robot1.**", false);
  ASSERT_TRUE(e) << e.error().message();
  EXPECT_EQ(*e, (std::vector<std::string>{"horus/robot1", "horus/robot1/*"}));
  e = dds_topic_expressions("a.**.b", false);
  ASSERT_TRUE(e);
  EXPECT_EQ(*e, (std::vector<std::string>{"horus/a/b", "horus/a/*/b"}));
  e = dds_topic_expressions("**", false);
  ASSERT_TRUE(e);
  EXPECT_EQ(*e, (std::vector<std::string>{"horus", "horus/*"}));
  e = dds_topic_expressions("fleet.map", false);
  ASSERT_TRUE(e);
  EXPECT_EQ(*e, (std::vector<std::string>{"horus/fleet/map"}));
}

TEST(SecurityPolicy, ASingleStarIsRefusedWhereWideningWouldGrantMore) {
  auto e = dds_topic_expressions("*.cmd_vel", false);
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().message().find("'*' (exactly one segment) cannot be granted exactly"), std::string::npos)
      << e.error().message();
  e = dds_topic_expressions("*.cmd_vel", true);
  ASSERT_TRUE(e);
  EXPECT_EQ(*e, (std::vector<std::string>{"horus/*/cmd_vel"}));
  EXPECT_FALSE(dds_topic_expressions("a.**.b.**.c.**.d.**.e.**", true));
  EXPECT_FALSE(dds_topic_expressions("bad..pattern", true));
  // In the governance, a `sign` rule is a weaker protection: it must not be widened.
  auto g = governance_xml({{{"*.camera", Protection::Sign}}, std::nullopt});
  ASSERT_FALSE(g);
  EXPECT_NE(g.error().message().find("protection: sign"), std::string::npos) << g.error().message();
}

TEST(SecurityPolicy, GovernanceListsTheRulesInOrderThenEncryptsEverythingElse) {
  auto g = governance_xml({{{"horus.fleet.heartbeat", Protection::Sign}, {"**.camera", Protection::Encrypt}}, 7u});
  ASSERT_TRUE(g) << g.error().message();
  const std::size_t hb = g->find("<topic_expression>horus/horus/fleet/heartbeat</topic_expression>");
  const std::size_t cam = g->find("<topic_expression>horus/*/camera</topic_expression>");
  const std::size_t rest = g->find("<topic_expression>*</topic_expression>");
  ASSERT_NE(hb, std::string::npos) << *g;
  ASSERT_NE(cam, std::string::npos) << *g;
  ASSERT_NE(rest, std::string::npos) << *g;
  EXPECT_LT(hb, cam);
  EXPECT_LT(cam, rest);
  EXPECT_NE(g->find("<data_protection_kind>NONE</data_protection_kind>", hb), std::string::npos);
  EXPECT_LT(g->find("<data_protection_kind>NONE</data_protection_kind>", hb), cam);
  EXPECT_NE(g->find("<domains><id>7</id></domains>"), std::string::npos);
  EXPECT_NE(g->find("<allow_unauthenticated_participants>false</allow_unauthenticated_participants>"), std::string::npos);
  EXPECT_NE(g->find("<enable_join_access_control>true</enable_join_access_control>"), std::string::npos);
}

TEST(SecurityPolicy, ATopicsProtectionIsTheFirstRuleDdsSecurityMatchesElseEncrypt) {
  const GovernanceSpec spec{{{"horus.fleet.heartbeat", Protection::Sign},
                             {"robot1.*", Protection::Encrypt},
                             {"robot1.**", Protection::Sign}},
                            {}};
  const auto heartbeat = protection_of(spec, "horus.fleet.heartbeat");
  EXPECT_EQ(heartbeat.protection, Protection::Sign);
  EXPECT_EQ(heartbeat.rule, std::optional<std::size_t>(0));
  // fnmatch's '*' crosses '/': the widened encrypt rule takes two segments below robot1 too.
  EXPECT_EQ(protection_of(spec, "robot1.cam.left").rule, std::optional<std::size_t>(1));
  EXPECT_EQ(protection_of(spec, "robot1.cam.left").protection, Protection::Encrypt);
  EXPECT_EQ(protection_of(spec, "robot1").rule, std::optional<std::size_t>(2));
  EXPECT_EQ(protection_of(spec, "robot1").protection, Protection::Sign);
  EXPECT_EQ(protection_of(spec, "robot2.pose").rule, std::nullopt);
  EXPECT_EQ(protection_of(spec, "robot2.pose").protection, Protection::Encrypt);
}

TEST(SecurityPolicy, PermissionsAllowWhatIsListedAndTheFleetLayerAndDenyTheRest) {
  PermissionsSpec spec;
  spec.grant = "robot1";
  spec.subject = "CN=robot1,O=horus";
  spec.publish = {"robot1.**"};
  spec.subscribe = {"fleet.map"};
  spec.not_before = std::chrono::system_clock::now();
  spec.not_after = spec.not_before + 24h;
  auto p = permissions_xml(spec);
  ASSERT_TRUE(p) << p.error().message();
  EXPECT_NE(p->find("<subject_name>CN=robot1,O=horus</subject_name>"), std::string::npos) << *p;
  const std::size_t pub = p->find("<publish>"), sub = p->find("<subscribe>");
  ASSERT_NE(pub, std::string::npos);
  ASSERT_NE(sub, std::string::npos);
  EXPECT_LT(p->find("<topic>horus/robot1/*</topic>", pub), sub);
  EXPECT_LT(p->find("<topic>horus/horus/fleet/*</topic>", pub), sub);
  EXPECT_NE(p->find("<topic>horus/fleet/map</topic>", sub), std::string::npos);
  EXPECT_EQ(p->find("<topic>horus/robot1/*</topic>", sub), std::string::npos);
  EXPECT_NE(p->find("<default>DENY</default>"), std::string::npos);
  // Every domain Cyclone DDS can use (a range without an end would be its start alone there).
  EXPECT_NE(p->find("<domains><id_range><min>0</min><max>230</max></id_range></domains>"), std::string::npos) << *p;
  spec.publish = {"*.cmd_vel"};
  auto wide = permissions_xml(spec);
  ASSERT_FALSE(wide);
  EXPECT_NE(wide.error().message().find("--publish: pattern '*.cmd_vel'"), std::string::npos) << wide.error().message();
}

// ---------------------------------------------------------------------------- keystore

// A keystore with host robot1 (publishes robot1.**, subscribes **) and its files, made the way
// `horus security` makes them.
struct Fleet {
  TempDir dir;
  Keystore ks{dir.path / "keys"};
  void make(const std::string& host = "robot1") {
    auto init = init_keystore(ks, {});
    ASSERT_TRUE(init) << init.error().message();
    add(host);
  }
  void add(const std::string& host, Validity validity = {}) {
    auto h = create_host(ks, host, validity, false);
    ASSERT_TRUE(h) << h.error().message();
    PermissionsSpec spec;
    spec.publish = {host + ".**"};
    spec.subscribe = {"**"};
    auto p = write_permissions(ks, host, spec, {});
    ASSERT_TRUE(p) << p.error().message();
  }
  horus::net::Security security(const std::string& host = "robot1", SecurityMode mode = SecurityMode::Enforce) const {
    return {mode, ks.dir().string(), host, "test"};
  }
};

TEST(Keystore, AFreshKeystoreChecksCleanAndGivesAParticipantItsFiles) {
  Fleet f;
  ASSERT_NO_FATAL_FAILURE(f.make());
  const CheckReport r = check_keystore(f.ks, Clock::now());
  EXPECT_EQ(r.errors, 0);
  EXPECT_EQ(r.warnings, 0);
  std::string text;
  for (const auto& l : r.lines) text += l.item + ": " + l.text + "\n";
  EXPECT_NE(text.find("host robot1: certificate: CN=robot1,O=horus, issued by the identity CA"), std::string::npos) << text;
  EXPECT_NE(text.find("governance: signed by the permissions CA"), std::string::npos) << text;
  struct stat st{};
  ASSERT_EQ(::stat(f.ks.host_key("robot1").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  ASSERT_EQ(::stat(f.ks.identity_ca_key().c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  ASSERT_EQ(::stat((f.ks.dir() / "private").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0700u);
  auto files = participant_files(f.security());
  ASSERT_TRUE(files) << files.error().message();
  EXPECT_EQ(files->subject, "CN=robot1,O=horus");
  EXPECT_EQ(files->permissions, f.ks.permissions_p7s("robot1"));
  EXPECT_GT(files->expires, Clock::now() + 300 * 24h);
  EXPECT_EQ(file_uri(files->governance).rfind("file:///", 0), 0u);
}

TEST(Keystore, ItsCasAreNeverReplacedNorAHostWithoutReplace) {
  Fleet f;
  ASSERT_NO_FATAL_FAILURE(f.make());
  const std::string ca = read(f.ks.identity_ca_cert());
  auto again = init_keystore(f.ks, {});
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().message().find("already has its CAs"), std::string::npos) << again.error().message();
  EXPECT_EQ(read(f.ks.identity_ca_cert()), ca);
  const std::string cert = read(f.ks.host_cert("robot1"));
  auto twice = create_host(f.ks, "robot1", {}, false);
  ASSERT_FALSE(twice);
  EXPECT_NE(twice.error().message().find("--replace"), std::string::npos) << twice.error().message();
  ASSERT_TRUE(create_host(f.ks, "robot1", {}, true));
  EXPECT_NE(read(f.ks.host_cert("robot1")), cert);  // rotated: a new key and certificate
  EXPECT_TRUE(participant_files(f.security()));     // the permissions name the subject, which stayed
}

TEST(Keystore, AnExpiredCertificateIsRefusedNamingTheFileAndTheFix) {
  Fleet f;
  ASSERT_NO_FATAL_FAILURE(f.make());
  Validity past;
  past.not_before = Clock::now() - 30 * 24h;
  past.not_after = Clock::now() - 24h;
  ASSERT_NO_FATAL_FAILURE(f.add("old", past));
  auto files = participant_files(f.security("old"));
  ASSERT_FALSE(files);
  EXPECT_EQ(files.error().code(), Errc::Config);
  const std::string& m = files.error().message();
  EXPECT_NE(m.find(f.ks.host_cert("old").string() + "' expired on"), std::string::npos) << m;
  EXPECT_NE(m.find("horus security host create"), std::string::npos) << m;
  EXPECT_EQ(check_keystore(f.ks, Clock::now()).errors, 1);
}

TEST(Keystore, ADocumentEditedAfterSigningIsRefused) {
  Fleet f;
  ASSERT_NO_FATAL_FAILURE(f.make());
  std::string p7s = read(f.ks.permissions_p7s("robot1"));
  const std::size_t at = p7s.find("horus/robot1/*");
  ASSERT_NE(at, std::string::npos);
  p7s.replace(at, 14, "horus/robot2/*");  // a host granting itself another robot's topics
  std::ofstream(f.ks.permissions_p7s("robot1")) << p7s;
  auto files = participant_files(f.security());
  ASSERT_FALSE(files);
  EXPECT_NE(files.error().message().find("its signature does not verify with the CA"), std::string::npos)
      << files.error().message();
}

TEST(Keystore, AnotherHostsPermissionsOrACertificateOfAnotherCaAreRefused) {
  Fleet f;
  ASSERT_NO_FATAL_FAILURE(f.make());
  ASSERT_NO_FATAL_FAILURE(f.add("robot2"));
  fs::copy_file(f.ks.permissions_p7s("robot2"), f.ks.permissions_p7s("robot1"), fs::copy_options::overwrite_existing);
  auto files = participant_files(f.security());
  ASSERT_FALSE(files);
  EXPECT_NE(files.error().message().find("their subject 'CN=robot2,O=horus' is not the certificate's 'CN=robot1,O=horus'"),
            std::string::npos)
      << files.error().message();

  Fleet other;
  ASSERT_NO_FATAL_FAILURE(other.make("robot3"));
  ASSERT_NO_FATAL_FAILURE(f.add("robot3"));
  fs::copy_file(other.ks.host_cert("robot3"), f.ks.host_cert("robot3"), fs::copy_options::overwrite_existing);
  fs::copy_file(other.ks.host_key("robot3"), f.ks.host_key("robot3"), fs::copy_options::overwrite_existing);
  files = participant_files(f.security("robot3"));
  ASSERT_FALSE(files);
  EXPECT_NE(files.error().message().find("is not valid with the keystore's identity CA"), std::string::npos)
      << files.error().message();
}

TEST(Keystore, AKeyOthersCanReadIsRefused) {
  Fleet f;
  ASSERT_NO_FATAL_FAILURE(f.make());
  ASSERT_EQ(::chmod(f.ks.host_key("robot1").c_str(), 0644), 0);
  auto files = participant_files(f.security());
  ASSERT_FALSE(files);
  EXPECT_NE(files.error().message().find("can be read by other users (mode 0644); `chmod 600` it"), std::string::npos)
      << files.error().message();
}

TEST(Keystore, PermissiveRunsPlainWhenTheFilesAreMissingAndEnforceRefuses) {
  TempDir dir;
  const horus::net::Security missing{SecurityMode::Permissive, (dir.path / "none").string(), "robot1", "test"};
  auto p = secure_participant(missing, "test transport");
  ASSERT_TRUE(p) << p.error().message();
  EXPECT_FALSE(p->has_value());
  auto e = secure_participant({SecurityMode::Enforce, missing.keystore, "robot1", "test"}, "test transport");
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().message().find("identity_ca.cert.pem' cannot be read"), std::string::npos) << e.error().message();
  auto off = secure_participant({}, "test transport");
  ASSERT_TRUE(off);
  EXPECT_FALSE(off->has_value());
}

// ---------------------------------------------------------------------------- other DDS programs

TEST(DdsConfig, AnotherProgramGetsTheStandardPropertiesAndDocumentsNamingTheIdentitysFiles) {
  Fleet f;
  ASSERT_NO_FATAL_FAILURE(f.make());
  auto files = participant_files(f.security());
  ASSERT_TRUE(files) << files.error().message();
  const auto properties = dds_security_properties(*files);
  ASSERT_EQ(properties.size(), 9u);
  EXPECT_EQ(properties.front(), std::make_pair(std::string("dds.sec.auth.plugin"), std::string("builtin.PKI-DH")));
  EXPECT_EQ(properties.back(), std::make_pair(std::string("dds.sec.crypto.plugin"), std::string("builtin.AES-GCM-GMAC")));
  auto fastdds = third_party_config(*files, "fastdds");
  ASSERT_TRUE(fastdds) << fastdds.error().message();
  auto cyclone = third_party_config(*files, "cyclonedds");
  ASSERT_TRUE(cyclone) << cyclone.error().message();
  for (const auto& [name, value] : properties) {
    EXPECT_NE(fastdds->find("<name>" + name + "</name><value>" + value + "</value>"), std::string::npos) << name;
  }
  EXPECT_NE(fastdds->find("is_default_profile=\"true\""), std::string::npos) << *fastdds;
  EXPECT_NE(cyclone->find("<CycloneDDS><Domain Id=\"any\"><Security><Authentication>"), std::string::npos) << *cyclone;
  EXPECT_NE(cyclone->find("<PrivateKey>" + file_uri(f.ks.host_key("robot1")) + "</PrivateKey>"), std::string::npos) << *cyclone;
  EXPECT_NE(cyclone->find("<Permissions>" + file_uri(f.ks.permissions_p7s("robot1")) + "</Permissions>"), std::string::npos);
  // The plug-ins by path where this machine has them, by name otherwise.
  const fs::path plugins = cyclone_plugin_dir();
  const std::string auth = plugins.empty() ? "dds_security_auth" : (plugins / "libdds_security_auth.so").string();
  EXPECT_NE(cyclone->find("<Library path=\"" + auth + "\" initFunction=\"init_authentication\""), std::string::npos)
      << *cyclone;
  if (!plugins.empty()) {
    EXPECT_TRUE(fs::exists(plugins / "libdds_security_crypto.so"));
  }
  auto other = third_party_config(*files, "opendds");
  ASSERT_FALSE(other);
  EXPECT_EQ(other.error().code(), Errc::InvalidArgument);
  EXPECT_NE(other.error().message().find("'opendds': expected cyclonedds"), std::string::npos) << other.error().message();
}

}  // namespace

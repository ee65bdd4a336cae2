// The byte-level interface between Topic<T> and a network transport (Cyclone DDS, Fast DDS, LCM).
//
// Topic<T>'s network bridge encodes a message in the transport's wire format (XCDR1 for DDS,
// lcm-gen's for LCM) straight into the buffer the transport provides, and decodes what arrives
// into the topic's local ring. A transport moves bytes only: it never sees T. One Transport per
// process and configuration (a DDS participant); one Endpoint per topic and process (a writer
// and a reader). Transports register themselves by name (horus/transport_registry.hpp).
//
// This header includes no DDS or LCM header: <horus/topic.hpp> stays fast to compile.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "horus/error.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::net {

/// Whether a lost sample is sent again (reliable) or not (best effort).
enum class Reliability : std::uint8_t { BestEffort, Reliable };
/// Whether a late-joining subscriber gets the last `depth` samples (transient local) or not.
enum class Durability : std::uint8_t { Volatile, TransientLocal };

/// "reliable" / "best effort", "transient local" / "volatile": the names messages use.
std::string_view to_string(Reliability r) noexcept;
std::string_view to_string(Durability d) noexcept;

/// Largest DDS domain id: the RTPS port mapping (7400 + 250 x domain + ...) has no room above it.
inline constexpr std::uint32_t kMaxDomainId = 232;

struct Qos {
  Reliability reliability = Reliability::Reliable;
  Durability durability = Durability::Volatile;
  std::uint32_t depth = 16;  // history depth (KEEP_LAST), from the topic's capacity
  std::int64_t deadline_ns = 0;  // DEADLINE period (writer and reader); 0: none
  std::int64_t lifespan_ns = 0;  // LIFESPAN of a written sample; 0: none
  std::int8_t priority = 0;      // the topic's share of the host's link: -1 low, 0 normal, 1 high
};

/// DDS-Security for fleet topics (the configuration file's `security:` section,
/// HORUS_SECURITY, HORUS_SECURITY_KEYSTORE, HORUS_SECURITY_IDENTITY; security/README.md).
/// Off: plain DDS. Enforce: a DDS transport opens only as an authenticated participant with
/// access control and encryption, a missing or invalid file of the keystore is an error, and a
/// transport without security (LCM) refuses to open. Permissive: secure when the identity's files
/// are there and valid, plain (with a warning) when they are not, and LCM opens with a warning.
enum class SecurityMode : std::uint8_t { Off, Permissive, Enforce };
/// "off", "permissive", "enforce".
std::string_view to_string(SecurityMode m) noexcept;

struct Security {
  SecurityMode mode = SecurityMode::Off;
  std::string keystore;  // the keystore directory (horus security keystore init)
  std::string identity;  // this host's identity in it (horus security host create)
  std::string origin;    // where the settings came from, for errors; empty when mode is Off
  bool operator==(const Security&) const = default;
};

/// Checks an identity's name (a host in a keystore, the CN of its certificate): 1 to 64
/// letters, digits, '_', '-', '.'; the error says what is wrong.
Result<void> validate_identity_name(std::string_view name);

/// What governance gives a topic's samples under security (a topic rule's `protection:`):
/// encrypted (AES-GCM, the default) or signed only (GMAC: authenticated, readable on the wire).
enum class Protection : std::uint8_t { Encrypt, Sign };
/// "encrypt", "sign".
std::string_view to_string(Protection p) noexcept;

/// Process-wide settings of a transport (one participant per distinct DDS domain and
/// localhost_only; one LCM instance per URL). Made by the configuration (api/, from the
/// environment and the configuration file) and passed to TransportInfo::open.
struct Config {
  std::uint32_t domain_id = 0;  // DDS domain (HORUS_DOMAIN_ID, network.domain_id)
  bool localhost_only = false;  // loopback only, no multicast (HORUS_DDS_LOCALHOST=1, network.localhost_only)
  /// The LCM URL (HORUS_LCM_URL, LCM_DEFAULT_URL, network.lcm_url); empty: LCM's default.
  std::string lcm_url;
  /// Where lcm_url came from, for errors ("environment variable HORUS_LCM_URL",
  /// "configuration file 'f.yaml', network.lcm_url"); empty when lcm_url is.
  std::string lcm_url_origin;
  /// Hosts (names or IPv4 addresses) that discovery and data reach by unicast, with multicast
  /// off: for networks that filter or flood multicast (Wi-Fi). Empty: multicast discovery.
  /// (HORUS_PEERS, network.peers.) DDS only: the LCM transport refuses it.
  std::vector<std::string> peers;
  std::string peers_origin;  // where peers came from, for errors; empty when peers is
  /// The host's link budget in bytes per second (network.max_bandwidth); 0: none. A transport
  /// that can pace what it sends (Fast DDS's flow controllers) paces its fragments at it.
  std::uint64_t link_bandwidth = 0;
  /// DDS-Security (Security); LCM refuses SecurityMode::Enforce.
  Security security;
  bool operator==(const Config&) const = default;
};

/// The configuration file's `network:` section (horus/config.hpp), used where the environment
/// says nothing. `origin` names the file, for errors.
struct FileDefaults {
  std::optional<std::uint32_t> domain_id;
  std::optional<bool> localhost_only;
  std::optional<std::string> lcm_url;
  std::optional<std::vector<std::string>> peers;  // checked by check_peer
  std::optional<std::uint64_t> link_bandwidth;    // network.max_bandwidth
  std::optional<SecurityMode> security_mode;      // security.mode
  std::optional<std::string> security_keystore;   // security.keystore
  std::optional<std::string> security_identity;   // security.identity
  int security_line = 0;                          // the line of the security section (0: not known)
  std::string origin;
  int lcm_url_line = 0;  // where lcm_url and peers are in the file (0: not known), for errors
  int peers_line = 0;
};

/// With peers (Config::peers), discovery probes these participant indexes on each peer: the
/// DDS participants of one host (two per process with fleet topics) number at most this + 1.
inline constexpr std::uint32_t kMaxPeerIndex = 63;

/// Checks one entry of a peers list: a host name (letters, digits, '-' and '.', at most 253
/// characters) or an IPv4 address; an error message naming what was wrong, or empty.
std::string check_peer(std::string_view peer);

}  // namespace horus::net

namespace horus {
struct Environment;
}

namespace horus::net {

/// The network settings from the environment's HORUS_DOMAIN_ID (0 to kMaxDomainId),
/// HORUS_DDS_LOCALHOST (1/true/yes/on: loopback only, no multicast; 0/false/no/off: the LAN),
/// HORUS_LCM_URL and LCM_DEFAULT_URL; where one is unset, the file's value, else domain 0, the
/// LAN and LCM's default URL. An error names the variable, its value and what is expected.
/// (The process's settings: horus::net::config_from_environment() in horus/config.hpp.)
Result<Config> config_from(const Environment& env, const FileDefaults& file);

/// A DDS entity's GUID (prefix and entity id): what ROS 2 calls its GID (rmw_dds_common/msg/Gid).
using Guid = std::array<std::uint8_t, 16>;

/// One topic as a backend sees it.
struct EndpointSpec {
  std::string topic;       // the horus topic name ("fleet.robot_1.pose")
  std::string wire_topic;  // the backend's topic or channel name ("horus/fleet/robot_1/pose")
  std::string type_name;   // the wire type name ("horus::msg::Pose2D")
  std::uint64_t type_hash = 0;
  Qos qos;
  /// The largest message of the topic in bytes (its ring slot, or its pool slot for large
  /// data); 0 when unknown. A backend sizes its buffers of unacknowledged samples by it.
  std::uint64_t max_message_bytes = 0;
  /// USER_DATA of the writer and the reader (DDS): ROS 2's "typehash=RIHS01_<sha256>;" on a
  /// topic mapped onto ROS 2 (docs/ROS2.md); empty: none. A remote endpoint of the same type name
  /// whose USER_DATA carries another type hash is reported (Listener::on_error).
  std::string user_data = {};
  /// Whether the endpoint receives from the start; false: it only sends until
  /// set_receiving(true) (a host whose handles only publish). Like set_receiving, a hint:
  /// a backend that gains nothing by not receiving (DDS) ignores it.
  bool receive = true;
  /// false: a reader only, no writer (DDS): an observer such as `horus topic echo`, which no
  /// publisher should match as a subscriber of its own QoS nor count as a writer. write() then
  /// fails.
  bool send = true;
};

/// A sample that arrived: the serialized body (for DDS: the XCDR1 bytes after the 4-byte
/// encapsulation header, final padding removed) and its byte order. Valid during the call only.
struct Sample {
  std::span<const std::byte> body;
  bool little_endian = true;
};

/// What an endpoint reports to its topic. Calls come from the backend's threads, one at a
/// time per endpoint (the transport serializes them), never after the endpoint is destroyed.
class Listener {
 public:
  virtual void on_sample(const Sample& sample) = 0;
  /// Something the user must hear about: a remote endpoint of another type on our topic, an
  /// incompatible QoS, a sample that is not valid XCDR1. The message names the topic and
  /// both sides. Counted and logged by the topic.
  virtual void on_error(std::string_view message) = 0;
  /// Messages (or datagrams, when the backend cannot tell messages apart) the backend lost
  /// before they reached this endpoint, e.g. LCM datagrams the kernel dropped because the
  /// socket buffer was full. Added to the topic's dropped_count().
  virtual void on_lost(std::uint64_t count) { (void)count; }
  /// How many samples the listener can take now without losing one (SIZE_MAX: any number). A
  /// reliable fleet topic whose host subscribers are a whole ring behind says 0. A transport
  /// that holds samples (Transport::holds_samples) takes no more than this and leaves the rest
  /// in its reader, whose flow control slows the remote writer, until Endpoint::take_held().
  virtual std::size_t room() { return SIZE_MAX; }
  /// The remote writers or readers matched by the endpoint came or went: ask its
  /// matched_publishers()/matched_subscribers() (from another thread, not from this call).
  virtual void on_matched() {}

 protected:
  ~Listener() = default;
};

/// Fills the body of a sample to be sent: exactly `body.size()` bytes.
struct BodyWriter {
  void (*fill)(void* context, std::span<std::byte> body);
  void* context;
};

/// One topic of one process: a writer and a reader. Destroying it stops its callbacks first.
class Endpoint {
 public:
  virtual ~Endpoint() = default;
  /// Sends one sample of `body_size` bytes, filled in place by `writer`. Thread-safe.
  virtual Result<void> write(std::size_t body_size, const BodyWriter& writer) = 0;
  /// A hint from the topic's bridge: `false` when no handle of the host reads the topic any
  /// more (they all only publish), `true` when one does again. A backend that delivers this
  /// process's own samples back (LCM) stops receiving the channel meanwhile, so its own
  /// traffic costs it nothing. Thread-safe; never called from a listener callback.
  virtual void set_receiving(bool on) noexcept { (void)on; }
  /// Takes what the reader held back while Listener::room() said 0, as far as room() allows
  /// now. Thread-safe; never called from a listener callback.
  virtual void take_held() noexcept {}
  /// The GUIDs of its writer and reader (DDS; a topic mapped onto ROS 2 lists them in the ROS 2
  /// graph); nothing for a transport without them (LCM) or an entity security left out.
  virtual std::optional<Guid> writer_guid() const { return std::nullopt; }
  virtual std::optional<Guid> reader_guid() const { return std::nullopt; }
  /// Remote writers matched with our reader (other processes and hosts).
  virtual std::uint32_t matched_publishers() const = 0;
  /// Remote readers matched with our writer.
  virtual std::uint32_t matched_subscribers() const = 0;
};

/// One backend in one process (a DDS participant, an LCM instance).
class Transport {
 public:
  virtual ~Transport() = default;
  /// "cyclonedds", "fastdds", "lcm".
  virtual std::string_view name() const noexcept = 0;
  /// Creates the writer and reader of a topic. Samples this process writes are not delivered
  /// back to it (the topic's local ring already has them).
  virtual Result<std::unique_ptr<Endpoint>> open(const EndpointSpec& spec, Listener& listener) = 0;
  /// True when samples this process writes also come back to its own endpoints (LCM: the
  /// multicast loops back, and the messages carry no sender). The topic then does not write
  /// what it sends into its ring: the sample arrives once, through the endpoint.
  virtual bool delivers_own_samples() const noexcept { return false; }
  /// True when its endpoints honour Listener::room(): a sample not taken stays in the reader
  /// and the protocol pushes back on the writer (DDS, reliable). LCM has nowhere to keep it.
  virtual bool holds_samples() const noexcept { return false; }
  /// The participant's GUID (DDS), or nothing (LCM).
  virtual std::optional<Guid> participant_guid() const { return std::nullopt; }
  /// The endpoints of other participants its discovery knows now, on every topic of the domain
  /// (DDS: `horus topic list --ros2`); none where it has no discovery (LCM).
  struct Remote {
    Guid guid;
    std::string wire_topic, type_name;
    bool publisher = false;
    std::string type_hash;  // a ROS 2 endpoint's USER_DATA "typehash=...", or empty
  };
  virtual std::vector<Remote> remote_endpoints() const { return {}; }
  /// True when it runs under DDS-Security (net::Security): its peers are authenticated hosts of
  /// the keystore, their access checked, the traffic signed or encrypted.
  virtual bool secure() const noexcept { return false; }
};

}  // namespace horus::net

HORUS_API_END

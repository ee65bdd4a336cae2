// The Cyclone DDS (0.10, C API) backend of horus::net: see horus/network.hpp (the contract)
// and horus/dds/transports.hpp.
//
// One CycloneTransport per domain and process (net::SharedCache, keyed by the domain id; its
// shutdown rule is in horus/transport/shared_cache.hpp): its own DDS domain (our XML
// configuration, CYCLONEDDS_URI is not read) and one participant. It watches the built-in
// DCPSPublication and DCPSSubscription topics to report remote endpoints that use one of our
// topic names with another type name (Cyclone 0.10 raises no INCONSISTENT_TOPIC for that;
// net::RemoteTypes does the bookkeeping).
//
// One CycloneEndpoint per open() (cyclone_endpoint.cpp).
#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cyclone_internal.hpp"
#include "horus/detail/repeat_filter.hpp"
#include "horus/dds/transports.hpp"
#include "horus/security/dds_config.hpp"
#include "horus/transport_registry.hpp"

namespace horus::dds {
namespace cyclone {

std::string dds_error(dds_return_t rc) {
  return std::string(dds_strretcode(rc)) + " (" + std::to_string(rc) + ")";
}

std::string endpoint_label(const net::EndpointSpec& spec) {
  return "topic '" + spec.topic + "' (DDS topic '" + spec.wire_topic + "')";
}

namespace {

using net::kMaxDomainId;  // the largest id whose DDSI ports fit in 16 bits

// Cyclone's rule for topic names (dds_topic.c): letters, digits, '_' and '/', not starting
// with a digit; names starting with "DCPS" are reserved for the built-in topics.
bool valid_wire_topic(std::string_view name) noexcept {
  if (name.empty() || (name[0] >= '0' && name[0] <= '9') || name.starts_with("DCPS")) return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '/';
    if (!ok) return false;
  }
  return true;
}

std::string domain_xml(const net::Config& config, const std::optional<security::ParticipantFiles>& secure) {
  std::string xml = "<CycloneDDS><Domain Id=\"any\">";
  if (secure) xml += security::cyclone_security_xml(*secure, security::cyclone_plugin_dir());
  // A link budget means a constrained link (Wi-Fi): datagrams that fit one Ethernet frame, so
  // that a lost packet loses one DDSI fragment, not a whole IP-fragmented datagram, and lost IP
  // fragments never fill the receiving kernel's reassembly memory (seen: 4 MiB of incomplete
  // datagrams after a congested run made every fragmented datagram fail for 30 s).
  const std::string mtu = config.link_bandwidth > 0 ? "<MaxMessageSize>1456B</MaxMessageSize>" : "";
  if (config.localhost_only) {
    // Loopback only, no multicast: discovery by unicast to the well-known ports of
    // participant indexes 0..40 on 127.0.0.1 (what Fast DDS, with initial peer 127.0.0.1,
    // probes too).
    xml +=
        "<General>"
        "<Interfaces><NetworkInterface address=\"127.0.0.1\" multicast=\"false\"/></Interfaces>"
        "<AllowMulticast>false</AllowMulticast>" +
        mtu +
        "</General>"
        "<Discovery>"
        "<ParticipantIndex>auto</ParticipantIndex>"
        "<MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>"
        "<Peers><Peer Address=\"127.0.0.1\"/></Peers>"
        "</Discovery>";
  } else if (!config.peers.empty()) {
    // A network without multicast (Wi-Fi that filters it): discovery by unicast to the peers'
    // well-known ports of participant indexes 0..kMaxPeerIndex, data by unicast. The peers
    // are host names or IPv4 addresses (net::check_peer): nothing to escape.
    xml += "<General><AllowMulticast>false</AllowMulticast>" + mtu +
           "</General>"
           "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
           "<MaxAutoParticipantIndex>" + std::to_string(net::kMaxPeerIndex) + "</MaxAutoParticipantIndex><Peers>";
    for (const std::string& peer : config.peers) xml += "<Peer Address=\"" + peer + "\"/>";
    xml += "</Peers></Discovery>";
  } else if (!mtu.empty()) {
    xml += "<General>" + mtu + "</General>";
  }
  // Large socket buffers for fragmented multi-megabyte samples; min="default" accepts what
  // the kernel grants (net.core.rmem_max / wmem_max).
  xml +=
      "<Internal>"
      // One receive thread for every socket, woken through a pipe to stop: with a thread per
      // socket Cyclone stops each by sending it a datagram, which never arrives when the link is
      // down, the interface gone or multicast filtered, and dds_delete waits forever.
      "<MultipleReceiveThreads>false</MultipleReceiveThreads>"
      // CycloneTransport::linger waits for acknowledgements instead, with one bound per process.
      "<WriterLingerDuration>0s</WriterLingerDuration>"
      "<SocketReceiveBufferSize min=\"default\" max=\"8MiB\"/>"
      "<SocketSendBufferSize min=\"64KiB\" max=\"4MiB\"/>"
      "</Internal>"
      "<SharedMemory><Enable>false</Enable></SharedMemory>"
      "</Domain></CycloneDDS>";
  return xml;
}

// Cyclone's own warnings and errors (a send that fails while a link is down, every second) go
// to horus's log, each kind of line once until it has been quiet a while; it would print them
// on stderr. The sink is the process's (Cyclone has one): set once, before the first domain.
void cyclone_log_sink(void*, const dds_log_data_t* data) {
  if (data == nullptr || data->message == nullptr) return;
  const std::string_view text(data->message, data->size);  // without Cyclone's header (time, thread)
  const auto level = (data->priority & (DDS_LC_FATAL | DDS_LC_ERROR)) != 0 ? spdlog::level::err
                     : (data->priority & DDS_LC_WARNING) != 0              ? spdlog::level::warn
                                                                           : spdlog::level::debug;
  horus::detail::log_transport_line(level, "Cyclone DDS", text);
}

void route_cyclone_log() {
  static std::once_flag once;
  std::call_once(once, [] {
    horus::detail::open_transport_log();
    dds_set_log_sink(&cyclone_log_sink, nullptr);
  });
}

// A built-in topic instance as a remote-endpoint id.
net::RemoteTypes::Id remote_id(dds_instance_handle_t handle) noexcept {
  net::RemoteTypes::Id id{};
  static_assert(sizeof handle <= sizeof id);
  std::memcpy(id.data(), &handle, sizeof handle);
  return id;
}

}  // namespace

// ---------------------------------------------------------------------------- CycloneTransport

CycloneTransport::~CycloneTransport() {
  if (participant_ > 0) dds_delete(participant_);  // waits for the built-in readers' listeners
  if (domain_ > 0) {
    // Delete the domain unless someone else (outside horus) put a participant in it.
    if (dds_get_children(domain_, nullptr, 0) == 0) dds_delete(domain_);
  }
  // ticket_, destroyed last, frees the domain id in the cache.
}

void CycloneTransport::linger(dds_entity_t writer) noexcept {
  net::process_linger().before_delete([writer](std::chrono::milliseconds wait) {
    return dds_wait_for_acks(writer, std::chrono::nanoseconds(wait).count()) != DDS_RETCODE_TIMEOUT;
  });
}

void CycloneTransport::on_publication(dds_entity_t reader, void* arg) {
  static_cast<CycloneTransport*>(arg)->take_builtin(reader, true);
}
void CycloneTransport::on_subscription(dds_entity_t reader, void* arg) {
  static_cast<CycloneTransport*>(arg)->take_builtin(reader, false);
}

namespace {
// An endpoint's USER_DATA as text (ROS 2's "typehash=...;"), or empty.
std::string user_data_of(const dds_qos_t* qos) {
  void* data = nullptr;
  std::size_t size = 0;
  if (qos == nullptr || !dds_qget_userdata(qos, &data, &size) || data == nullptr) return {};
  std::string out(static_cast<const char*>(data), size);
  dds_free(data);
  return out;
}
}  // namespace

// Drains a DCPSPublication / DCPSSubscription reader into the remote-type watcher, which reports,
// once each, the endpoints of other participants whose type differs from one of ours.
void CycloneTransport::take_builtin(dds_entity_t reader, bool publisher) noexcept {
  try {
    struct Event {
      net::RemoteTypes::Id id;
      bool alive;
      std::string topic, type, user_data;
      net::Guid guid{};
    };
    std::vector<Event> events;
    for (;;) {
      void* samples[kTakeBatch] = {};
      dds_sample_info_t info[kTakeBatch];
      const dds_return_t n = dds_take(reader, samples, info, kTakeBatch, kTakeBatch);
      if (n <= 0) break;
      try {
        for (dds_return_t i = 0; i < n; i++) {
          const auto id = remote_id(info[i].instance_handle);
          if (info[i].instance_state != DDS_IST_ALIVE) {
            events.push_back(Event{id, false, {}, {}, {}, {}});
            continue;
          }
          if (!info[i].valid_data) continue;
          const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
          if (std::memcmp(&ep->participant_key, &guid_, sizeof guid_) == 0) continue;  // ours
          Event e{id, true, ep->topic_name ? ep->topic_name : "", ep->type_name ? ep->type_name : "",
                  user_data_of(ep->qos), {}};
          static_assert(sizeof(ep->key.v) == sizeof(e.guid));
          std::memcpy(e.guid.data(), ep->key.v, e.guid.size());
          events.push_back(std::move(e));
        }
      } catch (...) {
        dds_return_loan(reader, samples, n);
        throw;
      }
      dds_return_loan(reader, samples, n);
      if (static_cast<std::uint32_t>(n) < kTakeBatch) break;
    }
    for (const Event& e : events) {
      if (e.alive)
        remote_types_.remote_seen(e.id, e.topic, e.type, publisher, e.user_data, &e.guid);
      else
        remote_types_.remote_gone(e.id);
    }
  } catch (...) {  // out of memory: nothing sensible to do on a Cyclone thread
  }
}

Result<std::shared_ptr<CycloneTransport>> CycloneTransport::create(net::CacheTicket ticket, const net::Config& config) {
  auto t = std::make_shared<CycloneTransport>(Private{}, std::move(ticket), config);
  const std::string where = "Cyclone DDS domain " + std::to_string(config.domain_id) +
                            " (localhost_only=" + (config.localhost_only ? "true" : "false") + ")";
  route_cyclone_log();
  auto secure = security::secure_participant(config.security, where);
  if (!secure) return std::unexpected(std::move(secure.error()));
  t->secure_ = secure->has_value();
  const std::string xml = domain_xml(config, *secure);
  t->domain_ = dds_create_domain(config.domain_id, xml.c_str());
  if (t->domain_ < 0) {
    const dds_return_t rc = t->domain_;
    t->domain_ = 0;
    if (rc == DDS_RETCODE_PRECONDITION_NOT_MET)
      return fail(Errc::ConfigMismatch, where + ": the domain already exists in this process, created outside horus "
                                                "with other settings; horus needs to create it with its own");
    return fail(Errc::Io, where + ": cannot start the domain: " + dds_error(rc));
  }
  // USER_DATA "enclave=/;" as every ROS 2 participant has (rmw_dds_common): ROS 2's graph
  // tools take horus's participant for one of theirs, in the root security enclave.
  QosPtr participant_qos(dds_create_qos());
  if (!participant_qos) return fail(Errc::Io, where + ": out of memory");
  dds_qset_userdata(participant_qos.get(), kParticipantUserData.data(), kParticipantUserData.size());
  t->participant_ = dds_create_participant(config.domain_id, participant_qos.get(), nullptr);
  if (t->participant_ < 0) {
    const dds_return_t rc = t->participant_;
    t->participant_ = 0;
    if (t->secure_)
      return fail(Errc::Config, where + ": Cyclone DDS refused the secure participant of identity '" +
                                    config.security.identity + "' in keystore '" + config.security.keystore + "': " +
                                    dds_error(rc) + " (its log says why; `horus security check` checks the keystore)");
    return fail(Errc::Io, where + ": cannot create the participant: " + dds_error(rc));
  }
  if (const dds_return_t rc = dds_get_guid(t->participant_, &t->guid_); rc < 0)
    return fail(Errc::Io, where + ": cannot read the participant GUID: " + dds_error(rc));

  ListenerPtr pub_listener(dds_create_listener(t.get()));
  ListenerPtr sub_listener(dds_create_listener(t.get()));
  if (!pub_listener || !sub_listener) return fail(Errc::Io, where + ": out of memory");
  dds_lset_data_available(pub_listener.get(), &CycloneTransport::on_publication);
  dds_lset_data_available(sub_listener.get(), &CycloneTransport::on_subscription);
  const dds_entity_t pubs = dds_create_reader(t->participant_, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, pub_listener.get());
  if (pubs < 0) return fail(Errc::Io, where + ": cannot read the DCPSPublication built-in topic: " + dds_error(pubs));
  const dds_entity_t subs = dds_create_reader(t->participant_, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, sub_listener.get());
  if (subs < 0) return fail(Errc::Io, where + ": cannot read the DCPSSubscription built-in topic: " + dds_error(subs));
  // What was discovered before the listeners were attached.
  t->take_builtin(pubs, true);
  t->take_builtin(subs, false);
  return t;
}

Result<std::unique_ptr<net::Endpoint>> CycloneTransport::open(const net::EndpointSpec& spec, net::Listener& listener) {
  const std::string label = endpoint_label(spec);
  if (!valid_wire_topic(spec.wire_topic))
    return fail(Errc::InvalidName, label + ": Cyclone DDS rejects the topic name '" + spec.wire_topic +
                                       "' (expected letters, digits, '_' and '/', not starting with a digit "
                                       "or \"DCPS\")");
  if (spec.type_name.empty()) return fail(Errc::InvalidArgument, label + ": empty type name, expected e.g. 'horus::msg::Pose2D'");
  if (spec.qos.depth == 0 || spec.qos.depth > static_cast<std::uint32_t>(INT32_MAX))
    return fail(Errc::InvalidArgument, label + ": history depth " + std::to_string(spec.qos.depth) +
                                           ", expected 1.." + std::to_string(INT32_MAX));
  const auto conflict = [&](const std::string& other) {
    return fail(Errc::TypeMismatch, label + ": this process already uses the DDS topic with type '" + other +
                                        "', not '" + spec.type_name + "'");
  };
  if (std::string other = remote_types_.local_conflict(spec.wire_topic, spec.type_name); !other.empty())
    return conflict(other);

  auto core = std::make_shared<EndpointCore>(spec, listener);
  auto endpoint = std::make_unique<CycloneEndpoint>(shared_from_this(), core);
  if (auto created = endpoint->create(); !created) return std::unexpected(std::move(created.error()));
  // Watched for remote endpoints of another type; the ones already known are reported now.
  std::string other = remote_types_.add_local(core.get(), spec.wire_topic, spec.type_name, core->label(),
                                              [core](const std::string& message) { core->report(message); },
                                              spec.user_data);
  if (!other.empty()) return conflict(other);  // lost a race
  endpoint->mark_registered();
  return std::unique_ptr<net::Endpoint>(std::move(endpoint));
}

}  // namespace cyclone

Result<std::shared_ptr<net::Transport>> cyclone_transport(const net::Config& config) {
  if (config.domain_id > net::kMaxDomainId)
    return fail(Errc::InvalidArgument, "Cyclone DDS: domain id " + std::to_string(config.domain_id) +
                                           " is out of range, expected 0.." + std::to_string(net::kMaxDomainId));
  // One transport per domain id: a second configuration of the same domain is refused.
  auto got = net::SharedCache<cyclone::CycloneTransport>::instance().get(
      std::to_string(config.domain_id),
      [&](net::CacheTicket ticket) { return cyclone::CycloneTransport::create(std::move(ticket), config); },
      "Cyclone DDS domain " + std::to_string(config.domain_id) +
          ": the previous transport of this domain did not shut down within 10 s");
  if (!got) return std::unexpected(std::move(got.error()));
  if (const net::Config& other = (*got)->config(); other.peers != config.peers)
    return fail(Errc::ConfigMismatch, "Cyclone DDS domain " + std::to_string(config.domain_id) +
                                          " is already used in this process with other peers; one configuration "
                                          "per domain and process");
  if (const net::Config& other = (*got)->config(); other.security != config.security)
    return fail(Errc::ConfigMismatch, "Cyclone DDS domain " + std::to_string(config.domain_id) +
                                          " is already used in this process with other security settings; one "
                                          "configuration per domain and process");
  if (const net::Config& other = (*got)->config(); other.localhost_only != config.localhost_only)
    return fail(Errc::ConfigMismatch,
                "Cyclone DDS domain " + std::to_string(config.domain_id) +
                    " is already used in this process with localhost_only=" + (other.localhost_only ? "true" : "false") +
                    "; a transport with localhost_only=" + (config.localhost_only ? "true" : "false") +
                    " cannot share it (one configuration per domain and process)");
  return std::shared_ptr<net::Transport>(std::move(*got));
}

void register_cyclonedds() {
  (void)net::register_transport(
      {"cyclonedds", net::WireFormat::Xcdr1, &topic_name,
       [](const net::Config& config) -> Result<std::shared_ptr<net::Transport>> { return cyclone_transport(config); }});
}

}  // namespace horus::dds

// The Fast DDS 2.9 backend of horus::net (see horus/network.hpp for the contract).
//
// One DomainParticipant per distinct net::Config in the process, shared by the Transport object and
// every Endpoint (each holds a shared_ptr); it is deleted with its publisher, subscriber and topics
// when the last of them goes. UDPv4 only: no shared-memory transport and no data sharing, so Fast
// DDS creates nothing in /dev/shm. With localhost_only, discovery is unicast to 127.0.0.1 on the
// well-known participant ports (no multicast), which Cyclone DDS configured the same way also
// finds.
//
// One Endpoint per open(): a DataWriter and a DataReader on a keyless topic whose type is the raw
// XCDR1 type of fastdds_raw_type.hpp, registered under the wire type name. Samples written by any
// participant of this process are never delivered, and matched counts are remote only. Fast DDS
// 2.9 cannot ignore local endpoints, so the reader reads through a ContentFilteredTopic whose
// filter (a class known to this process only) rejects this process's samples before they enter
// the reader's history: left there, they would crowd out remote samples (KEEP_LAST drops a remote
// sample older than the oldest held, and a fragmented one finds the history full). The reader also
// drops by GUID prefix what would still get through.
//
// Threading: Fast DDS calls our listeners from its threads, and from the application's thread
// inside write() (intra-process delivery) and open() (matching with known endpoints). Listener
// calls of one endpoint are serialized by its Core's endpoint gate, which a Fast DDS callback
// never waits for (EndpointGate::drain): the thread inside drains whatever arrived meanwhile. Nothing is delivered on the
// application's thread; what open() gives rise to (incompatible QoS with a known endpoint) is
// handed to a small per-participant dispatcher thread.
//
// Files: fastdds_internal.hpp lists the pieces. The per-configuration participant cache is
// net::SharedCache (its shutdown rule is in horus/transport/shared_cache.hpp); remote endpoints
// of another type on our topics are watched by net::RemoteTypes.
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>
#include <fastdds/dds/topic/qos/TopicQos.hpp>
#include <fastdds/rtps/common/Locator.h>
#include <fastdds/rtps/reader/ReaderDiscoveryInfo.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/writer/WriterDiscoveryInfo.h>
#include <fastrtps/utils/IPLocator.h>

#include "fastdds_internal.hpp"
#include "horus/detail/repeat_filter.hpp"
#include "horus/dds/transports.hpp"
#include "horus/security/dds_config.hpp"
#include "horus/transport_registry.hpp"

namespace horus::dds {
namespace fastdds_detail {
namespace {

constexpr std::uint32_t kSocketBuffer = 4u << 20;  // 4 MiB: a 6 MB sample's fragments fit in flight
constexpr std::uint32_t kInitialPeersRange = 32;   // participant indexes probed on 127.0.0.1
// Fast DDS 2.9 drops a discovery string parameter over 256 bytes (length + characters + NUL,
// padded to 4): topic and type names of more than 251 characters never match.
constexpr std::size_t kMaxNameLength = 251;

net::RemoteTypes::Id remote_id(const rtps::GUID_t& guid) {
  net::RemoteTypes::Id id{};
  std::copy(std::begin(guid.guidPrefix.value), std::end(guid.guidPrefix.value), id.begin());
  std::copy(std::begin(guid.entityId.value), std::end(guid.entityId.value), id.begin() + 12);
  return id;
}

// Fast DDS's warnings and errors go to horus's log (its default consumer writes to stdout),
// each kind of line once until it has been quiet a while (a link that stays down).
class HorusLogConsumer final : public fd::LogConsumer {
 public:
  void Consume(const fd::Log::Entry& entry) override {
    auto level = entry.kind == fd::Log::Kind::Error     ? spdlog::level::err
                 : entry.kind == fd::Log::Kind::Warning ? spdlog::level::warn
                                                        : spdlog::level::debug;
    // Not worth a warning: a reliable writer whose readers lag (the back-pressure the bridge
    // handles), and a reader that lets go of a writer when its participant is deleted (every
    // process's end).
    for (const char* routine : {"Full WriterCache", "Automatically unmatching"})
      if (entry.message.find(routine) != std::string::npos) level = spdlog::level::debug;
    std::string text = entry.message;
    if (entry.context.category != nullptr) text = std::string(entry.context.category) + ": " + text;
    horus::detail::log_transport_line(level, "Fast DDS", text);
  }
};

// A peer's IPv4 address (a host name is looked up; Fast DDS's locators take addresses only).
Result<std::array<unsigned char, 4>> resolve_ipv4(const std::string& host) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  if (const int rc = ::getaddrinfo(host.c_str(), nullptr, &hints, &found); rc != 0 || found == nullptr)
    return fail(Errc::Config, std::string("cannot be resolved to an IPv4 address: ") + ::gai_strerror(rc));
  std::array<unsigned char, 4> out{};
  std::memcpy(out.data(), &reinterpret_cast<const sockaddr_in*>(found->ai_addr)->sin_addr, 4);
  ::freeaddrinfo(found);
  return out;
}

void quiet_fastdds_log() {
  static std::once_flag once;
  std::call_once(once, [] {
    horus::detail::open_transport_log();
    fd::Log::ClearConsumers();
    fd::Log::RegisterConsumer(std::make_unique<HorusLogConsumer>());
    fd::Log::SetVerbosity(fd::Log::Kind::Warning);
  });
}

// Discovery without multicast: on loopback only, or by unicast to the configured peers (both
// with the transport `udp`'s settings); nothing when multicast discovery applies.
Result<void> set_unicast_discovery(fd::DomainParticipantQos& pq, eprosima::fastdds::rtps::UDPv4TransportDescriptor& udp,
                                   const net::Config& config) {
  if (config.localhost_only) {
    udp.interfaceWhiteList.emplace_back("127.0.0.1");
    rtps::Locator_t loopback;
    loopback.kind = LOCATOR_KIND_UDPv4;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(loopback, 127, 0, 0, 1);
    loopback.port = 0;  // 0: the well-known ports of the domain and participant index
    // A metatraffic unicast locator and no multicast one: discovery without multicast.
    pq.wire_protocol().builtin.metatrafficUnicastLocatorList.push_back(loopback);
    pq.wire_protocol().builtin.initialPeersList.push_back(loopback);  // probes kInitialPeersRange indexes
    pq.wire_protocol().default_unicast_locator_list.push_back(loopback);
  } else if (!config.peers.empty()) {
    // A network without multicast: discovery by unicast to the peers' well-known ports of
    // participant indexes 0..kMaxPeerIndex, and a unicast metatraffic locator of our own (any
    // interface) with no multicast one, so that nothing goes to 239.255.0.1.
    udp.maxInitialPeersRange = net::kMaxPeerIndex + 1;
    rtps::Locator_t any;
    any.kind = LOCATOR_KIND_UDPv4;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(any, 0, 0, 0, 0);
    any.port = 0;
    pq.wire_protocol().builtin.metatrafficUnicastLocatorList.push_back(any);
    pq.wire_protocol().default_unicast_locator_list.push_back(any);
    for (const std::string& peer : config.peers) {
      auto address = resolve_ipv4(peer);
      if (!address)
        return fail(Errc::Config, config.peers_origin + ": peer '" + peer + "' " + address.error().message());
      rtps::Locator_t locator;
      locator.kind = LOCATOR_KIND_UDPv4;
      eprosima::fastrtps::rtps::IPLocator::setIPv4(locator, (*address)[0], (*address)[1], (*address)[2], (*address)[3]);
      locator.port = 0;  // 0: the well-known ports of the domain and participant index
      pq.wire_protocol().builtin.initialPeersList.push_back(locator);
    }
  }
  return {};
}

// The host's link budget (network.max_bandwidth, `link_bandwidth` bytes per second): the flow
// controller the writers send through, and the transport `udp`'s datagrams.
void set_link_budget(fd::DomainParticipantQos& pq, eprosima::fastdds::rtps::UDPv4TransportDescriptor& udp,
                     std::uint64_t link_bandwidth) {
  // A constrained link (Wi-Fi): datagrams that fit one Ethernet frame, so that a lost packet
  // loses one RTPS fragment, not a whole IP-fragmented datagram, and lost IP fragments never
  // fill the receiving kernel's reassembly memory (seen: 4 MiB of incomplete datagrams after
  // a congested run made every fragmented datagram fail for 30 s).
  udp.maxMessageSize = kLinkDatagramBytes;
  auto fc = std::make_shared<eprosima::fastdds::rtps::FlowControllerDescriptor>();
  fc->name = kLinkFlowController;
  fc->scheduler = eprosima::fastdds::rtps::FlowControllerSchedulerPolicy::HIGH_PRIORITY;
  fc->max_bytes_per_period = static_cast<std::int32_t>(
      std::clamp<std::uint64_t>(link_bandwidth * kLinkPeriodMs / 1000, 1500, INT32_MAX));
  fc->period_ms = kLinkPeriodMs;
  pq.flow_controllers().push_back(fc);
}

}  // namespace

// ---- participant listener ---------------------------------------------------------------------

void ParticipantListener::on_participant_discovery(fd::DomainParticipant*, rtps::ParticipantDiscoveryInfo&& info) {
  if (info.status == rtps::ParticipantDiscoveryInfo::REMOVED_PARTICIPANT ||
      info.status == rtps::ParticipantDiscoveryInfo::DROPPED_PARTICIPANT)
    transport_.on_remote_participant_gone(info.info.m_guid.guidPrefix);
}

namespace {
// An endpoint's USER_DATA as text (ROS 2's "typehash=...;").
std::string user_data_text(const fd::UserDataQosPolicy& p) {
  const auto& v = p.data_vec();
  return std::string(reinterpret_cast<const char*>(v.data()), v.size());
}
}  // namespace

void ParticipantListener::on_publisher_discovery(fd::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) {
  transport_.on_remote_endpoint(info.info.guid(), info.info.topicName().to_string(),
                                info.info.typeName().to_string(), true,
                                info.status == rtps::WriterDiscoveryInfo::REMOVED_WRITER,
                                user_data_text(info.info.m_qos.m_userData));
}

void ParticipantListener::on_subscriber_discovery(fd::DomainParticipant*, rtps::ReaderDiscoveryInfo&& info) {
  transport_.on_remote_endpoint(info.info.guid(), info.info.topicName().to_string(),
                                info.info.typeName().to_string(), false,
                                info.status == rtps::ReaderDiscoveryInfo::REMOVED_READER,
                                user_data_text(info.info.m_qos.m_userData));
}

// ---- the transport ----------------------------------------------------------------------------

Result<void> FastddsTransport::start() {
  quiet_fastdds_log();
  factory_ = fd::DomainParticipantFactory::get_shared_instance();
  if (!factory_) return fail(Errc::Io, "Fast DDS: the DomainParticipantFactory is not available");

  // A QoS object of our own (not PARTICIPANT_QOS_DEFAULT): XML default profiles do not apply.
  fd::DomainParticipantQos pq;
  pq.name(control_ ? "horus-control" : "horus");
  pq.transport().use_builtin_transports = false;  // drops the default UDPv4 + shared-memory pair
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->sendBufferSize = kSocketBuffer;
  udp->receiveBufferSize = kSocketBuffer;
  udp->maxInitialPeersRange = kInitialPeersRange;
  if (auto ok = set_unicast_discovery(pq, *udp, config_); !ok) return ok;
  pq.transport().user_transports.push_back(udp);
  // Announce every second instead of Fast DDS's 3 s: a participant that starts while the others
  // run learns of them only from these periodic announcements (they do not answer its own), so
  // a late process or tool (a robot rebooting, `horus topic echo`) meets the fleet within about
  // a second. The lease stays 20 s.
  pq.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(1, 0);
  // The host's link budget (network.max_bandwidth): the writers send through a flow controller
  // that paces their fragments at it (kLinkPeriodMs slices), higher priority first, so that a
  // pose goes between two fragments of a camera frame and a large frame does not overflow a
  // short link queue. Fast DDS cuts fragments to fit one slice.
  if (config_.link_bandwidth > 0) set_link_budget(pq, *udp, config_.link_bandwidth);

  // DDS-Security: Fast DDS's built-in plug-ins (PKI-DH, Access-Permissions, AES-GCM-GMAC) with
  // the identity's checked files.
  const std::string where = "Fast DDS domain " + std::to_string(config_.domain_id);
  auto secure = security::secure_participant(config_.security, where);
  if (!secure) return std::unexpected(std::move(secure.error()));
  if (*secure) {
    const security::ParticipantFiles& f = **secure;
    auto& props = pq.properties().properties();
    for (auto& [name, value] : security::dds_security_properties(f)) props.emplace_back(name, value);
    secure_ = true;
  }
  // USER_DATA "enclave=/;" as every ROS 2 participant has (horus/dds/transports.hpp).
  pq.user_data().setValue(std::vector<rtps::octet>(kParticipantUserData.begin(), kParticipantUserData.end()));
  participant_ = factory_->create_participant(static_cast<fd::DomainId_t>(config_.domain_id), pq, &listener_,
                                              fd::StatusMask::none());
  if (participant_ == nullptr && secure_)
    return fail(Errc::Config, where + ": Fast DDS refused the secure participant of identity '" + config_.security.identity +
                                  "' in keystore '" + config_.security.keystore +
                                  "' (its log above says why; `horus security check` checks the keystore)");
  if (participant_ == nullptr)
    return fail(Errc::Io, "Fast DDS could not create a participant on domain " + std::to_string(config_.domain_id) +
                              (config_.localhost_only ? " (loopback only, UDPv4)" : " (UDPv4)") +
                              "; expected free UDP ports in the domain's range");
  prefix_ = participant_->guid().guidPrefix;
  add_local_prefix(prefix_);
  if (participant_->register_content_filter_factory(not_local_class().c_str(), &not_local_factory()) !=
      ReturnCode_t::RETCODE_OK)
    return fail(Errc::Io, "Fast DDS could not register the content filter that keeps this process's own samples "
                          "out of its readers (domain " + std::to_string(config_.domain_id) + ")");

  fd::PublisherQos pubq;
  publisher_ = participant_->create_publisher(pubq, nullptr, fd::StatusMask::none());
  fd::SubscriberQos subq;
  subq.entity_factory().autoenable_created_entities = false;
  subscriber_ = participant_->create_subscriber(subq, nullptr, fd::StatusMask::none());
  if (publisher_ == nullptr || subscriber_ == nullptr)
    return fail(Errc::Io, "Fast DDS could not create the publisher or subscriber of the participant on domain " +
                              std::to_string(config_.domain_id));
  return {};
}

FastddsTransport::~FastddsTransport() {
  dispatcher_.stop();
  if (participant_ != nullptr) {
    participant_->set_listener(nullptr);  // waits for discovery callbacks in progress
    participant_->delete_contained_entities();
    factory_->delete_participant(participant_);
    remove_local_prefix(prefix_);
  }
  // ticket_, destroyed last, frees the configuration in the cache.
}

Result<fd::Topic*> FastddsTransport::acquire_topic(const net::EndpointSpec& spec) {
  std::lock_guard lk(entities_mu_);
  if (auto it = topics_.find(spec.wire_topic); it != topics_.end()) {
    if (it->second.type_name != spec.type_name)
      return fail(Errc::TypeMismatch, "topic '" + spec.topic + "' (DDS topic '" + spec.wire_topic +
                                          "') is already open in this process with type '" + it->second.type_name +
                                          "'; this open expects '" + spec.type_name + "'");
    ++it->second.refs;
    return it->second.topic;
  }
  if (types_.find(spec.type_name) == types_.end()) {
    fd::TypeSupport ts(new RawXcdr1Type(spec.type_name));
    if (ts.register_type(participant_) != ReturnCode_t::RETCODE_OK)
      return fail(Errc::Io,
                  "topic '" + spec.topic + "': Fast DDS could not register the type '" + spec.type_name + "'");
    types_.emplace(spec.type_name, std::move(ts));
  }
  fd::TopicQos tq;
  fd::Topic* topic = participant_->create_topic(spec.wire_topic, spec.type_name, tq, nullptr, fd::StatusMask::none());
  if (topic == nullptr && secure_)
    return fail(Errc::Config, "topic '" + spec.topic + "' (DDS topic '" + spec.wire_topic +
                                  "'): " + security::not_permitted(config_.security, "publish or subscribe"));
  if (topic == nullptr)
    return fail(Errc::Io, "topic '" + spec.topic + "': Fast DDS could not create the DDS topic '" + spec.wire_topic +
                              "' of type '" + spec.type_name + "'");
  topics_.emplace(spec.wire_topic, TopicEntry{topic, spec.type_name, 1});
  return topic;
}

Result<fd::ContentFilteredTopic*> FastddsTransport::create_filtered(const net::EndpointSpec& spec, fd::Topic* topic) {
  std::lock_guard lk(entities_mu_);
  // A local name only (it appears in the reader's discovery data, nowhere else).
  const std::string name = "horus-not-local#" + std::to_string(++filtered_count_);
  fd::ContentFilteredTopic* filtered =
      participant_->create_contentfilteredtopic(name, topic, kNotLocalExpression, {}, not_local_class().c_str());
  if (filtered == nullptr)
    return fail(Errc::Io, "topic '" + spec.topic + "': Fast DDS could not create the content-filtered topic '" + name +
                              "' over the DDS topic '" + spec.wire_topic + "'");
  return filtered;
}

void FastddsTransport::linger(fd::DataWriter* writer) noexcept {
  // The fleet layer's own topics (heartbeats, announcements, queries) are current state, sent
  // again: a closing watcher (`horus fleet --once` on a lossy link) does not wait for them.
  if (control_) return;
  net::process_linger().before_delete([writer](std::chrono::milliseconds wait) {
    const auto ns = std::chrono::nanoseconds(wait).count();
    return writer->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(ns / 1000000000),
                                                                           static_cast<std::uint32_t>(ns % 1000000000))) ==
           ReturnCode_t::RETCODE_OK;
  });
}

void FastddsTransport::delete_filtered(fd::ContentFilteredTopic* filtered) {
  std::lock_guard lk(entities_mu_);
  participant_->delete_contentfilteredtopic(filtered);
}

void FastddsTransport::release_topic(const std::string& wire_topic) {
  std::lock_guard lk(entities_mu_);
  auto it = topics_.find(wire_topic);
  if (it == topics_.end()) return;
  if (--it->second.refs > 0) return;
  participant_->delete_topic(it->second.topic);
  topics_.erase(it);
}

void FastddsTransport::detach(const std::shared_ptr<Core>& core) { remote_types_.remove_local(core.get()); }

void FastddsTransport::on_remote_endpoint(const rtps::GUID_t& guid, const std::string& topic, const std::string& type,
                                          bool writer, bool removed, const std::string& user_data) {
  if (is_local(guid.guidPrefix)) return;
  if (removed)
    remote_types_.remote_gone(remote_id(guid));
  else
    remote_types_.remote_seen(remote_id(guid), topic, type, writer, user_data);
}

void FastddsTransport::on_remote_participant_gone(const rtps::GuidPrefix_t& prefix) {
  remote_types_.remotes_gone(std::span<const std::uint8_t>(prefix.value, sizeof prefix.value));
}

Result<std::unique_ptr<net::Endpoint>> FastddsTransport::open(const net::EndpointSpec& spec, net::Listener& listener) {
  AppCall app;
  if (spec.wire_topic.empty() || spec.wire_topic.size() > kMaxNameLength)
    return fail(Errc::InvalidArgument, "topic '" + shorten(spec.topic) + "': the DDS topic name '" +
                                           shorten(spec.wire_topic) + "' has " +
                                           std::to_string(spec.wire_topic.size()) + " characters; expected 1 to " +
                                           std::to_string(kMaxNameLength));
  if (spec.type_name.empty() || spec.type_name.size() > kMaxNameLength)
    return fail(Errc::InvalidArgument, "topic '" + shorten(spec.topic) + "': the DDS type name '" +
                                           shorten(spec.type_name) + "' has " + std::to_string(spec.type_name.size()) +
                                           " characters; expected 1 to " + std::to_string(kMaxNameLength));
  if (spec.qos.depth == 0)
    return fail(Errc::InvalidArgument, "topic '" + spec.topic + "': a history depth of 0; expected at least 1");

  auto topic = acquire_topic(spec);
  if (!topic) return std::unexpected(std::move(topic.error()));

  auto core = std::make_shared<Core>(spec, listener, dispatcher_);
  auto endpoint = std::make_unique<FastddsEndpoint>(shared_from_this(), core);  // releases the topic
  auto filtered = create_filtered(spec, *topic);
  if (!filtered) return std::unexpected(std::move(filtered.error()));
  if (auto created = endpoint->create(*topic, *filtered); !created) return std::unexpected(std::move(created.error()));

  // Watched for remote endpoints of another type; the ones already known are reported now
  // (through the dispatcher: this is an application thread). acquire_topic already refused
  // another type of this process on the topic.
  (void)remote_types_.add_local(core.get(), spec.wire_topic, spec.type_name, core->topic_label(),
                                [core](const std::string& message) { core->post_error(message); }, spec.user_data);
  return std::unique_ptr<net::Endpoint>(std::move(endpoint));
}

}  // namespace fastdds_detail

Result<std::shared_ptr<net::Transport>> fastdds_transport(const net::Config& config, bool control) {
  using fastdds_detail::FastddsTransport;
  if (config.domain_id > net::kMaxDomainId)
    return fail(Errc::InvalidArgument, "Fast DDS: domain id " + std::to_string(config.domain_id) +
                                           " is out of range; expected 0 to " + std::to_string(net::kMaxDomainId));
  // One participant per configuration (domain id and localhost_only).
  // The fleet layer's own topics have a participant of their own (TransportInfo::open_control).
  std::string key = std::to_string(config.domain_id) + (config.localhost_only ? "/localhost" : "/lan") +
                    (control ? "/control" : "");
  for (const std::string& peer : config.peers) key += "/" + peer;
  auto got = net::SharedCache<FastddsTransport>::instance().get(
      key,
      [&](net::CacheTicket ticket) -> Result<std::shared_ptr<FastddsTransport>> {
        auto transport = std::make_shared<FastddsTransport>(std::move(ticket), config, control);
        if (auto started = transport->start(); !started) return std::unexpected(std::move(started.error()));
        return transport;
      },
      "Fast DDS domain " + std::to_string(config.domain_id) +
          ": the previous participant of this configuration did not shut down within 10 s");
  if (!got) return std::unexpected(std::move(got.error()));
  return std::shared_ptr<net::Transport>(std::move(*got));
}

void register_fastdds() {
  (void)net::register_transport(
      {"fastdds", net::WireFormat::Xcdr1, &topic_name,
       [](const net::Config& config) -> Result<std::shared_ptr<net::Transport>> { return fastdds_transport(config); },
       [](const net::Config& config) -> Result<std::shared_ptr<net::Transport>> {
         return fastdds_transport(config, true);
       }});
}

}  // namespace horus::dds

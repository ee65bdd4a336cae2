// The endpoint of the Cyclone DDS transport (see cyclone_transport.cpp): one DDS topic with
// the raw-bytes sertype (cyclone_sertype.hpp), a writer and a reader that ignore this
// participant's own samples, and the reports of incompatible QoS. Everything it reports goes
// through its EndpointCore's gate (horus/transport/endpoint_gate.hpp).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

#include "cyclone_internal.hpp"
#include "horus/log.hpp"
#include "horus/security/keystore.hpp"
#include "horus/transport/encapsulation.hpp"

namespace horus::dds::cyclone {
namespace {

constexpr dds_duration_t kMaxBlockingTime = DDS_MSECS(100);  // reliable write() blocks at most this
constexpr int32_t kReaderSamples = 4096;  // a reliable reader's samples not yet taken, at most
constexpr std::size_t kMaxBody = 2147483640u;  // Cyclone's default MaxSampleSize (2^31 - 1), minus header

std::string_view policy_name(std::uint32_t id) noexcept {
  switch (id) {
    case DDS_USERDATA_QOS_POLICY_ID: return "user data";
    case DDS_DURABILITY_QOS_POLICY_ID: return "durability";
    case DDS_PRESENTATION_QOS_POLICY_ID: return "presentation";
    case DDS_DEADLINE_QOS_POLICY_ID: return "deadline";
    case DDS_LATENCYBUDGET_QOS_POLICY_ID: return "latency budget";
    case DDS_OWNERSHIP_QOS_POLICY_ID: return "ownership";
    case DDS_OWNERSHIPSTRENGTH_QOS_POLICY_ID: return "ownership strength";
    case DDS_LIVELINESS_QOS_POLICY_ID: return "liveliness";
    case DDS_TIMEBASEDFILTER_QOS_POLICY_ID: return "time-based filter";
    case DDS_PARTITION_QOS_POLICY_ID: return "partition";
    case DDS_RELIABILITY_QOS_POLICY_ID: return "reliability";
    case DDS_DESTINATIONORDER_QOS_POLICY_ID: return "destination order";
    case DDS_HISTORY_QOS_POLICY_ID: return "history";
    case DDS_RESOURCELIMITS_QOS_POLICY_ID: return "resource limits";
    case DDS_ENTITYFACTORY_QOS_POLICY_ID: return "entity factory";
    case DDS_WRITERDATALIFECYCLE_QOS_POLICY_ID: return "writer data lifecycle";
    case DDS_READERDATALIFECYCLE_QOS_POLICY_ID: return "reader data lifecycle";
    case DDS_TOPICDATA_QOS_POLICY_ID: return "topic data";
    case DDS_GROUPDATA_QOS_POLICY_ID: return "group data";
    case DDS_TRANSPORTPRIORITY_QOS_POLICY_ID: return "transport priority";
    case DDS_LIFESPAN_QOS_POLICY_ID: return "lifespan";
    case DDS_DURABILITYSERVICE_QOS_POLICY_ID: return "durability service";
    case DDS_PROPERTY_QOS_POLICY_ID: return "property";
    case DDS_TYPE_CONSISTENCY_ENFORCEMENT_QOS_POLICY_ID: return "type consistency (type information)";
    case DDS_DATA_REPRESENTATION_QOS_POLICY_ID: return "data representation";
    default: break;
  }
  return "unknown";
}

// What this side asks for, in the terms of the policy that did not match.
std::string own_setting(std::uint32_t id, const net::Qos& qos, std::string_view type_name) {
  switch (id) {
    case DDS_RELIABILITY_QOS_POLICY_ID: return std::string(net::to_string(qos.reliability));
    case DDS_DURABILITY_QOS_POLICY_ID: return std::string(net::to_string(qos.durability));
    case DDS_HISTORY_QOS_POLICY_ID: return "keep_last " + std::to_string(qos.depth);
    case DDS_DEADLINE_QOS_POLICY_ID:
      return qos.deadline_ns > 0 ? "a deadline of " + std::to_string(qos.deadline_ns / 1000000) + " ms (offered)"
                                 : "no deadline (a reader requesting one does not match)";
    case DDS_DATA_REPRESENTATION_QOS_POLICY_ID: return "XCDR1 only";
    case DDS_TYPE_CONSISTENCY_ENFORCEMENT_QOS_POLICY_ID:
      return "type '" + std::string(type_name) + "' without XTypes type information";
    default: return "the defaults";
  }
}

// Cyclone listener callbacks of an endpoint's reader and writer (arg: the EndpointCore).
void on_data_available(dds_entity_t reader, void* arg) { static_cast<EndpointCore*>(arg)->take_all(reader); }

void on_sample_lost(dds_entity_t, const dds_sample_lost_status_t status, void* arg) {
  if (status.total_count_change > 0) static_cast<EndpointCore*>(arg)->lost(static_cast<std::uint64_t>(status.total_count_change));
}

void on_publication_matched(dds_entity_t, const dds_publication_matched_status_t, void* arg) {
  static_cast<EndpointCore*>(arg)->matched();
}

void on_subscription_matched(dds_entity_t, const dds_subscription_matched_status_t, void* arg) {
  static_cast<EndpointCore*>(arg)->matched();
}

void on_requested_incompatible_qos(dds_entity_t, const dds_requested_incompatible_qos_status_t status, void* arg) {
  auto* core = static_cast<EndpointCore*>(arg);
  try {
    core->report(core->label() + ": a remote publisher offers an incompatible " +
                 std::string(policy_name(status.last_policy_id)) + " QoS (this reader requests " +
                 own_setting(status.last_policy_id, core->spec().qos, core->spec().type_name) +
                 "); they will not communicate");
  } catch (...) {
  }
}

void on_offered_incompatible_qos(dds_entity_t, const dds_offered_incompatible_qos_status_t status, void* arg) {
  auto* core = static_cast<EndpointCore*>(arg);
  try {
    core->report(core->label() + ": a remote subscriber requests an incompatible " +
                 std::string(policy_name(status.last_policy_id)) + " QoS (this writer offers " +
                 own_setting(status.last_policy_id, core->spec().qos, core->spec().type_name) +
                 "); they will not communicate");
  } catch (...) {
  }
}

}  // namespace

// ---------------------------------------------------------------------------- EndpointCore

void EndpointCore::take_all(dds_entity_t reader) noexcept {
  gate_.run([&](net::EndpointGate::Calls& calls) {
    ddsi_serdata* data[kTakeBatch];
    dds_sample_info_t info[kTakeBatch];
    for (;;) {
      // No more than the listener has room for: the rest waits in the reader (held samples;
      // a full reliable reader makes the remote writer wait), until take_held().
      const std::size_t want = std::min<std::size_t>(kTakeBatch, calls.room());
      if (want == 0) return;
      const dds_return_t n = dds_takecdr(reader, data, static_cast<std::uint32_t>(want), info, DDS_ANY_STATE);
      if (n <= 0) return;
      for (dds_return_t i = 0; i < n; i++) {
        if (info[i].valid_data && calls.open()) deliver(calls, data[i]);
        ddsi_serdata_unref(data[i]);
      }
      if (static_cast<std::size_t>(n) < want) return;  // the reader is empty
    }
  });
}

void EndpointCore::deliver(net::EndpointGate::Calls& calls, const ddsi_serdata* sample) noexcept {
  try {
    std::span<const std::byte> bytes = raw_serdata_bytes(sample);
    if (bytes.data() == nullptr) {  // not our serdata (cannot happen with this reader's sertype)
      try {
        scratch_.resize(ddsi_serdata_size(sample));
      } catch (...) {
        calls.error(label() + ": out of memory for a sample; dropped");
        return;
      }
      ddsi_serdata_to_ser(sample, 0, scratch_.size(), scratch_.data());
      bytes = scratch_;
    }
    auto parsed = net::encapsulation::parse(bytes);
    if (const auto* problem = std::get_if<std::string>(&parsed)) {
      calls.error(label() + ": " + *problem);
      return;
    }
    calls.sample(std::get<net::Sample>(parsed));
  } catch (...) {  // out of memory for a message
  }
}

// ---------------------------------------------------------------------------- CycloneEndpoint

CycloneEndpoint::~CycloneEndpoint() {
  if (registered_) transport_->remote_types().remove_local(core_.get());  // no more discovery reports
  core_->close();                                                         // no more listener calls at all
  // Deleting the reader and writer waits for a listener callback in progress.
  if (reader_ > 0) dds_delete(reader_);
  if (writer_ > 0 && core_->spec().qos.reliability == net::Reliability::Reliable) transport_->linger(writer_);
  if (writer_ > 0) dds_delete(writer_);
  if (topic_ > 0) dds_delete(topic_);
}

namespace {

// The writer's QoS, which the reader shares but for DEADLINE and LIFESPAN (create()).
void set_endpoint_qos(dds_qos_t* qos, const net::Qos& q) {
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  if (q.reliability == net::Reliability::Reliable)
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, kMaxBlockingTime);
  else
    dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_durability(qos, q.durability == net::Durability::TransientLocal ? DDS_DURABILITY_TRANSIENT_LOCAL
                                                                            : DDS_DURABILITY_VOLATILE);
  // Reliable: KEEP_ALL, so nothing is dropped silently under load. A writer whose unacknowledged
  // samples pile up blocks (max_blocking_time) and the bridge retries: the back-pressure reaches
  // the host's publishers through the ring. A reader holds at most kReaderSamples not yet taken
  // and refuses more (unacknowledged: the writer sends them again). Best effort: KEEP_LAST depth.
  if (q.reliability == net::Reliability::Reliable) {
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    dds_qset_resource_limits(qos, kReaderSamples, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  } else {
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, static_cast<int32_t>(q.depth));
  }
  // Cyclone keeps durability_service.history (default KEEP_LAST 1) for late joiners.
  dds_qset_durability_service(qos, 0, DDS_HISTORY_KEEP_LAST, static_cast<int32_t>(q.depth),
                              DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  dds_qset_data_representation(qos, 1, &xcdr1);
  dds_qset_ignorelocal(qos, DDS_IGNORELOCAL_PARTICIPANT);
  // DEADLINE and LIFESPAN on the writer only (create()'s reader has neither): what it offers
  // other vendors' readers. A reader requesting a deadline would not match writers of hosts
  // that offer none; horus's handles enforce both themselves (horus/detail/watch.hpp).
  if (q.deadline_ns > 0) dds_qset_deadline(qos, q.deadline_ns);
  if (q.lifespan_ns > 0) dds_qset_lifespan(qos, q.lifespan_ns);
}

}  // namespace

Result<void> CycloneEndpoint::create() {
  const net::EndpointSpec& spec = core_->spec();
  const dds_entity_t participant = transport_->participant();
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;

  QosPtr topic_qos(dds_create_qos());
  if (!topic_qos) return fail(Errc::Io, core_->label() + ": out of memory");
  dds_qset_data_representation(topic_qos.get(), 1, &xcdr1);

  ddsi_sertype* sertype = make_raw_sertype(spec.type_name.c_str());
  if (sertype == nullptr) return fail(Errc::Io, core_->label() + ": out of memory");
  topic_ = dds_create_topic_sertype(participant, spec.wire_topic.c_str(), &sertype, topic_qos.get(), nullptr, nullptr);
  if (topic_ < 0) {
    const dds_return_t rc = topic_;
    topic_ = 0;
    ddsi_sertype_unref(sertype);
    if (rc == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY)
      return fail(Errc::Config, core_->label() + ": " + security::not_permitted(transport_->config().security, "publish or subscribe"));
    if (rc == DDS_RETCODE_BAD_PARAMETER)
      return fail(Errc::InvalidName, core_->label() + ": Cyclone DDS rejects the topic name '" + spec.wire_topic +
                                         "' (expected letters, digits, '_' and '/', not starting with a digit)");
    return fail(Errc::Io, core_->label() + ": cannot create the DDS topic with type '" + spec.type_name +
                              "': " + dds_error(rc));
  }
  sertype_ = sertype;  // the registered one, kept alive by topic_

  QosPtr qos(dds_create_qos());
  if (!qos) return fail(Errc::Io, core_->label() + ": out of memory");
  set_endpoint_qos(qos.get(), spec.qos);
  // A topic mapped onto ROS 2: "typehash=RIHS01_...;" on both, as rmw does.
  if (!spec.user_data.empty()) dds_qset_userdata(qos.get(), spec.user_data.data(), spec.user_data.size());

  ListenerPtr writer_listener(dds_create_listener(core_.get()));
  ListenerPtr reader_listener(dds_create_listener(core_.get()));
  if (!writer_listener || !reader_listener) return fail(Errc::Io, core_->label() + ": out of memory");
  dds_lset_offered_incompatible_qos(writer_listener.get(), on_offered_incompatible_qos);
  dds_lset_requested_incompatible_qos(reader_listener.get(), on_requested_incompatible_qos);
  dds_lset_data_available(reader_listener.get(), on_data_available);
  dds_lset_sample_lost(reader_listener.get(), on_sample_lost);
  dds_lset_publication_matched(writer_listener.get(), on_publication_matched);
  dds_lset_subscription_matched(reader_listener.get(), on_subscription_matched);

  // Under DDS-Security, the host's permissions may allow only one direction: the other one is
  // left out (what this host's publishers write then stays on the host: write() says why, the
  // bridge counts it as dropped). Neither direction is an error.
  writer_ = spec.send ? dds_create_writer(participant, topic_, qos.get(), writer_listener.get()) : 0;
  bool publish_denied = false;
  if (writer_ < 0) {
    const dds_return_t rc = writer_;
    writer_ = 0;
    if (rc != DDS_RETCODE_NOT_ALLOWED_BY_SECURITY)
      return fail(Errc::Io, core_->label() + ": cannot create the DDS writer: " + dds_error(rc));
    publish_denied = true;
  }
  dds_qset_deadline(qos.get(), DDS_INFINITY);
  dds_qset_lifespan(qos.get(), DDS_INFINITY);
  reader_ = dds_create_reader(participant, topic_, qos.get(), reader_listener.get());
  if (reader_ < 0) {
    const dds_return_t rc = reader_;
    reader_ = 0;
    if (rc != DDS_RETCODE_NOT_ALLOWED_BY_SECURITY || publish_denied)
      return rc == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY
                 ? fail(Errc::Config, core_->label() + ": " + security::not_permitted(transport_->config().security, "publish or subscribe"))
                 : fail(Errc::Io, core_->label() + ": cannot create the DDS reader: " + dds_error(rc));
    detail::log().info("{}: {}; what other hosts publish on it does not reach this host", core_->label(),
                       security::not_permitted(transport_->config().security, "subscribe"));
  }
  if (publish_denied)
    detail::log().info("{}: {}; what this host publishes on it stays on this host", core_->label(),
                       security::not_permitted(transport_->config().security, "publish"));
  return {};
}

Result<void> CycloneEndpoint::write(std::size_t body_size, const net::BodyWriter& writer) {
  if (body_size > kMaxBody)
    return fail(Errc::MessageTooLarge, core_->label() + ": a body of " + std::to_string(body_size) +
                                           " bytes exceeds the largest DDS sample (" + std::to_string(kMaxBody) +
                                           " bytes)");
  if (writer_ == 0)  // access control refused the writer (create())
    return fail(Errc::Config, core_->label() + ": " + security::not_permitted(transport_->config().security, "publish"));
  const auto size = static_cast<std::uint32_t>(net::encapsulation::serialized_size(body_size));
  std::byte* bytes = nullptr;
  ddsi_serdata* data = make_raw_serdata(sertype_, size, &bytes);
  if (data == nullptr)
    return fail(Errc::Io, core_->label() + ": out of memory for a sample of " + std::to_string(size) + " bytes");
  net::encapsulation::write_header_and_padding(std::span<std::byte>(bytes, size), body_size);
  try {
    writer.fill(writer.context, std::span<std::byte>(bytes + net::encapsulation::kHeaderSize, body_size));
  } catch (...) {
    ddsi_serdata_unref(data);
    throw;
  }
  const dds_return_t rc = dds_writecdr(writer_, data);  // consumes `data`
  if (rc == DDS_RETCODE_OK) return {};
  if (rc == DDS_RETCODE_TIMEOUT)
    return fail(Errc::Timeout, core_->label() + ": write of " + std::to_string(body_size) +
                                   " bytes timed out after 100 ms: a reliable subscriber is not keeping up");
  return fail(Errc::Io, core_->label() + ": write of " + std::to_string(body_size) + " bytes failed: " + dds_error(rc));
}

std::uint32_t CycloneEndpoint::matched_publishers() const {
  dds_subscription_matched_status_t status{};
  if (reader_ == 0 || dds_get_subscription_matched_status(reader_, &status) < 0) return 0;
  return status.current_count;
}

std::uint32_t CycloneEndpoint::matched_subscribers() const {
  dds_publication_matched_status_t status{};
  if (writer_ == 0 || dds_get_publication_matched_status(writer_, &status) < 0) return 0;
  return status.current_count;
}

}  // namespace horus::dds::cyclone

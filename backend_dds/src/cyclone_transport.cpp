// The Cyclone DDS (0.10, C API) backend of horus::net: see horus/network.hpp (the contract)
// and horus/dds/transports.hpp.
//
// One CycloneTransport per domain and process: its own DDS domain (our XML configuration,
// CYCLONEDDS_URI is not read) and one participant. It watches the built-in DCPSPublication
// and DCPSSubscription topics to report remote endpoints that use one of our topic names
// with another type name (Cyclone 0.10 raises no INCONSISTENT_TOPIC for that).
//
// One CycloneEndpoint per open(): a topic with the raw-bytes sertype (cyclone_sertype.hpp),
// a writer and a reader that ignore this participant's own samples. Everything it reports
// goes through its EndpointCore, which serializes the listener calls and stops them for
// good when the endpoint closes.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include <dds/dds.h>

#include "cyclone_sertype.hpp"
#include "horus/dds/transports.hpp"
#include "horus/transport_registry.hpp"

namespace horus::dds {
namespace {

using net::kMaxDomainId;  // the largest id whose DDSI ports fit in 16 bits
constexpr dds_duration_t kMaxBlockingTime = DDS_MSECS(100);  // reliable write() blocks at most this
constexpr std::size_t kMaxBody = 2147483640u;  // Cyclone's default MaxSampleSize (2^31 - 1), minus header
constexpr std::uint32_t kTakeBatch = 16;

// ---------------------------------------------------------------------------- helpers

std::string_view reliability_name(net::Reliability r) noexcept {
  return r == net::Reliability::Reliable ? "reliable" : "best_effort";
}
std::string_view durability_name(net::Durability d) noexcept {
  return d == net::Durability::TransientLocal ? "transient_local" : "volatile";
}

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
    case DDS_RELIABILITY_QOS_POLICY_ID: return std::string(reliability_name(qos.reliability));
    case DDS_DURABILITY_QOS_POLICY_ID: return std::string(durability_name(qos.durability));
    case DDS_HISTORY_QOS_POLICY_ID: return "keep_last " + std::to_string(qos.depth);
    case DDS_DATA_REPRESENTATION_QOS_POLICY_ID: return "XCDR1 only";
    case DDS_TYPE_CONSISTENCY_ENFORCEMENT_QOS_POLICY_ID:
      return "type '" + std::string(type_name) + "' without XTypes type information";
    default: return "the defaults";
  }
}

std::string dds_error(dds_return_t rc) {
  return std::string(dds_strretcode(rc)) + " (" + std::to_string(rc) + ")";
}

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

std::string domain_xml(const net::Config& config) {
  std::string xml = "<CycloneDDS><Domain Id=\"any\">";
  if (config.localhost_only) {
    // Loopback only, no multicast: discovery by unicast to the well-known ports of
    // participant indexes 0..40 on 127.0.0.1 (what Fast DDS, with initial peer 127.0.0.1,
    // probes too).
    xml +=
        "<General>"
        "<Interfaces><NetworkInterface address=\"127.0.0.1\" multicast=\"false\"/></Interfaces>"
        "<AllowMulticast>false</AllowMulticast>"
        "</General>"
        "<Discovery>"
        "<ParticipantIndex>auto</ParticipantIndex>"
        "<MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>"
        "<Peers><Peer Address=\"127.0.0.1\"/></Peers>"
        "</Discovery>";
  }
  // Large socket buffers for fragmented multi-megabyte samples; min="default" accepts what
  // the kernel grants (net.core.rmem_max / wmem_max).
  xml +=
      "<Internal>"
      "<SocketReceiveBufferSize min=\"default\" max=\"8MiB\"/>"
      "<SocketSendBufferSize min=\"64KiB\" max=\"4MiB\"/>"
      "</Internal>"
      "<SharedMemory><Enable>false</Enable></SharedMemory>"
      "</Domain></CycloneDDS>";
  return xml;
}

struct QosDeleter {
  void operator()(dds_qos_t* q) const noexcept { dds_delete_qos(q); }
};
using QosPtr = std::unique_ptr<dds_qos_t, QosDeleter>;
struct ListenerDeleter {
  void operator()(dds_listener_t* l) const noexcept { dds_delete_listener(l); }
};
using ListenerPtr = std::unique_ptr<dds_listener_t, ListenerDeleter>;

// ---------------------------------------------------------------------------- EndpointCore

// The part of an endpoint that Cyclone's threads and the transport's discovery watcher
// reach. All listener calls go through it, under `mutex`; once closed, none is made.
class EndpointCore {
 public:
  EndpointCore(const net::EndpointSpec& spec, net::Listener& listener)
      : spec_(spec),
        label_("topic '" + spec.topic + "' (DDS topic '" + spec.wire_topic + "')"),
        listener_(listener) {}

  const net::EndpointSpec& spec() const noexcept { return spec_; }
  const std::string& label() const noexcept { return label_; }

  void report(std::string_view message) noexcept {
    std::lock_guard lock(mutex_);
    if (!closed_) report_locked(message);
  }

  // After this returns, the listener is never called again.
  void close() noexcept {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }

  // Takes every sample the reader holds and hands the valid ones to the listener.
  void take_all(dds_entity_t reader) noexcept {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    ddsi_serdata* data[kTakeBatch];
    dds_sample_info_t info[kTakeBatch];
    for (;;) {
      const dds_return_t n = dds_takecdr(reader, data, kTakeBatch, info, DDS_ANY_STATE);
      if (n <= 0) return;
      for (dds_return_t i = 0; i < n; i++) {
        if (info[i].valid_data && !closed_) deliver_locked(data[i]);
        ddsi_serdata_unref(data[i]);
      }
      if (static_cast<std::uint32_t>(n) < kTakeBatch) return;
    }
  }

 private:
  void report_locked(std::string_view message) noexcept {
    try {
      listener_.on_error(message);
    } catch (...) {  // nothing to do with it on a Cyclone thread
    }
  }

  void deliver_locked(const ddsi_serdata* sample) noexcept {
    std::span<const std::byte> bytes = cyclone::raw_serdata_bytes(sample);
    if (bytes.data() == nullptr) {  // not our serdata (cannot happen with this reader's sertype)
      try {
        scratch_.resize(ddsi_serdata_size(sample));
      } catch (...) {
        report_locked(label_ + ": out of memory for a sample; dropped");
        return;
      }
      ddsi_serdata_to_ser(sample, 0, scratch_.size(), scratch_.data());
      bytes = scratch_;
    }
    try {
      if (bytes.size() < 4) {
        report_locked(label_ + ": a sample of " + std::to_string(bytes.size()) +
                      " bytes, shorter than the 4-byte encapsulation header; dropped");
        return;
      }
      const auto b0 = std::to_integer<unsigned>(bytes[0]), b1 = std::to_integer<unsigned>(bytes[1]);
      if (b0 != 0 || b1 > 1) {
        char hex[8];
        std::snprintf(hex, sizeof hex, "0x%02x%02x", b0, b1);
        report_locked(label_ + ": a sample with encapsulation " + hex +
                      ", expected XCDR1 (0x0000 or 0x0001); dropped");
        return;
      }
      const std::size_t padding = std::to_integer<std::size_t>(bytes[3]) & 3u;
      const std::size_t available = bytes.size() - 4;
      if (padding > available) {
        report_locked(label_ + ": a sample of " + std::to_string(available) + " body bytes claims " +
                      std::to_string(padding) + " bytes of final padding; dropped");
        return;
      }
      listener_.on_sample(net::Sample{bytes.subspan(4, available - padding), b1 == 1});
    } catch (const std::exception& e) {
      report_locked(label_ + ": the sample handler failed: " + e.what());
    } catch (...) {
      report_locked(label_ + ": the sample handler failed");
    }
  }

  const net::EndpointSpec spec_;
  const std::string label_;
  net::Listener& listener_;
  std::mutex mutex_;
  bool closed_ = false;                // guarded by mutex_
  std::vector<std::byte> scratch_;     // guarded by mutex_
};

// Cyclone listener callbacks of an endpoint's reader and writer (arg: the EndpointCore).
void on_data_available(dds_entity_t reader, void* arg) { static_cast<EndpointCore*>(arg)->take_all(reader); }

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

// ---------------------------------------------------------------------------- CycloneTransport

class CycloneTransport;

struct Registry {
  struct Entry {
    net::Config config;
    std::weak_ptr<CycloneTransport> transport;
    const CycloneTransport* owner;
  };
  std::mutex mutex;
  std::condition_variable changed;  // an entry was removed
  std::map<std::uint32_t, Entry> domains;
};

Registry& registry() {
  static Registry* const instance = new Registry();  // never destroyed: transports may outlive statics
  return *instance;
}

class CycloneTransport final : public net::Transport, public std::enable_shared_from_this<CycloneTransport> {
  struct Private {};

 public:
  CycloneTransport(Private, const net::Config& config) : config_(config) {}
  CycloneTransport(const CycloneTransport&) = delete;
  CycloneTransport& operator=(const CycloneTransport&) = delete;

  // Called with the registry locked.
  static Result<std::shared_ptr<CycloneTransport>> create(const net::Config& config);

  ~CycloneTransport() override {
    if (participant_ > 0) dds_delete(participant_);  // waits for the built-in readers' listeners
    if (domain_ > 0) {
      // Delete the domain unless someone else (outside horus) put a participant in it.
      if (dds_get_children(domain_, nullptr, 0) == 0) dds_delete(domain_);
    }
    if (registered_) {
      Registry& reg = registry();
      std::lock_guard lock(reg.mutex);
      auto it = reg.domains.find(config_.domain_id);
      if (it != reg.domains.end() && it->second.owner == this) reg.domains.erase(it);
      reg.changed.notify_all();
    }
  }

  std::string_view name() const noexcept override { return "cyclonedds"; }

  Result<std::unique_ptr<net::Endpoint>> open(const net::EndpointSpec& spec, net::Listener& listener) override;

  void mark_registered() noexcept { registered_ = true; }
  const net::Config& config() const noexcept { return config_; }
  dds_entity_t participant() const noexcept { return participant_; }

  // Another endpoint of this process on spec.wire_topic with another type name, if any.
  std::string local_type_conflict(const net::EndpointSpec& spec) {
    std::lock_guard lock(mutex_);
    return local_type_conflict_locked(spec);
  }

  // Adds `core` to the topic map (unless another type holds its topic: returns that type)
  // and reports the remote endpoints already known to carry another type.
  std::string add_endpoint(const std::shared_ptr<EndpointCore>& core) {
    std::vector<std::string> messages;
    {
      std::lock_guard lock(mutex_);
      if (std::string other = local_type_conflict_locked(core->spec()); !other.empty()) return other;
      endpoints_.emplace(core->spec().wire_topic, core);
      for (const auto& [handle, remote] : remotes_)
        if (remote.topic_name == core->spec().wire_topic && remote.type_name != core->spec().type_name)
          messages.push_back(mismatch_message(*core, remote));
    }
    for (const std::string& m : messages) core->report(m);
    return {};
  }

  void remove_endpoint(const EndpointCore* core) {
    std::lock_guard lock(mutex_);
    auto [first, last] = endpoints_.equal_range(core->spec().wire_topic);
    for (auto it = first; it != last; ++it) {
      if (it->second.get() == core) {
        endpoints_.erase(it);
        return;
      }
    }
  }

 private:
  struct Remote {
    std::string topic_name;
    std::string type_name;
    bool publisher;
  };

  std::string local_type_conflict_locked(const net::EndpointSpec& spec) const {
    auto [first, last] = endpoints_.equal_range(spec.wire_topic);
    for (auto it = first; it != last; ++it)
      if (it->second->spec().type_name != spec.type_name) return it->second->spec().type_name;
    return {};
  }

  static std::string mismatch_message(const EndpointCore& core, const Remote& remote) {
    return core.label() + ": a remote " + (remote.publisher ? "publisher" : "subscriber") + " carries type '" +
           remote.type_name + "', this process expects '" + core.spec().type_name + "'; they will not communicate";
  }

  static void on_publication(dds_entity_t reader, void* arg) {
    static_cast<CycloneTransport*>(arg)->take_builtin(reader, true);
  }
  static void on_subscription(dds_entity_t reader, void* arg) {
    static_cast<CycloneTransport*>(arg)->take_builtin(reader, false);
  }

  // Drains a DCPSPublication / DCPSSubscription reader: remembers the endpoints of other
  // participants and reports, once each, those whose type differs from one of ours.
  void take_builtin(dds_entity_t reader, bool publisher) noexcept {
    try {
      std::vector<std::pair<std::shared_ptr<EndpointCore>, std::string>> reports;
      for (;;) {
        void* samples[kTakeBatch] = {};
        dds_sample_info_t info[kTakeBatch];
        const dds_return_t n = dds_take(reader, samples, info, kTakeBatch, kTakeBatch);
        if (n <= 0) break;
        {
          std::lock_guard lock(mutex_);
          for (dds_return_t i = 0; i < n; i++) {
            const dds_instance_handle_t handle = info[i].instance_handle;
            if (info[i].instance_state != DDS_IST_ALIVE) {
              remotes_.erase(handle);
              continue;
            }
            if (!info[i].valid_data) continue;
            const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
            if (std::memcmp(&ep->participant_key, &guid_, sizeof guid_) == 0) continue;  // ours
            Remote remote{ep->topic_name ? ep->topic_name : "", ep->type_name ? ep->type_name : "", publisher};
            auto [it, inserted] = remotes_.try_emplace(handle, std::move(remote));
            if (!inserted) continue;
            auto [first, last] = endpoints_.equal_range(it->second.topic_name);
            for (auto e = first; e != last; ++e)
              if (e->second->spec().type_name != it->second.type_name)
                reports.emplace_back(e->second, mismatch_message(*e->second, it->second));
          }
        }
        dds_return_loan(reader, samples, n);
        if (static_cast<std::uint32_t>(n) < kTakeBatch) break;
      }
      for (const auto& [core, message] : reports) core->report(message);
    } catch (...) {  // out of memory: nothing sensible to do on a Cyclone thread
    }
  }

  const net::Config config_;
  bool registered_ = false;
  dds_entity_t domain_ = 0;
  dds_entity_t participant_ = 0;
  dds_guid_t guid_{};

  std::mutex mutex_;
  std::multimap<std::string, std::shared_ptr<EndpointCore>> endpoints_;  // by wire topic
  std::unordered_map<dds_instance_handle_t, Remote> remotes_;              // by built-in instance
};

// ---------------------------------------------------------------------------- CycloneEndpoint

class CycloneEndpoint final : public net::Endpoint {
 public:
  CycloneEndpoint(std::shared_ptr<CycloneTransport> transport, std::shared_ptr<EndpointCore> core)
      : transport_(std::move(transport)), core_(std::move(core)) {}
  CycloneEndpoint(const CycloneEndpoint&) = delete;
  CycloneEndpoint& operator=(const CycloneEndpoint&) = delete;

  ~CycloneEndpoint() override {
    if (registered_) transport_->remove_endpoint(core_.get());  // no more discovery reports
    core_->close();                                             // no more listener calls at all
    // Deleting the reader and writer waits for a listener callback in progress.
    if (reader_ > 0) dds_delete(reader_);
    if (writer_ > 0) dds_delete(writer_);
    if (topic_ > 0) dds_delete(topic_);
  }

  Result<void> create() {
    const net::EndpointSpec& spec = core_->spec();
    const dds_entity_t participant = transport_->participant();
    dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;

    QosPtr topic_qos(dds_create_qos());
    if (!topic_qos) return fail(Errc::Io, core_->label() + ": out of memory");
    dds_qset_data_representation(topic_qos.get(), 1, &xcdr1);

    ddsi_sertype* sertype = cyclone::make_raw_sertype(spec.type_name.c_str());
    if (sertype == nullptr) return fail(Errc::Io, core_->label() + ": out of memory");
    topic_ = dds_create_topic_sertype(participant, spec.wire_topic.c_str(), &sertype, topic_qos.get(), nullptr, nullptr);
    if (topic_ < 0) {
      const dds_return_t rc = topic_;
      topic_ = 0;
      ddsi_sertype_unref(sertype);
      if (rc == DDS_RETCODE_BAD_PARAMETER)
        return fail(Errc::InvalidName, core_->label() + ": Cyclone DDS rejects the topic name '" + spec.wire_topic +
                                           "' (expected letters, digits, '_' and '/', not starting with a digit)");
      return fail(Errc::Io, core_->label() + ": cannot create the DDS topic with type '" + spec.type_name +
                                "': " + dds_error(rc));
    }
    sertype_ = sertype;  // the registered one, kept alive by topic_

    QosPtr qos(dds_create_qos());
    if (!qos) return fail(Errc::Io, core_->label() + ": out of memory");
    if (spec.qos.reliability == net::Reliability::Reliable)
      dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, kMaxBlockingTime);
    else
      dds_qset_reliability(qos.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
    dds_qset_durability(qos.get(), spec.qos.durability == net::Durability::TransientLocal
                                       ? DDS_DURABILITY_TRANSIENT_LOCAL
                                       : DDS_DURABILITY_VOLATILE);
    dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, static_cast<int32_t>(spec.qos.depth));
    // Cyclone keeps durability_service.history (default KEEP_LAST 1) for late joiners.
    dds_qset_durability_service(qos.get(), 0, DDS_HISTORY_KEEP_LAST, static_cast<int32_t>(spec.qos.depth),
                                DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
    dds_qset_data_representation(qos.get(), 1, &xcdr1);
    dds_qset_ignorelocal(qos.get(), DDS_IGNORELOCAL_PARTICIPANT);

    ListenerPtr writer_listener(dds_create_listener(core_.get()));
    ListenerPtr reader_listener(dds_create_listener(core_.get()));
    if (!writer_listener || !reader_listener) return fail(Errc::Io, core_->label() + ": out of memory");
    dds_lset_offered_incompatible_qos(writer_listener.get(), on_offered_incompatible_qos);
    dds_lset_requested_incompatible_qos(reader_listener.get(), on_requested_incompatible_qos);
    dds_lset_data_available(reader_listener.get(), on_data_available);

    writer_ = dds_create_writer(participant, topic_, qos.get(), writer_listener.get());
    if (writer_ < 0) {
      const dds_return_t rc = writer_;
      writer_ = 0;
      return fail(Errc::Io, core_->label() + ": cannot create the DDS writer: " + dds_error(rc));
    }
    reader_ = dds_create_reader(participant, topic_, qos.get(), reader_listener.get());
    if (reader_ < 0) {
      const dds_return_t rc = reader_;
      reader_ = 0;
      return fail(Errc::Io, core_->label() + ": cannot create the DDS reader: " + dds_error(rc));
    }
    return {};
  }

  void mark_registered() noexcept { registered_ = true; }

  Result<void> write(std::size_t body_size, const net::BodyWriter& writer) override {
    if (body_size > kMaxBody)
      return fail(Errc::MessageTooLarge, core_->label() + ": a body of " + std::to_string(body_size) +
                                             " bytes exceeds the largest DDS sample (" + std::to_string(kMaxBody) +
                                             " bytes)");
    const std::size_t padding = (4 - body_size % 4) % 4;
    const auto size = static_cast<std::uint32_t>(4 + body_size + padding);
    std::byte* bytes = nullptr;
    ddsi_serdata* data = cyclone::make_raw_serdata(sertype_, size, &bytes);
    if (data == nullptr)
      return fail(Errc::Io, core_->label() + ": out of memory for a sample of " + std::to_string(size) + " bytes");
    bytes[0] = std::byte{0x00};  // CDR_LE: XCDR1, little endian
    bytes[1] = std::byte{0x01};
    bytes[2] = std::byte{0x00};
    bytes[3] = static_cast<std::byte>(padding);  // options: number of padding bytes at the end
    for (std::size_t i = 0; i < padding; i++) bytes[4 + body_size + i] = std::byte{0};
    try {
      writer.fill(writer.context, std::span<std::byte>(bytes + 4, body_size));
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

  std::uint32_t matched_publishers() const override {
    dds_subscription_matched_status_t status{};
    if (dds_get_subscription_matched_status(reader_, &status) < 0) return 0;
    return status.current_count;
  }

  std::uint32_t matched_subscribers() const override {
    dds_publication_matched_status_t status{};
    if (dds_get_publication_matched_status(writer_, &status) < 0) return 0;
    return status.current_count;
  }

 private:
  std::shared_ptr<CycloneTransport> transport_;  // keeps the participant alive
  std::shared_ptr<EndpointCore> core_;
  bool registered_ = false;
  ddsi_sertype* sertype_ = nullptr;
  dds_entity_t topic_ = 0;
  dds_entity_t writer_ = 0;
  dds_entity_t reader_ = 0;
};

// ---------------------------------------------------------------------------- definitions

Result<std::shared_ptr<CycloneTransport>> CycloneTransport::create(const net::Config& config) {
  auto t = std::make_shared<CycloneTransport>(Private{}, config);
  const std::string where = "Cyclone DDS domain " + std::to_string(config.domain_id) +
                            " (localhost_only=" + (config.localhost_only ? "true" : "false") + ")";
  const std::string xml = domain_xml(config);
  t->domain_ = dds_create_domain(config.domain_id, xml.c_str());
  if (t->domain_ < 0) {
    const dds_return_t rc = t->domain_;
    t->domain_ = 0;
    if (rc == DDS_RETCODE_PRECONDITION_NOT_MET)
      return fail(Errc::ConfigMismatch, where + ": the domain already exists in this process, created outside horus "
                                                "with other settings; horus needs to create it with its own");
    return fail(Errc::Io, where + ": cannot start the domain: " + dds_error(rc));
  }
  t->participant_ = dds_create_participant(config.domain_id, nullptr, nullptr);
  if (t->participant_ < 0) {
    const dds_return_t rc = t->participant_;
    t->participant_ = 0;
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
  const std::string label = "topic '" + spec.topic + "' (DDS topic '" + spec.wire_topic + "')";
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
  if (std::string other = local_type_conflict(spec); !other.empty()) return conflict(other);

  auto core = std::make_shared<EndpointCore>(spec, listener);
  auto endpoint = std::make_unique<CycloneEndpoint>(shared_from_this(), core);
  if (auto created = endpoint->create(); !created) return std::unexpected(std::move(created.error()));
  if (std::string other = add_endpoint(core); !other.empty()) return conflict(other);  // lost a race
  endpoint->mark_registered();
  return std::unique_ptr<net::Endpoint>(std::move(endpoint));
}

}  // namespace

Result<std::shared_ptr<net::Transport>> cyclone_transport(const net::Config& config) {
  if (config.domain_id > kMaxDomainId)
    return fail(Errc::InvalidArgument, "Cyclone DDS: domain id " + std::to_string(config.domain_id) +
                                           " is out of range, expected 0.." + std::to_string(kMaxDomainId));
  Registry& reg = registry();
  std::shared_ptr<CycloneTransport> existing;  // declared before the lock: released after it
  std::unique_lock lock(reg.mutex);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (;;) {
    auto it = reg.domains.find(config.domain_id);
    if (it == reg.domains.end()) break;
    existing = it->second.transport.lock();
    if (existing) {
      if (it->second.config == config) return std::shared_ptr<net::Transport>(existing);
      const net::Config& other = it->second.config;
      return fail(Errc::ConfigMismatch,
                  "Cyclone DDS domain " + std::to_string(config.domain_id) +
                      " is already used in this process with localhost_only=" + (other.localhost_only ? "true" : "false") +
                      "; a transport with localhost_only=" + (config.localhost_only ? "true" : "false") +
                      " cannot share it (one configuration per domain and process)");
    }
    // The last user just released it; wait until its participant is gone.
    if (reg.changed.wait_until(lock, deadline) == std::cv_status::timeout && reg.domains.count(config.domain_id) != 0)
      return fail(Errc::Timeout, "Cyclone DDS domain " + std::to_string(config.domain_id) +
                                     ": the previous transport of this domain did not shut down within 10 s");
  }
  auto created = CycloneTransport::create(config);
  if (!created) return std::unexpected(std::move(created.error()));
  reg.domains.insert_or_assign(config.domain_id, Registry::Entry{config, *created, created->get()});
  (*created)->mark_registered();
  return std::shared_ptr<net::Transport>(std::move(*created));
}

void register_cyclonedds() {
  (void)net::register_transport(
      {"cyclonedds", net::WireFormat::Xcdr1, &topic_name, []() -> Result<std::shared_ptr<net::Transport>> {
         auto config = net::config_from_environment();
         if (!config) return std::unexpected(std::move(config.error()));
         return cyclone_transport(*config);
       }});
}

}  // namespace horus::dds

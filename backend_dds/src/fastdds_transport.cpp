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
// calls of one endpoint are serialized by its Core's mutex, which a Fast DDS callback only
// try-locks: the thread holding it drains whatever arrived meanwhile. Nothing is delivered on the
// application's thread; what open() gives rise to (incompatible QoS with a known endpoint) is
// handed to a small per-participant dispatcher thread.
#include <algorithm>
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include <unistd.h>

#include <fastdds/dds/core/LoanableSequence.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/dds/topic/qos/TopicQos.hpp>
#include <fastdds/rtps/common/Guid.h>
#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastdds/rtps/common/Locator.h>
#include <fastdds/rtps/reader/ReaderDiscoveryInfo.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/writer/WriterDiscoveryInfo.h>
#include <fastrtps/utils/IPLocator.h>

#include "fastdds_raw_type.hpp"
#include "horus/dds/transports.hpp"
#include "horus/transport_registry.hpp"
#include "horus/error.hpp"
#include "horus/network.hpp"

namespace horus::dds {
namespace {

namespace fd = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;
using eprosima::fastrtps::types::ReturnCode_t;
using fastdds_detail::RawReadSample;
using fastdds_detail::RawWriteSample;
using fastdds_detail::RawXcdr1Type;

using net::kMaxDomainId;  // RTPS well-known ports stay below 65536
constexpr std::uint32_t kSocketBuffer = 4u << 20;  // 4 MiB: a 6 MB sample's fragments fit in flight
constexpr std::uint32_t kInitialPeersRange = 32;   // participant indexes probed on 127.0.0.1
constexpr std::int32_t kMaxBlockingMs = 100;       // reliable write: bounded wait
constexpr std::int32_t kHeartbeatMs = 100;         // reliable writer: quick repair of lost fragments
// Fast DDS 2.9 drops a discovery string parameter over 256 bytes (length + characters + NUL,
// padded to 4): topic and type names of more than 251 characters never match.
constexpr std::size_t kMaxNameLength = 251;

// ---- thread context ---------------------------------------------------------------------------

// > 0 while the application's thread is inside write(), open() or an endpoint's destructor: Fast
// DDS may call our listeners synchronously there, and the application's listener must not run.
thread_local int t_app_call = 0;

struct AppCall {
  AppCall() noexcept { ++t_app_call; }
  ~AppCall() { --t_app_call; }
  AppCall(const AppCall&) = delete;
  AppCall& operator=(const AppCall&) = delete;
};

// > 0 while this thread is inside Endpoint::write(): Fast DDS delivers a new sample to the readers
// of this process synchronously there, so a sample filtered on this thread is our own.
thread_local int t_writing = 0;

struct Writing {
  Writing() noexcept { ++t_writing; }
  ~Writing() { --t_writing; }
  Writing(const Writing&) = delete;
  Writing& operator=(const Writing&) = delete;
};

// ---- process-wide registry of our participants' GUID prefixes -----------------------------------

using Prefix = std::array<std::uint8_t, 12>;

Prefix to_prefix(const rtps::GuidPrefix_t& p) {
  Prefix out{};
  std::copy(std::begin(p.value), std::end(p.value), out.begin());
  return out;
}

struct LocalPrefixes {
  std::mutex mu;
  std::vector<Prefix> prefixes;  // a handful: one per live participant of this process
};

LocalPrefixes& local_prefixes() {
  static auto* instance = new LocalPrefixes();  // never destroyed: used by late destructors
  return *instance;
}

void add_local_prefix(const rtps::GuidPrefix_t& p) {
  auto& reg = local_prefixes();
  std::lock_guard lk(reg.mu);
  reg.prefixes.push_back(to_prefix(p));
}

void remove_local_prefix(const rtps::GuidPrefix_t& p) {
  auto& reg = local_prefixes();
  std::lock_guard lk(reg.mu);
  const Prefix key = to_prefix(p);
  if (auto it = std::find(reg.prefixes.begin(), reg.prefixes.end(), key); it != reg.prefixes.end())
    reg.prefixes.erase(it);
}

/// Whether an entity belongs to a participant of this process.
bool is_local(const rtps::GuidPrefix_t& p) {
  auto& reg = local_prefixes();
  const Prefix key = to_prefix(p);
  std::lock_guard lk(reg.mu);
  return std::find(reg.prefixes.begin(), reg.prefixes.end(), key) != reg.prefixes.end();
}

// ---- the "not from this process" content filter ------------------------------------------------

/// Rejects, for a reader of this process, samples written by this process. Evaluated by this
/// process only: its class name is unique to the process, so no remote writer applies it.
class NotLocalFilter final : public fd::IContentFilter {
 public:
  bool evaluate(const SerializedPayload&, const FilterSampleInfo& info, const rtps::GUID_t& reader) const override {
    if (!is_local(reader.guidPrefix)) return true;
    if (t_writing > 0) return false;  // delivered inside our write(): our own
    const rtps::GUID_t& writer = info.sample_identity.writer_guid();
    return writer == rtps::GUID_t::unknown() || !is_local(writer.guidPrefix);
  }
};

class NotLocalFilterFactory final : public fd::IContentFilterFactory {
 public:
  ReturnCode_t create_content_filter(const char*, const char*, const fd::TopicDataType*, const char*,
                                     const ParameterSeq&, fd::IContentFilter*& filter_instance) override {
    filter_instance = &filter_;
    return ReturnCode_t::RETCODE_OK;
  }
  ReturnCode_t delete_content_filter(const char*, fd::IContentFilter*) override { return ReturnCode_t::RETCODE_OK; }

 private:
  NotLocalFilter filter_;
};

NotLocalFilterFactory& not_local_factory() {
  static auto* instance = new NotLocalFilterFactory();  // never destroyed: participants may outlive statics
  return *instance;
}

/// "horus_not_local_<pid>_<random>": remote processes never know it, so they never filter for us.
const std::string& not_local_class() {
  static const std::string name = [] {
    std::random_device rd;
    const auto r = (static_cast<std::uint64_t>(rd()) << 32) ^ rd();
    return "horus_not_local_" + std::to_string(::getpid()) + "_" + std::to_string(r);
  }();
  return name;
}

constexpr const char* kNotLocalExpression = "not from this process";  // non-empty: empty passes all

// ---- names for messages -------------------------------------------------------------------------

std::string_view reliability_name(net::Reliability r) {
  return r == net::Reliability::Reliable ? "reliable" : "best effort";
}
std::string_view durability_name(net::Durability d) {
  return d == net::Durability::TransientLocal ? "transient local" : "volatile";
}

std::string_view policy_name(std::uint32_t id) {
  switch (id) {
    case fd::DURABILITY_QOS_POLICY_ID: return "durability";
    case fd::PRESENTATION_QOS_POLICY_ID: return "presentation";
    case fd::DEADLINE_QOS_POLICY_ID: return "deadline";
    case fd::LATENCYBUDGET_QOS_POLICY_ID: return "latency budget";
    case fd::OWNERSHIP_QOS_POLICY_ID: return "ownership";
    case fd::LIVELINESS_QOS_POLICY_ID: return "liveliness";
    case fd::PARTITION_QOS_POLICY_ID: return "partition";
    case fd::RELIABILITY_QOS_POLICY_ID: return "reliability";
    case fd::DESTINATIONORDER_QOS_POLICY_ID: return "destination order";
    case fd::DATAREPRESENTATION_QOS_POLICY_ID: return "data representation";
    case fd::TYPECONSISTENCYENFORCEMENT_QOS_POLICY_ID: return "type consistency";
    case fd::DISABLEPOSITIVEACKS_QOS_POLICY_ID: return "disable positive acks";
    default: return {};
  }
}

std::string describe(const net::Qos& q) {
  std::string s;
  s += reliability_name(q.reliability);
  s += ", ";
  s += durability_name(q.durability);
  s += ", depth ";
  s += std::to_string(q.depth);
  return s;
}

/// A name cut to 64 characters for a message.
std::string shorten(const std::string& name) {
  return name.size() <= 64 ? name : name.substr(0, 61) + "...";
}

std::string hex2(std::uint8_t a, std::uint8_t b) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02x%02x", a, b);
  return buf;
}

// ---- the dispatcher: delivers what arose on an application thread ------------------------------

class Core;

class Dispatcher {
 public:
  Dispatcher() = default;
  Dispatcher(const Dispatcher&) = delete;
  Dispatcher& operator=(const Dispatcher&) = delete;
  ~Dispatcher() { stop(); }

  void post(std::shared_ptr<Core> core);

  void stop() {
    {
      std::lock_guard lk(mu_);
      stopping_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
    std::lock_guard lk(mu_);
    queue_.clear();
  }

 private:
  void run();

  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::shared_ptr<Core>> queue_;
  bool stopping_ = false;
  std::thread thread_;  // started on first use
};

// ---- Core: what one endpoint's callbacks share ----------------------------------------------

/// The callback side of one endpoint. Fast DDS listener objects reach it by pointer; the endpoint
/// and the transport's topic index hold it by shared_ptr.
class Core : public std::enable_shared_from_this<Core> {
 public:
  Core(net::EndpointSpec spec, net::Listener& listener, Dispatcher& dispatcher)
      : spec_(std::move(spec)), dispatcher_(dispatcher), listener_(&listener) {}

  const net::EndpointSpec& spec() const { return spec_; }

  /// "topic 'fleet.pose' (DDS topic 'horus/fleet/pose')".
  std::string topic_label() const {
    return "topic '" + spec_.topic + "' (DDS topic '" + spec_.wire_topic + "')";
  }

  void attach_reader(fd::DataReader* reader) {
    std::lock_guard lk(mu_);
    reader_ = reader;
  }

  /// Stops every later listener call; waits for one in progress. Not from this endpoint's callback.
  void close() {
    std::lock_guard lk(mu_);
    listener_ = nullptr;
    reader_ = nullptr;
    std::lock_guard qk(queue_mu_);
    errors_.clear();
  }

  void post_error(std::string message) {
    {
      std::lock_guard lk(queue_mu_);
      errors_.push_back(std::move(message));
    }
    drain();
  }

  /// Delivers queued errors and available samples, unless another thread is doing so (it then
  /// picks this up) or this is an application thread (the dispatcher then does it).
  void drain() {
    if (t_app_call > 0) {
      bool has_errors;
      {
        std::lock_guard lk(queue_mu_);
        has_errors = !errors_.empty();
      }
      if (has_errors) dispatcher_.post(shared_from_this());
      return;  // no remote sample arrives on an application thread; the filter keeps our own out
    }
    const auto self = std::this_thread::get_id();
    pending_.store(true);
    if (owner_.load() == self) return;  // re-entered from our own delivery: it loops on pending_
    for (;;) {
      {
        std::unique_lock lk(mu_, std::try_to_lock);
        if (!lk.owns_lock()) return;  // the holder sees pending_ after it unlocks
        owner_.store(self);
        while (pending_.exchange(false)) deliver_locked();
        owner_.store(std::thread::id{});
      }
      if (!pending_.load()) return;
    }
  }

  // ---- matched remote endpoints ----
  void on_matched(bool reader_side, const rtps::InstanceHandle_t& handle, std::int32_t change) {
    const rtps::GUID_t guid = rtps::iHandle2GUID(handle);
    if (change == 0 || is_local(guid.guidPrefix)) return;
    std::lock_guard lk(matched_mu_);
    auto& set = reader_side ? remote_writers_ : remote_readers_;
    if (change > 0)
      set.insert(guid);
    else
      set.erase(guid);
  }
  std::uint32_t matched(bool reader_side) const {
    std::lock_guard lk(matched_mu_);
    return static_cast<std::uint32_t>(reader_side ? remote_writers_.size() : remote_readers_.size());
  }

  // ---- incompatible QoS ----
  void on_incompatible(bool reader_side, const fd::IncompatibleQosStatus& status) {
    std::string policies;
    {
      std::lock_guard lk(matched_mu_);
      auto& last = reader_side ? requested_counts_ : offered_counts_;
      if (last.size() < status.policies.size()) last.resize(status.policies.size(), 0);
      for (std::size_t i = 0; i < status.policies.size(); ++i) {
        const auto count = status.policies[i].count;
        if (count > last[i]) {
          const auto name = policy_name(static_cast<std::uint32_t>(i));
          if (!policies.empty()) policies += ", ";
          policies += name.empty() ? "policy " + std::to_string(i) : std::string(name);
        }
        last[i] = count;
      }
    }
    if (policies.empty()) {
      const auto name = policy_name(status.last_policy_id);
      policies = name.empty() ? "policy " + std::to_string(status.last_policy_id) : std::string(name);
    }
    std::string msg = topic_label();
    if (reader_side) {
      msg += ": a remote publisher offers a QoS incompatible with this subscriber's request (" + policies +
             "; this side requests " + describe(spec_.qos) + "); they will not communicate";
    } else {
      msg += ": a remote subscriber requests a QoS this publisher does not offer (" + policies +
             "; this side offers " + describe(spec_.qos) + "); they will not communicate";
    }
    post_error(std::move(msg));
  }

  /// Remote endpoints already reported as carrying another type (guarded by the transport's
  /// discovery mutex).
  std::set<rtps::GUID_t> reported_types;

 private:
  void call_error(const std::string& message) {
    try {
      listener_->on_error(message);
    } catch (...) {
      // A listener must not throw into Fast DDS's threads; nothing sensible is left to do.
    }
  }

  void call_sample(const net::Sample& sample) {
    try {
      listener_->on_sample(sample);
    } catch (const std::exception& e) {
      call_error(topic_label() + ": the sample handler threw (" + e.what() + "); the sample was dropped");
    } catch (...) {
      call_error(topic_label() + ": the sample handler threw; the sample was dropped");
    }
  }

  void deliver_sample(const RawReadSample& s) {
    const std::uint8_t* p = s.data;
    const std::uint32_t n = s.length;
    if (p == nullptr || n < 4) {
      call_error("topic '" + spec_.topic + "': a sample of " + std::to_string(n) +
                 " bytes, shorter than the 4-byte encapsulation header; dropped");
      return;
    }
    if (p[0] != 0x00 || p[1] > 0x01) {
      call_error("topic '" + spec_.topic + "': a sample with encapsulation " + hex2(p[0], p[1]) +
                 ", expected XCDR1 (0x0000 or 0x0001); dropped");
      return;
    }
    const std::uint32_t pad = p[3] & 0x03u;
    if (n - 4 < pad) {
      call_error("topic '" + spec_.topic + "': a sample of " + std::to_string(n) + " bytes declares " +
                 std::to_string(pad) + " bytes of final padding, more than its body; dropped");
      return;
    }
    const net::Sample sample{
        std::span<const std::byte>(reinterpret_cast<const std::byte*>(p + 4), n - 4 - pad), p[1] == 0x01};
    call_sample(sample);
  }

  // mu_ held.
  void deliver_locked() {
    std::vector<std::string> errors;
    {
      std::lock_guard lk(queue_mu_);
      errors.swap(errors_);
    }
    if (listener_ == nullptr) return;
    for (const auto& e : errors) call_error(e);
    if (reader_ == nullptr) return;
    fd::LoanableSequence<RawReadSample> data;
    fd::SampleInfoSeq infos;
    while (reader_->take(data, infos) == ReturnCode_t::RETCODE_OK) {
      for (fd::LoanableCollection::size_type i = 0; i < infos.length(); ++i) {
        const fd::SampleInfo& info = infos[i];
        if (!info.valid_data) continue;
        if (is_local(info.sample_identity.writer_guid().guidPrefix)) continue;  // our own sample
        deliver_sample(data[i]);
      }
      reader_->return_loan(data, infos);
    }
  }

  const net::EndpointSpec spec_;
  Dispatcher& dispatcher_;

  std::mutex mu_;                            // serializes listener calls
  net::Listener* listener_ = nullptr;        // null once closed (mu_)
  fd::DataReader* reader_ = nullptr;         // (mu_)
  std::atomic<bool> pending_{false};         // something to deliver
  std::atomic<std::thread::id> owner_{};     // the thread delivering, if any

  std::mutex queue_mu_;
  std::vector<std::string> errors_;          // waiting for delivery (queue_mu_)

  mutable std::mutex matched_mu_;
  std::set<rtps::GUID_t> remote_writers_, remote_readers_;
  std::vector<std::uint32_t> requested_counts_, offered_counts_;
};

void Dispatcher::post(std::shared_ptr<Core> core) {
  {
    std::lock_guard lk(mu_);
    if (stopping_) return;
    queue_.push_back(std::move(core));
    if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
  }
  cv_.notify_one();
}

void Dispatcher::run() {
  std::unique_lock lk(mu_);
  for (;;) {
    cv_.wait(lk, [this] { return stopping_ || !queue_.empty(); });
    if (stopping_) return;
    auto core = std::move(queue_.front());
    queue_.pop_front();
    lk.unlock();
    core->drain();
    core.reset();
    lk.lock();
  }
}

// ---- Fast DDS listener objects --------------------------------------------------------------

class ReaderListener final : public fd::DataReaderListener {
 public:
  explicit ReaderListener(Core& core) : core_(core) {}
  void on_data_available(fd::DataReader*) override { core_.drain(); }
  void on_subscription_matched(fd::DataReader*, const fd::SubscriptionMatchedStatus& s) override {
    core_.on_matched(true, s.last_publication_handle, s.current_count_change);
  }
  void on_requested_incompatible_qos(fd::DataReader*, const fd::RequestedIncompatibleQosStatus& s) override {
    core_.on_incompatible(true, s);
  }

 private:
  Core& core_;
};

class WriterListener final : public fd::DataWriterListener {
 public:
  explicit WriterListener(Core& core) : core_(core) {}
  void on_publication_matched(fd::DataWriter*, const fd::PublicationMatchedStatus& s) override {
    core_.on_matched(false, s.last_subscription_handle, s.current_count_change);
  }
  void on_offered_incompatible_qos(fd::DataWriter*, const fd::OfferedIncompatibleQosStatus& s) override {
    core_.on_incompatible(false, s);
  }

 private:
  Core& core_;
};

// ---- the transport ----------------------------------------------------------------------------

class FastddsTransport;

class ParticipantListener final : public fd::DomainParticipantListener {
 public:
  explicit ParticipantListener(FastddsTransport& transport) : transport_(transport) {}
  void on_participant_discovery(fd::DomainParticipant*, rtps::ParticipantDiscoveryInfo&& info) override;
  void on_publisher_discovery(fd::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override;
  void on_subscriber_discovery(fd::DomainParticipant*, rtps::ReaderDiscoveryInfo&& info) override;

 private:
  FastddsTransport& transport_;
};

class FastddsTransport final : public net::Transport, public std::enable_shared_from_this<FastddsTransport> {
 public:
  explicit FastddsTransport(net::Config config) : config_(config), listener_(*this) {}
  FastddsTransport(const FastddsTransport&) = delete;
  FastddsTransport& operator=(const FastddsTransport&) = delete;
  ~FastddsTransport() override;

  Result<void> start();

  std::string_view name() const noexcept override { return "fastdds"; }
  Result<std::unique_ptr<net::Endpoint>> open(const net::EndpointSpec& spec, net::Listener& listener) override;

  // For endpoints.
  fd::Publisher* publisher() const { return publisher_; }
  fd::Subscriber* subscriber() const { return subscriber_; }
  void detach(const std::shared_ptr<Core>& core);
  void release_topic(const std::string& wire_topic);
  Result<fd::ContentFilteredTopic*> create_filtered(const net::EndpointSpec& spec, fd::Topic* topic);
  void delete_filtered(fd::ContentFilteredTopic* filtered);

  // For the participant listener.
  void on_remote_endpoint(const rtps::GUID_t& guid, std::string topic, std::string type, bool writer, bool removed);
  void on_remote_participant_gone(const rtps::GuidPrefix_t& prefix);

 private:
  Result<fd::Topic*> acquire_topic(const net::EndpointSpec& spec);
  std::string mismatch_message(const Core& core, const std::string& remote_type, bool writer) const;

  const net::Config config_;
  std::shared_ptr<fd::DomainParticipantFactory> factory_;
  fd::DomainParticipant* participant_ = nullptr;
  fd::Publisher* publisher_ = nullptr;
  fd::Subscriber* subscriber_ = nullptr;
  rtps::GuidPrefix_t prefix_;
  ParticipantListener listener_;
  Dispatcher dispatcher_;

  // Types and topics (held while calling Fast DDS's create/delete; discovery never takes it).
  std::mutex entities_mu_;
  std::map<std::string, fd::TypeSupport> types_;  // registered once per participant
  struct TopicEntry {
    fd::Topic* topic = nullptr;
    std::string type_name;
    int refs = 0;
  };
  std::map<std::string, TopicEntry> topics_;
  std::uint64_t filtered_count_ = 0;

  // Discovery state (never held while calling Fast DDS or a listener).
  std::mutex discovery_mu_;
  std::multimap<std::string, std::shared_ptr<Core>> cores_by_topic_;
  struct RemoteEndpoint {
    std::string topic, type;
    bool writer = false;
  };
  std::map<rtps::GUID_t, RemoteEndpoint> remote_;
};

void ParticipantListener::on_participant_discovery(fd::DomainParticipant*, rtps::ParticipantDiscoveryInfo&& info) {
  if (info.status == rtps::ParticipantDiscoveryInfo::REMOVED_PARTICIPANT ||
      info.status == rtps::ParticipantDiscoveryInfo::DROPPED_PARTICIPANT)
    transport_.on_remote_participant_gone(info.info.m_guid.guidPrefix);
}

void ParticipantListener::on_publisher_discovery(fd::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) {
  transport_.on_remote_endpoint(info.info.guid(), info.info.topicName().to_string(),
                                info.info.typeName().to_string(), true,
                                info.status == rtps::WriterDiscoveryInfo::REMOVED_WRITER);
}

void ParticipantListener::on_subscriber_discovery(fd::DomainParticipant*, rtps::ReaderDiscoveryInfo&& info) {
  transport_.on_remote_endpoint(info.info.guid(), info.info.topicName().to_string(),
                                info.info.typeName().to_string(), false,
                                info.status == rtps::ReaderDiscoveryInfo::REMOVED_READER);
}

// ---- endpoint -------------------------------------------------------------------------------

class FastddsEndpoint final : public net::Endpoint {
 public:
  // The transport has acquired the endpoint's topic; the destructor releases it.
  FastddsEndpoint(std::shared_ptr<FastddsTransport> transport, std::shared_ptr<Core> core)
      : transport_(std::move(transport)), core_(std::move(core)), reader_listener_(*core_), writer_listener_(*core_) {}
  FastddsEndpoint(const FastddsEndpoint&) = delete;
  FastddsEndpoint& operator=(const FastddsEndpoint&) = delete;

  ~FastddsEndpoint() override {
    AppCall app;
    transport_->detach(core_);
    core_->close();  // waits for a callback in progress; none after this
    if (reader_ != nullptr) {
      reader_->set_listener(nullptr);
      transport_->subscriber()->delete_datareader(reader_);
    }
    if (filtered_ != nullptr) transport_->delete_filtered(filtered_);
    if (writer_ != nullptr) {
      writer_->set_listener(nullptr);
      transport_->publisher()->delete_datawriter(writer_);
    }
    transport_->release_topic(core_->spec().wire_topic);
  }

  Result<void> create(fd::Topic* topic, fd::ContentFilteredTopic* filtered);

  Result<void> write(std::size_t body_size, const net::BodyWriter& writer) override {
    if (body_size > fastdds_detail::kMaxBodySize)
      return fail(Errc::MessageTooLarge, "topic '" + core_->spec().topic + "': a body of " + std::to_string(body_size) +
                                             " bytes exceeds the largest DDS sample (" +
                                             std::to_string(fastdds_detail::kMaxBodySize) + " bytes)");
    if (writer.fill == nullptr)
      return fail(Errc::InvalidArgument,
                  "topic '" + core_->spec().topic + "': write() needs a BodyWriter with a fill function");
    RawWriteSample sample;
    sample.body_size = body_size;
    sample.writer = &writer;
    ReturnCode_t rc;
    {
      AppCall app;
      Writing writing;
      rc = writer_->write(&sample, rtps::c_InstanceHandle_Unknown);
    }
    if (sample.error) std::rethrow_exception(sample.error);
    if (rc == ReturnCode_t::RETCODE_OK) return {};
    if (rc == ReturnCode_t::RETCODE_TIMEOUT)
      return fail(Errc::Timeout, core_->topic_label() + ": the " +
                                     std::string(reliability_name(core_->spec().qos.reliability)) +
                                     " writer could not take a sample of " + std::to_string(body_size) +
                                     " bytes within its " + std::to_string(kMaxBlockingMs) + " ms blocking bound");
    if (rc == ReturnCode_t::RETCODE_OUT_OF_RESOURCES)
      return fail(Errc::Io, core_->topic_label() + ": Fast DDS is out of resources for a sample of " +
                                std::to_string(body_size) + " bytes");
    return fail(Errc::Io, core_->topic_label() + ": Fast DDS failed to write a sample of " + std::to_string(body_size) +
                              " bytes (return code " + std::to_string(rc()) + ")");
  }

  std::uint32_t matched_publishers() const override { return core_->matched(true); }
  std::uint32_t matched_subscribers() const override { return core_->matched(false); }

 private:
  std::shared_ptr<FastddsTransport> transport_;
  std::shared_ptr<Core> core_;
  ReaderListener reader_listener_;
  WriterListener writer_listener_;
  fd::ContentFilteredTopic* filtered_ = nullptr;
  fd::DataReader* reader_ = nullptr;
  fd::DataWriter* writer_ = nullptr;
};

Result<void> FastddsEndpoint::create(fd::Topic* topic, fd::ContentFilteredTopic* filtered) {
  filtered_ = filtered;
  const net::EndpointSpec& spec = core_->spec();
  const net::Qos& q = spec.qos;
  const auto depth = static_cast<std::int32_t>(std::min<std::uint32_t>(q.depth, 1u << 20));
  const bool reliable = q.reliability == net::Reliability::Reliable;
  const bool transient = q.durability == net::Durability::TransientLocal;
  const eprosima::fastrtps::Duration_t max_blocking(0, static_cast<std::uint32_t>(kMaxBlockingMs) * 1000000u);

  fd::DataWriterQos wq;
  wq.reliability().kind = reliable ? fd::RELIABLE_RELIABILITY_QOS : fd::BEST_EFFORT_RELIABILITY_QOS;
  wq.reliability().max_blocking_time = max_blocking;
  wq.durability().kind = transient ? fd::TRANSIENT_LOCAL_DURABILITY_QOS : fd::VOLATILE_DURABILITY_QOS;
  wq.history().kind = fd::KEEP_LAST_HISTORY_QOS;
  wq.history().depth = depth;
  wq.resource_limits().max_instances = 1;
  wq.resource_limits().max_samples_per_instance = depth;
  wq.resource_limits().max_samples = depth;
  wq.resource_limits().allocated_samples = std::min(depth, 16);
  wq.data_sharing().off();
  wq.representation().m_value = {fd::XCDR_DATA_REPRESENTATION};
  wq.publish_mode().kind = fd::SYNCHRONOUS_PUBLISH_MODE;
  wq.endpoint().history_memory_policy = rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  wq.reliable_writer_qos().times.heartbeatPeriod =
      eprosima::fastrtps::Duration_t(0, static_cast<std::uint32_t>(kHeartbeatMs) * 1000000u);

  fd::DataReaderQos rq;
  rq.reliability().kind = wq.reliability().kind;
  rq.reliability().max_blocking_time = max_blocking;
  rq.durability().kind = wq.durability().kind;
  rq.history().kind = fd::KEEP_LAST_HISTORY_QOS;
  rq.history().depth = depth;
  rq.resource_limits().max_instances = 1;
  rq.resource_limits().max_samples_per_instance = depth;
  rq.resource_limits().max_samples = depth;
  rq.resource_limits().allocated_samples = std::min(depth, 16);
  rq.data_sharing().off();
  rq.type_consistency().representation.m_value = {fd::XCDR_DATA_REPRESENTATION};
  rq.endpoint().history_memory_policy = rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;

  // The reader is created disabled (subscriber QoS), so the core knows it before data can arrive.
  reader_ = transport_->subscriber()->create_datareader(
      filtered, rq, &reader_listener_,
      fd::StatusMask::data_available() << fd::StatusMask::subscription_matched()
                                       << fd::StatusMask::requested_incompatible_qos());
  if (reader_ == nullptr)
    return fail(Errc::Io, core_->topic_label() + ": Fast DDS could not create the DataReader (QoS " +
                              describe(q) + ")");
  core_->attach_reader(reader_);
  writer_ = transport_->publisher()->create_datawriter(
      topic, wq, &writer_listener_,
      fd::StatusMask::publication_matched() << fd::StatusMask::offered_incompatible_qos());
  if (writer_ == nullptr)
    return fail(Errc::Io, core_->topic_label() + ": Fast DDS could not create the DataWriter (QoS " +
                              describe(q) + ")");
  if (reader_->enable() != ReturnCode_t::RETCODE_OK)
    return fail(Errc::Io, core_->topic_label() + ": Fast DDS could not enable the DataReader");
  return {};
}

// ---- transport implementation -----------------------------------------------------------------

void quiet_fastdds_log() {
  static std::once_flag once;
  std::call_once(once, [] {
    // The library must not print: Fast DDS's default consumer writes to stdout.
    fd::Log::SetVerbosity(fd::Log::Kind::Error);
    fd::Log::ClearConsumers();
  });
}

Result<void> FastddsTransport::start() {
  quiet_fastdds_log();
  factory_ = fd::DomainParticipantFactory::get_shared_instance();
  if (!factory_) return fail(Errc::Io, "Fast DDS: the DomainParticipantFactory is not available");

  // A QoS object of our own (not PARTICIPANT_QOS_DEFAULT): XML default profiles do not apply.
  fd::DomainParticipantQos pq;
  pq.name("horus");
  pq.transport().use_builtin_transports = false;  // drops the default UDPv4 + shared-memory pair
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->sendBufferSize = kSocketBuffer;
  udp->receiveBufferSize = kSocketBuffer;
  udp->maxInitialPeersRange = kInitialPeersRange;
  if (config_.localhost_only) {
    udp->interfaceWhiteList.emplace_back("127.0.0.1");
    rtps::Locator_t loopback;
    loopback.kind = LOCATOR_KIND_UDPv4;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(loopback, 127, 0, 0, 1);
    loopback.port = 0;  // 0: the well-known ports of the domain and participant index
    // A metatraffic unicast locator and no multicast one: discovery without multicast.
    pq.wire_protocol().builtin.metatrafficUnicastLocatorList.push_back(loopback);
    pq.wire_protocol().builtin.initialPeersList.push_back(loopback);  // probes kInitialPeersRange indexes
    pq.wire_protocol().default_unicast_locator_list.push_back(loopback);
  }
  pq.transport().user_transports.push_back(udp);

  participant_ = factory_->create_participant(static_cast<fd::DomainId_t>(config_.domain_id), pq, &listener_,
                                              fd::StatusMask::none());
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

std::string FastddsTransport::mismatch_message(const Core& core, const std::string& remote_type, bool writer) const {
  return core.topic_label() + ": a remote " + (writer ? "publisher" : "subscriber") + " carries type '" + remote_type +
         "', this process expects '" + core.spec().type_name + "'; they will not communicate";
}

void FastddsTransport::detach(const std::shared_ptr<Core>& core) {
  std::lock_guard lk(discovery_mu_);
  auto [first, last] = cores_by_topic_.equal_range(core->spec().wire_topic);
  for (auto it = first; it != last; ++it) {
    if (it->second == core) {
      cores_by_topic_.erase(it);
      break;
    }
  }
}

void FastddsTransport::on_remote_endpoint(const rtps::GUID_t& guid, std::string topic, std::string type, bool writer,
                                          bool removed) {
  if (is_local(guid.guidPrefix)) return;
  std::vector<std::pair<std::shared_ptr<Core>, std::string>> reports;
  {
    std::lock_guard lk(discovery_mu_);
    if (removed) {
      remote_.erase(guid);
      auto [first, last] = cores_by_topic_.equal_range(topic);
      for (auto it = first; it != last; ++it) it->second->reported_types.erase(guid);
      return;
    }
    auto [first, last] = cores_by_topic_.equal_range(topic);
    for (auto it = first; it != last; ++it) {
      Core& core = *it->second;
      if (core.spec().type_name != type && core.reported_types.insert(guid).second)
        reports.emplace_back(it->second, mismatch_message(core, type, writer));
    }
    remote_[guid] = RemoteEndpoint{std::move(topic), std::move(type), writer};
  }
  for (auto& [core, message] : reports) core->post_error(std::move(message));
}

void FastddsTransport::on_remote_participant_gone(const rtps::GuidPrefix_t& prefix) {
  std::lock_guard lk(discovery_mu_);
  for (auto it = remote_.begin(); it != remote_.end();) {
    if (it->first.guidPrefix == prefix) {
      for (auto& [topic, core] : cores_by_topic_) core->reported_types.erase(it->first);
      it = remote_.erase(it);
    } else {
      ++it;
    }
  }
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

  // Index it for discovery, and report remote endpoints of another type already known.
  std::vector<std::string> reports;
  {
    std::lock_guard lk(discovery_mu_);
    cores_by_topic_.emplace(spec.wire_topic, core);
    for (const auto& [guid, remote] : remote_) {
      if (remote.topic == spec.wire_topic && remote.type != spec.type_name && core->reported_types.insert(guid).second)
        reports.push_back(mismatch_message(*core, remote.type, remote.writer));
    }
  }
  for (auto& message : reports) core->post_error(std::move(message));
  return std::unique_ptr<net::Endpoint>(std::move(endpoint));
}

// ---- registry -----------------------------------------------------------------------------------

struct Registry {
  std::mutex mu;
  std::vector<std::pair<net::Config, std::weak_ptr<FastddsTransport>>> entries;
};

Registry& registry() {
  static auto* instance = new Registry();  // never destroyed: transports may outlive statics
  return *instance;
}

}  // namespace

Result<std::shared_ptr<net::Transport>> fastdds_transport(const net::Config& config) {
  if (config.domain_id > kMaxDomainId)
    return fail(Errc::InvalidArgument, "Fast DDS: domain id " + std::to_string(config.domain_id) +
                                           " is out of range; expected 0 to " + std::to_string(kMaxDomainId));
  auto& reg = registry();
  std::lock_guard lk(reg.mu);
  std::erase_if(reg.entries, [](const auto& e) { return e.second.expired(); });
  for (const auto& [cfg, weak] : reg.entries) {
    if (cfg == config) {
      if (auto live = weak.lock()) return std::shared_ptr<net::Transport>(std::move(live));
    }
  }
  auto transport = std::make_shared<FastddsTransport>(config);
  if (auto started = transport->start(); !started) return std::unexpected(std::move(started.error()));
  reg.entries.emplace_back(config, transport);
  return std::shared_ptr<net::Transport>(std::move(transport));
}

void register_fastdds() {
  (void)net::register_transport(
      {"fastdds", net::WireFormat::Xcdr1, &topic_name, []() -> Result<std::shared_ptr<net::Transport>> {
         auto config = net::config_from_environment();
         if (!config) return std::unexpected(std::move(config.error()));
         return fastdds_transport(*config);
       }});
}

}  // namespace horus::dds

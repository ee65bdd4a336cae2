// The pieces of the Fast DDS transport (private to backend_dds), see fastdds_transport.cpp for
// the design:
//   fastdds_local.cpp      what belongs to this process: thread context, our participants' GUID
//                          prefixes, the "not from this process" content filter
//   fastdds_endpoint.cpp   Core (delivery through the endpoint gate), the dispatcher, the
//                          endpoint (DataWriter + DataReader) and its Fast DDS listeners
//   fastdds_qos.cpp        QoS names, matched counts, incompatible-QoS reports
//   fastdds_transport.cpp  the participant, topics and types, discovery, the per-config cache
//   fastdds_raw_type.hpp   the raw XCDR1 TopicDataType
#pragma once

#include <cstring>
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/common/Guid.h>
#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastdds/rtps/flowcontrol/FlowControllerDescriptor.hpp>
#include <fastdds/rtps/flowcontrol/FlowControllerSchedulerPolicy.hpp>

#include "fastdds_raw_type.hpp"
#include "horus/error.hpp"
#include "horus/network.hpp"
#include "horus/transport/endpoint_gate.hpp"
#include "horus/transport/linger.hpp"
#include "horus/transport/remote_types.hpp"
#include "horus/transport/shared_cache.hpp"

namespace horus::dds::fastdds_detail {

namespace fd = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

/// A GUID as 16 bytes: the prefix, then the entity id.
inline horus::net::Guid guid_of(const rtps::GUID_t& g) {
  horus::net::Guid out;
  std::memcpy(out.data(), g.guidPrefix.value, 12);
  std::memcpy(out.data() + 12, g.entityId.value, 4);
  return out;
}
using eprosima::fastrtps::types::ReturnCode_t;

inline constexpr std::int32_t kMaxBlockingMs = 100;  // reliable write: bounded wait
// The host's link budget (net::Config::link_bandwidth): the participant's flow controller and
// its slice of time.
inline constexpr const char* kLinkFlowController = "horus.link";
inline constexpr std::uint64_t kLinkPeriodMs = 5;
inline constexpr std::uint32_t kLinkDatagramBytes = 1472;  // an Ethernet frame's UDP payload

// ---- thread context (fastdds_local.cpp) ------------------------------------------------------

// > 0 while the application's thread is inside write(), open() or an endpoint's destructor: Fast
// DDS may call our listeners synchronously there, and the application's listener must not run.
inline thread_local int t_app_call = 0;

struct AppCall {
  AppCall() noexcept { ++t_app_call; }
  ~AppCall() { --t_app_call; }
  AppCall(const AppCall&) = delete;
  AppCall& operator=(const AppCall&) = delete;
};

// > 0 while this thread is inside Endpoint::write(): Fast DDS delivers a new sample to the readers
// of this process synchronously there, so a sample filtered on this thread is our own.
inline thread_local int t_writing = 0;

struct Writing {
  Writing() noexcept { ++t_writing; }
  ~Writing() { --t_writing; }
  Writing(const Writing&) = delete;
  Writing& operator=(const Writing&) = delete;
};

// ---- this process's participants and the content filter (fastdds_local.cpp) ----------------

void add_local_prefix(const rtps::GuidPrefix_t& p);
void remove_local_prefix(const rtps::GuidPrefix_t& p);
/// Whether an entity belongs to a participant of this process.
bool is_local(const rtps::GuidPrefix_t& p);

/// The content filter factory that rejects, for a reader of this process, samples written by
/// this process, and its class name ("horus_not_local_<pid>_<random>": remote processes never
/// know it, so they never filter for us).
fd::IContentFilterFactory& not_local_factory();
const std::string& not_local_class();
inline constexpr const char* kNotLocalExpression = "not from this process";  // non-empty: empty passes all

// ---- QoS names, matching, errors (fastdds_qos.cpp) --------------------------------------------

/// "reliable, volatile, depth 16".
std::string describe(const net::Qos& q);
/// A name cut to 64 characters for a message.
std::string shorten(const std::string& name);

// ---- endpoints (fastdds_endpoint.cpp) ---------------------------------------------------------

class Core;

/// Delivers what arose on an application thread (a per-participant thread, started on first use).
class Dispatcher {
 public:
  Dispatcher() = default;
  Dispatcher(const Dispatcher&) = delete;
  Dispatcher& operator=(const Dispatcher&) = delete;
  ~Dispatcher() { stop(); }

  void post(std::shared_ptr<Core> core);
  void stop();

 private:
  void run();

  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::shared_ptr<Core>> queue_;
  bool stopping_ = false;
  std::thread thread_;  // started on first use
};

/// The callback side of one endpoint. Fast DDS listener objects reach it by pointer; the endpoint
/// and the transport's remote-type watcher hold it by shared_ptr. Listener calls go through its
/// gate, which a Fast DDS callback never waits for (EndpointGate::drain).
class Core : public std::enable_shared_from_this<Core> {
 public:
  Core(net::EndpointSpec spec, net::Listener& listener, Dispatcher& dispatcher);

  const net::EndpointSpec& spec() const { return spec_; }
  /// "topic 'fleet.pose' (DDS topic 'horus/fleet/pose')".
  const std::string& topic_label() const { return gate_.label(); }

  void attach_reader(fd::DataReader* reader) { reader_.store(reader, std::memory_order_release); }
  /// Stops every later listener call; waits for one in progress on another thread.
  void close();
  void post_error(std::string message);
  /// Samples of remote writers the reader will never get (Fast DDS's SAMPLE_LOST: a KEEP_LAST
  /// writer overwrote them before our reader acknowledged): added to the topic's lost count.
  void post_lost(std::int32_t count);
  /// The matched remote endpoints changed: the listener hears it (on_matched) from the gate.
  void post_matched();
  /// Delivers queued errors and available samples, unless another thread is doing so (it then
  /// picks this up) or this is an application thread (the dispatcher then does it).
  void drain();

  // Matched remote endpoints and incompatible QoS (fastdds_qos.cpp).
  void on_matched(bool reader_side, const rtps::InstanceHandle_t& handle, std::int32_t change);
  std::uint32_t matched(bool reader_side) const;
  void on_incompatible(bool reader_side, const fd::IncompatibleQosStatus& status);

 private:
  void deliver(net::EndpointGate::Calls& calls);
  void deliver_sample(net::EndpointGate::Calls& calls, const RawReadSample& s);

  const net::EndpointSpec spec_;
  Dispatcher& dispatcher_;
  net::EndpointGate gate_;
  std::atomic<fd::DataReader*> reader_{nullptr};  // set before the reader is enabled

  std::mutex queue_mu_;
  std::vector<std::string> errors_;  // waiting for delivery (queue_mu_)
  std::uint64_t lost_ = 0;           // samples lost, waiting for delivery (queue_mu_)
  bool matched_changed_ = false;     // on_matched waiting for delivery (queue_mu_)

  mutable std::mutex matched_mu_;
  std::set<rtps::GUID_t> remote_writers_, remote_readers_;
  std::vector<std::uint32_t> requested_counts_, offered_counts_;
};

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
  void on_sample_lost(fd::DataReader*, const fd::SampleLostStatus& s) override { core_.post_lost(s.total_count_change); }

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

// ---- the transport (fastdds_transport.cpp) ----------------------------------------------------

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
  static constexpr std::string_view kCacheName = "Fast DDS participants";  // its net::SharedCache
  FastddsTransport(net::CacheTicket ticket, net::Config config, bool control = false)
      : ticket_(std::move(ticket)), config_(config), control_(control), listener_(*this) {}
  FastddsTransport(const FastddsTransport&) = delete;
  FastddsTransport& operator=(const FastddsTransport&) = delete;
  ~FastddsTransport() override;

  Result<void> start();

  std::string_view name() const noexcept override { return "fastdds"; }
  bool holds_samples() const noexcept override { return true; }
  bool secure() const noexcept override { return secure_; }
  std::vector<Remote> remote_endpoints() const override { return remote_types_.remotes(); }
  std::optional<net::Guid> participant_guid() const override {
    return participant_ != nullptr ? std::optional(guid_of(participant_->guid())) : std::nullopt;
  }
  Result<std::unique_ptr<net::Endpoint>> open(const net::EndpointSpec& spec, net::Listener& listener) override;

  // For endpoints.
  fd::Publisher* publisher() const { return publisher_; }
  /// True when writers go through the link budget's flow controller (kLinkFlowController).
  bool paced() const { return config_.link_bandwidth > 0; }
  const net::Config& config() const noexcept { return config_; }
  fd::Subscriber* subscriber() const { return subscriber_; }
  void detach(const std::shared_ptr<Core>& core);
  void release_topic(const std::string& wire_topic);
  Result<fd::ContentFilteredTopic*> create_filtered(const net::EndpointSpec& spec, fd::Topic* topic);
  void delete_filtered(fd::ContentFilteredTopic* filtered);
  /// Before a reliable writer is deleted: waits until its readers acknowledged what it wrote
  /// (net::process_linger(), horus/transport/linger.hpp: its bound and when it does not wait).
  void linger(fd::DataWriter* writer) noexcept;

  // For the participant listener.
  void on_remote_endpoint(const rtps::GUID_t& guid, const std::string& topic, const std::string& type, bool writer,
                          bool removed, const std::string& user_data);
  void on_remote_participant_gone(const rtps::GuidPrefix_t& prefix);

 private:
  Result<fd::Topic*> acquire_topic(const net::EndpointSpec& spec);

  net::CacheTicket ticket_;  // first: removes the cache entry after everything else is gone
  const net::Config config_;
  const bool control_;  // the fleet layer's participant (TransportInfo::open_control)
  bool secure_ = false;  // DDS-Security on (set by start)
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

  // Remote endpoints of another type on our topics (never locked while calling Fast DDS).
  net::RemoteTypes remote_types_;
};

class FastddsEndpoint final : public net::Endpoint {
 public:
  // The transport has acquired the endpoint's topic; the destructor releases it.
  FastddsEndpoint(std::shared_ptr<FastddsTransport> transport, std::shared_ptr<Core> core)
      : transport_(std::move(transport)), core_(std::move(core)), reader_listener_(*core_), writer_listener_(*core_) {}
  FastddsEndpoint(const FastddsEndpoint&) = delete;
  FastddsEndpoint& operator=(const FastddsEndpoint&) = delete;
  ~FastddsEndpoint() override;

  Result<void> create(fd::Topic* topic, fd::ContentFilteredTopic* filtered);

  Result<void> write(std::size_t body_size, const net::BodyWriter& writer) override;
  void take_held() noexcept override { core_->drain(); }
  std::uint32_t matched_publishers() const override { return core_->matched(true); }
  std::uint32_t matched_subscribers() const override { return core_->matched(false); }
  std::optional<net::Guid> writer_guid() const override {
    return writer_ != nullptr ? std::optional(guid_of(writer_->guid())) : std::nullopt;
  }
  std::optional<net::Guid> reader_guid() const override {
    return reader_ != nullptr ? std::optional(guid_of(reader_->guid())) : std::nullopt;
  }

 private:
  std::shared_ptr<FastddsTransport> transport_;
  std::shared_ptr<Core> core_;
  ReaderListener reader_listener_;
  WriterListener writer_listener_;
  fd::ContentFilteredTopic* filtered_ = nullptr;
  fd::DataReader* reader_ = nullptr;
  fd::DataWriter* writer_ = nullptr;
};

}  // namespace horus::dds::fastdds_detail

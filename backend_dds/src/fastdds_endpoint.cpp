// The endpoint of the Fast DDS transport (see fastdds_transport.cpp): Core delivers what arrives
// through the endpoint's gate (horus/transport/endpoint_gate.hpp), the dispatcher delivers what
// arose on an application thread, FastddsEndpoint owns the DataWriter and DataReader.
#include <algorithm>
#include <cstdint>
#include <exception>
#include <string>
#include <utility>
#include <variant>

#include <fastdds/dds/core/LoanableSequence.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include "fastdds_internal.hpp"
#include "horus/log.hpp"
#include "horus/security/keystore.hpp"

namespace horus::dds::fastdds_detail {
namespace {

constexpr std::int32_t kHeartbeatMs = 100;  // reliable writer: quick repair of lost fragments
constexpr std::int32_t kReaderSamples = 4096;  // a reliable reader's samples not yet taken, at most
// A reliable volatile writer keeps up to this many bytes of samples not yet acknowledged (at
// most kWriterSamples samples, at least the topic's depth) before write() blocks: with only
// `depth` (16) a writer of small messages waits for acknowledgements every 16 samples and
// sends about 2.9k CmdVel/s on loopback, against 31k for KEEP_LAST 16 and 34k / 56k for
// KEEP_ALL within 256 / 1024 samples (bench/dds/raw_fastdds_pingpong, BENCH_KEEP_ALL).
// More than kWriterSamples lets writers outrun what an overloaded host can acknowledge: with
// 4096, the load test's 150 topics on 2 vCPUs starved the participants' leases and lost data.
constexpr std::uint64_t kWriterBytes = 16u << 20;
constexpr std::int32_t kWriterSamples = 256;

std::string endpoint_label(const net::EndpointSpec& spec) {
  return "topic '" + spec.topic + "' (DDS topic '" + spec.wire_topic + "')";
}

}  // namespace

// ---- Core -------------------------------------------------------------------------------------

Core::Core(net::EndpointSpec spec, net::Listener& listener, Dispatcher& dispatcher)
    : spec_(std::move(spec)), dispatcher_(dispatcher), gate_(listener, endpoint_label(spec_)) {}

void Core::close() {
  gate_.close();
  reader_.store(nullptr, std::memory_order_release);
  std::lock_guard qk(queue_mu_);
  errors_.clear();
}

void Core::post_error(std::string message) {
  {
    std::lock_guard lk(queue_mu_);
    errors_.push_back(std::move(message));
  }
  drain();
}

void Core::post_lost(std::int32_t count) {
  if (count <= 0) return;
  {
    std::lock_guard lk(queue_mu_);
    lost_ += static_cast<std::uint64_t>(count);
  }
  drain();
}

void Core::post_matched() {
  {
    std::lock_guard lk(queue_mu_);
    matched_changed_ = true;
  }
  drain();
}

void Core::drain() {
  if (t_app_call > 0) {
    bool has_errors;
    {
      std::lock_guard lk(queue_mu_);
      has_errors = !errors_.empty() || lost_ != 0 || matched_changed_;
    }
    if (has_errors) dispatcher_.post(shared_from_this());
    return;  // no remote sample arrives on an application thread; the filter keeps our own out
  }
  gate_.drain([this](net::EndpointGate::Calls& calls) { deliver(calls); });
}

void Core::deliver_sample(net::EndpointGate::Calls& calls, const RawReadSample& s) {
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(s.data), s.data != nullptr ? s.length : 0);
  auto parsed = net::encapsulation::parse(bytes);
  if (const auto* problem = std::get_if<std::string>(&parsed)) {
    calls.error(topic_label() + ": " + *problem);
    return;
  }
  calls.sample(std::get<net::Sample>(parsed));
}

// Inside the gate.
void Core::deliver(net::EndpointGate::Calls& calls) {
  std::vector<std::string> errors;
  std::uint64_t lost = 0;
  bool matched = false;
  {
    std::lock_guard lk(queue_mu_);
    errors.swap(errors_);
    lost = std::exchange(lost_, 0);
    matched = std::exchange(matched_changed_, false);
  }
  for (const auto& e : errors) calls.error(e);
  if (lost != 0) calls.lost(lost);
  if (matched) calls.matched();
  fd::DataReader* reader = reader_.load(std::memory_order_acquire);
  if (reader == nullptr) return;
  fd::LoanableSequence<RawReadSample> data;
  fd::SampleInfoSeq infos;
  // No more than the listener has room for: the rest waits in the reader (held samples; a full
  // reliable reader makes the remote writer wait), until take_held().
  for (;;) {
    const std::size_t room = calls.room();
    if (room == 0 || !calls.open()) break;
    const auto max = static_cast<std::int32_t>(std::min<std::size_t>(room, 256));
    if (reader->take(data, infos, max) != ReturnCode_t::RETCODE_OK) break;
    for (fd::LoanableCollection::size_type i = 0; i < infos.length(); ++i) {
      const fd::SampleInfo& info = infos[i];
      if (!info.valid_data) continue;
      if (is_local(info.sample_identity.writer_guid().guidPrefix)) continue;  // our own sample
      deliver_sample(calls, data[i]);
    }
    reader->return_loan(data, infos);
  }
}

// ---- Dispatcher -------------------------------------------------------------------------------

void Dispatcher::post(std::shared_ptr<Core> core) {
  {
    std::lock_guard lk(mu_);
    if (stopping_) return;
    queue_.push_back(std::move(core));
    if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
  }
  cv_.notify_one();
}

void Dispatcher::stop() {
  {
    std::lock_guard lk(mu_);
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  std::lock_guard lk(mu_);
  queue_.clear();
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

// ---- FastddsEndpoint --------------------------------------------------------------------------

FastddsEndpoint::~FastddsEndpoint() {
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
    if (core_->spec().qos.reliability == net::Reliability::Reliable) transport_->linger(writer_);
    transport_->publisher()->delete_datawriter(writer_);
  }
  transport_->release_topic(core_->spec().wire_topic);
}

Result<void> FastddsEndpoint::write(std::size_t body_size, const net::BodyWriter& writer) {
  if (body_size > kMaxBodySize)
    return fail(Errc::MessageTooLarge, "topic '" + core_->spec().topic + "': a body of " + std::to_string(body_size) +
                                           " bytes exceeds the largest DDS sample (" + std::to_string(kMaxBodySize) +
                                           " bytes)");
  if (writer.fill == nullptr)
    return fail(Errc::InvalidArgument,
                "topic '" + core_->spec().topic + "': write() needs a BodyWriter with a fill function");
  if (writer_ == nullptr)
    return fail(Errc::Config, core_->topic_label() + ": " + security::not_permitted(transport_->config().security, "publish"));
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
                                   std::string(net::to_string(core_->spec().qos.reliability)) +
                                   " writer could not take a sample of " + std::to_string(body_size) +
                                   " bytes within its " + std::to_string(kMaxBlockingMs) + " ms blocking bound");
  if (rc == ReturnCode_t::RETCODE_OUT_OF_RESOURCES)
    return fail(Errc::Io, core_->topic_label() + ": Fast DDS is out of resources for a sample of " +
                              std::to_string(body_size) + " bytes");
  return fail(Errc::Io, core_->topic_label() + ": Fast DDS failed to write a sample of " + std::to_string(body_size) +
                            " bytes (return code " + std::to_string(rc()) + ")");
}

namespace {

std::int32_t history_depth(const net::Qos& q) {
  return static_cast<std::int32_t>(std::min<std::uint32_t>(q.depth, 1u << 20));
}

eprosima::fastrtps::Duration_t max_blocking_time() {
  return eprosima::fastrtps::Duration_t(0, static_cast<std::uint32_t>(kMaxBlockingMs) * 1000000u);
}

// The DataWriter's QoS for `spec` (`paced`: through the link budget's flow controller).
fd::DataWriterQos writer_qos(const net::EndpointSpec& spec, bool paced) {
  const net::Qos& q = spec.qos;
  const auto depth = history_depth(q);
  const bool reliable = q.reliability == net::Reliability::Reliable;
  const bool transient = q.durability == net::Durability::TransientLocal;
  const eprosima::fastrtps::Duration_t max_blocking = max_blocking_time();

  fd::DataWriterQos wq;
  wq.reliability().kind = reliable ? fd::RELIABLE_RELIABILITY_QOS : fd::BEST_EFFORT_RELIABILITY_QOS;
  wq.reliability().max_blocking_time = max_blocking;
  wq.durability().kind = transient ? fd::TRANSIENT_LOCAL_DURABILITY_QOS : fd::VOLATILE_DURABILITY_QOS;
  // Reliable: KEEP_ALL within `depth` samples (resource limits), so nothing is dropped silently
  // under load: a writer whose readers lag blocks (max_blocking_time), the bridge retries and the
  // back-pressure reaches the host's publishers; a full reader refuses samples, which the writer
  // sends again. Best effort: KEEP_LAST depth.
  wq.history().kind = reliable ? fd::KEEP_ALL_HISTORY_QOS : fd::KEEP_LAST_HISTORY_QOS;
  wq.history().depth = depth;
  wq.resource_limits().max_instances = 1;
  // A transient-local writer keeps `depth` for late joiners; a volatile reliable one may hold
  // more unacknowledged samples (kWriterBytes), allocated only as they pile up.
  const std::int32_t writer_samples =
      reliable && !transient
          ? std::max(depth, static_cast<std::int32_t>(std::clamp<std::uint64_t>(
                                kWriterBytes / std::max<std::uint64_t>(spec.max_message_bytes, 64), 1,
                                static_cast<std::uint64_t>(kWriterSamples))))
          : depth;
  wq.resource_limits().max_samples_per_instance = writer_samples;
  wq.resource_limits().max_samples = writer_samples;
  wq.resource_limits().allocated_samples = std::min(depth, 16);
  wq.data_sharing().off();
  wq.representation().m_value = {fd::XCDR_DATA_REPRESENTATION};
  // A topic mapped onto ROS 2: "typehash=RIHS01_...;" on the writer and the reader, as rmw does.
  if (!spec.user_data.empty()) wq.user_data().setValue(std::vector<rtps::octet>(spec.user_data.begin(), spec.user_data.end()));
  wq.publish_mode().kind = fd::SYNCHRONOUS_PUBLISH_MODE;
  wq.endpoint().history_memory_policy = rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  wq.reliable_writer_qos().times.heartbeatPeriod =
      eprosima::fastrtps::Duration_t(0, static_cast<std::uint32_t>(kHeartbeatMs) * 1000000u);

  // DEADLINE and LIFESPAN on the writer only: what it offers other vendors' readers. A reader
  // requesting a deadline would not match writers of hosts that offer none; horus's handles
  // enforce both themselves (horus/detail/watch.hpp).
  auto duration = [](std::int64_t ns) {
    return eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(ns / 1000000000),
                                          static_cast<std::uint32_t>(ns % 1000000000));
  };
  if (q.deadline_ns > 0) wq.deadline().period = duration(q.deadline_ns);
  if (q.lifespan_ns > 0) wq.lifespan().duration = duration(q.lifespan_ns);
  // The host's link budget: fragments paced by the participant's flow controller, by priority
  // (fastdds.sfc.priority: -10 the highest, 10 the lowest). The write returns at once; the
  // controller's thread sends.
  if (paced) {
    wq.publish_mode().kind = fd::ASYNCHRONOUS_PUBLISH_MODE;
    wq.publish_mode().flow_controller_name = kLinkFlowController;
    wq.properties().properties().emplace_back("fastdds.sfc.priority", q.priority > 0 ? "-10" : q.priority < 0 ? "10" : "0");
  }
  return wq;
}

// The DataReader's QoS: the writer's (`wq`) reliability, durability and history.
fd::DataReaderQos reader_qos(const net::Qos& q, const fd::DataWriterQos& wq) {
  const auto depth = history_depth(q);
  const bool reliable = q.reliability == net::Reliability::Reliable;
  const eprosima::fastrtps::Duration_t max_blocking = max_blocking_time();
  fd::DataReaderQos rq;
  rq.reliability().kind = wq.reliability().kind;
  rq.reliability().max_blocking_time = max_blocking;
  rq.durability().kind = wq.durability().kind;
  rq.history().kind = wq.history().kind;
  rq.history().depth = depth;
  rq.resource_limits().max_instances = 1;
  // A reliable reader keeps up to kReaderSamples the bridge has not taken yet (it takes no more
  // than the host's subscribers have room for): a buffer before the writer is pushed back.
  const std::int32_t reader_samples = reliable ? std::max(depth, kReaderSamples) : depth;
  rq.resource_limits().max_samples_per_instance = reader_samples;
  rq.resource_limits().max_samples = reader_samples;
  rq.resource_limits().allocated_samples = std::min(depth, 16);
  rq.data_sharing().off();
  rq.type_consistency().representation.m_value = {fd::XCDR_DATA_REPRESENTATION};
  rq.endpoint().history_memory_policy = rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  rq.user_data() = wq.user_data();
  return rq;
}

}  // namespace

Result<void> FastddsEndpoint::create(fd::Topic* topic, fd::ContentFilteredTopic* filtered) {
  filtered_ = filtered;
  const net::Qos& q = core_->spec().qos;
  const fd::DataWriterQos wq = writer_qos(core_->spec(), transport_->paced());
  const fd::DataReaderQos rq = reader_qos(q, wq);

  // The reader is created disabled (subscriber QoS), so the core knows it before data can arrive.
  // Under DDS-Security, the host's permissions may allow only one direction (Fast DDS then
  // creates no entity and logs why): the other one is left out, and write() says why.
  const bool secure = transport_->secure();
  const net::Security& security = transport_->config().security;
  reader_ = transport_->subscriber()->create_datareader(
      filtered, rq, &reader_listener_,
      fd::StatusMask::data_available() << fd::StatusMask::subscription_matched()
                                       << fd::StatusMask::requested_incompatible_qos() << fd::StatusMask::sample_lost());
  if (reader_ == nullptr && !secure)
    return fail(Errc::Io, core_->topic_label() + ": Fast DDS could not create the DataReader (QoS " +
                              describe(q) + ")");
  if (reader_ != nullptr) core_->attach_reader(reader_);
  if (!core_->spec().send) return reader_ != nullptr && reader_->enable() == ReturnCode_t::RETCODE_OK
                                    ? Result<void>{}
                                    : fail(Errc::Io, core_->topic_label() + ": Fast DDS could not enable the DataReader");
  writer_ = transport_->publisher()->create_datawriter(
      topic, wq, &writer_listener_,
      fd::StatusMask::publication_matched() << fd::StatusMask::offered_incompatible_qos());
  if (writer_ == nullptr && !secure)
    return fail(Errc::Io, core_->topic_label() + ": Fast DDS could not create the DataWriter (QoS " +
                              describe(q) + ")");
  if (writer_ == nullptr && reader_ == nullptr)
    return fail(Errc::Config, core_->topic_label() + ": " + security::not_permitted(security, "publish or subscribe"));
  if (writer_ == nullptr)
    detail::log().info("{}: {}; what this host publishes on it stays on this host", core_->topic_label(),
                       security::not_permitted(security, "publish"));
  if (reader_ == nullptr) {
    detail::log().info("{}: {}; what other hosts publish on it does not reach this host", core_->topic_label(),
                       security::not_permitted(security, "subscribe"));
    return {};
  }
  if (reader_->enable() != ReturnCode_t::RETCODE_OK)
    return fail(Errc::Io, core_->topic_label() + ": Fast DDS could not enable the DataReader");
  return {};
}

}  // namespace horus::dds::fastdds_detail

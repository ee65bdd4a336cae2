// fastdds_echo: a plain Fast DDS 2.9 C++ program built at test time from what fastddsgen makes
// of horus-idlgen's .idl files (no horus code). For each type of the list it takes samples on
// <prefix>/<Type> into the generated class and writes them back on <prefix>/<Type>/echo, so a
// horus process that gets back what it sent proves both directions field for field.
//
//   fastdds_echo <domain> <prefix> <seconds>      prints "ready"; stops when stdin closes
//
// Loopback only (UDPv4 on 127.0.0.1, unicast discovery), as horus's HORUS_DDS_LOCALHOST=1, on
// top of the default participant profile of FASTRTPS_DEFAULT_PROFILES_FILE when set: how its
// user adds DDS-Security (the profile `horus security dds-config --for fastdds` writes).
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include "geometryPubSubTypes.h"
#include "inputPubSubTypes.h"
#include "navigationPubSubTypes.h"
#include "perceptionPubSubTypes.h"
#include "sensorPubSubTypes.h"
#include "visionPubSubTypes.h"
#include "wiretestPubSubTypes.h"

namespace fd = eprosima::fastdds::dds;

namespace {

struct EchoBase {
  virtual ~EchoBase() = default;
  virtual unsigned long pump() = 0;
};

template <class PubSub>
struct Echo final : EchoBase {
  fd::DataReader* reader = nullptr;
  fd::DataWriter* writer = nullptr;
  typename PubSub::type sample;  // the generated class: its own deserializer fills it
  unsigned long pump() override {
    unsigned long n = 0;
    fd::SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data && writer->write(&sample)) ++n;
    return n;
  }
};

bool parent_gone() {
  pollfd p{0, POLLIN, 0};
  char c;
  if (::poll(&p, 1, 0) <= 0) return false;
  return ::read(0, &c, 1) <= 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: fastdds_echo <domain> <prefix> <seconds>\n");
    return 2;
  }
  const int domain = std::atoi(argv[1]);
  const std::string prefix = argv[2];
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(std::atoi(argv[3]));

  auto* factory = fd::DomainParticipantFactory::get_instance();
  factory->load_profiles();
  fd::DomainParticipantQos pq = factory->get_default_participant_qos();
  pq.transport().use_builtin_transports = false;
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList.emplace_back("127.0.0.1");
  udp->maxInitialPeersRange = 32;
  udp->sendBufferSize = udp->receiveBufferSize = 4 << 20;
  eprosima::fastrtps::rtps::Locator_t loopback;
  loopback.kind = LOCATOR_KIND_UDPv4;
  eprosima::fastrtps::rtps::IPLocator::setIPv4(loopback, 127, 0, 0, 1);
  loopback.port = 0;
  pq.wire_protocol().builtin.metatrafficUnicastLocatorList.push_back(loopback);
  pq.wire_protocol().builtin.initialPeersList.push_back(loopback);
  pq.wire_protocol().default_unicast_locator_list.push_back(loopback);
  pq.transport().user_transports.push_back(udp);
  fd::DomainParticipant* pp = factory->create_participant(static_cast<fd::DomainId_t>(domain), pq);
  if (pp == nullptr) {
    std::fprintf(stderr, "fastdds_echo: cannot create a participant\n");
    return 3;
  }
  fd::Publisher* pub = pp->create_publisher(fd::PUBLISHER_QOS_DEFAULT);
  fd::Subscriber* sub = pp->create_subscriber(fd::SUBSCRIBER_QOS_DEFAULT);

  // Reader best effort (accepts any writer), writer reliable + transient local (satisfies any reader).
  fd::DataReaderQos rq;
  rq.reliability().kind = fd::BEST_EFFORT_RELIABILITY_QOS;
  rq.history().kind = fd::KEEP_LAST_HISTORY_QOS;
  rq.history().depth = 16;
  rq.data_sharing().off();
  rq.type_consistency().representation.m_value = {fd::XCDR_DATA_REPRESENTATION};
  fd::DataWriterQos wq;
  wq.reliability().kind = fd::RELIABLE_RELIABILITY_QOS;
  wq.durability().kind = fd::TRANSIENT_LOCAL_DURABILITY_QOS;
  wq.history().kind = fd::KEEP_LAST_HISTORY_QOS;
  wq.history().depth = 16;
  wq.data_sharing().off();
  wq.representation().m_value = {fd::XCDR_DATA_REPRESENTATION};

  std::vector<std::unique_ptr<EchoBase>> echoes;
  bool ok = true;
  auto add = [&]<class PubSub>(const char* name, PubSub*) {
    fd::TypeSupport type(new PubSub());
    type.register_type(pp);
    const std::string in = prefix + "/" + name;
    fd::Topic* ti = pp->create_topic(in, type.get_type_name(), fd::TOPIC_QOS_DEFAULT);
    fd::Topic* to = pp->create_topic(in + "/echo", type.get_type_name(), fd::TOPIC_QOS_DEFAULT);
    auto e = std::make_unique<Echo<PubSub>>();
    if (ti != nullptr) e->reader = sub->create_datareader(ti, rq);
    if (to != nullptr) e->writer = pub->create_datawriter(to, wq);
    if (e->reader == nullptr || e->writer == nullptr) {
      std::fprintf(stderr, "fastdds_echo: cannot create the endpoints of %s\n", name);
      ok = false;
      return;
    }
    echoes.push_back(std::move(e));
  };
  add("Pose2D", static_cast<horus::msg::Pose2DPubSubType*>(nullptr));
  add("TransformStamped", static_cast<horus::msg::TransformStampedPubSubType*>(nullptr));
  add("Imu", static_cast<horus::msg::ImuPubSubType*>(nullptr));
  add("LaserScan", static_cast<horus::msg::LaserScanPubSubType*>(nullptr));
  add("BatteryState", static_cast<horus::msg::BatteryStatePubSubType*>(nullptr));
  add("JoystickInput", static_cast<horus::msg::JoystickInputPubSubType*>(nullptr));
  add("OccupancyGrid", static_cast<horus::msg::OccupancyGridPubSubType*>(nullptr));
  add("Image", static_cast<horus::msg::ImagePubSubType*>(nullptr));
  add("Tensor", static_cast<horus::msg::TensorPubSubType*>(nullptr));
  add("All", static_cast<wiretest::AllPubSubType*>(nullptr));
  add("Keywords", static_cast<wiretest::KeywordsPubSubType*>(nullptr));
  add("Widths", static_cast<wiretest::WidthsPubSubType*>(nullptr));
  if (!ok) return 3;
  std::printf("ready\n");
  std::fflush(stdout);
  unsigned long echoed = 0;
  while (std::chrono::steady_clock::now() < end && !parent_gone()) {
    for (auto& e : echoes) echoed += e->pump();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::fprintf(stderr, "fastdds_echo: echoed %lu samples\n", echoed);
  echoes.clear();
  pp->delete_contained_entities();
  factory->delete_participant(pp);
  return 0;
}

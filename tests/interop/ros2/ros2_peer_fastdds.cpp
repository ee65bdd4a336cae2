// ros2_peer_fastdds: what a ROS 2 node built on rmw_fastrtps_cpp puts on the DDS wire, without
// ROS 2: a plain Fast DDS 2.9 program over fastddsgen's output of ros2_types.idl (ROS 2's type
// names, pkg::msg::dds_::Name_), on ROS 2's topic names (rt/<name>), with ROS 2's USER_DATA on its
// participant ("enclave=/;") and endpoints ("typehash=RIHS01_...;").
//
//   ros2_peer_fastdds <domain> <prefix> <seconds> <report> <hash per entry...>
//
// The same behaviour and report as ros2_peer_cyclone.c: each entry's rt/<prefix>/<name> read,
// reported as text (ros2_peer_report.h) and written back on rt/<prefix>/<name>_echo; the USER_DATA
// of every remote writer on those topics (with its GUID) and of every remote participant, and what
// other participants say of their nodes on ros_discovery_info. Loopback only.
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include "ros2_typesPubSubTypes.h"

#include "ros2_peer_report.h"

namespace fd = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;
using namespace geometry_msgs::msg::dds_;
using namespace sensor_msgs::msg::dds_;

namespace {

std::mutex g_out_mutex;
FILE* g_out = nullptr;
std::string g_prefix;  // "rt/<prefix>/"

std::string text_of(const std::vector<rtps::octet>& v) { return std::string(v.begin(), v.end()); }

std::array<uint8_t, 16> guid_bytes(const rtps::GUID_t& g) {
  std::array<uint8_t, 16> out{};
  std::copy(std::begin(g.guidPrefix.value), std::end(g.guidPrefix.value), out.begin());
  std::copy(std::begin(g.entityId.value), std::end(g.entityId.value), out.begin() + 12);
  return out;
}
std::array<uint8_t, 16> g_own{};  // our participant's GUID

// What ros_discovery_info says: a line per node of each participant (not ours).
void report_graph(fd::DataReader* reader) {
  rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_ p;
  fd::SampleInfo info;
  while (reader->take_next_sample(&p, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || std::equal(g_own.begin(), g_own.end(), p.gid().data().begin())) continue;
    char gid[33], g[33];
    hex16(p.gid().data().data(), gid);
    std::lock_guard lock(g_out_mutex);
    for (const auto& node : p.node_entities_info_seq()) {
      std::fprintf(g_out, "graph %s %s %s writers", gid, node.node_namespace().c_str(), node.node_name().c_str());
      for (const auto& w : node.writer_gid_seq()) std::fprintf(g_out, " %s", hex16(w.data().data(), g));
      std::fprintf(g_out, " readers");
      for (const auto& r : node.reader_gid_seq()) std::fprintf(g_out, " %s", hex16(r.data().data(), g));
      std::fprintf(g_out, "\n");
    }
  }
}

// What discovery tells of the others: participants' and our topics' writers' USER_DATA.
class Discovery final : public fd::DomainParticipantListener {
  void on_participant_discovery(fd::DomainParticipant*, rtps::ParticipantDiscoveryInfo&& info) override {
    if (info.status != rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT) return;
    const std::string ud = text_of(info.info.m_userData.data_vec());
    if (ud.empty()) return;
    std::lock_guard lock(g_out_mutex);
    std::fprintf(g_out, "participant %s\n", ud.c_str());
  }
  void on_publisher_discovery(fd::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override {
    if (info.status != rtps::WriterDiscoveryInfo::DISCOVERED_WRITER) return;
    const std::string topic = info.info.topicName().to_string();
    if (topic.rfind(g_prefix, 0) != 0 || topic.size() >= 5 && topic.compare(topic.size() - 5, 5, "_echo") == 0) return;
    const std::string ud = text_of(info.info.m_qos.m_userData.data_vec());
    char guid[33];
    std::lock_guard lock(g_out_mutex);
    std::fprintf(g_out, "userdata %s %s %s\n", topic.c_str(), hex16(guid_bytes(info.info.guid()).data(), guid),
                 ud.empty() ? "(none)" : ud.c_str());
  }
};

void report(const Twist_& m) {
  REPORT_TWIST(g_out, m.linear().x(), m.linear().y(), m.linear().z(), m.angular().x(), m.angular().y(), m.angular().z());
}
void report(const LaserScan_& m) {
  const auto& r = m.ranges();
  const std::size_t n = r.size();
  REPORT_SCAN(g_out, m.header().stamp().sec(), m.header().stamp().nanosec(), m.header().frame_id().c_str(), m.angle_min(),
              m.angle_max(), m.angle_increment(), m.range_min(), m.range_max(), n, n > 0 ? r[0] : 0.0f,
              n > 1 ? r[1] : 0.0f, n > 0 ? r[n - 1] : 0.0f);
}
void report(const Image_& m) {
  REPORT_IMAGE(g_out, m.header().stamp().sec(), m.header().stamp().nanosec(), m.header().frame_id().c_str(), m.height(),
               m.width(), m.encoding().c_str(), m.is_bigendian(), m.step(), m.data().size(),
               checksum(m.data().data(), static_cast<uint32_t>(m.data().size())));
}
void report(const JointState_& m) {
  const auto& names = m.name();
  const std::size_t n = names.size();
  REPORT_JOINTS(g_out, m.header().stamp().sec(), m.header().stamp().nanosec(), m.header().frame_id().c_str(), n,
                n > 0 ? names[0].c_str() : "-", m.position().empty() ? 0.0 : m.position()[0],
                m.velocity().empty() ? 0.0 : m.velocity()[0], m.effort().empty() ? 0.0 : m.effort()[0],
                n > 0 ? names[n - 1].c_str() : "-", m.position().empty() ? 0.0 : m.position().back());
}
void report(const nav_msgs::msg::dds_::Odometry_& m) {
  const auto& p = m.pose().pose();
  REPORT_ODOM(g_out, m.header().stamp().sec(), m.header().stamp().nanosec(), m.header().frame_id().c_str(),
              m.child_frame_id().c_str(), p.position().x(), p.position().y(), p.position().z(), p.orientation().x(),
              p.orientation().y(), p.orientation().z(), p.orientation().w(), m.twist().twist().linear().x(),
              m.twist().twist().angular().z(), m.pose().covariance()[0], m.pose().covariance()[35],
              m.twist().covariance()[7]);
}
void report(const tf2_msgs::msg::dds_::TFMessage_& m) {
  if (m.transforms().empty()) {
    std::fprintf(g_out, "tf 0\n");
    return;
  }
  const auto& t = m.transforms()[0];
  const auto& x = t.transform();
  REPORT_TF(g_out, m.transforms().size(), t.header().stamp().sec(), t.header().stamp().nanosec(),
            t.header().frame_id().c_str(), t.child_frame_id().c_str(), x.translation().x(), x.translation().y(),
            x.translation().z(), x.rotation().x(), x.rotation().y(), x.rotation().z(), x.rotation().w());
}

struct PeerBase {
  virtual ~PeerBase() = default;
  virtual void pump() = 0;
};

template <class PubSub>
struct Peer final : PeerBase {
  fd::DataReader* reader = nullptr;
  fd::DataWriter* writer = nullptr;
  typename PubSub::type sample;  // the generated class: its own deserializer fills it
  void pump() override {
    fd::SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      {
        std::lock_guard lock(g_out_mutex);
        report(sample);
      }
      writer->write(&sample);
    }
  }
};

bool parent_gone() {
  pollfd p{0, POLLIN, 0};
  char c;
  if (::poll(&p, 1, 0) <= 0) return false;
  return ::read(0, &c, 1) <= 0;
}

// Loopback only; with ROS2_PEER_LAN=1 (a test that runs it on a namespace host) Fast DDS's
// defaults: the host's interfaces, multicast discovery.
fd::DomainParticipantQos loopback_participant(fd::DomainParticipantFactory* factory) {
  fd::DomainParticipantQos pq = factory->get_default_participant_qos();
  const char* lan = std::getenv("ROS2_PEER_LAN");
  if (lan != nullptr && std::string_view(lan) == "1") {
    const std::string enclave = "enclave=/;";
    pq.user_data().setValue(std::vector<rtps::octet>(enclave.begin(), enclave.end()));
    return pq;
  }
  pq.transport().use_builtin_transports = false;
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList.emplace_back("127.0.0.1");
  udp->maxInitialPeersRange = 32;
  udp->sendBufferSize = udp->receiveBufferSize = 4 << 20;
  rtps::Locator_t loopback;
  loopback.kind = LOCATOR_KIND_UDPv4;
  eprosima::fastrtps::rtps::IPLocator::setIPv4(loopback, 127, 0, 0, 1);
  loopback.port = 0;
  pq.wire_protocol().builtin.metatrafficUnicastLocatorList.push_back(loopback);
  pq.wire_protocol().builtin.initialPeersList.push_back(loopback);
  pq.wire_protocol().default_unicast_locator_list.push_back(loopback);
  pq.transport().user_transports.push_back(udp);
  const std::string enclave = "enclave=/;";
  pq.user_data().setValue(std::vector<rtps::octet>(enclave.begin(), enclave.end()));
  return pq;
}

}  // namespace

int main(int argc, char** argv) {
  constexpr int kEntries = 6;
  if (argc != 5 + kEntries) {
    std::fprintf(stderr, "usage: ros2_peer_fastdds <domain> <prefix> <seconds> <report> <%d type hashes>\n", kEntries);
    return 2;
  }
  const int domain = std::atoi(argv[1]);
  g_prefix = "rt/" + std::string(argv[2]) + "/";
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(std::atoi(argv[3]));
  g_out = std::fopen(argv[4], "w");
  if (g_out == nullptr) return 3;
  auto* factory = fd::DomainParticipantFactory::get_instance();
  Discovery discovery;
  fd::DomainParticipant* pp = factory->create_participant(static_cast<fd::DomainId_t>(domain),
                                                          loopback_participant(factory), &discovery);
  if (pp == nullptr) return 3;
  fd::Publisher* pub = pp->create_publisher(fd::PUBLISHER_QOS_DEFAULT);
  fd::Subscriber* sub = pp->create_subscriber(fd::SUBSCRIBER_QOS_DEFAULT);
  g_own = guid_bytes(pp->guid());
  // ros_discovery_info as a ROS 2 participant reads it: reliable, transient local, keep last.
  fd::TypeSupport graph_type(new rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_PubSubType());
  graph_type.register_type(pp);
  fd::DataReaderQos gq;
  gq.reliability().kind = fd::RELIABLE_RELIABILITY_QOS;
  gq.durability().kind = fd::TRANSIENT_LOCAL_DURABILITY_QOS;
  gq.history().kind = fd::KEEP_LAST_HISTORY_QOS;
  gq.history().depth = 1;
  gq.data_sharing().off();
  fd::Topic* gt = pp->create_topic("ros_discovery_info", graph_type.get_type_name(), fd::TOPIC_QOS_DEFAULT);
  fd::DataReader* graph = gt != nullptr ? sub->create_datareader(gt, gq) : nullptr;
  if (graph == nullptr) return 3;

  std::vector<std::unique_ptr<PeerBase>> peers;
  bool ok = true;
  int index = 0;
  auto add = [&]<class PubSub>(const char* name, PubSub*) {
    // ROS 2's default profile (reliable, volatile, keep last 10) with its USER_DATA; the echo
    // writer transient local, so that it satisfies any reader.
    const std::string ud = std::string("typehash=") + argv[5 + index++] + ";";
    fd::DataReaderQos rq;
    rq.reliability().kind = fd::RELIABLE_RELIABILITY_QOS;
    rq.history().kind = fd::KEEP_LAST_HISTORY_QOS;
    rq.history().depth = 10;
    rq.data_sharing().off();
    rq.user_data().setValue(std::vector<rtps::octet>(ud.begin(), ud.end()));
    fd::DataWriterQos wq;
    wq.reliability().kind = fd::RELIABLE_RELIABILITY_QOS;
    wq.durability().kind = fd::TRANSIENT_LOCAL_DURABILITY_QOS;
    wq.history().kind = fd::KEEP_LAST_HISTORY_QOS;
    wq.history().depth = 10;
    wq.data_sharing().off();
    wq.user_data().setValue(std::vector<rtps::octet>(ud.begin(), ud.end()));
    fd::TypeSupport type(new PubSub());
    type.register_type(pp);
    const std::string in = g_prefix + name;
    fd::Topic* ti = pp->create_topic(in, type.get_type_name(), fd::TOPIC_QOS_DEFAULT);
    fd::Topic* to = pp->create_topic(in + "_echo", type.get_type_name(), fd::TOPIC_QOS_DEFAULT);
    auto p = std::make_unique<Peer<PubSub>>();
    if (ti != nullptr) p->reader = sub->create_datareader(ti, rq);
    if (to != nullptr) p->writer = pub->create_datawriter(to, wq);
    if (p->reader == nullptr || p->writer == nullptr) {
      std::fprintf(stderr, "ros2_peer_fastdds: cannot create the endpoints of %s\n", in.c_str());
      ok = false;
      return;
    }
    peers.push_back(std::move(p));
  };
  add("cmd_vel", static_cast<Twist_PubSubType*>(nullptr));
  add("scan", static_cast<LaserScan_PubSubType*>(nullptr));
  add("image", static_cast<Image_PubSubType*>(nullptr));
  add("joints", static_cast<JointState_PubSubType*>(nullptr));
  add("odom", static_cast<nav_msgs::msg::dds_::Odometry_PubSubType*>(nullptr));
  add("tf", static_cast<tf2_msgs::msg::dds_::TFMessage_PubSubType*>(nullptr));
  if (!ok) return 3;
  std::printf("ready\n");
  std::fflush(stdout);
  while (std::chrono::steady_clock::now() < end && !parent_gone()) {
    for (auto& p : peers) p->pump();
    report_graph(graph);
    {
      std::lock_guard lock(g_out_mutex);
      std::fflush(g_out);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  peers.clear();
  pp->delete_contained_entities();
  factory->delete_participant(pp);
  std::lock_guard lock(g_out_mutex);
  std::fclose(g_out);
  return 0;
}

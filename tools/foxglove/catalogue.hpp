// What `horus foxglove` finds to serve (hub.cpp asks every 500 ms): this host's topics (the local registry) and the
// fleet's (what other hosts announce), filtered by the patterns; for each the channels it makes (the topic in its own
// schema, and beside a type Foxglove draws the converted TOPIC/foxglove), the connection graph, and the status page's
// figures of hosts and topics (rates from the sent counts between scans, or what the owning host announced).
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "horus/discovery/registry.hpp"
#include "horus/fleet.hpp"
#include "horus/network.hpp"
#include "protocol.hpp"

namespace horus::tools::fox {

// One channel as a scan found it.
struct Desc {
  ServerChannel adv;  // id filled when advertised
  std::string horus_topic;
  std::string type;  // horus type name
  std::uint64_t hash = 0;
  std::string signature;
  std::string via;  // the network backend to read it through (empty: shared memory)
  bool converted = false;
  bool remote_raw = false;  // not a standard type: read through its signature (RemoteReader)
  std::string ros2_type;    // a ROS 2 topic of the domain (`--ros2`), read as this ROS 2 type
  bool operator==(const Desc& o) const {
    return adv.topic == o.adv.topic && adv.schema_name == o.adv.schema_name && adv.schema == o.adv.schema &&
           adv.encoding == o.adv.encoding && via == o.via;
  }
};

struct Scan {
  std::map<std::string, Desc> channels;  // by channel topic
  Graph graph;
  nlohmann::json topics = nlohmann::json::array();  // the status page's
  nlohmann::json hosts = nlohmann::json::array();
  nlohmann::json unserved = nlohmann::json::array();  // topics not served, and why
  std::string host;
};

class Catalogue {
 public:
  Catalogue(std::vector<std::string> patterns, const std::string& ns);
  /// What there is now (`fleet`: the fleet layer, or null on this host alone; `ros2`: the DDS
  /// transport whose domain's ROS 2 topics are served too, or null). One thread calls it.
  Scan scan(Fleet* fleet, net::Transport* ros2 = nullptr);

 private:
  using Clock = std::chrono::steady_clock;
  bool wanted(const std::string& name) const;
  void add_channels(std::map<std::string, Desc>& out, Desc d);
  double rate_of(const discovery::TopicEntry& t, Clock::time_point now,
                 std::map<std::string, std::pair<std::uint64_t, Clock::time_point>>& counts);
  void scan_local(Scan& r, std::set<std::string>& local_names);
  void scan_fleet(Scan& r, const Fleet& fleet, const std::set<std::string>& local_names);
  void scan_ros2(Scan& r, const net::Transport& transport);

  std::vector<std::string> patterns_;
  discovery::Scanner scanner_;
  std::string host_;
  std::map<std::string, std::string> idl_cache_;
  std::map<std::string, std::pair<std::uint64_t, Clock::time_point>> last_counts_;
  std::map<std::string, double> rates_;
  std::set<std::pair<std::string, std::string>> unserved_;
};

}  // namespace horus::tools::fox

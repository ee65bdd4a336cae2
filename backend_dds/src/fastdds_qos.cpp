// QoS for the Fast DDS transport: names for messages, the remote endpoints matched with an
// endpoint, and the reports of incompatible QoS. See fastdds_transport.cpp.
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>

#include "fastdds_internal.hpp"

namespace horus::dds::fastdds_detail {
namespace {

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

}  // namespace

std::string describe(const net::Qos& q) {
  std::string s;
  s += net::to_string(q.reliability);
  s += ", ";
  s += net::to_string(q.durability);
  s += ", depth ";
  s += std::to_string(q.depth);
  s += q.deadline_ns > 0 ? ", deadline " + std::to_string(q.deadline_ns / 1000000) + " ms offered" : ", no deadline";
  if (q.lifespan_ns > 0) s += ", lifespan " + std::to_string(q.lifespan_ns / 1000000) + " ms";
  return s;
}

std::string shorten(const std::string& name) {
  return name.size() <= 64 ? name : name.substr(0, 61) + "...";
}

void Core::on_matched(bool reader_side, const rtps::InstanceHandle_t& handle, std::int32_t change) {
  const rtps::GUID_t guid = rtps::iHandle2GUID(handle);
  if (change == 0 || is_local(guid.guidPrefix)) return;
  {
    std::lock_guard lk(matched_mu_);
    auto& set = reader_side ? remote_writers_ : remote_readers_;
    if (change > 0)
      set.insert(guid);
    else
      set.erase(guid);
  }
  post_matched();
}

std::uint32_t Core::matched(bool reader_side) const {
  std::lock_guard lk(matched_mu_);
  return static_cast<std::uint32_t>(reader_side ? remote_writers_.size() : remote_readers_.size());
}

void Core::on_incompatible(bool reader_side, const fd::IncompatibleQosStatus& status) {
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

}  // namespace horus::dds::fastdds_detail

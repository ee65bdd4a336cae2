// What belongs to this process, for the Fast DDS transport: the GUID prefixes of our
// participants, and the content filter that keeps this process's own samples out of its readers
// (Fast DDS 2.9 cannot ignore local endpoints). See fastdds_transport.cpp.
#include <algorithm>
#include <array>
#include <cstdint>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>

#include "fastdds_internal.hpp"
#include "horus/detail/process.hpp"

namespace horus::dds::fastdds_detail {
namespace {

using Prefix = std::array<std::uint8_t, 12>;

Prefix to_prefix(const rtps::GuidPrefix_t& p) {
  Prefix out{};
  std::copy(std::begin(p.value), std::end(p.value), out.begin());
  return out;
}

struct LocalPrefixes {
  static constexpr horus::detail::PartSpec kPart{"Fast DDS local prefixes", horus::detail::PartLifetime::Process,
                                                 "read by participants' destructors, which may run late"};
  std::mutex mu;
  std::vector<Prefix> prefixes;  // a handful: one per live participant of this process
};

LocalPrefixes& local_prefixes() { return horus::detail::Process::part<LocalPrefixes>(); }

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
  static constexpr horus::detail::PartSpec kPart{"Fast DDS content filter", horus::detail::PartLifetime::Process,
                                                 "participants may outlive the statics"};
  ReturnCode_t create_content_filter(const char*, const char*, const fd::TopicDataType*, const char*,
                                     const ParameterSeq&, fd::IContentFilter*& filter_instance) override {
    filter_instance = &filter_;
    return ReturnCode_t::RETCODE_OK;
  }
  ReturnCode_t delete_content_filter(const char*, fd::IContentFilter*) override { return ReturnCode_t::RETCODE_OK; }

 private:
  NotLocalFilter filter_;
};

}  // namespace

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

bool is_local(const rtps::GuidPrefix_t& p) {
  auto& reg = local_prefixes();
  const Prefix key = to_prefix(p);
  std::lock_guard lk(reg.mu);
  return std::find(reg.prefixes.begin(), reg.prefixes.end(), key) != reg.prefixes.end();
}

fd::IContentFilterFactory& not_local_factory() { return horus::detail::Process::part<NotLocalFilterFactory>(); }

const std::string& not_local_class() {
  static const std::string name = [] {
    std::random_device rd;
    const auto r = (static_cast<std::uint64_t>(rd()) << 32) ^ rd();
    return "horus_not_local_" + std::to_string(::getpid()) + "_" + std::to_string(r);
  }();
  return name;
}

}  // namespace horus::dds::fastdds_detail

// A Fast DDS 2.9 TopicDataType that moves already-encoded XCDR1 bytes: the DDS type name is set
// at run time ("horus::msg::Pose2D"), the topic is keyless, and no TypeObject or TypeInformation
// is announced, so remote endpoints match by type name only (as with fastddsgen output for a
// `@final struct` without -typeobject).
//
// Writing: the sample handed to DataWriter::write is a RawWriteSample (body size + BodyWriter);
// serialize() writes the encapsulation header and lets the BodyWriter fill the body in place.
// Reading: deserialize() copies nothing; it records where the payload lies. The reader takes with
// loans, so the payload stays valid until the loan is returned, and the endpoint validates the
// header itself (deserialize's result is ignored by Fast DDS on the loan path: a bad sample would
// otherwise vanish silently).
//
// Internal to the Fast DDS backend; include after the Fast DDS headers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <functional>
#include <span>
#include <string>

#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastdds/rtps/common/SerializedPayload.h>

#include "horus/network.hpp"
#include "horus/transport/encapsulation.hpp"

namespace horus::dds::fastdds_detail {

/// Tags the two sample kinds that share the one TopicDataType (write side, read side).
enum class RawKind : std::uint32_t { Write = 0x57525431u, Read = 0x52445231u };

/// What DataWriter::write receives: the body size and who fills it.
struct RawWriteSample {
  RawKind kind = RawKind::Write;
  std::size_t body_size = 0;
  const net::BodyWriter* writer = nullptr;
  std::exception_ptr error;  // an exception thrown by the BodyWriter, rethrown after write()
};

/// What a loaned read sample holds: the received payload (encapsulation header included).
struct RawReadSample {
  RawKind kind = RawKind::Read;
  const std::uint8_t* data = nullptr;
  std::uint32_t length = 0;
};

/// The largest body a sample can carry (the serialized payload length is 32-bit).
inline constexpr std::size_t kMaxBodySize = 0xFFFFFFFFu - 8u;

class RawXcdr1Type final : public eprosima::fastdds::dds::TopicDataType {
 public:
  explicit RawXcdr1Type(const std::string& dds_type_name) {
    setName(dds_type_name.c_str());
    m_typeSize = 256;            // first guess for pool entries; PREALLOCATED_WITH_REALLOC grows them
    m_isGetKeyDefined = false;   // keyless
    auto_fill_type_object(false);
    auto_fill_type_information(false);
  }

  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    auto* s = static_cast<RawWriteSample*>(data);
    if (s == nullptr || s->kind != RawKind::Write || s->writer == nullptr || s->body_size > kMaxBodySize) return false;
    const std::size_t total = net::encapsulation::serialized_size(s->body_size);
    if (payload->max_size < total) return false;  // the pool hands out getSerializedSizeProvider() bytes
    auto* p = reinterpret_cast<std::byte*>(payload->data);
    net::encapsulation::write_header_and_padding(std::span<std::byte>(p, total), s->body_size);  // CDR_LE
    try {
      s->writer->fill(s->writer->context, std::span<std::byte>(p + net::encapsulation::kHeaderSize, s->body_size));
    } catch (...) {
      s->error = std::current_exception();
      return false;
    }
    payload->length = static_cast<std::uint32_t>(total);
    payload->encapsulation = CDR_LE;
    return true;
  }

  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    auto* s = static_cast<RawReadSample*>(data);
    if (s == nullptr || s->kind != RawKind::Read) return false;
    s->data = payload->data;
    s->length = payload->data != nullptr ? payload->length : 0;
    return true;
  }

  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data]() -> std::uint32_t {
      const auto* s = static_cast<const RawWriteSample*>(data);
      if (s == nullptr || s->kind != RawKind::Write || s->body_size > kMaxBodySize) return 4;
      return static_cast<std::uint32_t>(net::encapsulation::serialized_size(s->body_size));
    };
  }

  void* createData() override { return new RawReadSample(); }
  void deleteData(void* data) override { delete static_cast<RawReadSample*>(data); }

  bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

}  // namespace horus::dds::fastdds_detail

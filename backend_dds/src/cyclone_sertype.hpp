// A raw-bytes ddsi_sertype / ddsi_serdata for Cyclone DDS 0.10 (private to backend_dds).
//
// The serialized form of a sample is exactly the DDSI payload: the 4-byte encapsulation
// header (00 01 00 pp = CDR little endian / XCDR1, pp = number of padding bytes at the end)
// followed by the XCDR body. Cyclone never interprets it: the horus codec encodes and
// decodes, this type only carries the bytes. The type is keyless (every sample is the same
// instance), which is what idlc generates for a struct without @key members, and allows the
// XCDR1 data representation only.
//
// Compile with -DDDS_NDEBUG (pkg-config CycloneDDS adds it): the implementation reads the
// received fragment chain through Cyclone's internal q_radmin.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>

namespace horus::dds::cyclone {

/// The sample type seen through dds_write / dds_take on this sertype (horus itself uses
/// dds_writecdr / dds_takecdr and never needs it): the serialized bytes including the
/// encapsulation header, owned (malloc) by the sample.
struct RawSample {
  unsigned char* data;
  std::uint32_t size;
};

/// A new, unregistered sertype named `type_name` ("horus::msg::Pose2D"), keyless, XCDR1
/// only, refcount 1 (dds_create_topic_sertype takes it over). nullptr when out of memory.
ddsi_sertype* make_raw_sertype(const char* type_name) noexcept;

/// Whether `type` is a sertype made by make_raw_sertype.
bool is_raw_sertype(const ddsi_sertype* type) noexcept;

/// A new data serdata of `type` (made by make_raw_sertype) able to hold `size` serialized
/// bytes (header included); `*bytes` receives where to write them. The bytes are not
/// initialised except those past `size` up to the next multiple of 4. Refcount 1
/// (dds_writecdr consumes it). nullptr when out of memory.
ddsi_serdata* make_raw_serdata(const ddsi_sertype* type, std::uint32_t size, std::byte** bytes) noexcept;

/// The serialized bytes (header included) of a serdata made by this sertype; an empty span
/// for a serdata of another sertype (then use ddsi_serdata_to_ser).
std::span<const std::byte> raw_serdata_bytes(const ddsi_serdata* data) noexcept;

}  // namespace horus::dds::cyclone

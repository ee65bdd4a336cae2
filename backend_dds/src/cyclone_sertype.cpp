// The raw-bytes sertype of the Cyclone DDS backend: see cyclone_sertype.hpp.
#include "cyclone_sertype.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>

#include <dds/ddsi/q_radmin.h>  // struct nn_rdata, NN_RMSG_PAYLOADOFF, NN_RDATA_PAYLOAD_OFF

namespace horus::dds::cyclone {
namespace {

// One allocation: the serdata, then the serialized bytes (capacity rounded up to 4, the
// bytes past `size` zeroed).
struct RawSerdata {
  ddsi_serdata c;
  std::uint32_t size;  // serialized size, header included
  std::uint32_t pad;
  unsigned char* bytes() noexcept { return reinterpret_cast<unsigned char*>(this + 1); }
  const unsigned char* bytes() const noexcept { return reinterpret_cast<const unsigned char*>(this + 1); }
};
static_assert(alignof(RawSerdata) >= 4);

constexpr unsigned char kEmptyCdrLe[4] = {0x00, 0x01, 0x00, 0x00};  // CDR_LE header, empty body

RawSerdata* as_raw(ddsi_serdata* d) noexcept { return reinterpret_cast<RawSerdata*>(d); }
const RawSerdata* as_raw(const ddsi_serdata* d) noexcept { return reinterpret_cast<const RawSerdata*>(d); }

// A serdata of `type` (not nullptr) for `size` bytes.
RawSerdata* alloc_serdata(const ddsi_sertype* type, ddsi_serdata_kind kind, std::size_t size) noexcept {
  if (size > UINT32_MAX - 3u) return nullptr;
  const std::size_t capacity = (size + 3u) & ~std::size_t{3};
  auto* d = static_cast<RawSerdata*>(std::malloc(sizeof(RawSerdata) + (capacity != 0 ? capacity : 4u)));
  if (d == nullptr) return nullptr;
  std::memset(static_cast<void*>(d), 0, sizeof(RawSerdata));
  ddsi_serdata_init(&d->c, type, kind);
  d->c.hash = type->serdata_basehash;  // keyless: one instance, one hash
  d->size = static_cast<std::uint32_t>(size);
  if (capacity > size) std::memset(d->bytes() + size, 0, capacity - size);
  return d;
}

RawSerdata* empty_serdata(const ddsi_sertype* type, ddsi_serdata_kind kind) noexcept {
  RawSerdata* d = alloc_serdata(type, kind, sizeof kEmptyCdrLe);
  if (d != nullptr) std::memcpy(d->bytes(), kEmptyCdrLe, sizeof kEmptyCdrLe);
  return d;
}

// ------------------------------------------------------------------ serdata operations

bool sd_eqkey(const ddsi_serdata*, const ddsi_serdata*) { return true; }  // keyless

std::uint32_t sd_get_size(const ddsi_serdata* d) { return as_raw(d)->size; }

// From a chain of received fragments (byte ranges [min, maxp1) of the sample, in order,
// possibly overlapping, the first one holding the header).
ddsi_serdata* sd_from_ser(const ddsi_sertype* type, ddsi_serdata_kind kind, const nn_rdata* frag, std::size_t size) {
  RawSerdata* d = alloc_serdata(type, kind, size);
  if (d == nullptr) return nullptr;
  std::size_t off = 0;
  for (; frag != nullptr && off < size; frag = frag->nextfrag) {
    if (frag->min > off) break;  // a hole: cannot happen in a complete chain
    const std::size_t end = frag->maxp1 < size ? frag->maxp1 : size;
    if (end > off) {
      const unsigned char* payload = NN_RMSG_PAYLOADOFF(frag->rmsg, NN_RDATA_PAYLOAD_OFF(frag));
      std::memcpy(d->bytes() + off, payload + (off - frag->min), end - off);
      off = end;
    }
  }
  if (off < size) std::memset(d->bytes() + off, 0, size - off);
  return &d->c;
}

ddsi_serdata* sd_from_ser_iov(const ddsi_sertype* type, ddsi_serdata_kind kind, ddsrt_msg_iovlen_t niov,
                              const ddsrt_iovec_t* iov, std::size_t size) {
  RawSerdata* d = alloc_serdata(type, kind, size);
  if (d == nullptr) return nullptr;
  std::size_t off = 0;
  for (ddsrt_msg_iovlen_t i = 0; i < niov && off < size; i++) {
    std::size_t n = iov[i].iov_len;
    if (n > size - off) n = size - off;
    std::memcpy(d->bytes() + off, iov[i].iov_base, n);
    off += n;
  }
  if (off < size) std::memset(d->bytes() + off, 0, size - off);
  return &d->c;
}

ddsi_serdata* sd_from_keyhash(const ddsi_sertype* type, const ddsi_keyhash*) {
  RawSerdata* d = empty_serdata(type, SDK_KEY);
  return d != nullptr ? &d->c : nullptr;
}

ddsi_serdata* sd_from_sample(const ddsi_sertype* type, ddsi_serdata_kind kind, const void* sample) {
  const auto* s = static_cast<const RawSample*>(sample);
  if (kind == SDK_KEY || s == nullptr || s->data == nullptr || s->size < 4) {
    RawSerdata* d = empty_serdata(type, kind);
    return d != nullptr ? &d->c : nullptr;
  }
  RawSerdata* d = alloc_serdata(type, kind, s->size);
  if (d == nullptr) return nullptr;
  std::memcpy(d->bytes(), s->data, s->size);
  return &d->c;
}

void sd_to_ser(const ddsi_serdata* d, std::size_t off, std::size_t size, void* buf) {
  std::memcpy(buf, as_raw(d)->bytes() + off, size);
}

ddsi_serdata* sd_to_ser_ref(const ddsi_serdata* d, std::size_t off, std::size_t size, ddsrt_iovec_t* ref) {
  ref->iov_base = const_cast<unsigned char*>(as_raw(d)->bytes() + off);
  ref->iov_len = static_cast<ddsrt_iov_len_t>(size);
  return ddsi_serdata_ref(d);
}

void sd_to_ser_unref(ddsi_serdata* d, const ddsrt_iovec_t*) { ddsi_serdata_unref(d); }

bool sd_to_sample(const ddsi_serdata* d, void* sample, void**, void*) {
  const RawSerdata* r = as_raw(d);
  auto* s = static_cast<RawSample*>(sample);
  auto* data = static_cast<unsigned char*>(std::realloc(s->data, r->size != 0 ? r->size : 1u));
  if (data == nullptr) return false;
  std::memcpy(data, r->bytes(), r->size);
  s->data = data;
  s->size = r->size;
  return true;
}

// The key of a keyless sample is empty: keep just an empty CDR header.
ddsi_serdata* sd_to_untyped(const ddsi_serdata* d) {
  RawSerdata* u = empty_serdata(d->type, SDK_KEY);
  if (u == nullptr) return nullptr;
  u->c.hash = d->hash;
  u->c.type = nullptr;  // untyped by convention
  return &u->c;
}

bool sd_untyped_to_sample(const ddsi_sertype*, const ddsi_serdata*, void* sample, void**, void*) {
  auto* s = static_cast<RawSample*>(sample);
  std::free(s->data);
  s->data = nullptr;
  s->size = 0;
  return true;
}

void sd_free(ddsi_serdata* d) { std::free(as_raw(d)); }

std::size_t sd_print(const ddsi_sertype*, const ddsi_serdata* d, char* buf, std::size_t bufsize) {
  const int n = std::snprintf(buf, bufsize, "raw(%u bytes)", static_cast<unsigned>(as_raw(d)->size));
  return n > 0 ? static_cast<std::size_t>(n) : 0u;
}

void sd_get_keyhash(const ddsi_serdata*, ddsi_keyhash* buf, bool) { std::memset(buf, 0, sizeof *buf); }

const ddsi_serdata_ops kSerdataOps = {
    .eqkey = sd_eqkey,
    .get_size = sd_get_size,
    .from_ser = sd_from_ser,
    .from_ser_iov = sd_from_ser_iov,
    .from_keyhash = sd_from_keyhash,
    .from_sample = sd_from_sample,
    .to_ser = sd_to_ser,
    .to_ser_ref = sd_to_ser_ref,
    .to_ser_unref = sd_to_ser_unref,
    .to_sample = sd_to_sample,
    .to_untyped = sd_to_untyped,
    .untyped_to_sample = sd_untyped_to_sample,
    .free = sd_free,
    .print = sd_print,
    .get_keyhash = sd_get_keyhash,
#ifdef DDS_HAS_SHM  // Debian's libddsc is built with iceoryx support (disabled at run time)
    .get_sample_size = nullptr,
    .from_iox_buffer = nullptr,
#endif
};

// ------------------------------------------------------------------ sertype operations

void st_free(ddsi_sertype* type) {
  ddsi_sertype_fini(type);
  delete type;
}

void st_zero_samples(const ddsi_sertype*, void* samples, std::size_t count) {
  std::memset(samples, 0, count * sizeof(RawSample));
}

void st_realloc_samples(void** ptrs, const ddsi_sertype*, void* old, std::size_t old_count, std::size_t count) {
  auto* samples = static_cast<RawSample*>(std::realloc(old, (count != 0 ? count : 1u) * sizeof(RawSample)));
  if (samples == nullptr) return;  // Cyclone gives no way to report it; old stays valid
  if (count > old_count) std::memset(static_cast<void*>(samples + old_count), 0, (count - old_count) * sizeof(RawSample));
  if (ptrs != nullptr)
    for (std::size_t i = 0; i < count; i++) ptrs[i] = &samples[i];
}

void st_free_samples(const ddsi_sertype*, void** ptrs, std::size_t count, dds_free_op_t op) {
  if (count == 0 || ptrs == nullptr) return;
  if (op & DDS_FREE_CONTENTS_BIT) {
    for (std::size_t i = 0; i < count; i++) {
      auto* s = static_cast<RawSample*>(ptrs[i]);
      std::free(s->data);
      s->data = nullptr;
      s->size = 0;
    }
  }
  if (op & DDS_FREE_ALL_BIT) std::free(ptrs[0]);
}

// Cyclone has already compared the type name, the flags and the operations.
bool st_equal(const ddsi_sertype*, const ddsi_sertype*) { return true; }
std::uint32_t st_hash(const ddsi_sertype*) { return 0; }

// No XTypes type information: peers match on the type name only (as with XCDR1 peers that
// send no TypeInformation).
ddsi_typeid_t* st_type_id(const ddsi_sertype*, ddsi_typeid_kind_t) { return nullptr; }
ddsi_typemap_t* st_type_map(const ddsi_sertype*) { return nullptr; }
ddsi_typeinfo_t* st_type_info(const ddsi_sertype*) { return nullptr; }

const ddsi_sertype_ops kSertypeOps = {
    .version = ddsi_sertype_v0,
    .arg = nullptr,
    .free = st_free,
    .zero_samples = st_zero_samples,
    .realloc_samples = st_realloc_samples,
    .free_samples = st_free_samples,
    .equal = st_equal,
    .hash = st_hash,
    .type_id = st_type_id,
    .type_map = st_type_map,
    .type_info = st_type_info,
    .derive_sertype = nullptr,  // writers and readers use this sertype itself
    .get_serialized_size = nullptr,
    .serialize_into = nullptr,
};

}  // namespace

ddsi_sertype* make_raw_sertype(const char* type_name) noexcept {
  auto* type = new (std::nothrow) ddsi_sertype{};
  if (type == nullptr) return nullptr;
  ddsi_sertype_init_flags(type, type_name, &kSertypeOps, &kSerdataOps, DDSI_SERTYPE_FLAG_TOPICKIND_NO_KEY);
  type->allowed_data_representation = DDS_DATA_REPRESENTATION_FLAG_XCDR1;
  return type;
}

bool is_raw_sertype(const ddsi_sertype* type) noexcept { return type != nullptr && type->ops == &kSertypeOps; }

ddsi_serdata* make_raw_serdata(const ddsi_sertype* type, std::uint32_t size, std::byte** bytes) noexcept {
  RawSerdata* d = alloc_serdata(type, SDK_DATA, size);
  if (d == nullptr) return nullptr;
  *bytes = reinterpret_cast<std::byte*>(d->bytes());
  return &d->c;
}

std::span<const std::byte> raw_serdata_bytes(const ddsi_serdata* data) noexcept {
  if (data == nullptr || data->ops != &kSerdataOps) return {};
  const RawSerdata* d = as_raw(data);
  return {reinterpret_cast<const std::byte*>(d->bytes()), d->size};
}

}  // namespace horus::dds::cyclone

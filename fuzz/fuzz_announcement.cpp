// libFuzzer target: a fleet announcement as another host sends it over DDS (encapsulation and
// XCDR1) and what horus::Fleet then checks of it: every type signature parses and hashes to the
// type it names (wire::parse_signature with the announced hash), as `horus topic echo` of a type
// it lacks relies on.
#include <variant>

#include "fuzz_common.hpp"
#include "horus/transport/encapsulation.hpp"
#include "horus/wire/dynamic.hpp"
#include "horus/wire/xcdr1.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto sample = horus::net::encapsulation::parse(horus::fuzz::bytes(data, size));
  const auto* s = std::get_if<horus::net::Sample>(&sample);
  if (s == nullptr) return 0;
  auto a = horus::cdr::decode<horus::fleet::Announcement>(s->body, s->little_endian);
  if (!a) return 0;
  for (const auto& t : a->types) {
    const bool hashes = horus::wire::signature_hash(t.signature) == t.type_hash;
    auto parsed = horus::wire::parse_signature(t.signature, t.type_hash);
    if (hashes && !parsed && parsed.error().find("hash") != std::string::npos) std::abort();  // the two checks disagree
  }
  return 0;
}

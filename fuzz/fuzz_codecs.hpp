// The round-trip check the codec targets share: what a decoder accepts, its encoder writes back,
// and the decoder reads again to the same bytes (a decoder that accepts what it cannot write
// back, or reads its own bytes differently, is a bug the fuzzer reports as a crash).
#pragma once

#include <cstdlib>
#include <exception>
#include <vector>

namespace horus::fuzz {

template <class T, class Encode, class Decode>
void round_trip(const T& first, Encode encode, Decode decode) {
  std::vector<std::byte> bytes;
  try {
    bytes = encode(first);
  } catch (const std::exception&) {
    return;  // a value the encoder refuses (a count above its limit): refused, not corrupted
  }
  auto again = decode(bytes);
  if (!again) std::abort();  // our own bytes do not decode
  if (encode(*again) != bytes) std::abort();  // they decode to something else
}

}  // namespace horus::fuzz

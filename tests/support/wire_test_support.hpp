// Helpers of the wire codec tests (test_cdr, test_lcm_codec): bytes from hex text, and a
// wiretest::All with a distinct value in every field.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "wire_test_types.hpp"

namespace wiretest {

/// "01 ab\n02" -> {0x01, 0xab, 0x02}: spaces and newlines are ignored.
inline std::vector<std::byte> hex(const std::string& text) {
  std::vector<std::byte> out;
  for (std::size_t i = 0; i < text.size();) {
    if (text[i] == ' ' || text[i] == '\n') {
      ++i;
      continue;
    }
    out.push_back(static_cast<std::byte>(std::stoi(text.substr(i, 2), nullptr, 16)));
    i += 2;
  }
  return out;
}

/// Every field set, to values whose bytes are easy to spot.
inline wiretest::All all_sample() {
  wiretest::All m;
  m.flag = true;
  m.c = 'x';
  m.i8 = -2;
  m.u16 = 0x1234;
  m.i32 = -3;
  m.u64 = 0x0102030405060708ULL;
  m.f = 1.5f;
  m.d = 2.5;
  m.mode = wiretest::Mode::Auto;
  m.raw = wiretest::Raw::B;
  m.name = {'a', 'b', 0, 0};
  m.shorts = {1, 2, 3};
  m.text = "hi";
  m.values = {0.5};
  m.inners = {wiretest::Inner{7, 1.0}};
  m.words = {"a", ""};
  m.inner = wiretest::Inner{9, -1.0};
  return m;
}

}  // namespace wiretest

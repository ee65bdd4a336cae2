// RepeatFilter (core/include/horus/detail/repeat_filter.hpp): a transport's line that repeats
// while a link is down is logged once, then again only after a quiet time, with the count held.
#include <gtest/gtest.h>

#include <chrono>

#include "horus/detail/repeat_filter.hpp"

namespace {

using horus::detail::RepeatFilter;
using namespace std::chrono_literals;

TEST(RepeatFilter, NumbersDoNotMakeALineNew) {
  EXPECT_EQ(RepeatFilter::kind_of("ddsi_udp_conn_write to udp/239.255.0.1:11651 failed with retcode -1"),
            "ddsi_udp_conn_write to udp/#.#.#.#:# failed with retcode -#");
  EXPECT_EQ(RepeatFilter::kind_of("no digits"), "no digits");
  EXPECT_EQ(RepeatFilter::kind_of(""), "");
}

TEST(RepeatFilter, ALineIsShownOnceThenAgainAfterAQuietTimeWithTheCountHeldBack) {
  RepeatFilter f(10s);
  const auto t0 = RepeatFilter::Clock::time_point{} + 1000s;
  ASSERT_EQ(f.admit("send failed", t0), 0u);
  for (int i = 1; i <= 20; ++i) EXPECT_FALSE(f.admit("send failed", t0 + i * 1s).has_value()) << i;  // every second
  EXPECT_EQ(f.admit("another line", t0 + 21s), 0u);  // a change is shown at once
  // Quiet for 10 s: shown again, with the 20 held back.
  EXPECT_EQ(f.admit("send failed", t0 + 30s), 20u);
  EXPECT_FALSE(f.admit("send failed", t0 + 31s).has_value());
}

TEST(RepeatFilter, ItKeepsABoundedNumberOfKinds) {
  RepeatFilter f(10s, 4);
  const auto t0 = RepeatFilter::Clock::time_point{} + 1000s;
  for (int i = 0; i < 4; ++i) EXPECT_EQ(f.admit("kind " + std::string(1, static_cast<char>('a' + i)), t0 + i * 1ms), 0u);
  EXPECT_EQ(f.admit("kind e", t0 + 5ms), 0u);   // forgets "kind a", the oldest
  EXPECT_EQ(f.admit("kind a", t0 + 6ms), 0u);   // new again
  EXPECT_FALSE(f.admit("kind e", t0 + 7ms).has_value());
}

}  // namespace

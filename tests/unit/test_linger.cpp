// net::Linger (core/include/horus/transport/linger.hpp): a closing reliable writer waits for its
// readers' acknowledgements, at most kWait; once a wait ran out, the process's writers do not
// wait for kQuiet.
#include <gtest/gtest.h>

#include <chrono>

#include "horus/transport/linger.hpp"

namespace {

using horus::net::Linger;

TEST(Linger, WritersWaitUntilOneWaitRunsOutThenNoneWaitsForAWhile) {
  Linger linger;
  int waits = 0;
  std::chrono::milliseconds asked{0};
  auto answered = [&](std::chrono::milliseconds bound) {
    ++waits;
    asked = bound;
    return true;
  };
  auto ran_out = [&](std::chrono::milliseconds bound) {
    ++waits;
    asked = bound;
    return false;
  };
  linger.before_delete(answered);
  linger.before_delete(answered);
  EXPECT_EQ(waits, 2);  // every reader answered: the next writer waits too
  EXPECT_EQ(asked, Linger::kWait);
  linger.before_delete(ran_out);
  EXPECT_EQ(waits, 3);
  for (int i = 0; i < 10; ++i) linger.before_delete(answered);
  EXPECT_EQ(waits, 3) << "a writer waited within kQuiet of a wait that ran out";
}

TEST(Linger, TheProcessHasOne) { EXPECT_EQ(&horus::net::process_linger(), &horus::net::process_linger()); }

}  // namespace

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "horus/msg/all.hpp"
#include "message_trips_impl.hpp"

namespace horus_test {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

const std::vector<MessageType>& standard_types() {
  static const std::vector<MessageType> types = detail::entries(horus::msg::AllMessages{});
  return types;
}

std::vector<MessageType> standard_and_wire_test_types() {
  auto all = standard_types();
  all.insert(all.end(), wire_test_types().begin(), wire_test_types().end());
  return all;
}

std::vector<MessageType> types_named(std::initializer_list<std::string_view> names) {
  const auto all = standard_and_wire_test_types();
  std::vector<MessageType> out;
  for (auto n : names) {
    auto it = std::find_if(all.begin(), all.end(), [&](const MessageType& t) { return t.name == n; });
    if (it == all.end()) {
      std::fprintf(stderr, "types_named: no message type '%.*s'\n", static_cast<int>(n.size()), n.data());
      std::abort();
    }
    out.push_back(*it);
  }
  return out;
}

std::vector<std::string> round_trip_all(horus::Backend mine, const std::string& prefix,
                                        const std::vector<MessageType>& types) {
  std::vector<std::string> failures;
  std::vector<std::unique_ptr<Trip>> trips;
  std::vector<bool> done(types.size(), false);
  for (std::size_t i = 0; i < types.size(); ++i) {
    trips.push_back(types[i].trip());
    if (auto err = trips[i]->open(mine, prefix); !err.empty()) {
      failures.push_back(std::string(types[i].name) + ": " + err);
      done[i] = true;
    }
  }
  const auto deadline = Clock::now() + 90s;
  auto last_send = Clock::now() - 1s;
  std::size_t pending = types.size();
  while (pending > 0 && Clock::now() < deadline) {
    const bool resend = Clock::now() - last_send > 300ms;
    if (resend) last_send = Clock::now();
    pending = 0;
    for (std::size_t i = 0; i < trips.size(); ++i) {
      if (done[i]) continue;
      if (resend) trips[i]->send();
      if (trips[i]->poll()) done[i] = true;
      else ++pending;
    }
    std::this_thread::sleep_for(2ms);
  }
  for (std::size_t i = 0; i < trips.size(); ++i) {
    const std::string name(types[i].name);
    if (!done[i]) failures.push_back(name + ": no echo within 90 s");
    else if (!trips[i]->failure().empty()) failures.push_back(name + ": came back different: " + trips[i]->failure());
  }
  return failures;
}

int echo_all(const std::string& prefix, const std::vector<MessageType>& types, Clock::time_point deadline,
             bool (*stop)()) {
  std::vector<std::unique_ptr<Echo>> echoes;
  bool ok = true;
  for (const auto& t : types) {
    echoes.push_back(t.echo());
    if (auto err = echoes.back()->open(prefix); !err.empty()) {
      std::fprintf(stderr, "horus_dds_peer: %s\n", err.c_str());
      ok = false;
    }
  }
  if (!ok) return 3;
  std::printf("ready\n");
  std::fflush(stdout);
  while (Clock::now() < deadline && !stop()) {
    for (auto& e : echoes) e->pump();
    std::this_thread::sleep_for(1ms);
  }
  return 0;
}

}  // namespace horus_test

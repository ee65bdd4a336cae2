// Every message type through a network round trip, compiled once: the tests that send each
// standard message (and the wire test types) to an echoing peer, and the peer that echoes them,
// use these entries instead of instantiating Topic<T> for every type in every file
// (message_trips.cpp and message_trips_wiretest.cpp instantiate each type once).
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "horus/backend.hpp"

namespace horus_test {

/// One type's round trip: sends a sample on <prefix>.<Type> and expects it back on
/// <prefix>.<Type>.echo, equal field for field.
class Trip {
 public:
  virtual ~Trip() = default;
  /// Opens both topics; an error message, or empty.
  virtual std::string open(horus::Backend mine, const std::string& prefix) = 0;
  virtual void send() = 0;
  /// Takes what came back; true once the echo arrived (failure() then says if it differed).
  virtual bool poll() = 0;
  virtual const std::string& failure() const = 0;
};

/// One type's echo: what arrives on <prefix>.<Type> is sent back on <prefix>.<Type>.echo.
class Echo {
 public:
  virtual ~Echo() = default;
  /// Opens both topics on the backend HORUS_BACKEND names; an error message, or empty.
  virtual std::string open(const std::string& prefix) = 0;
  virtual void pump() = 0;
};

struct MessageType {
  std::string_view name;  // the unqualified type name ("Pose2D")
  std::unique_ptr<Trip> (*trip)();
  std::unique_ptr<Echo> (*echo)();
  /// Encodes a sample in XCDR1 and, when LCM can carry the type, in LCM;
  /// decodes each through the type's signature alone (horus/wire/dynamic.hpp) and compares
  /// with to_json; then checks that every truncation fails in both decoders alike. The
  /// failures, or empty.
  std::string (*dynamic_check)();
  /// The sample Trip sends, as horus::to_json renders it (text), and the type's signature.
  std::string (*sample_json)();
  std::string (*signature)();
};

/// The 81 standard messages, in catalogue order.
const std::vector<MessageType>& standard_types();
/// wiretest::All, wiretest::Keywords, wiretest::Widths (every IDL construct; tests/support/wire_test_types.hpp).
const std::vector<MessageType>& wire_test_types();
/// The entries of these names, from both lists (a name that is in neither is a test bug: aborts).
std::vector<MessageType> types_named(std::initializer_list<std::string_view> names);
/// The standard messages, then the wire test types.
std::vector<MessageType> standard_and_wire_test_types();

/// Sends a sample of every type and expects each back, equal field for field, from an echoing
/// peer: resends every 300 ms (best-effort types may lose a sample while discovery completes),
/// for at most 90 s. The failures, one per type.
std::vector<std::string> round_trip_all(horus::Backend mine, const std::string& prefix,
                                        const std::vector<MessageType>& types);

/// Echoes every type until `deadline` or until stop() says so; 3 when a topic did not open
/// (printed on stderr). Prints "ready" on stdout once every topic is open.
int echo_all(const std::string& prefix, const std::vector<MessageType>& types,
             std::chrono::steady_clock::time_point deadline, bool (*stop)());

}  // namespace horus_test

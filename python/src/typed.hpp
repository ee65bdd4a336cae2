// What the module knows of each standard message at run time: its Python class, and its topic
// behind a small interface (AnyTopic; over the library's own AnyTopic of the type, compiled once
// in the library), made per type in the messages_*.cpp files (three, built in parallel).
#pragma once

#include <pybind11/pybind11.h>

#include <nlohmann/json_fwd.hpp>

#include <chrono>
#include <functional>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "horus/backend.hpp"
#include "horus/error.hpp"
#include "horus/metrics.hpp"
#include "horus/waitset.hpp"

namespace horus::python {

namespace py = pybind11;

/// Raises the horus.Error subclass of e's code (horus.TypeMismatchError, ...), with e's message.
[[noreturn]] void raise(const Error& e);

/// A topic handle of one standard type, driven from Python. Calls that wait release the GIL.
class AnyTopic {
 public:
  virtual ~AnyTopic() = default;
  virtual void send(py::handle msg) = 0;
  virtual bool try_send(py::handle msg) = 0;
  /// Waits up to `timeout` for space and sends (the GIL released meanwhile): nothing when sent,
  /// the Errc::Timeout error when the ring stayed full; raises the other errors.
  virtual std::optional<Error> send_blocking(py::handle msg, std::chrono::nanoseconds timeout) = 0;
  virtual py::object recv() = 0;
  virtual py::object recv_for(std::chrono::nanoseconds timeout) = 0;
  virtual py::object read_latest() = 0;
  virtual bool wait_for(std::chrono::nanoseconds timeout) = 0;
  virtual bool has_message() = 0;
  virtual std::uint64_t pending_count() = 0;
  virtual std::uint64_t dropped_count() const = 0;
  virtual std::uint32_t pub_count() const = 0;
  virtual std::uint32_t sub_count() const = 0;
  virtual TopicMetrics metrics() const = 0;
  virtual std::uint64_t deadline_missed_count() const = 0;
  virtual std::uint64_t expired_count() const = 0;
  virtual std::uint64_t network_errors() const = 0;
  virtual bool is_bridge() const = 0;
  virtual std::uint32_t capacity() const = 0;
  virtual std::size_t max_message_size() const = 0;
  virtual Backend backend() const = 0;
  virtual std::string_view name() const = 0;
  virtual void publish_only() = 0;
  virtual WaitSet::Id attach(WaitSet& ws) = 0;
  /// Large data: a slot of the pool lent for the message a descriptor object (args[0]) or
  /// Type.describe's arguments describe; the loan keeps `self` (this handle) alive.
  virtual py::object loan(const py::args& args, std::shared_ptr<AnyTopic> self) = 0;
};

/// Registered for each standard type when the module loads.
struct MessageType {
  std::string qualified;  // "horus::msg::Pose2D"
  std::string short_name;  // "Pose2D"
  std::uint64_t hash = 0;
  py::object cls;          // horus.msg.Pose2D
  bool large = false;      // Image, DepthImage, PointCloud, Tensor (a pool; loan())
  std::uint64_t lcm_fingerprint = 0;  // lcm-gen's (0: no LCM encoding): an LCM log's channels carry only it
  std::unique_ptr<AnyTopic> (*open)(const std::string& name, const TopicOptions& options) = nullptr;
};

/// Adds a type (messages_*.cpp, at module load).
void register_type(MessageType type);
/// The type whose Python class is `cls` (or whose name is the str `cls`: "Pose2D" or
/// "horus::msg::Pose2D"); raises TypeError naming what was given when there is none.
const MessageType& type_of(py::handle cls);
/// The type called `qualified`, or null.
const MessageType* find_type(std::string_view qualified);
/// The type whose LCM fingerprint is `fingerprint`, or null.
const MessageType* find_type_by_lcm_fingerprint(std::uint64_t fingerprint);

/// The message classes, domain by domain (messages_*.cpp).
void bind_messages_first(py::module_& msg);
void bind_messages_second(py::module_& msg);
void bind_messages_third(py::module_& msg);

/// Topics, WaitSet, Trigger (topic.cpp); Fleet, config, record (tools.cpp); GenericMessage
/// values (generic.cpp).
void bind_topics(py::module_& m);
void bind_tools(py::module_& m);
void bind_generic(py::module_& msg);

/// A Python dict / list / number from JSON and back (to_dict / from_dict).
py::object json_to_py(const nlohmann::json& j);
nlohmann::json py_to_json(py::handle h, const std::string& path);

/// Seconds (a float; None: forever) as a duration; negative is refused.
std::chrono::nanoseconds seconds(py::handle s, std::string_view what);

}  // namespace horus::python

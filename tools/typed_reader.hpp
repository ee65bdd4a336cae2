// A subscriber of a standard-message topic whose type is known only at run time (horus topic
// echo / hz): one Topic<T> per standard type behind a small interface, instantiated once per
// type in typed_reader_*.cpp (two files, so the build compiles the halves in parallel).
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "horus/backend.hpp"

namespace horus::tools {

class TypedReader {
 public:
  virtual ~TypedReader() = default;
  /// The next message as text (JSON or the one-line summary), or nothing.
  virtual std::optional<std::string> recv_text(bool json) = 0;
  /// Takes the next message without printing it; false when there was none.
  virtual bool recv_any() = 0;
  /// Sleeps until a message is waiting or `timeout` passes (Topic::wait_for); true: one is.
  virtual bool wait(std::chrono::nanoseconds timeout) = 0;
};

/// Opens topic `name` (with `backend`: shared memory, or the fleet transport the segment names)
/// as the standard message called `type_name`. Nothing, with
/// `error` empty, when it is not a standard type; nothing with `error` set when opening failed.
std::unique_ptr<TypedReader> open_reader(std::string_view type_name, const std::string& name, const Backend& backend,
                                         std::string& error);

namespace detail {
std::unique_ptr<TypedReader> open_reader_first_half(std::string_view type_name, const std::string& name,
                                                    const Backend& backend, std::string& error, bool& known);
std::unique_ptr<TypedReader> open_reader_second_half(std::string_view type_name, const std::string& name,
                                                     const Backend& backend, std::string& error, bool& known);
}  // namespace detail

}  // namespace horus::tools

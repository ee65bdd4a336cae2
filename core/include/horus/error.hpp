// Errors of horus: an enum class code plus a message that names the topic,
// what was found and what was expected.
//
// Fallible calls return horus::Result<T> (std::expected<T, horus::Error>);
// throwing forms (Topic<T>(name)) throw horus::Exception carrying the same Error.
#pragma once

#include <expected>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

enum class Errc {
  InvalidName,       // a topic name breaks the naming rules
  TypeMismatch,      // the topic already carries another message type
  InvalidArgument,   // a bad capacity, slot size or other parameter
  ConfigMismatch,    // the topic exists with another capacity
  LimitReached,      // too many publishers or subscribers on one topic
  Timeout,           // a blocking call ran out of time
  MessageTooLarge,   // a message does not fit its slot
  Config,            // a malformed setting (an environment variable such as HORUS_BACKEND)
  Io,                // an operating-system call failed
  Corrupt,           // bytes (a file, a recording) are not what their format says
};

/// A short stable name of the code ("type_mismatch").
std::string_view to_string(Errc code) noexcept;

class Error {
 public:
  Error(Errc code, std::string message) : code_(code), message_(std::move(message)) {}
  Errc code() const noexcept { return code_; }
  const std::string& message() const noexcept { return message_; }
  bool operator==(Errc code) const noexcept { return code_ == code; }

 private:
  Errc code_;
  std::string message_;
};

class Exception : public std::runtime_error {
 public:
  explicit Exception(Error error) : std::runtime_error(error.message()), error_(std::move(error)) {}
  const Error& error() const noexcept { return error_; }
  Errc code() const noexcept { return error_.code(); }

 private:
  Error error_;
};

template <class T>
using Result = std::expected<T, Error>;

/// Shorthand for returning an error: `return horus::fail(Errc::InvalidName, "...")`.
inline std::unexpected<Error> fail(Errc code, std::string message) {
  return std::unexpected<Error>(std::in_place, code, std::move(message));
}

}  // namespace horus

HORUS_API_END

#include "horus/error.hpp"

namespace horus {

std::string_view to_string(Errc code) noexcept {
  switch (code) {
    case Errc::InvalidName: return "invalid_name";
    case Errc::TypeMismatch: return "type_mismatch";
    case Errc::InvalidArgument: return "invalid_argument";
    case Errc::ConfigMismatch: return "config_mismatch";
    case Errc::LimitReached: return "limit_reached";
    case Errc::Timeout: return "timeout";
    case Errc::MessageTooLarge: return "message_too_large";
    case Errc::Config: return "config";
    case Errc::Io: return "io";
    case Errc::Corrupt: return "corrupt";
  }
  return "unknown";
}

}  // namespace horus

#include "horus/transport/endpoint_gate.hpp"

#include <exception>
#include <utility>

namespace horus::net {

EndpointGate::EndpointGate(Listener& listener, std::string label) : listener_(listener), label_(std::move(label)) {}

void EndpointGate::close() noexcept {
  if (inside()) {  // from the endpoint's own call: this thread holds mutex_
    open_.store(false, std::memory_order_release);
    return;
  }
  std::lock_guard lock(mutex_);
  open_.store(false, std::memory_order_release);
}

void EndpointGate::Calls::sample(const Sample& sample) noexcept {
  if (!gate_.is_open()) return;
  try {
    gate_.listener_.on_sample(sample);
  } catch (const std::exception& e) {
    try {
      error(gate_.label_ + ": the sample handler failed: " + e.what());
    } catch (...) {
    }
  } catch (...) {
    try {
      error(gate_.label_ + ": the sample handler failed");
    } catch (...) {
    }
  }
}

void EndpointGate::Calls::error(std::string_view message) noexcept {
  if (!gate_.is_open()) return;
  try {
    gate_.listener_.on_error(message);
  } catch (...) {  // a listener must not throw into a transport's thread
  }
}

std::size_t EndpointGate::Calls::room() noexcept {
  if (!gate_.is_open()) return 0;
  try {
    return gate_.listener_.room();
  } catch (...) {
    return 0;
  }
}

void EndpointGate::Calls::matched() noexcept {
  if (!gate_.is_open()) return;
  try {
    gate_.listener_.on_matched();
  } catch (...) {
  }
}

void EndpointGate::Calls::lost(std::uint64_t count) noexcept {
  if (!gate_.is_open()) return;
  try {
    gate_.listener_.on_lost(count);
  } catch (...) {
  }
}

}  // namespace horus::net

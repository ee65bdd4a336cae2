// The functions of horus/msg/audio.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/audio.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <expected>
#include <span>
#include <string>
#include <string_view>

namespace horus::msg {

std::expected<AudioFrame, std::string> AudioFrame::create(std::uint32_t sample_rate_hz, std::uint8_t channel_count,
                                                          std::span<const float> data) {
  if (sample_rate_hz == 0) return std::unexpected(std::string("AudioFrame sample rate must be > 0 Hz"));
  if (channel_count == 0) return std::unexpected(std::string("AudioFrame needs at least 1 channel"));
  if (data.size() > kMaxSamples)
    return std::unexpected(fmt::format("AudioFrame holds at most {} samples; got {}", kMaxSamples, data.size()));
  if (data.size() % channel_count != 0)
    return std::unexpected(fmt::format("AudioFrame got {} samples, not a multiple of its {} channels",
                                       data.size(), static_cast<int>(channel_count)));
  AudioFrame f{};
  f.sample_rate = sample_rate_hz;
  f.channels = channel_count;
  f.set_encoding(AudioEncoding::F32);
  std::copy(data.begin(), data.end(), f.samples.begin());
  f.num_samples = static_cast<std::uint32_t>(data.size());
  return f;
}

std::string AudioFrame::log_summary() const {
  const std::string_view name = to_string(encoding_enum());
  const std::string enc = name.empty() ? fmt::format("encoding {}", static_cast<int>(encoding)) : std::string(name);
  std::string out = fmt::format("AudioFrame({} ch, {} Hz, {} samples, {:.1f} ms, {}", static_cast<int>(channels),
                                sample_rate, num_samples, duration_ms(), enc);
  if (!frame_id_str().empty()) out += fmt::format(", {}", frame_id_str());
  out += ')';
  return out;
}

}  // namespace horus::msg

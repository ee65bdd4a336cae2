// Audio messages: AudioEncoding and AudioFrame (HORUS audio.rs; the spec names
// them: "up to 4800 samples, configurable sample rate and channels").
//
// AudioFrame is fixed-size (trivially copyable, about 19 KB): 4800 float
// samples cover 100 ms of 48 kHz mono. Multi-channel samples are interleaved
// (L R L R ...). As for every message, AudioFrame{} is all zeros (sample rate 0,
// 0 channels, so its duration is 0); HORUS's Rust default is 16 kHz mono.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

/// Most samples one AudioFrame holds (all channels together).
inline constexpr std::size_t MAX_AUDIO_SAMPLES = 4800;

/// Sample format of the source. The samples themselves are always stored as
/// float: F32 means they are in [-1, 1]; I16 means they hold 16-bit integer
/// values, [-32768, 32767].
enum class AudioEncoding : std::uint8_t { F32 = 0, I16 = 1 };
HORUS_REFLECT_ENUM(AudioEncoding, F32, I16)

// ---------------------------------------------------------------------------
/// A chunk of audio from a microphone or other source. samples[0, num_samples)
/// are valid; with several channels they are interleaved, so a frame (one
/// sample per channel) is `channels` consecutive samples.
struct AudioFrame {
  static constexpr std::size_t kMaxSamples = MAX_AUDIO_SAMPLES;

  std::array<float, kMaxSamples> samples{};  ///< interleaved
  std::uint32_t num_samples{};               ///< valid samples, all channels (stereo: frames * 2)
  std::uint32_t sample_rate{};               ///< Hz (8000, 16000, 44100, 48000 ...)
  std::uint8_t channels{};                   ///< 1 = mono, 2 = stereo
  std::uint8_t encoding{};                   ///< an AudioEncoding
  std::array<std::uint8_t, 2> _pad{};        ///< alignment (as HORUS), always zero
  std::uint64_t timestamp_ns{};
  std::array<char, 32> frame_id{};           ///< source name ("mic_left"), NUL-terminated, at most 31 characters

  /// A frame of interleaved samples (F32 encoding, no frame id, timestamp 0),
  /// or an error naming the problem: more than 4800 samples (HORUS would
  /// silently drop the rest), a sample rate or channel count of 0, or a sample
  /// count that is not a whole number of frames (a multiple of channels).
  static std::expected<AudioFrame, std::string> create(std::uint32_t sample_rate_hz, std::uint8_t channel_count,
                                                       std::span<const float> data);
  /// Throwing form of create() (HORUS's multi_channel): std::invalid_argument with create()'s message.
  static AudioFrame make(std::uint32_t sample_rate_hz, std::uint8_t channel_count, std::span<const float> data) {
    auto f = create(sample_rate_hz, channel_count, data);
    if (!f) throw std::invalid_argument(f.error());
    return *f;
  }
  /// One channel (HORUS's AudioFrame::mono). Throws std::invalid_argument as make().
  static AudioFrame mono(std::uint32_t sample_rate_hz, std::span<const float> data) {
    return make(sample_rate_hz, 1, data);
  }
  /// Two interleaved channels, L R L R ... (HORUS's AudioFrame::stereo). Throws
  /// std::invalid_argument as make(), also for an odd sample count.
  static AudioFrame stereo(std::uint32_t sample_rate_hz, std::span<const float> data) {
    return make(sample_rate_hz, 2, data);
  }

  /// A copy with the source name set. Throws std::invalid_argument when it
  /// does not fit (at most 31 characters, no NUL); HORUS cuts it.
  [[nodiscard]] AudioFrame with_frame_id(std::string_view id) const {
    AudioFrame f = *this;
    if (!f.set_frame_id(id))
      throw std::invalid_argument("AudioFrame frame_id '" + std::string(id) + "' has " + std::to_string(id.size()) +
                                  " characters; at most 31 fit (and no NUL)");
    return f;
  }
  /// A copy with the timestamp (ns since the epoch).
  [[nodiscard]] AudioFrame with_timestamp(std::uint64_t stamp_ns) const {
    AudioFrame f = *this;
    f.timestamp_ns = stamp_ns;
    return f;
  }

  /// Sets the source name; returns false, changing nothing, when it does not fit (31 characters at most, no NUL).
  constexpr bool set_frame_id(std::string_view id) noexcept { return set_fixed_str(frame_id, id); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }

  constexpr AudioEncoding encoding_enum() const noexcept { return static_cast<AudioEncoding>(encoding); }
  constexpr void set_encoding(AudioEncoding e) noexcept { encoding = static_cast<std::uint8_t>(e); }

  /// num_samples, clamped to kMaxSamples (a received message may hold any value).
  constexpr std::size_t sample_count() const noexcept { return std::min<std::size_t>(num_samples, kMaxSamples); }
  /// The valid samples, interleaved.
  constexpr std::span<const float> valid_samples() const noexcept {
    return std::span<const float>(samples.data(), sample_count());
  }
  /// Frames (samples per channel): num_samples / channels, 0 with no channels.
  constexpr std::uint32_t frame_count() const noexcept {
    return channels == 0 ? 0u : static_cast<std::uint32_t>(sample_count() / channels);
  }
  /// The sample of channel `channel` in frame `frame`, or nullopt when either is out of range.
  constexpr std::optional<float> sample_at(std::size_t frame, std::size_t channel) const noexcept {
    if (channel >= channels || frame >= frame_count()) return std::nullopt;
    return samples[frame * channels + channel];
  }

  /// Duration in milliseconds: frames / sample_rate * 1000; 0 when the sample
  /// rate or the channel count is 0.
  constexpr double duration_ms() const noexcept {
    if (sample_rate == 0 || channels == 0) return 0.0;
    return static_cast<double>(sample_count()) / static_cast<double>(channels) / static_cast<double>(sample_rate) *
           1000.0;
  }
  /// Duration in seconds (duration_ms() / 1000).
  constexpr double duration_seconds() const noexcept { return duration_ms() / 1000.0; }

  /// "AudioFrame(2 ch, 48000 Hz, 960 samples, 10.0 ms, F32, mic_array)"; the
  /// source part is left out when empty.
  std::string log_summary() const;

  friend constexpr bool operator==(const AudioFrame&, const AudioFrame&) = default;
};
HORUS_REFLECT(AudioFrame, samples, num_samples, sample_rate, channels, encoding, _pad, timestamp_ns, frame_id)

static_assert(horus::reflect::is_fixed_size<AudioFrame>, "AudioFrame must be trivially copyable and standard layout");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(AudioFrame)

}  // namespace horus::msg

HORUS_API_END

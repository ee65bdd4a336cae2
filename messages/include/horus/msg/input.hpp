// Input messages: JoystickInput (gamepad buttons, axes, hats, connection) and
// KeyboardInput (keys with modifier flags).
//
// Both are events, one per change, with the layout and helpers of HORUS
// joystick_msg.rs and keyboard_input_msg.rs (the spec only names the types).
// Text fields are NUL-terminated; a name that does not fit is refused (HORUS
// Rust cuts it). Timestamps are milliseconds since the epoch, as in HORUS.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// One gamepad or joystick event. event_type says which kind (EVENT_BUTTON,
/// EVENT_AXIS, EVENT_HAT, EVENT_CONNECTION); element_id and element_name say
/// which button, axis or hat. value is 0 or 1 for buttons, -1 to 1 for axes, a
/// direction for hats, 1 (connected) or 0 (disconnected) for connection events.
struct JoystickInput {
  static constexpr std::string_view EVENT_BUTTON = "button";
  static constexpr std::string_view EVENT_AXIS = "axis";
  static constexpr std::string_view EVENT_HAT = "hat";
  static constexpr std::string_view EVENT_CONNECTION = "connection";

  std::uint32_t joystick_id{};          ///< controller index (0, 1, 2 ...)
  std::array<char, 16> event_type{};    ///< one of the EVENT_ names, NUL-terminated
  std::uint32_t element_id{};           ///< button, axis or hat number
  std::array<char, 32> element_name{};  ///< e.g. "A", "LeftStickX"; NUL-terminated, at most 31 characters
  float value{};                        ///< see above
  std::uint8_t pressed{};               ///< buttons: 1 = pressed, 0 = released; 0 for other events
  std::uint64_t timestamp_ms{};         ///< ms since the epoch

  /// A button press (value 1, pressed 1) or release (value 0, pressed 0). The
  /// timestamp is left 0. Throws std::invalid_argument when the name does not
  /// fit (at most 31 characters, no NUL).
  static JoystickInput new_button(std::uint32_t joystick, std::uint32_t button_id, std::string_view name,
                                  bool is_down) {
    return event(joystick, EVENT_BUTTON, button_id, name, is_down ? 1.0f : 0.0f, is_down ? 1 : 0);
  }
  /// An axis moved to value (-1 to 1); as new_button for the name.
  static JoystickInput new_axis(std::uint32_t joystick, std::uint32_t axis_id, std::string_view name, float v) {
    return event(joystick, EVENT_AXIS, axis_id, name, v, 0);
  }
  /// A hat (d-pad) moved to value; as new_button for the name.
  static JoystickInput new_hat(std::uint32_t joystick, std::uint32_t hat_id, std::string_view name, float v) {
    return event(joystick, EVENT_HAT, hat_id, name, v, 0);
  }
  /// The controller connected (value 1, name "Connected") or disconnected
  /// (value 0, name "Disconnected"); element_id 0.
  static JoystickInput new_connection(std::uint32_t joystick, bool connected) {
    return event(joystick, EVENT_CONNECTION, 0, connected ? "Connected" : "Disconnected", connected ? 1.0f : 0.0f, 0);
  }

  /// Sets the event type; returns false, changing nothing, when it does not fit (15 characters at most).
  constexpr bool set_event_type(std::string_view type) noexcept { return set_fixed_str(event_type, type); }
  constexpr std::string_view event_type_str() const noexcept { return fixed_str_view(event_type); }
  /// Sets the element name; returns false, changing nothing, when it does not fit (31 characters at most).
  constexpr bool set_element_name(std::string_view name) noexcept { return set_fixed_str(element_name, name); }
  constexpr std::string_view element_name_str() const noexcept { return fixed_str_view(element_name); }

  constexpr bool is_button() const noexcept { return event_type_str() == EVENT_BUTTON; }
  constexpr bool is_axis() const noexcept { return event_type_str() == EVENT_AXIS; }
  constexpr bool is_hat() const noexcept { return event_type_str() == EVENT_HAT; }
  constexpr bool is_connection_event() const noexcept { return event_type_str() == EVENT_CONNECTION; }
  /// A connection event with value > 0 (NaN gives false).
  constexpr bool is_connected() const noexcept { return is_connection_event() && value > 0.0f; }
  /// pressed is non-zero (only button events set it).
  constexpr bool is_pressed() const noexcept { return pressed != 0; }

  friend constexpr bool operator==(const JoystickInput&, const JoystickInput&) = default;

 private:
  static JoystickInput event(std::uint32_t joystick, std::string_view type, std::uint32_t id, std::string_view name,
                             float v, int is_down) {
    JoystickInput j{};
    if (!j.set_element_name(name))
      throw std::invalid_argument("JoystickInput element name '" + std::string(name) + "' has " +
                                  std::to_string(name.size()) + " characters; at most 31 fit");
    j.set_event_type(type);
    j.joystick_id = joystick;
    j.element_id = id;
    j.value = v;
    j.pressed = static_cast<std::uint8_t>(is_down);
    return j;
  }
};
HORUS_REFLECT(JoystickInput, joystick_id, event_type, element_id, element_name, value, pressed, timestamp_ms)

// ---------------------------------------------------------------------------
/// One key press or release, with the modifier keys held at the time as bit
/// flags (MODIFIER_CTRL | MODIFIER_SHIFT ...). code is the raw key code of the
/// input system.
struct KeyboardInput {
  static constexpr std::uint32_t MODIFIER_CTRL = 1u << 0;
  static constexpr std::uint32_t MODIFIER_ALT = 1u << 1;
  static constexpr std::uint32_t MODIFIER_SHIFT = 1u << 2;
  static constexpr std::uint32_t MODIFIER_SUPER = 1u << 3;
  static constexpr std::uint32_t MODIFIER_HYPER = 1u << 4;
  static constexpr std::uint32_t MODIFIER_META = 1u << 5;

  std::array<char, 32> key_name{};  ///< e.g. "a", "Enter"; NUL-terminated, at most 31 characters
  std::uint32_t code{};             ///< raw key code
  std::uint32_t modifier_flags{};   ///< MODIFIER_ bits
  std::uint8_t pressed{};           ///< 1 = press, 0 = release
  std::uint64_t timestamp_ms{};     ///< ms since the epoch

  /// The spec's KeyboardInput::new(key, code, modifiers, pressed), with the
  /// modifiers as MODIFIER_ bits (HORUS takes names: see modifier_flag()). The
  /// timestamp is left 0. Throws std::invalid_argument when the key name does
  /// not fit (at most 31 characters, no NUL).
  static KeyboardInput make(std::string_view key, std::uint32_t key_code, std::uint32_t modifiers, bool is_down) {
    KeyboardInput k{};
    if (!k.set_key_name(key))
      throw std::invalid_argument("KeyboardInput key name '" + std::string(key) + "' has " +
                                  std::to_string(key.size()) + " characters; at most 31 fit");
    k.code = key_code;
    k.modifier_flags = modifiers;
    k.pressed = static_cast<std::uint8_t>(is_down ? 1 : 0);
    return k;
  }

  /// The flag of a modifier named "Ctrl", "Alt", "Shift", "Super", "Hyper" or
  /// "Meta" (exact spelling, as HORUS); 0 for any other name.
  static constexpr std::uint32_t modifier_flag(std::string_view name) noexcept {
    for (const auto& m : kModifiers)
      if (m.name == name) return m.flag;
    return 0;
  }

  /// True when the modifier called name (see modifier_flag()) was held; an unknown name gives false.
  constexpr bool has_modifier(std::string_view name) const noexcept {
    const std::uint32_t flag = modifier_flag(name);
    return flag != 0 && (modifier_flags & flag) != 0;
  }
  /// True when every flag in mask was held (a mask of 0 asks for nothing and gives true).
  constexpr bool has_modifiers(std::uint32_t mask) const noexcept { return (modifier_flags & mask) == mask; }
  constexpr bool is_ctrl() const noexcept { return (modifier_flags & MODIFIER_CTRL) != 0; }
  constexpr bool is_shift() const noexcept { return (modifier_flags & MODIFIER_SHIFT) != 0; }
  constexpr bool is_alt() const noexcept { return (modifier_flags & MODIFIER_ALT) != 0; }

  /// The names of the modifiers held, in the order Ctrl, Alt, Shift, Super,
  /// Hyper, Meta (unknown bits are left out).
  std::vector<std::string_view> modifiers() const {
    std::vector<std::string_view> names;
    for (const auto& m : kModifiers)
      if ((modifier_flags & m.flag) != 0) names.push_back(m.name);
    return names;
  }

  /// Sets the key name; returns false, changing nothing, when it does not fit.
  constexpr bool set_key_name(std::string_view key) noexcept { return set_fixed_str(key_name, key); }
  constexpr std::string_view key_name_str() const noexcept { return fixed_str_view(key_name); }

  /// pressed is non-zero (a press, not a release).
  constexpr bool is_pressed() const noexcept { return pressed != 0; }

  friend constexpr bool operator==(const KeyboardInput&, const KeyboardInput&) = default;

 private:
  struct ModifierName {
    std::string_view name;
    std::uint32_t flag;
  };
  static constexpr std::array<ModifierName, 6> kModifiers{{{"Ctrl", MODIFIER_CTRL},
                                                           {"Alt", MODIFIER_ALT},
                                                           {"Shift", MODIFIER_SHIFT},
                                                           {"Super", MODIFIER_SUPER},
                                                           {"Hyper", MODIFIER_HYPER},
                                                           {"Meta", MODIFIER_META}}};
};
HORUS_REFLECT(KeyboardInput, key_name, code, modifier_flags, pressed, timestamp_ms)

static_assert(horus::reflect::is_fixed_size<JoystickInput>,
              "JoystickInput must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<KeyboardInput>,
              "KeyboardInput must be trivially copyable and standard layout");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(JoystickInput, KeyboardInput)

}  // namespace horus::msg

HORUS_API_END

// SPDX-License-Identifier: LGPL-2.1-or-later
// The TtsFAPInterface data as draft-ietf-avt-rtp-pfap-00 carries it (sections 5 and 6).
//
// Types hold wire values: every field's range is the range of its bits on the wire, and
// is_valid() says whether a value fits. Nothing here allocates.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace pfap {

inline constexpr int64_t kNsPerMs = 1'000'000;

inline constexpr int kMinFapIndex = 3;
inline constexpr int kMaxFapIndex = 74;
// FAP indexes 69..74 carry the MPEG-4 expressions 1..6 (joy, sadness, anger, fear, disgust,
// surprise): index = 68 + expression.
inline constexpr int kFirstExpressionIndex = 69;
// An expression FAP's amplitude is the expression's intensity: MPEG-4's expression_intensity
// (FAP 2), 6 bits.
inline constexpr int32_t kMaxExpressionIntensity = 63;
inline constexpr int kFapCount = kMaxFapIndex + 1;  // arrays indexed by FAP index
inline constexpr int32_t kMaxAmplitude = 2529600;
inline constexpr uint16_t kMaxTransitionMs = 16383;      // 14 bits
inline constexpr uint16_t kMaxPhonemeDurationMs = 4095;  // 12 bits
inline constexpr unsigned kMaxF0Hz = 510;                // 8 bits in units of 2 Hz
// MPEG-4 allows up to 40 consecutive bookmarks before one phoneme.
inline constexpr int kMaxBookmarksPerPhoneme = 40;

enum class Curve : uint8_t {
  kLinear = 1,    // straight to the target over T
  kTriangle = 2,  // to the target over T/2, back over T/2
  kSpline = 3,    // smooth (cubic Hermite) to the target over T
};

// One FAP target: a bookmark's effect on one FAP. Also the type of a recovery entry
// (section 6.4), whose transition_ms is the time still remaining at the packet's timestamp.
struct Fap {
  uint8_t index = kMinFapIndex;  // 3..74
  int32_t amplitude = 0;         // |amplitude| <= kMaxAmplitude, in the FAP's own units
  uint16_t transition_ms = 0;    // 0..16383
  Curve curve = Curve::kLinear;

  bool operator==(const Fap&) const = default;
};

struct Phoneme {
  uint8_t symbol = 0;        // out-of-band phoneme alphabet
  uint16_t duration_ms = 0;  // 0..4095
  uint8_t f0 = 0;            // f0 average in units of 2 Hz (see f0_code)
  bool stress = false;
  bool word_begin = false;
  bool end_of_text = false;  // InfoBits 11: end of text, which also ends the packet

  bool operator==(const Phoneme&) const = default;
  unsigned f0_hz() const { return 2u * f0; }
};

// Inline: the codec checks every descriptor, and a call each costs more than the check. Each
// range is one unsigned comparison (a value below the range wraps round to a large one).
inline bool is_valid(const Fap& fap) {
  const uint32_t magnitude = fap.amplitude < 0 ? 0u - static_cast<uint32_t>(fap.amplitude)
                                               : static_cast<uint32_t>(fap.amplitude);
  constexpr auto kFirstCurve = static_cast<unsigned>(Curve::kLinear);
  constexpr auto kLastCurve = static_cast<unsigned>(Curve::kSpline);
  return static_cast<unsigned>(fap.index - kMinFapIndex) <= unsigned{kMaxFapIndex - kMinFapIndex} &&
         magnitude <= uint32_t{kMaxAmplitude} && fap.transition_ms <= kMaxTransitionMs &&
         static_cast<unsigned>(fap.curve) - kFirstCurve <= kLastCurve - kFirstCurve;
}
inline bool is_valid(const Phoneme& phoneme) {
  return phoneme.duration_ms <= kMaxPhonemeDurationMs;
}

// The f0 code for a frequency in Hz: nearest 2 Hz step, halves rounded up, saturating at
// 510 Hz (code 255).
uint8_t f0_code(unsigned hz);

// The weight 0..1 of an expression whose FAP (68 + expression) has `amplitude`: the
// intensity over 63, clamped, so that a value outside 0..63 saturates. pfapface's face, the
// blendshapes and pfap.js (web/src/face_model.js, held to this by tests/web) all weigh
// expressions by it.
double expression_weight(double amplitude);

// A phoneme longer than 4095 ms as the consecutive pieces the wire can carry: pieces of
// 4095 ms, then the rest. The first piece keeps stress and word begin, the last keeps end of
// text; the symbol and f0 repeat. A phoneme that fits comes back unchanged.
void split_long_phoneme(const Phoneme& phoneme, uint32_t duration_ms, std::vector<Phoneme>& out);

}  // namespace pfap

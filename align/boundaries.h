// SPDX-License-Identifier: LGPL-2.1-or-later
// Where phoneme boundaries lie, beyond what the warp gives: espeak-ng's phoneme starts moved to
// where phonetic labels put them, and boundaries next to a pause moved onto the recording's
// silence. Each rule and what it gave on the Festival corpus: docs/align.md.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mfcc.h"
#include "speech.h"

namespace pfap::align {

// How much earlier than espeak-ng's phoneme events phonetic labels put the boundaries: the
// signed median error was +12 ms on both halves of the Festival corpus; 10 ms was chosen on
// the tuning half (docs/align.md).
inline constexpr double kPhoneticLeadSeconds = 0.010;

// Moves the starts of `syn`'s phonemes (espeak-ng's) to phonetic convention, in place:
//  - espeak-ng starts a voiceless stop (p, t, k, ch) at its release, its closure (digital
//    silence) at the end of the phoneme before; labels start a stop at its closure, which is
//    also where the lips close. A phoneme after a non-pause whose start is preceded, within
//    10 ms, by at least 5 ms of silence (|sample| <= 8) starts where that silence starts
//    (at most 150 ms back).
//  - then every start after the first moves kPhoneticLeadSeconds earlier, never before the
//    start before it.
void to_phonetic_boundaries(tts::Speech& syn);

// Pads `syn` with `pad` samples of silence at both ends, each end a pause: the first phoneme
// when it is one (espeak-ng starts some texts with a short pause), else a pause put before it;
// the same at the end, end of text moved onto it. A recording's silence before and after its
// speech, however long, then has a pause to be (pause_frames() lets the warp hold it there).
// Which ends got a pause of their own:
struct EndPauses {
  bool first = false, last = false;
};
EndPauses pad_with_pauses(tts::Speech& syn, size_t pad);

// Per frame of `features` (the synthetic speech of `phonemes`, whose starts are `offset`
// samples earlier), whether a pause the speaker makes and the synthesis lacks may be matched
// there: the last frame before each word that follows speech, so that the word's start maps
// to the pause's end and the word before holds over it; and every frame of a pause at the
// start or the end, which holds the recording's silence before and after its speech (issue
// 31). Speakers pause between words; at every phoneme boundary it did worse (docs/align.md,
// "Live").
std::vector<bool> pause_frames(const std::vector<tts::SpokenPhoneme>& phonemes, size_t offset,
                               const Features& features);

// How far snap_to_silence() moves a boundary at most, and how much silence it takes for an
// edge, in ms.
inline constexpr unsigned kSnapRadiusMs = 100;
inline constexpr unsigned kMinSilenceMs = 20;
// Blocks more than this below the loudest are digital silence, no floor: 70, 80 and 90 were
// tried on the Festival corpora, 90 ended the last sound best (docs/align.md).
inline constexpr float kFloorRangeDb = 90;
// How long a stop's closure after a pause is taken to be: silence cannot tell; on the Festival
// kal corpus 40 to 80 ms gave the same first-sound p90, 50 was chosen (docs/align.md).
inline constexpr unsigned kStopClosureMs = 50;
// A stop before a pause ends where its release ends: at the last edge into silence at most this
// long after the edge where its closure begins (its closure 25..75 ms on slt, then a burst).
// The one bound tried, measured on kal, ked and slt (docs/align.md).
inline constexpr unsigned kMaxStopReleaseMs = 100;

// A weak onset (/f/, /h/, /dh/) rises out of silence more slowly than a vowel, for tens of ms
// below the silence threshold: an onset starts where it first rises kOnsetRiseDb above the
// silence just before it, at most kMaxRiseMs before the threshold's edge. That silence's own
// level, not the recording's floor: live the floor is taken over the audio kept, and a margin
// under the floor's threshold put some first sounds early there. Chosen on kal: 4 and 6 dB put
// its first sound within p90 15 ms, 10 dB within 25; 30 ms back within 20 (docs/align.md).
inline constexpr float kOnsetRiseDb = 6;
inline constexpr unsigned kMaxRiseMs = 50;

// Festival's lead-in carries a hum (kal: 160 ms whose loudest 5 ms block is 24..26 dB below
// the loudest, then 45 ms of silence), as loud as a weak consonant. Sound before the first
// sound that stays more than kHumBelowLoudestDb below the loudest and ends in silence within
// kMaxHumMs is no speech: the first sound starts after it. Chosen on kal's two such sentences
// (34 and 40): a fricative before a stop's closure (/s/ of "st") is louder, a weak onset (/f/,
// /h/) runs into its vowel.
inline constexpr float kHumBelowLoudestDb = 22;
inline constexpr unsigned kMaxHumMs = 300;

// Moves each boundary next to a pause in `phonemes` (a start into a pause: speech ends; a
// start out of one: speech begins) onto the nearest edge of silence in `audio` within
// kSnapRadiusMs: the warp matches a fading end of speech with the synthetic pause. `starts[k]`
// is phoneme k + 1's start in samples of `audio` (phoneme 0 starts at 0). Silence: 5 ms
// blocks below the recording's floor + 20 dB, or below its loudest - 20 dB if that is lower,
// for at least kMinSilenceMs. The floor is the 10th-percentile block of those within
// kFloorRangeDb of the loudest: digital silence (zeros before or after the speech, however
// long) has no level to be a floor. A stop (p t k b d g ch jh) out of a pause starts
// kStopClosureMs before the edge: its closure is silent, the edge its release, and phonetic
// labels (and the lips) start it at its closure; one into a pause ends where its release ends
// (kMaxStopReleaseMs), not at its closure. The first sound starts after any hum
// (kHumBelowLoudestDb); when the warp puts it in silence with no edge within the radius (live,
// at a hum that the speech heard since makes silence), at the next edge within kMaxHumMs. An
// onset starts where it rises out of the silence (kOnsetRiseDb).
void snap_to_silence(const std::vector<tts::SpokenPhoneme>& phonemes,
                     std::span<const int16_t> audio, unsigned rate, std::vector<double>& starts);

// Where `sound`, the first sound after a pause at the start, starts in `audio` at the first edge
// into sound at or after sample `from`, as snap_to_silence() starts it at that edge (past a hum,
// at a stop's closure, where an onset rises: possibly before `from`); audio.size() when no such
// edge follows. Live, the pause before the first sound is not given out past it (live.h).
size_t next_sound_start(const tts::SpokenPhoneme& sound, std::span<const int16_t> audio,
                        unsigned rate, size_t from);

}  // namespace pfap::align

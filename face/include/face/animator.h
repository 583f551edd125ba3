// SPDX-License-Identifier: LGPL-2.1-or-later
// A face over time: the FAP state of every bookmark, the mouth shapes of the phonemes and the
// expressions, as amplitudes of every FAP at any time (docs/face.md).
#pragma once

#include <cstdint>
#include <string>

#include "face/model.h"
#include "pfap/blendshapes.h"
#include "pfap/fap_state.h"
#include "pfap/markup_event.h"
#include "pfap/phoneme_table.h"

namespace pfap::face {

// A mouth is the library's pfap::VisemeMouth, each viseme's pfap::viseme_mouth(), so that the
// face drawn and the blendshapes sent (pfap/blendshapes.h) have one table.
using MouthShape = pfap::VisemeMouth;

// The mouth of a phoneme whose viseme is unknown, at its widest (mid-phoneme).
MouthShape generic_mouth();

// How long the mouth takes to go from one shape to the next (coarticulation): at most this,
// and at most half the phoneme.
inline constexpr int64_t kMouthEaseNs = 80'000'000;

class Animator {
 public:
  // The alphabet of the phoneme symbols; nullptr when unknown, and then every phoneme opens
  // and closes a generic mouth over its duration.
  void set_alphabet(const pfap::PhonemeAlphabet* alphabet) { alphabet_ = alphabet; }

  // Applies one event at `time_ns` (its PTS): a phoneme's mouth and FAPs, a recovered state's
  // entries (each with its remaining transition), or a complete state (every FAP to 0, then
  // its entries). Times must not go back (an earlier one is taken as the last). Returns false
  // for a phoneme that has no known mouth shape (no alphabet, or a symbol not in it).
  bool apply(const pfap::MarkupEvent& event, int64_t time_ns);

  // Every FAP's amplitude at `time_ns`, at or after the last event: the bookmarked state plus
  // the phoneme's mouth plus the expressions' displacements.
  FapValues faps(int64_t time_ns) const;
  FacePose pose(int64_t time_ns) const { return pose_from_faps(faps(time_ns)); }

  // What a debug overlay shows at `time_ns`: the phoneme sounding (or "pause") and every FAP
  // whose bookmarked amplitude is not 0, as "index:amplitude".
  std::string describe(int64_t time_ns) const;

  // The time of the last event applied, as apply() took it (0 before any).
  int64_t last_ns() const { return last_ns_; }

  // When the last phoneme is over and the last transition has ended.
  int64_t end_ns() const { return end_ns_; }

  // The neutral face with no events, as after construction (the alphabet stays).
  void reset();

 private:
  MouthShape mouth(int64_t time_ns) const;

  // The phoneme last applied: the mouth eases from `from` (the shape it had when the phoneme
  // started) to the phoneme's shape, then after its end back to the closed mouth.
  struct Sound {
    MouthShape from;
    MouthShape to;
    bool generic = false;  // no known viseme: `to` scaled by how far into the phoneme
    int64_t start_ns = 0;
    int64_t end_ns = 0;
    std::string name;
  };

  const pfap::PhonemeAlphabet* alphabet_ = nullptr;
  pfap::FapState state_;
  Sound sound_;
  int64_t last_ns_ = 0;
  int64_t end_ns_ = 0;
};

}  // namespace pfap::face

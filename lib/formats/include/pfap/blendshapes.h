// SPDX-License-Identifier: LGPL-2.1-or-later
// A face's FAP amplitudes and current viseme as Apple ARKit's 52 blendshape weights, and the
// head's pose, which ARKit keeps outside the blendshapes (docs/visemes.md, "Blendshapes").
#pragma once

#include <array>
#include <string_view>

#include "pfap/model.h"
#include "pfap/phoneme_table.h"

namespace pfap {

inline constexpr int kBlendshapeCount = 52;

// ARKit's blendshape locations, in the order of its documentation (ARFaceAnchor
// .BlendShapeLocation). Left and Right are the face's own sides, as MPEG-4's l and r.
enum class Blendshape : uint8_t {
  eyeBlinkLeft,
  eyeLookDownLeft,
  eyeLookInLeft,
  eyeLookOutLeft,
  eyeLookUpLeft,
  eyeSquintLeft,
  eyeWideLeft,
  eyeBlinkRight,
  eyeLookDownRight,
  eyeLookInRight,
  eyeLookOutRight,
  eyeLookUpRight,
  eyeSquintRight,
  eyeWideRight,
  jawForward,
  jawLeft,
  jawRight,
  jawOpen,
  mouthClose,
  mouthFunnel,
  mouthPucker,
  mouthLeft,
  mouthRight,
  mouthSmileLeft,
  mouthSmileRight,
  mouthFrownLeft,
  mouthFrownRight,
  mouthDimpleLeft,
  mouthDimpleRight,
  mouthStretchLeft,
  mouthStretchRight,
  mouthRollLower,
  mouthRollUpper,
  mouthShrugLower,
  mouthShrugUpper,
  mouthPressLeft,
  mouthPressRight,
  mouthLowerDownLeft,
  mouthLowerDownRight,
  mouthUpperUpLeft,
  mouthUpperUpRight,
  browDownLeft,
  browDownRight,
  browInnerUp,
  browOuterUpLeft,
  browOuterUpRight,
  cheekPuff,
  cheekSquintLeft,
  cheekSquintRight,
  noseSneerLeft,
  noseSneerRight,
  tongueOut,
};

// Every name as ARKit spells it, by Blendshape.
const std::array<std::string_view, kBlendshapeCount>& blendshape_names();

using BlendshapeWeights = std::array<double, kBlendshapeCount>;  // each 0..1, by Blendshape
using FapAmplitudes = std::array<double, kFapCount>;             // by FAP index, 0..2 unused

// The head's rotation from FAPs 48..50, in radians: pitch positive looks down, yaw positive
// turns to the face's left, roll positive tilts to the face's right (MPEG-4's directions).
struct HeadPose {
  double pitch = 0;
  double yaw = 0;
  double roll = 0;
};

// A mouth as FAP displacements, the same on both sides, in FAP units: what pfapface's animator
// (pfap::face::Animator) adds for a viseme, and what the blendshapes read (add_mouth says
// which FAPs each field moves).
struct VisemeMouth {
  double open_jaw = 0;
  double lower_t_midlip = 0;
  double raise_b_midlip = 0;
  double stretch_corner = 0;
  double raise_corner = 0;
  double push_lip = 0;

  VisemeMouth blend(const VisemeMouth& to, double u) const;  // u = 0 this, 1 `to`
  bool operator==(const VisemeMouth&) const = default;
};

// The mouth of `viseme` (kNone: closed, neutral).
VisemeMouth viseme_mouth(Viseme viseme);

// Adds `mouth` to the lip FAPs, inner and outer: jaw (FAP 3), upper mid lip down (4; 8, 9 by
// 0.7), lower mid lip up (5; 10, 11 by 0.7), corners out (6, 7, 53, 54), corners up (12, 13,
// 59, 60), lips pushed (16, 17). The points beside the middle of each lip move less.
void add_mouth(FapAmplitudes& faps, const VisemeMouth& mouth);

// The weights for `faps` (amplitudes in FAP units, as FapState gives them) with `mouth` on
// them, while `viseme` sounds (kNone in pauses; it adds what FAPs cannot say, th's tongue):
// each FAP moves the blendshapes of its feature in proportion to its amplitude, the
// expressions 69..74 (intensity 0..63) add their combinations, and each sum is clamped to 0..1.
BlendshapeWeights blendshape_weights(const FapAmplitudes& faps, const VisemeMouth& mouth,
                                     Viseme viseme);
// The same with the viseme's own mouth.
BlendshapeWeights blendshape_weights(const FapAmplitudes& faps, Viseme viseme);

HeadPose head_pose(const FapAmplitudes& faps);

}  // namespace pfap

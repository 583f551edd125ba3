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

// The weights for `faps` (amplitudes in FAP units, as FapState gives them) while `viseme`
// sounds (kNone in pauses): each FAP moves the blendshapes of its feature in proportion to
// its amplitude, the viseme adds its mouth shape, the expressions 69..74 (intensity 0..63)
// add their combinations, and each sum is clamped to 0..1.
BlendshapeWeights blendshape_weights(const FapAmplitudes& faps, Viseme viseme);

HeadPose head_pose(const FapAmplitudes& faps);

}  // namespace pfap

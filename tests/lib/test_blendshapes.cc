// SPDX-License-Identifier: LGPL-2.1-or-later
// FAP states and visemes to ARKit blendshape weights: known states give the expected weights,
// every weight stays in 0..1, and the names are ARKit's.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <string>

#include "pfap/blendshapes.h"

namespace pfap {
namespace {

using B = Blendshape;

double weight(const BlendshapeWeights& w, B b) { return w[static_cast<size_t>(b)]; }

// ARKit's 52 names (ARFaceAnchor.BlendShapeLocation), as its documentation lists them.
TEST(Blendshapes, NamesAreArkitsFiftyTwo) {
  const std::set<std::string> arkit{
      "eyeBlinkLeft",     "eyeLookDownLeft",    "eyeLookInLeft",       "eyeLookOutLeft",
      "eyeLookUpLeft",    "eyeSquintLeft",      "eyeWideLeft",         "eyeBlinkRight",
      "eyeLookDownRight", "eyeLookInRight",     "eyeLookOutRight",     "eyeLookUpRight",
      "eyeSquintRight",   "eyeWideRight",       "jawForward",          "jawLeft",
      "jawRight",         "jawOpen",            "mouthClose",          "mouthFunnel",
      "mouthPucker",      "mouthLeft",          "mouthRight",          "mouthSmileLeft",
      "mouthSmileRight",  "mouthFrownLeft",     "mouthFrownRight",     "mouthDimpleLeft",
      "mouthDimpleRight", "mouthStretchLeft",   "mouthStretchRight",   "mouthRollLower",
      "mouthRollUpper",   "mouthShrugLower",    "mouthShrugUpper",     "mouthPressLeft",
      "mouthPressRight",  "mouthLowerDownLeft", "mouthLowerDownRight", "mouthUpperUpLeft",
      "mouthUpperUpRight", "browDownLeft",      "browDownRight",       "browInnerUp",
      "browOuterUpLeft",  "browOuterUpRight",   "cheekPuff",           "cheekSquintLeft",
      "cheekSquintRight", "noseSneerLeft",      "noseSneerRight",      "tongueOut"};
  ASSERT_EQ(arkit.size(), 52u);
  std::set<std::string> ours;
  for (std::string_view name : blendshape_names()) ours.insert(std::string(name));
  EXPECT_EQ(ours, arkit);
  EXPECT_EQ(blendshape_names()[static_cast<size_t>(B::jawOpen)], "jawOpen");
  EXPECT_EQ(blendshape_names()[static_cast<size_t>(B::tongueOut)], "tongueOut");
  EXPECT_EQ(blendshape_names()[static_cast<size_t>(B::mouthSmileRight)], "mouthSmileRight");
}

TEST(Blendshapes, NeutralFaceIsAllZero) {
  for (double w : blendshape_weights(FapAmplitudes{}, Viseme::kNone)) EXPECT_EQ(w, 0);
}

TEST(Blendshapes, JawOpensWithFap3) {
  FapAmplitudes f{};
  f[3] = 256;
  BlendshapeWeights w = blendshape_weights(f, Viseme::kNone);
  EXPECT_DOUBLE_EQ(weight(w, B::jawOpen), 0.5);
  f[3] = 512;
  EXPECT_DOUBLE_EQ(weight(blendshape_weights(f, Viseme::kNone), B::jawOpen), 1.0);
  f[3] = -300;  // a jaw cannot close past closed
  EXPECT_EQ(weight(blendshape_weights(f, Viseme::kNone), B::jawOpen), 0);
}

TEST(Blendshapes, JoySmiles) {
  FapAmplitudes f{};
  f[69] = 63;  // joy at full intensity
  const BlendshapeWeights w = blendshape_weights(f, Viseme::kNone);
  EXPECT_GE(weight(w, B::mouthSmileLeft), 0.8);
  EXPECT_GE(weight(w, B::mouthSmileRight), 0.8);
  EXPECT_GT(weight(w, B::cheekSquintLeft), 0.5);
  EXPECT_EQ(weight(w, B::mouthFrownLeft), 0);
  f[69] = 0;
  f[74] = 63;  // surprise
  const BlendshapeWeights s = blendshape_weights(f, Viseme::kNone);
  EXPECT_EQ(weight(s, B::mouthSmileLeft), 0);
  EXPECT_EQ(weight(s, B::browInnerUp), 1);
  EXPECT_EQ(weight(s, B::eyeWideLeft), 1);
  // The corner FAPs smile on their own side only.
  FapAmplitudes corners{};
  corners[12] = 130;
  const BlendshapeWeights c = blendshape_weights(corners, Viseme::kNone);
  EXPECT_DOUBLE_EQ(weight(c, B::mouthSmileLeft), 1);
  EXPECT_EQ(weight(c, B::mouthSmileRight), 0);
  corners[13] = -55;
  EXPECT_DOUBLE_EQ(weight(blendshape_weights(corners, Viseme::kNone), B::mouthFrownRight), 0.5);
}

TEST(Blendshapes, EyelidFapsBlink) {
  FapAmplitudes f{};
  f[19] = 1024;  // the left upper lid down by its whole opening
  BlendshapeWeights w = blendshape_weights(f, Viseme::kNone);
  EXPECT_DOUBLE_EQ(weight(w, B::eyeBlinkLeft), 1);
  EXPECT_EQ(weight(w, B::eyeBlinkRight), 0);
  f[20] = 512;
  w = blendshape_weights(f, Viseme::kNone);
  EXPECT_DOUBLE_EQ(weight(w, B::eyeBlinkRight), 0.5);
  f[19] = -160;  // raised: wide open
  w = blendshape_weights(f, Viseme::kNone);
  EXPECT_EQ(weight(w, B::eyeBlinkLeft), 0);
  EXPECT_DOUBLE_EQ(weight(w, B::eyeWideLeft), 0.5);
  f[21] = 150;  // lower lid up
  EXPECT_DOUBLE_EQ(weight(blendshape_weights(f, Viseme::kNone), B::eyeSquintLeft), 0.5);
}

TEST(Blendshapes, GazeBrowsCheeksAndHead) {
  FapAmplitudes f{};
  f[23] = 52360;   // both eyes 30 degrees to the face's left
  f[24] = 52360;
  f[25] = -26180;  // left eye 15 degrees up
  f[31] = 140;     // left inner brow up
  f[32] = 140;
  f[35] = 280;     // left outer brow up
  f[38] = 320;     // right brow squeezed in
  f[39] = 200;     // cheeks puffed
  f[40] = 200;
  f[42] = 70;      // right cheek lifted
  f[48] = 10000;   // head pitch 0.1 rad
  f[50] = -5000;
  const BlendshapeWeights w = blendshape_weights(f, Viseme::kNone);
  EXPECT_DOUBLE_EQ(weight(w, B::eyeLookOutLeft), 1);
  EXPECT_DOUBLE_EQ(weight(w, B::eyeLookInRight), 1);
  EXPECT_EQ(weight(w, B::eyeLookInLeft), 0);
  EXPECT_DOUBLE_EQ(weight(w, B::eyeLookUpLeft), 0.5);
  EXPECT_DOUBLE_EQ(weight(w, B::browInnerUp), 0.5);
  EXPECT_DOUBLE_EQ(weight(w, B::browOuterUpLeft), 1);
  EXPECT_EQ(weight(w, B::browOuterUpRight), 0);
  EXPECT_DOUBLE_EQ(weight(w, B::browDownRight), 1);
  EXPECT_DOUBLE_EQ(weight(w, B::cheekPuff), 1);
  EXPECT_DOUBLE_EQ(weight(w, B::cheekSquintRight), 0.5);
  const HeadPose head = head_pose(f);
  EXPECT_DOUBLE_EQ(head.pitch, 0.1);
  EXPECT_DOUBLE_EQ(head.yaw, 0);
  EXPECT_DOUBLE_EQ(head.roll, -0.05);
}

TEST(Blendshapes, VisemesShapeTheMouth) {
  const FapAmplitudes none{};
  const auto w = [&](Viseme v, B b) { return weight(blendshape_weights(none, v), b); };
  EXPECT_GT(w(Viseme::kA, B::jawOpen), 0.8);
  EXPECT_GT(w(Viseme::kA, B::jawOpen), w(Viseme::kE, B::jawOpen));
  EXPECT_GT(w(Viseme::kE, B::jawOpen), w(Viseme::kI, B::jawOpen));
  EXPECT_EQ(w(Viseme::kPBM, B::jawOpen), 0);
  EXPECT_GT(w(Viseme::kPBM, B::mouthPressLeft), 0.4);
  EXPECT_GT(w(Viseme::kU, B::mouthPucker), 0.5);
  EXPECT_GT(w(Viseme::kQ, B::mouthFunnel), 0.1);
  EXPECT_GT(w(Viseme::kI, B::mouthStretchLeft), 0.9);
  EXPECT_GT(w(Viseme::kFV, B::mouthShrugLower), 0.4);
  EXPECT_GT(w(Viseme::kTH, B::tongueOut), 0.2);
  EXPECT_EQ(w(Viseme::kA, B::tongueOut), 0);
}

TEST(Blendshapes, EveryWeightStaysWithinZeroAndOne) {
  std::mt19937 random(19);
  std::uniform_int_distribution<int32_t> amplitude(-kMaxAmplitude, kMaxAmplitude);
  std::uniform_int_distribution<int> small(-600, 600);
  for (int round = 0; round < 2000; ++round) {
    FapAmplitudes f{};
    for (int i = kMinFapIndex; i <= kMaxFapIndex; ++i) {
      f[i] = round % 2 == 0 ? amplitude(random) : small(random);
    }
    const Viseme viseme = static_cast<Viseme>(round % 15);
    for (double w : blendshape_weights(f, viseme)) {
      ASSERT_GE(w, 0);
      ASSERT_LE(w, 1);
    }
  }
}

}  // namespace
}  // namespace pfap

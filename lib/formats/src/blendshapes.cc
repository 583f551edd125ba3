// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap/blendshapes.h"

#include <algorithm>
#include <initializer_list>
#include <utility>

namespace pfap {
namespace {

using B = Blendshape;

// FAP amplitudes (in their own units) that give a weight of 1, taken from the face pfapface
// draws (face/src/model.cc, animator.cc) so that a weight of 1 is the largest move it makes.
constexpr double kJawFull = 512;         // FAP 3, MNS: pfapface's widest viseme (A) opens 430
constexpr double kJawMoveFull = 200;     // 14 (MNS), 15 (MW)
constexpr double kLipFull = 200;         // 4, 5, 8..11, 18, 51, 52, 55..58 (MNS)
constexpr double kPressFull = 60;        // 4 and 5 both in: anger presses by 30..40
constexpr double kStretchFull = 200;     // 6, 7, 53, 54 (MW): viseme I spreads 200
constexpr double kCornerUpFull = 130;    // 12, 13, 59, 60 (MNS): joy raises 130
constexpr double kCornerDownFull = 110;  // sadness lowers 110
constexpr double kPushFull = 240;        // 16, 17 (MNS): viseme U pushes 240
constexpr double kLidFull = 1024;        // 19, 20 (IRISD): the neutral opening is one IRISD
constexpr double kLidRaiseFull = 320;    // -19, -20: surprise opens 320
constexpr double kLowerLidFull = 300;    // 21, 22 (IRISD): anger 200, joy 150
constexpr double kGazeFull = 52360;      // 23..26 (1e-5 rad): 30 degrees
constexpr double kBrowUpFull = 280;      // 31..36 (ENS): surprise 280
constexpr double kBrowDownFull = 170;    // anger -170
constexpr double kSqueezeFull = 320;     // 37, 38 (ES): anger 160 gives half
constexpr double kPuffFull = 200;        // 39, 40 (ES)
constexpr double kCheekLiftFull = 140;   // 41, 42 (ENS): joy 140
constexpr double kTongueFull = 512;      // 45 thrust_tongue_tip (MW)
constexpr double kNoseFull = 200;        // 61..63 (ENS)
constexpr double kAngleUnit = 1e-5;      // rad, FAPs 48..50

// Each viseme's mouth, as face/src/animator.cc's viseme_shape (tests/face checks the two
// agree): {open_jaw, lower_t_midlip, raise_b_midlip, stretch_corner, raise_corner, push_lip}.
constexpr std::array<VisemeMouth, 15> kVisemeMouths{{
    {0, 0, 0, 0, 0, 0},          // none
    {0, 30, 30, 0, 0, 40},       // p b m
    {70, -40, 110, 0, 0, 0},     // f v
    {150, -20, 0, 20, 0, 0},     // th
    {130, 0, 0, 40, 0, 0},       // t d
    {190, 0, 0, 30, 0, 0},       // k g
    {110, 0, 0, -160, 0, 180},   // ch
    {50, -30, 0, 90, 20, 0},     // s z
    {160, 0, 0, 30, 0, 0},       // n l
    {120, 0, 0, -110, 0, 120},   // r
    {430, -20, 0, 40, 0, 0},     // A
    {290, -20, 0, 130, 20, 0},   // e
    {170, -20, 0, 200, 50, 0},   // I
    {380, 0, 0, -150, 0, 120},   // Q
    {120, 0, 0, -230, 0, 240},   // U
}};

// What FAPs cannot say about a viseme: the tongue between the teeth of th.
constexpr double kThTongue = 0.3;

// The six MPEG-4 expressions (FAPs 69..74) as blendshape combinations at full intensity. A
// judgment, after the FAP displacements pfapface gives them (face/src/model.cc) and FACS.
using Combination = std::initializer_list<std::pair<B, double>>;
const std::array<Combination, 6> kExpressions{{
    // joy: smile, cheeks up, lower lids up
    {{B::mouthSmileLeft, 0.8}, {B::mouthSmileRight, 0.8}, {B::cheekSquintLeft, 0.6},
     {B::cheekSquintRight, 0.6}, {B::eyeSquintLeft, 0.4}, {B::eyeSquintRight, 0.4},
     {B::mouthDimpleLeft, 0.2}, {B::mouthDimpleRight, 0.2}},
    // sadness: corners down, inner brows up, lids drooping
    {{B::mouthFrownLeft, 0.7}, {B::mouthFrownRight, 0.7}, {B::browInnerUp, 0.6},
     {B::browDownLeft, 0.2}, {B::browDownRight, 0.2}, {B::eyeBlinkLeft, 0.2},
     {B::eyeBlinkRight, 0.2}, {B::mouthShrugLower, 0.3}},
    // anger: brows down and together, eyes narrowed, lips pressed
    {{B::browDownLeft, 0.8}, {B::browDownRight, 0.8}, {B::eyeSquintLeft, 0.6},
     {B::eyeSquintRight, 0.6}, {B::mouthPressLeft, 0.5}, {B::mouthPressRight, 0.5},
     {B::noseSneerLeft, 0.3}, {B::noseSneerRight, 0.3}, {B::mouthFrownLeft, 0.3},
     {B::mouthFrownRight, 0.3}},
    // fear: brows up and together, eyes wide, mouth stretched and a little open
    {{B::browInnerUp, 0.8}, {B::browOuterUpLeft, 0.3}, {B::browOuterUpRight, 0.3},
     {B::eyeWideLeft, 0.8}, {B::eyeWideRight, 0.8}, {B::mouthStretchLeft, 0.5},
     {B::mouthStretchRight, 0.5}, {B::jawOpen, 0.3}},
    // disgust: nose wrinkled, upper lip up, corners down, brows lowered, cheeks up
    {{B::noseSneerLeft, 0.8}, {B::noseSneerRight, 0.8}, {B::mouthUpperUpLeft, 0.5},
     {B::mouthUpperUpRight, 0.5}, {B::mouthFrownLeft, 0.5}, {B::mouthFrownRight, 0.5},
     {B::browDownLeft, 0.4}, {B::browDownRight, 0.4}, {B::cheekSquintLeft, 0.4},
     {B::cheekSquintRight, 0.4}},
    // surprise: brows high, eyes wide, jaw dropped
    {{B::browInnerUp, 1.0}, {B::browOuterUpLeft, 1.0}, {B::browOuterUpRight, 1.0},
     {B::eyeWideLeft, 1.0}, {B::eyeWideRight, 1.0}, {B::jawOpen, 0.6}},
}};

constexpr std::array<std::string_view, kBlendshapeCount> kNames{
    "eyeBlinkLeft",        "eyeLookDownLeft",   "eyeLookInLeft",      "eyeLookOutLeft",
    "eyeLookUpLeft",       "eyeSquintLeft",     "eyeWideLeft",        "eyeBlinkRight",
    "eyeLookDownRight",    "eyeLookInRight",    "eyeLookOutRight",    "eyeLookUpRight",
    "eyeSquintRight",      "eyeWideRight",      "jawForward",         "jawLeft",
    "jawRight",            "jawOpen",           "mouthClose",         "mouthFunnel",
    "mouthPucker",         "mouthLeft",         "mouthRight",         "mouthSmileLeft",
    "mouthSmileRight",     "mouthFrownLeft",    "mouthFrownRight",    "mouthDimpleLeft",
    "mouthDimpleRight",    "mouthStretchLeft",  "mouthStretchRight",  "mouthRollLower",
    "mouthRollUpper",      "mouthShrugLower",   "mouthShrugUpper",    "mouthPressLeft",
    "mouthPressRight",     "mouthLowerDownLeft", "mouthLowerDownRight", "mouthUpperUpLeft",
    "mouthUpperUpRight",   "browDownLeft",      "browDownRight",      "browInnerUp",
    "browOuterUpLeft",     "browOuterUpRight",  "cheekPuff",          "cheekSquintLeft",
    "cheekSquintRight",    "noseSneerLeft",     "noseSneerRight",     "tongueOut",
};

// Right is always the shape after its Left, which the per-side rules below rely on.
static_assert(int(B::mouthStretchRight) == int(B::mouthStretchLeft) + 1 &&
              int(B::mouthSmileRight) == int(B::mouthSmileLeft) + 1 &&
              int(B::mouthFrownRight) == int(B::mouthFrownLeft) + 1 &&
              int(B::mouthUpperUpRight) == int(B::mouthUpperUpLeft) + 1 &&
              int(B::mouthLowerDownRight) == int(B::mouthLowerDownLeft) + 1 &&
              int(B::browOuterUpRight) == int(B::browOuterUpLeft) + 1 &&
              int(B::browDownRight) == int(B::browDownLeft) + 1 &&
              int(B::cheekSquintRight) == int(B::cheekSquintLeft) + 1 &&
              int(B::noseSneerRight) == int(B::noseSneerLeft) + 1);

double pos(double x) { return std::max(0.0, x); }
double neg(double x) { return std::max(0.0, -x); }

}  // namespace

const std::array<std::string_view, kBlendshapeCount>& blendshape_names() { return kNames; }

VisemeMouth VisemeMouth::blend(const VisemeMouth& to, double u) const {
  auto mix = [u](double a, double b) { return a + (b - a) * u; };
  return {mix(open_jaw, to.open_jaw),           mix(lower_t_midlip, to.lower_t_midlip),
          mix(raise_b_midlip, to.raise_b_midlip), mix(stretch_corner, to.stretch_corner),
          mix(raise_corner, to.raise_corner),   mix(push_lip, to.push_lip)};
}

VisemeMouth viseme_mouth(Viseme viseme) {
  return kVisemeMouths.at(static_cast<size_t>(viseme));
}

void add_mouth(FapAmplitudes& f, const VisemeMouth& m) {
  f[3] += m.open_jaw;
  f[4] += m.lower_t_midlip;
  f[8] += 0.7 * m.lower_t_midlip;
  f[9] += 0.7 * m.lower_t_midlip;
  f[5] += m.raise_b_midlip;
  f[10] += 0.7 * m.raise_b_midlip;
  f[11] += 0.7 * m.raise_b_midlip;
  for (int i : {6, 7, 53, 54}) f[i] += m.stretch_corner;
  for (int i : {12, 13, 59, 60}) f[i] += m.raise_corner;
  f[16] += m.push_lip;
  f[17] += m.push_lip;
}

BlendshapeWeights blendshape_weights(const FapAmplitudes& faps, Viseme viseme) {
  return blendshape_weights(faps, viseme_mouth(viseme), viseme);
}

BlendshapeWeights blendshape_weights(const FapAmplitudes& faps, const VisemeMouth& m,
                                     Viseme viseme) {
  // The mouth added to the FAPs as pfapface adds it (Animator::faps).
  FapAmplitudes f = faps;
  add_mouth(f, m);

  BlendshapeWeights w{};
  auto set = [&w](B b, double value) { w[static_cast<size_t>(b)] = value; };

  // Jaw: 3 down, 14 forward, 15 to the face's right.
  const double jaw = pos(f[3]) / kJawFull;
  set(B::jawOpen, jaw);
  set(B::jawForward, pos(f[14]) / kJawMoveFull);
  set(B::jawRight, pos(f[15]) / kJawMoveFull);
  set(B::jawLeft, neg(f[15]) / kJawMoveFull);

  // Lips. Mid lips: 4 (upper) down, 5 (lower) up; both in press the lips together, which
  // with the jaw open is ARKit's mouthClose. The outer contour (51, 52, 55..58) moves with
  // the inner one; the larger of the two counts.
  const double press = std::min(pos(f[4]), pos(f[5]));
  set(B::mouthClose, std::min(pos(f[3]), pos(f[4]) + pos(f[5])) / kJawFull);
  set(B::mouthPressLeft, press / kPressFull);
  set(B::mouthPressRight, press / kPressFull);
  set(B::mouthShrugUpper, pos(std::max(f[4], f[51]) - press) / kLipFull);
  set(B::mouthShrugLower, (pos(std::max(f[5], f[52]) - press) + pos(f[18])) / kLipFull);
  // Pushed lips pucker, or with the jaw open funnel; corners coming in pucker too.
  const double push = pos((f[16] + f[17]) / 2) / kPushFull;
  const double open = std::min(1.0, jaw);
  const double corners_in = neg((f[6] + f[7]) / 2) / kStretchFull;
  set(B::mouthPucker, push * (1 - open) + 0.5 * corners_in);
  set(B::mouthFunnel, push * open);
  set(B::mouthRollLower, neg(f[16]) / kPushFull);
  set(B::mouthRollUpper, neg(f[17]) / kPushFull);
  // The whole mouth to one side: one corner out, the other in.
  set(B::mouthLeft, std::min(pos(f[6]), neg(f[7])) / kStretchFull);
  set(B::mouthRight, std::min(neg(f[6]), pos(f[7])) / kStretchFull);
  for (int side = 0; side < 2; ++side) {
    auto side_set = [&](B left, double value) {
      w[static_cast<size_t>(left) + side] = value;  // each Right follows its Left
    };
    side_set(B::mouthStretchLeft, pos(std::max(f[6 + side], f[53 + side])) / kStretchFull);
    side_set(B::mouthSmileLeft, pos(std::max(f[12 + side], f[59 + side])) / kCornerUpFull);
    side_set(B::mouthFrownLeft, neg(std::min(f[12 + side], f[59 + side])) / kCornerDownFull);
    side_set(B::mouthUpperUpLeft,
             neg(std::min({f[8 + side], f[55 + side], f[4], f[51]})) / kLipFull);
    side_set(B::mouthLowerDownLeft,
             neg(std::min({f[10 + side], f[57 + side], f[5], f[52]})) / kLipFull);
    // Brows: 31 inner, 33 middle, 35 outer up; 37 squeezed together, which lowers them.
    side_set(B::browOuterUpLeft, pos(std::max(f[33 + side], f[35 + side])) / kBrowUpFull);
    side_set(B::browDownLeft, neg(std::min(f[31 + side], f[33 + side])) / kBrowDownFull +
                                  pos(f[37 + side]) / kSqueezeFull);
    side_set(B::cheekSquintLeft, pos(f[41 + side]) / kCheekLiftFull);
    side_set(B::noseSneerLeft, (pos(f[63]) + pos(f[61 + side])) / kNoseFull);
  }
  set(B::browInnerUp, pos((f[31] + f[32]) / 2) / kBrowUpFull);
  set(B::cheekPuff, pos((f[39] + f[40]) / 2) / kPuffFull);
  set(B::tongueOut, pos(f[45]) / kTongueFull + (viseme == Viseme::kTH ? kThTongue : 0));
  // No FAP dimples the mouth; joy does (below).

  // Eyes. ARKit's sides are the face's own, and so are MPEG-4's (l = the face's left).
  // Upper lids: 19, 20 down (blink) or up (wide); lower lids 21, 22 up (squint).
  set(B::eyeBlinkLeft, pos(f[19]) / kLidFull);
  set(B::eyeBlinkRight, pos(f[20]) / kLidFull);
  set(B::eyeWideLeft, neg(f[19]) / kLidRaiseFull);
  set(B::eyeWideRight, neg(f[20]) / kLidRaiseFull);
  set(B::eyeSquintLeft, pos(f[21]) / kLowerLidFull);
  set(B::eyeSquintRight, pos(f[22]) / kLowerLidFull);
  // Gaze: yaw 23, 24 positive looks to the face's left, which is out for the left eye and in
  // for the right; pitch 25, 26 positive looks down.
  set(B::eyeLookOutLeft, pos(f[23]) / kGazeFull);
  set(B::eyeLookInLeft, neg(f[23]) / kGazeFull);
  set(B::eyeLookInRight, pos(f[24]) / kGazeFull);
  set(B::eyeLookOutRight, neg(f[24]) / kGazeFull);
  set(B::eyeLookDownLeft, pos(f[25]) / kGazeFull);
  set(B::eyeLookUpLeft, neg(f[25]) / kGazeFull);
  set(B::eyeLookDownRight, pos(f[26]) / kGazeFull);
  set(B::eyeLookUpRight, neg(f[26]) / kGazeFull);

  // Expressions: FAP 68 + e carries intensity 0..63.
  for (size_t e = 0; e < kExpressions.size(); ++e) {
    const double weight = expression_weight(f[kFirstExpressionIndex + e]);
    if (weight == 0) continue;
    for (const auto& [shape, amount] : kExpressions[e]) {
      w[static_cast<size_t>(shape)] += weight * amount;
    }
  }
  for (double& weight : w) weight = std::clamp(weight, 0.0, 1.0);
  return w;
}

HeadPose head_pose(const FapAmplitudes& faps) {
  return {faps[48] * kAngleUnit, faps[49] * kAngleUnit, faps[50] * kAngleUnit};
}

}  // namespace pfap

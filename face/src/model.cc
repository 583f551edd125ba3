// SPDX-License-Identifier: LGPL-2.1-or-later
#include "face/model.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace pfap::face {
namespace {

// The neutral face, in face units (see model.h for the axes).
constexpr double kHeadRx = 0.36;  // half width
constexpr double kHeadRy = 0.5;   // half height
constexpr double kHeadRz = 0.36;  // depth of the front half: equal to kHeadRx, so that a
                                  // turned head keeps its silhouette
constexpr double kEyeY = -0.06;
constexpr double kEyeHalfWidth = 0.065;
constexpr double kEyeballRadius = 0.06;
constexpr double kBrowY = kEyeY - 0.085;
constexpr double kNoseY = kEyeY + kUnits.ens;
constexpr double kNoseDepth = 0.07;  // in front of the head's surface
constexpr double kMouthY = kNoseY + kUnits.mns;
constexpr double kCheekY = 0.15;
constexpr double kCheekX = 0.21;
constexpr double kMinLipThickness = 0.008;

// One FAP unit of each kind, in face units.
constexpr double kMns = kUnits.mns / 1024;
constexpr double kMw = kUnits.mw / 1024;
constexpr double kEns = kUnits.ens / 1024;
constexpr double kEs = kUnits.es / 1024;
constexpr double kIrisd = kUnits.irisd / 1024;

// The lip contours at rest (contour order as LipContour): the inner one a closed line, the
// outer one with a bow on the upper lip.
constexpr double kHalfMouth = kUnits.mw / 2;
constexpr LipContour kNeutralInner{{{-kHalfMouth, kMouthY},
                                    {-kHalfMouth / 2, kMouthY},
                                    {0, kMouthY},
                                    {kHalfMouth / 2, kMouthY},
                                    {kHalfMouth, kMouthY},
                                    {kHalfMouth / 2, kMouthY},
                                    {0, kMouthY},
                                    {-kHalfMouth / 2, kMouthY}}};
constexpr LipContour kNeutralOuter{{{-kHalfMouth - 0.012, kMouthY},
                                    {-kHalfMouth / 2, kMouthY - 0.04},
                                    {0, kMouthY - 0.032},
                                    {kHalfMouth / 2, kMouthY - 0.04},
                                    {kHalfMouth + 0.012, kMouthY},
                                    {kHalfMouth / 2, kMouthY + 0.038},
                                    {0, kMouthY + 0.045},
                                    {-kHalfMouth / 2, kMouthY + 0.038}}};

// FAP displacements of each expression at full intensity, in FAP units.
struct Displacement {
  int fap;
  double amount;
};
const std::array<std::vector<Displacement>, 6> kExpressions{{
    // joy: corners up and out, cheeks lifted, lower lids up
    {{12, 130},
     {13, 130},
     {59, 130},
     {60, 130},
     {6, 80},
     {7, 80},
     {53, 80},
     {54, 80},
     {41, 140},
     {42, 140},
     {21, 150},
     {22, 150}},
    // sadness: corners down, inner brows up, outer brows down, upper lids drooping
    {{12, -110},
     {13, -110},
     {59, -110},
     {60, -110},
     {31, 160},
     {32, 160},
     {35, -80},
     {36, -80},
     {19, 250},
     {20, 250},
     {4, 20},
     {5, 20}},
    // anger: brows down and together, eyes narrowed, lips pressed
    {{31, -170},
     {32, -170},
     {33, -110},
     {34, -110},
     {37, 160},
     {38, 160},
     {21, 200},
     {22, 200},
     {4, 30},
     {5, 40},
     {12, -40},
     {13, -40}},
    // fear: brows up and together, eyes wide, mouth open and stretched
    {{31, 220},
     {32, 220},
     {33, 160},
     {34, 160},
     {37, 90},
     {38, 90},
     {19, -300},
     {20, -300},
     {3, 160},
     {6, 110},
     {7, 110},
     {12, -40},
     {13, -40}},
    // disgust: upper lip raised, corners down, brows lowered, cheeks lifted
    {{4, -70},
     {51, -90},
     {12, -90},
     {13, -90},
     {59, -90},
     {60, -90},
     {33, -90},
     {34, -90},
     {41, 130},
     {42, 130},
     {21, 200},
     {22, 200}},
    // surprise: brows high, eyes wide, jaw dropped
    {{31, 280},
     {32, 280},
     {33, 300},
     {34, 300},
     {35, 260},
     {36, 260},
     {19, -320},
     {20, -320},
     {21, -100},
     {22, -100},
     {3, 380},
     {6, -60},
     {7, -60}},
}};

// `p` turned by `angle` towards -x at the top: clockwise on the viewer's side for a negative
// angle (the y axis points down).
Point rotated(Point p, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {p.x * c + p.y * s, -p.x * s + p.y * c};
}

// Projects a feature on the head's front surface (plus `depth` in front of it) after the
// head's pitch, yaw and roll, orthographically.
class Head {
 public:
  Head(double pitch, double yaw, double roll) : pitch_(pitch), yaw_(yaw), roll_(roll) {}

  Point project(Point p, double depth = 0) const {
    const double e = 1 - (p.x / kHeadRx) * (p.x / kHeadRx) - (p.y / kHeadRy) * (p.y / kHeadRy);
    const double z = kHeadRz * std::sqrt(std::max(0.0, e)) + depth;
    // Pitch (positive: the face looks down) turns the front downwards.
    const double y1 = p.y * std::cos(pitch_) + z * std::sin(pitch_);
    const double z1 = -p.y * std::sin(pitch_) + z * std::cos(pitch_);
    // Yaw (positive: the face turns to its left, the viewer's right).
    const double x2 = p.x * std::cos(yaw_) + z1 * std::sin(yaw_);
    return rotated({x2, y1}, roll_);
  }
  // The head turns around the neck, which shifts it a little sideways with yaw.
  double neck_shift() const { return 0.25 * kHeadRx * std::sin(yaw_); }
  double roll() const { return roll_; }
  double yaw() const { return yaw_; }

 private:
  double pitch_, yaw_, roll_;
};

// The jaw, in face units: FAP 3 down, 14 forward, 15 to the face's right (-x).
struct Jaw {
  double open;  // never up
  double shift;
  double thrust;
};

Jaw jaw_from_faps(const FapValues& f) {
  return {.open = std::max(0.0, f[3] * kMns), .shift = -f[15] * kMw, .thrust = f[14] * kMns};
}

// Inner lips. Upper points move down with 4, 8, 9; lower points with the jaw and up with 5,
// 10, 11; corners out with 6, 7 and up with 12, 13, and half with the jaw.
LipContour inner_lip_contour(const FapValues& f, const Jaw& jaw) {
  LipContour inner = kNeutralInner;
  const double stretch_left = f[6] * kMw, stretch_right = f[7] * kMw;
  // Pushed lips pucker: the corners come in.
  const double pucker = 0.3 * (f[16] + f[17]) / 2 * kMns;
  inner[0].x += -stretch_right + pucker + jaw.shift / 2;
  inner[0].y += jaw.open / 2 - f[13] * kMns;
  inner[4].x += stretch_left - pucker + jaw.shift / 2;
  inner[4].y += jaw.open / 2 - f[12] * kMns;
  inner[1].x += (-stretch_right + pucker) / 2;
  inner[3].x += (stretch_left - pucker) / 2;
  inner[5].x += (stretch_left - pucker) / 2 + jaw.shift;
  inner[7].x += (-stretch_right + pucker) / 2 + jaw.shift;
  inner[6].x += jaw.shift;
  inner[1].y += f[9] * kMns;
  inner[2].y += f[4] * kMns;
  inner[3].y += f[8] * kMns;
  inner[5].y += jaw.open - f[10] * kMns;
  inner[6].y += jaw.open - f[5] * kMns;
  inner[7].y += jaw.open - f[11] * kMns;
  // A lower lip raised past the upper one presses against it.
  for (int i = 5; i <= 7; ++i) inner[i].y = std::max(inner[i].y, inner[8 - i].y);
  return inner;
}

// Outer lips: where the inner ones went, then their own FAPs 51..60, lips thickened by
// pushing (16, 17) and the jaw's thrust (14), the lower lip lifted by the chin (18).
LipContour outer_lip_contour(const FapValues& f, const Jaw& jaw, const LipContour& inner) {
  LipContour outer = kNeutralOuter;
  for (size_t i = 0; i < outer.size(); ++i) {
    outer[i].x += inner[i].x - kNeutralInner[i].x;
    outer[i].y += inner[i].y - kNeutralInner[i].y;
  }
  outer[0].x -= f[54] * kMw;
  outer[0].y -= f[60] * kMns;
  outer[4].x += f[53] * kMw;
  outer[4].y -= f[59] * kMns;
  outer[1].y += f[56] * kMns - 0.25 * f[17] * kMns;
  outer[2].y += f[51] * kMns - 0.25 * f[17] * kMns;
  outer[3].y += f[55] * kMns - 0.25 * f[17] * kMns;
  const double lower_out = 0.25 * f[16] * kMns + 0.3 * jaw.thrust - 0.5 * f[18] * kMns;
  outer[5].y += -f[57] * kMns + lower_out;
  outer[6].y += -f[52] * kMns + lower_out;
  outer[7].y += -f[58] * kMns + lower_out;
  for (int i = 1; i <= 3; ++i) outer[i].y = std::min(outer[i].y, inner[i].y - kMinLipThickness);
  for (int i = 5; i <= 7; ++i) outer[i].y = std::max(outer[i].y, inner[i].y + kMinLipThickness);
  return outer;
}

// An eye: the upper lid down with 19, 20, the lower lid up with 21, 22 and with the cheek's
// lift (41, 42); the eyeball turns with 23..26.
Eye eye_from_faps(const FapValues& f, int side, double cheek_lift, const Head& head) {
  const double x = side == kLeft ? kUnits.es / 2 : -kUnits.es / 2;
  Eye eye;
  eye.center = head.project({x, kEyeY});
  // Foreshortened as the surface under it turns away.
  const double facing = std::atan2(x, kHeadRz);
  eye.half_width = kEyeHalfWidth * std::max(0.2, std::cos(facing + head.yaw()) / std::cos(facing));
  double upper = -kUnits.irisd / 2 + f[19 + side] * kIrisd;
  double lower = kUnits.irisd / 2 - f[21 + side] * kIrisd - 0.3 * cheek_lift;
  upper = std::max(upper, -kUnits.irisd);
  lower = std::min(lower, kUnits.irisd);
  if (lower < upper) upper = lower = (upper + lower) / 2;
  eye.upper_lid = upper;
  eye.lower_lid = lower;
  eye.pupil = {kEyeballRadius * std::sin(f[23 + side] * kAngleUnit),
               kEyeballRadius * std::sin(f[25 + side] * kAngleUnit)};
  eye.iris_radius = kUnits.irisd / 2;
  return eye;
}

// A brow: 31..36 up, 37, 38 towards the middle.
Brow brow_from_faps(const FapValues& f, int side, const Head& head) {
  const double sign = side == kLeft ? 1 : -1;
  const double squeeze = f[37 + side] * kEs;
  const std::array<Point, 3> brow{{{sign * 0.08, kBrowY - f[31 + side] * kEns},
                                   {sign * 0.16, kBrowY - 0.012 - f[33 + side] * kEns},
                                   {sign * 0.235, kBrowY + 0.004 - f[35 + side] * kEns}}};
  Brow projected;
  for (size_t i = 0; i < brow.size(); ++i) {
    projected.points[i] = head.project({brow[i].x - sign * squeeze, brow[i].y});
  }
  return projected;
}

// The silhouette: an ellipse, with the cheeks bulging, the jaw's lower part moved, and the
// whole shifted with the neck.
std::array<Point, 12> silhouette(const FapValues& f, const Jaw& jaw,
                                 const std::array<double, 2>& cheek_puff, const Head& head) {
  std::array<Point, 12> outline;
  for (size_t k = 0; k < outline.size(); ++k) {
    const double angle = (-90.0 + 30.0 * static_cast<double>(k)) * std::numbers::pi / 180;
    Point p{kHeadRx * std::cos(angle), kHeadRy * std::sin(angle)};
    if (k == 3 || k == 4) p.x += (k == 4 ? 1.0 : 0.5) * cheek_puff[kLeft];
    if (k == 8 || k == 9) p.x -= (k == 8 ? 1.0 : 0.5) * cheek_puff[kRight];
    if (k >= 4 && k <= 8) {
      const double share = (k == 4 || k == 8) ? 0.5 : 1.0;
      p.y += share * jaw.open;
      p.x += share * jaw.shift;
    }
    if (k == 6) p.y -= 0.5 * f[18] * kMns;
    outline[k] = rotated(p, head.roll());
  }
  const double shift = head.neck_shift();
  for (Point& p : outline) p.x += shift;
  return outline;
}

}  // namespace

double expression_weight(const FapValues& faps, int e) {
  return pfap::expression_weight(faps[pfap::kFirstExpressionIndex - 1 + e]);
}

void add_expressions(FapValues& faps) {
  std::array<double, 6> weights{};
  for (int e = 1; e <= 6; ++e) weights[e - 1] = expression_weight(faps, e);
  for (size_t e = 0; e < kExpressions.size(); ++e) {
    for (const Displacement& d : kExpressions[e]) faps[d.fap] += weights[e] * d.amount;
  }
}

FacePose pose_from_faps(const FapValues& f) {
  FacePose pose;
  // Roll (positive: the head tilts to its right, the viewer's left) turns the picture.
  const Head head(f[48] * kAngleUnit, f[49] * kAngleUnit, f[50] * kAngleUnit);
  pose.roll = head.roll();
  for (int e = 1; e <= 6; ++e) pose.expressions[e - 1] = expression_weight(f, e);
  const Jaw jaw = jaw_from_faps(f);
  pose.jaw_open = jaw.open;

  const LipContour inner = inner_lip_contour(f, jaw);
  const LipContour outer = outer_lip_contour(f, jaw, inner);
  const double lip_depth = 0.02 + 0.5 * (f[16] + f[17]) / 2 * kMns;
  for (size_t i = 0; i < outer.size(); ++i) {
    const double depth = i >= 5 ? lip_depth + jaw.thrust : lip_depth;
    pose.outer_lips[i] = head.project(outer[i], depth);
    pose.inner_lips[i] = head.project(inner[i], depth);
  }

  const double cheek_lift[2] = {f[41] * kEns, f[42] * kEns};
  for (int side : {kLeft, kRight}) {
    pose.eyes[side] = eye_from_faps(f, side, cheek_lift[side], head);
    pose.brows[side] = brow_from_faps(f, side, head);
    // Cheeks: 39, 40 puff outwards, 41, 42 lift.
    const double sign = side == kLeft ? 1 : -1;
    pose.cheek_puff[side] = std::max(0.0, f[39 + side] * kEs);
    pose.cheeks[side] =
        head.project({sign * (kCheekX + pose.cheek_puff[side] / 2), kCheekY - cheek_lift[side]});
  }
  pose.nose = head.project({0, kNoseY}, kNoseDepth);
  pose.outline = silhouette(f, jaw, pose.cheek_puff, head);
  pose.head_center = {head.neck_shift(), 0};
  return pose;
}

}  // namespace pfap::face

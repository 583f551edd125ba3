// SPDX-License-Identifier: LGPL-2.1-or-later
// The face's geometry: FAP amplitudes in, the 2D shapes a renderer draws out. No drawing and
// no GStreamer here (docs/face.md).
//
// Coordinates are face units: the head's neutral height is 1, the origin is the head's centre,
// x grows to the viewer's right (the face's own left, as MPEG-4's x axis), y grows downwards
// (as on screen; MPEG-4's y grows upwards, so "up" FAPs subtract from y). FAP amplitudes are
// scaled by the MPEG-4 FAP units of this face, each 1/1024 of a distance measured on its
// neutral shape (kUnits); angles are in the draft's angle units, 1e-5 rad.
#pragma once

#include <array>

#include "pfap/model.h"

namespace pfap::face {

// Amplitudes of every FAP, indexed by FAP number (0..2 unused).
using FapValues = std::array<double, pfap::kFapCount>;

// The MPEG-4 face animation parameter units of the drawn face: the neutral distances, in face
// units, of which one FAP unit is 1/1024 (angles: kAngleUnit rad).
struct FapUnits {
  double mns;    // mouth-nose separation
  double mw;     // mouth width
  double ens;    // eye-nose separation
  double es;     // eye separation (between the eye centres)
  double irisd;  // iris diameter, also the neutral eyelid opening
};
inline constexpr FapUnits kUnits{.mns = 0.14, .mw = 0.26, .ens = 0.18, .es = 0.34, .irisd = 0.055};
inline constexpr double kAngleUnit = 1e-5;  // rad

struct Point {
  double x = 0;
  double y = 0;
};

// Sides as MPEG-4 names them: the face's own left is the viewer's right.
enum Side { kLeft = 0, kRight = 1 };

struct Eye {
  Point center;           // where the eye's corners meet, projected
  double half_width = 0;  // corner to centre
  double upper_lid = 0;   // the upper lid's edge below the centre (negative: above)
  double lower_lid = 0;   // the lower lid's edge below the centre; >= upper_lid
  Point pupil;            // the iris centre, relative to `center`
  double iris_radius = 0;
};

struct Brow {
  std::array<Point, 3> points;  // inner, middle, outer
};

// Lip contours, each 8 points around: the corner on the viewer's left (the face's right),
// upper right-middle, upper middle, upper left-middle, the corner on the viewer's right, lower
// left-middle, lower middle, lower right-middle.
using LipContour = std::array<Point, 8>;

// Everything a renderer needs for one frame, projected onto the picture plane.
struct FacePose {
  // The head's tilt (FAP 50), rad: positive turns the top to -x. The points below are already
  // turned; a renderer drawing in the head's own frame turns by cairo_rotate(-roll).
  double roll = 0;
  Point head_center;
  std::array<Point, 12> outline;       // the head's silhouette, clockwise from the top
  std::array<Eye, 2> eyes;             // by Side
  std::array<Brow, 2> brows;           // by Side
  std::array<Point, 2> cheeks;         // cheek centres, by Side
  std::array<double, 2> cheek_puff{};  // how far each cheek bulges, face units
  Point nose;                          // the nose's tip
  LipContour outer_lips;
  LipContour inner_lips;  // the mouth opening; upper and lower halves coincide when closed
  double jaw_open = 0;    // face units the jaw has dropped
  std::array<double, 6> expressions{};  // joy, sadness, anger, fear, disgust, surprise: 0..1
};

// The weight (0..1) of MPEG-4 expression `e` (1..6) from FAP 68 + e, by
// pfap::expression_weight: its amplitude is the expression intensity of FAP 2, 0..63.
double expression_weight(const FapValues& faps, int e);

// Adds to `faps` the FAP displacements that make up the six expressions at their weights
// (FAPs 69..74 themselves stay as they are).
void add_expressions(FapValues& faps);

// The face for these amplitudes (expressions already added): every FAP moves its feature by
// amplitude x its unit, then the head rotates by pitch, yaw and roll (FAPs 48..50).
FacePose pose_from_faps(const FapValues& faps);

}  // namespace pfap::face

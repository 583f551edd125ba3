// SPDX-License-Identifier: LGPL-2.1-or-later
// The face's geometry: FAP amplitudes in, the 2D shapes a renderer draws out; the same model
// as pfapface's (face/src/model.cc, docs/face.md).
//
// Coordinates are face units: the head's neutral height is 1, the origin is the head's centre,
// x grows to the viewer's right (the face's own left), y grows downwards. FAP amplitudes are
// scaled by the MPEG-4 FAP units of this face, each 1/1024 of a neutral distance (FAP_UNITS);
// angles are in the draft's angle units, 1e-5 rad.

import { FAP_COUNT, FIRST_EXPRESSION_INDEX } from './model.js';

/** The neutral distances, in face units, of which one FAP unit is 1/1024. */
export const FAP_UNITS = Object.freeze({ mns: 0.14, mw: 0.26, ens: 0.18, es: 0.34, irisd: 0.055 });
/** The angle unit of the head-rotation FAPs (48..50): 1e-5 rad. */
export const ANGLE_UNIT = 1e-5; // rad

const U = FAP_UNITS;
const HEAD_RX = 0.36;
const HEAD_RY = 0.5;
const HEAD_RZ = 0.36;
const EYE_Y = -0.06;
const EYE_HALF_WIDTH = 0.065;
const EYEBALL_RADIUS = 0.06;
const BROW_Y = EYE_Y - 0.085;
const NOSE_Y = EYE_Y + U.ens;
const NOSE_DEPTH = 0.07;
const MOUTH_Y = NOSE_Y + U.mns;
const CHEEK_Y = 0.15;
const CHEEK_X = 0.21;
const MIN_LIP_THICKNESS = 0.008;

const MNS = U.mns / 1024;
const MW = U.mw / 1024;
const ENS = U.ens / 1024;
const ES = U.es / 1024;
const IRISD = U.irisd / 1024;

const HALF_MOUTH = U.mw / 2;
// Lip contours, 8 points: corner on the viewer's left, upper right-middle, upper middle,
// upper left-middle, corner on the viewer's right, lower left-middle, lower middle, lower
// right-middle.
const NEUTRAL_INNER = [
  [-HALF_MOUTH, MOUTH_Y], [-HALF_MOUTH / 2, MOUTH_Y], [0, MOUTH_Y], [HALF_MOUTH / 2, MOUTH_Y],
  [HALF_MOUTH, MOUTH_Y], [HALF_MOUTH / 2, MOUTH_Y], [0, MOUTH_Y], [-HALF_MOUTH / 2, MOUTH_Y],
];
const NEUTRAL_OUTER = [
  [-HALF_MOUTH - 0.012, MOUTH_Y], [-HALF_MOUTH / 2, MOUTH_Y - 0.04], [0, MOUTH_Y - 0.032],
  [HALF_MOUTH / 2, MOUTH_Y - 0.04], [HALF_MOUTH + 0.012, MOUTH_Y], [HALF_MOUTH / 2, MOUTH_Y + 0.038],
  [0, MOUTH_Y + 0.045], [-HALF_MOUTH / 2, MOUTH_Y + 0.038],
];

// FAP displacements of each expression at full intensity, [fap, amount] in FAP units.
const EXPRESSIONS = [
  // joy
  [[12, 130], [13, 130], [59, 130], [60, 130], [6, 80], [7, 80], [53, 80], [54, 80], [41, 140], [42, 140], [21, 150], [22, 150]],
  // sadness
  [[12, -110], [13, -110], [59, -110], [60, -110], [31, 160], [32, 160], [35, -80], [36, -80], [19, 250], [20, 250], [4, 20], [5, 20]],
  // anger
  [[31, -170], [32, -170], [33, -110], [34, -110], [37, 160], [38, 160], [21, 200], [22, 200], [4, 30], [5, 40], [12, -40], [13, -40]],
  // fear
  [[31, 220], [32, 220], [33, 160], [34, 160], [37, 90], [38, 90], [19, -300], [20, -300], [3, 160], [6, 110], [7, 110], [12, -40], [13, -40]],
  // disgust
  [[4, -70], [51, -90], [12, -90], [13, -90], [59, -90], [60, -90], [33, -90], [34, -90], [41, 130], [42, 130], [21, 200], [22, 200]],
  // surprise
  [[31, 280], [32, 280], [33, 300], [34, 300], [35, 260], [36, 260], [19, -320], [20, -320], [21, -100], [22, -100], [3, 380], [6, -60], [7, -60]],
];

/** Sides as MPEG-4 names them: the face's own left is the viewer's right. */
export const LEFT = 0;
export const RIGHT = 1;

// `p` turned by `angle` towards -x at the top.
function rotated(x, y, angle) {
  const c = Math.cos(angle);
  const s = Math.sin(angle);
  return { x: x * c + y * s, y: -x * s + y * c };
}

// Projects a point of the head's front surface (plus `depth` in front of it) after pitch,
// yaw and roll, orthographically.
function makeHead(pitch, yaw, roll) {
  return (x, y, depth = 0) => {
    const e = 1 - (x / HEAD_RX) * (x / HEAD_RX) - (y / HEAD_RY) * (y / HEAD_RY);
    const z = HEAD_RZ * Math.sqrt(Math.max(0.0, e)) + depth;
    const y1 = y * Math.cos(pitch) + z * Math.sin(pitch);
    const z1 = -y * Math.sin(pitch) + z * Math.cos(pitch);
    const x2 = x * Math.cos(yaw) + z1 * Math.sin(yaw);
    return rotated(x2, y1, roll);
  };
}

// The head turns around the neck, which shifts it a little sideways with yaw.
function neckShift(yaw) {
  return 0.25 * HEAD_RX * Math.sin(yaw);
}

// The jaw, in face units: FAP 3 down (never up), 14 forward, 15 to the face's right (-x).
function jawFromFaps(f) {
  return { open: Math.max(0.0, f[3] * MNS), shift: -f[15] * MW, thrust: f[14] * MNS };
}

// Inner lips. Upper points move down with 4, 8, 9; lower points with the jaw and up with 5,
// 10, 11; corners out with 6, 7 and up with 12, 13, and half with the jaw.
function innerLipContour(f, jaw) {
  const inner = NEUTRAL_INNER.map(([x, y]) => ({ x, y }));
  const stretchLeft = f[6] * MW;
  const stretchRight = f[7] * MW;
  const pucker = ((0.3 * (f[16] + f[17])) / 2) * MNS;
  inner[0].x += -stretchRight + pucker + jaw.shift / 2;
  inner[0].y += jaw.open / 2 - f[13] * MNS;
  inner[4].x += stretchLeft - pucker + jaw.shift / 2;
  inner[4].y += jaw.open / 2 - f[12] * MNS;
  inner[1].x += (-stretchRight + pucker) / 2;
  inner[3].x += (stretchLeft - pucker) / 2;
  inner[5].x += (stretchLeft - pucker) / 2 + jaw.shift;
  inner[7].x += (-stretchRight + pucker) / 2 + jaw.shift;
  inner[6].x += jaw.shift;
  inner[1].y += f[9] * MNS;
  inner[2].y += f[4] * MNS;
  inner[3].y += f[8] * MNS;
  inner[5].y += jaw.open - f[10] * MNS;
  inner[6].y += jaw.open - f[5] * MNS;
  inner[7].y += jaw.open - f[11] * MNS;
  for (let i = 5; i <= 7; ++i) inner[i].y = Math.max(inner[i].y, inner[8 - i].y);
  return inner;
}

// Outer lips: where the inner ones went, then their own FAPs 51..60, lips thickened by
// pushing (16, 17) and the jaw's thrust (14), the lower lip lifted by the chin (18).
function outerLipContour(f, jaw, inner) {
  const outer = NEUTRAL_OUTER.map(([x, y], i) => ({
    x: x + (inner[i].x - NEUTRAL_INNER[i][0]),
    y: y + (inner[i].y - NEUTRAL_INNER[i][1]),
  }));
  outer[0].x -= f[54] * MW;
  outer[0].y -= f[60] * MNS;
  outer[4].x += f[53] * MW;
  outer[4].y -= f[59] * MNS;
  outer[1].y += f[56] * MNS - 0.25 * f[17] * MNS;
  outer[2].y += f[51] * MNS - 0.25 * f[17] * MNS;
  outer[3].y += f[55] * MNS - 0.25 * f[17] * MNS;
  const lowerOut = 0.25 * f[16] * MNS + 0.3 * jaw.thrust - 0.5 * f[18] * MNS;
  outer[5].y += -f[57] * MNS + lowerOut;
  outer[6].y += -f[52] * MNS + lowerOut;
  outer[7].y += -f[58] * MNS + lowerOut;
  for (let i = 1; i <= 3; ++i) outer[i].y = Math.min(outer[i].y, inner[i].y - MIN_LIP_THICKNESS);
  for (let i = 5; i <= 7; ++i) outer[i].y = Math.max(outer[i].y, inner[i].y + MIN_LIP_THICKNESS);
  return outer;
}

// An eye: the upper lid down with 19, 20, the lower lid up with 21, 22 and with the cheek's
// lift (41, 42); the eyeball turns with 23..26.
function eyeFromFaps(f, side, cheekLift, project, yaw) {
  const x = side === LEFT ? U.es / 2 : -U.es / 2;
  const facing = Math.atan2(x, HEAD_RZ);
  let upper = -U.irisd / 2 + f[19 + side] * IRISD;
  let lower = U.irisd / 2 - f[21 + side] * IRISD - 0.3 * cheekLift;
  upper = Math.max(upper, -U.irisd);
  lower = Math.min(lower, U.irisd);
  if (lower < upper) upper = lower = (upper + lower) / 2;
  return {
    center: project(x, EYE_Y),
    halfWidth: EYE_HALF_WIDTH * Math.max(0.2, Math.cos(facing + yaw) / Math.cos(facing)),
    upperLid: upper,
    lowerLid: lower,
    pupil: { x: EYEBALL_RADIUS * Math.sin(f[23 + side] * ANGLE_UNIT), y: EYEBALL_RADIUS * Math.sin(f[25 + side] * ANGLE_UNIT) },
    irisRadius: U.irisd / 2,
  };
}

// A brow: 31..36 up, 37, 38 towards the middle.
function browFromFaps(f, side, project) {
  const sign = side === LEFT ? 1 : -1;
  const squeeze = f[37 + side] * ES;
  const brow = [
    [sign * 0.08, BROW_Y - f[31 + side] * ENS],
    [sign * 0.16, BROW_Y - 0.012 - f[33 + side] * ENS],
    [sign * 0.235, BROW_Y + 0.004 - f[35 + side] * ENS],
  ];
  return { points: brow.map(([bx, by]) => project(bx - sign * squeeze, by)) };
}

// The silhouette: an ellipse, with the cheeks bulging, the jaw's lower part moved, and the
// whole shifted with the neck.
function silhouette(f, jaw, cheekPuff, roll, yaw) {
  const outline = [];
  for (let k = 0; k < 12; ++k) {
    const angle = ((-90.0 + 30.0 * k) * Math.PI) / 180;
    let x = HEAD_RX * Math.cos(angle);
    let y = HEAD_RY * Math.sin(angle);
    if (k === 3 || k === 4) x += (k === 4 ? 1.0 : 0.5) * cheekPuff[LEFT];
    if (k === 8 || k === 9) x -= (k === 8 ? 1.0 : 0.5) * cheekPuff[RIGHT];
    if (k >= 4 && k <= 8) {
      const share = k === 4 || k === 8 ? 0.5 : 1.0;
      y += share * jaw.open;
      x += share * jaw.shift;
    }
    if (k === 6) y -= 0.5 * f[18] * MNS;
    outline.push(rotated(x, y, roll));
  }
  const shift = neckShift(yaw);
  for (const p of outline) p.x += shift;
  return outline;
}

/** A FapValues array: amplitudes by FAP index, 0..74 (0..2 unused). */
export function fapValues() {
  return new Float64Array(FAP_COUNT);
}

/**
 * The weight (0..1) of MPEG-4 expression `e` (1..6) from FAP 68 + e (intensity 0..63).
 * @param {ArrayLike<number>} faps
 * @param {number} e
 */
export function expressionWeight(faps, e) {
  return Math.min(Math.max(faps[FIRST_EXPRESSION_INDEX - 1 + e] / 63.0, 0.0), 1.0);
}

/**
 * Adds to `faps` the displacements of the six expressions at their weights.
 * @param {Float64Array} faps
 */
export function addExpressions(faps) {
  const weights = [1, 2, 3, 4, 5, 6].map((e) => expressionWeight(faps, e));
  EXPRESSIONS.forEach((displacements, e) => {
    for (const [fap, amount] of displacements) faps[fap] += weights[e] * amount;
  });
}

/**
 * The face for these amplitudes (expressions already added): points in face units.
 * @param {ArrayLike<number>} f FAP values by index
 * @returns {import('./index.js').FacePose}
 */
export function poseFromFaps(f) {
  const pitch = f[48] * ANGLE_UNIT;
  const yaw = f[49] * ANGLE_UNIT;
  const roll = f[50] * ANGLE_UNIT;
  const project = makeHead(pitch, yaw, roll);
  const expressions = [1, 2, 3, 4, 5, 6].map((e) => expressionWeight(f, e));
  const jaw = jawFromFaps(f);

  const inner = innerLipContour(f, jaw);
  const outer = outerLipContour(f, jaw, inner);
  const lipDepth = 0.02 + ((0.5 * (f[16] + f[17])) / 2) * MNS;
  const outerLips = outer.map((p, i) => project(p.x, p.y, i >= 5 ? lipDepth + jaw.thrust : lipDepth));
  const innerLips = inner.map((p, i) => project(p.x, p.y, i >= 5 ? lipDepth + jaw.thrust : lipDepth));

  const cheekLift = [f[41] * ENS, f[42] * ENS];
  const eyes = [];
  const brows = [];
  const cheeks = [];
  const cheekPuff = [];
  for (const side of [LEFT, RIGHT]) {
    eyes.push(eyeFromFaps(f, side, cheekLift[side], project, yaw));
    brows.push(browFromFaps(f, side, project));
    const sign = side === LEFT ? 1 : -1;
    cheekPuff.push(Math.max(0.0, f[39 + side] * ES));
    cheeks.push(project(sign * (CHEEK_X + cheekPuff[side] / 2), CHEEK_Y - cheekLift[side]));
  }
  const nose = project(0, NOSE_Y, NOSE_DEPTH);

  const outline = silhouette(f, jaw, cheekPuff, roll, yaw);
  return {
    roll,
    headCenter: { x: neckShift(yaw), y: 0 },
    outline,
    eyes,
    brows,
    cheeks,
    cheekPuff,
    nose,
    outerLips,
    innerLips,
    jawOpen: jaw.open,
    expressions,
  };
}

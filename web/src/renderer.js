// SPDX-License-Identifier: LGPL-2.1-or-later
// Draws a face pose on a canvas 2D context: what pfapface draws with cairo
// (face/src/renderer.cc, docs/face.md "Styles"), path for path and colour for colour, so that
// a browser and a GStreamer pipeline show the same face for the same state.

/** Drawing styles: flat colours, or black lines on white like a sketch. */
export const Style = Object.freeze({ CARTOON: 'cartoon', LINE: 'line' });

const TAU = 2 * Math.PI;

function mix(a, b, u) {
  return [a[0] + (b[0] - a[0]) * u, a[1] + (b[1] - a[1]) * u, a[2] + (b[2] - a[2]) * u];
}

function css(c, alpha = 1) {
  const v = (x) => Math.round(Math.min(Math.max(x, 0), 1) * 255);
  return `rgba(${v(c[0])},${v(c[1])},${v(c[2])},${alpha})`;
}

// cairo's fill and stroke consume the path; canvas's keep it.
function fill(ctx, rule) {
  ctx.fill(rule);
  ctx.beginPath();
}
function stroke(ctx) {
  ctx.stroke();
  ctx.beginPath();
}

// Continues the path along a smooth curve through `points` (Catmull-Rom as cubic Béziers);
// `closed` comes back to points[0].
function curveThrough(ctx, points, closed) {
  const n = points.length;
  const at = (i) => points[closed ? ((i % n) + n) % n : Math.min(Math.max(i, 0), n - 1)];
  for (let i = 0; i < (closed ? n : n - 1); ++i) {
    const p0 = at(i - 1);
    const p1 = at(i);
    const p2 = at(i + 1);
    const p3 = at(i + 2);
    ctx.bezierCurveTo(
      p1.x + (p2.x - p0.x) / 6, p1.y + (p2.y - p0.y) / 6,
      p2.x - (p3.x - p1.x) / 6, p2.y - (p3.y - p1.y) / 6,
      p2.x, p2.y,
    );
  }
  if (closed) ctx.closePath();
}

function spline(ctx, points, closed) {
  ctx.moveTo(points[0].x, points[0].y);
  curveThrough(ctx, points, closed);
}

// A lip contour as a closed path with sharp corners: upper half, then lower half.
function lipPath(ctx, c) {
  spline(ctx, [c[0], c[1], c[2], c[3], c[4]], false);
  curveThrough(ctx, [c[4], c[5], c[6], c[7], c[0]], false);
  ctx.closePath();
}

// The eye's opening between its lids, in the eye's own frame.
function eyePath(ctx, eye) {
  const w = eye.halfWidth;
  ctx.moveTo(-w, 0);
  ctx.bezierCurveTo(-w / 2, (4.0 / 3) * eye.upperLid, w / 2, (4.0 / 3) * eye.upperLid, w, 0);
  ctx.bezierCurveTo(w / 2, (4.0 / 3) * eye.lowerLid, -w / 2, (4.0 / 3) * eye.lowerLid, -w, 0);
  ctx.closePath();
}

function palette(style, pose) {
  if (style === Style.LINE) {
    const white = [1, 1, 1];
    const black = [0.08, 0.08, 0.08];
    return { background: white, skin: white, skinLine: black, hair: white, lips: white, mouth: black, teeth: white, iris: white, line: black, blush: white, filled: false };
  }
  // Anger and disgust redden the skin, fear and sadness pale it.
  const e = pose.expressions;
  let shaded = mix([0.96, 0.8, 0.66], [0.93, 0.55, 0.48], 0.6 * Math.max(e[2], 0.6 * e[4]));
  shaded = mix(shaded, [0.88, 0.88, 0.86], 0.5 * Math.max(e[3], 0.6 * e[1]));
  return {
    background: [0.8, 0.86, 0.92],
    skin: shaded,
    skinLine: [0.55, 0.36, 0.27],
    hair: [0.3, 0.19, 0.12],
    lips: [0.78, 0.33, 0.36],
    mouth: [0.33, 0.06, 0.09],
    teeth: [0.97, 0.96, 0.92],
    iris: [0.25, 0.45, 0.62],
    line: [0.2, 0.12, 0.08],
    blush: [0.95, 0.5, 0.52],
    filled: true,
  };
}

// The neck, then the hair behind the head.
function drawNeckAndHair(ctx, pose, p) {
  ctx.save();
  ctx.translate(pose.headCenter.x, 0);
  ctx.rotate(-pose.roll / 2);
  ctx.rect(-0.13, 0.3, 0.26, 0.5);
  ctx.fillStyle = css(mix(p.skin, p.skinLine, p.filled ? 0.25 : 0));
  ctx.fill();
  ctx.strokeStyle = css(p.skinLine);
  stroke(ctx);
  ctx.restore();
  if (p.filled) {
    ctx.save();
    ctx.translate(pose.headCenter.x, pose.headCenter.y);
    ctx.rotate(-pose.roll);
    ctx.scale(0.4, 0.5);
    ctx.arc(0, -0.06, 1, 0, TAU);
    ctx.restore();
    ctx.fillStyle = css(p.hair);
    fill(ctx);
  }
}

// The head, and a fringe over its forehead.
function drawHead(ctx, pose, p) {
  spline(ctx, pose.outline, true);
  ctx.fillStyle = css(p.skin);
  ctx.fill();
  ctx.strokeStyle = css(p.skinLine);
  stroke(ctx);

  // A fringe over the forehead, inside it.
  ctx.save();
  spline(ctx, pose.outline, true);
  ctx.clip();
  ctx.beginPath();
  ctx.save();
  ctx.translate(pose.headCenter.x, pose.headCenter.y);
  ctx.rotate(-pose.roll);
  ctx.moveTo(-0.5, -0.6);
  ctx.lineTo(0.5, -0.6);
  ctx.lineTo(0.5, -0.3);
  ctx.bezierCurveTo(0.2, -0.36, -0.1, -0.26, -0.5, -0.34);
  ctx.closePath();
  ctx.restore();
  if (p.filled) {
    ctx.fillStyle = css(p.hair);
    fill(ctx);
  } else {
    ctx.strokeStyle = css(p.line);
    stroke(ctx);
  }
  ctx.restore();
}

// Cheeks: a blush that grows when puffed and rises when lifted.
function drawCheeks(ctx, pose, p) {
  for (const side of [0, 1]) {
    const c = pose.cheeks[side];
    const r = 0.055 + pose.cheekPuff[side];
    if (p.filled) {
      const blush = ctx.createRadialGradient(c.x, c.y, 0, c.x, c.y, r);
      blush.addColorStop(0, css(p.blush, 0.35 + 0.3 * pose.expressions[0]));
      blush.addColorStop(1, css(p.blush, 0));
      ctx.fillStyle = blush;
      ctx.arc(c.x, c.y, r, 0, TAU);
      fill(ctx);
    } else {
      const left = side === 0;
      ctx.arc(c.x, c.y, r, left ? -0.6 : Math.PI - 0.2, left ? 0.2 : Math.PI + 0.6);
      ctx.strokeStyle = css(p.line);
      stroke(ctx);
    }
  }
}

// Eyes: white between the lids, the iris clipped by them, then the lids' lines.
function drawEyes(ctx, pose, p) {
  for (const eye of pose.eyes) {
    ctx.save();
    ctx.translate(eye.center.x, eye.center.y);
    ctx.rotate(-pose.roll);
    eyePath(ctx, eye);
    if (eye.lowerLid - eye.upperLid > 1e-4) {
      ctx.save();
      ctx.clip();
      ctx.fillStyle = css([1, 1, 1]);
      fill(ctx);
      ctx.arc(eye.pupil.x, eye.pupil.y, eye.irisRadius, 0, TAU);
      ctx.fillStyle = css(p.iris);
      ctx.fill();
      ctx.strokeStyle = css(p.line);
      ctx.lineWidth *= 0.6;
      stroke(ctx);
      ctx.arc(eye.pupil.x, eye.pupil.y, eye.irisRadius * 0.45, 0, TAU);
      ctx.fillStyle = css([0.02, 0.02, 0.02]);
      fill(ctx);
      if (p.filled) {
        ctx.arc(eye.pupil.x + eye.irisRadius * 0.35, eye.pupil.y - eye.irisRadius * 0.35, eye.irisRadius * 0.2, 0, TAU);
        ctx.fillStyle = css([1, 1, 1], 0.9);
        fill(ctx);
      }
      ctx.restore();
    }
    ctx.beginPath();
    eyePath(ctx, eye);
    ctx.strokeStyle = css(p.line);
    stroke(ctx);
    ctx.restore();
  }
}

function drawBrows(ctx, pose, p) {
  for (const brow of pose.brows) {
    spline(ctx, brow.points, false);
    ctx.save();
    ctx.lineWidth = 0.018;
    ctx.strokeStyle = css(p.filled ? p.hair : p.line);
    stroke(ctx);
    ctx.restore();
  }
}

// Nose: the line under its tip and one side.
function drawNose(ctx, pose, p) {
  const n = pose.nose;
  ctx.moveTo(n.x - 0.035, n.y - 0.005);
  ctx.bezierCurveTo(n.x - 0.02, n.y + 0.02, n.x + 0.02, n.y + 0.02, n.x + 0.035, n.y - 0.005);
  ctx.moveTo(n.x + 0.012, n.y - 0.1);
  ctx.bezierCurveTo(n.x + 0.02, n.y - 0.05, n.x + 0.035, n.y - 0.03, n.x + 0.03, n.y - 0.01);
  ctx.strokeStyle = css(p.skinLine);
  stroke(ctx);
}

// Mouth: the opening with teeth and tongue, then the lips around it.
function drawMouth(ctx, pose, p) {
  lipPath(ctx, pose.innerLips);
  ctx.fillStyle = css(p.mouth);
  ctx.fill();
  if (p.filled) {
    ctx.save();
    ctx.clip();
    ctx.beginPath();
    const top = pose.innerLips[2];
    const bottom = pose.innerLips[6];
    ctx.rect(top.x - 0.2, top.y - 0.05, 0.4, 0.05 + 0.022);
    ctx.fillStyle = css(p.teeth);
    fill(ctx);
    ctx.save();
    ctx.translate(bottom.x, bottom.y);
    ctx.scale(0.075, 0.03);
    ctx.arc(0, 0, 1, 0, TAU);
    ctx.restore();
    ctx.fillStyle = css([0.8, 0.38, 0.42]);
    fill(ctx);
    ctx.restore();
  }
  ctx.beginPath();
  lipPath(ctx, pose.outerLips);
  lipPath(ctx, pose.innerLips);
  ctx.fillStyle = css(p.lips);
  fill(ctx, 'evenodd');
  lipPath(ctx, pose.outerLips);
  ctx.strokeStyle = css(p.filled ? mix(p.lips, p.line, 0.5) : p.line);
  stroke(ctx);
  lipPath(ctx, pose.innerLips);
  ctx.strokeStyle = css(p.line);
  stroke(ctx);
}

function drawFace(ctx, pose, style, unit) {
  const p = palette(style, pose);
  ctx.lineWidth = Math.max(style === Style.LINE ? 0.008 : 0.006, 1.0 / unit);
  ctx.lineJoin = 'round';
  ctx.lineCap = 'round';
  ctx.beginPath();

  drawNeckAndHair(ctx, pose, p);
  drawHead(ctx, pose, p);
  drawCheeks(ctx, pose, p);
  drawEyes(ctx, pose, p);
  drawBrows(ctx, pose, p);
  drawNose(ctx, pose, p);
  drawMouth(ctx, pose, p);
}

// Breaks `text` at spaces into lines no wider than `width`.
function wrap(ctx, text, width) {
  const lines = [];
  let current = '';
  for (const word of text.split(' ')) {
    const candidate = current === '' ? word : `${current} ${word}`;
    if (ctx.measureText(candidate).width > width && current !== '') {
      lines.push(current);
      current = word;
    } else {
      current = candidate;
    }
  }
  if (current !== '') lines.push(current);
  return lines;
}

function drawOverlay(ctx, text, width, height) {
  const size = Math.max(9.0, height / 28.0);
  ctx.font = `${size}px monospace`;
  const margin = size / 3;
  const lines = wrap(ctx, text, width - 2 * margin);
  ctx.fillStyle = 'rgba(0,0,0,0.6)';
  ctx.fillRect(0, 0, width, margin * 2 + size * 1.2 * lines.length);
  ctx.fillStyle = 'rgb(255,255,255)';
  lines.forEach((line, i) => ctx.fillText(line, margin, margin + size * (1.2 * i + 0.95)));
}

/**
 * Draws `pose` centred on the whole of `ctx`'s canvas (`width` x `height` pixels), the head's
 * neutral height 78 % of the smaller side's room, over a plain background; `overlay`, when
 * not empty, at the top left in white on a dark band.
 * @param {CanvasRenderingContext2D} ctx
 * @param {import('./index.js').FacePose} pose
 * @param {{style?: 'cartoon'|'line', width?: number, height?: number, overlay?: string}} [options]
 */
export function renderFace(ctx, pose, options = {}) {
  const style = options.style ?? Style.CARTOON;
  const width = options.width ?? ctx.canvas.width;
  const height = options.height ?? ctx.canvas.height;
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.globalAlpha = 1;
  ctx.globalCompositeOperation = 'source-over';
  ctx.beginPath();
  ctx.fillStyle = css(palette(style, pose).background);
  ctx.fillRect(0, 0, width, height);

  const unit = Math.min(0.78 * height, (0.9 * width) / 0.8);
  ctx.save();
  ctx.translate(width / 2.0, height / 2.0);
  ctx.scale(unit, unit);
  drawFace(ctx, pose, style, unit);
  ctx.restore();
  if (options.overlay) drawOverlay(ctx, options.overlay, width, height);
  ctx.restore();
}

// SPDX-License-Identifier: LGPL-2.1-or-later
#include "face/renderer.h"

#include <cairo.h>

#include <algorithm>
#include <numbers>
#include <span>
#include <string>
#include <vector>

namespace pfap::face {
namespace {

struct Rgb {
  double r, g, b;
};

Rgb mix(Rgb a, Rgb b, double u) {
  return {a.r + (b.r - a.r) * u, a.g + (b.g - a.g) * u, a.b + (b.b - a.b) * u};
}

void set_color(cairo_t* cr, Rgb c, double alpha = 1) {
  cairo_set_source_rgba(cr, c.r, c.g, c.b, alpha);
}

// Continues the path, which is at points[0], along a smooth curve through `points`
// (Catmull-Rom as cubic Béziers); `closed` comes back to points[0].
void curve_through(cairo_t* cr, std::span<const Point> points, bool closed) {
  const auto n = static_cast<long>(points.size());
  auto at = [&](long i) {
    return points[static_cast<size_t>(closed ? (i % n + n) % n : std::clamp(i, 0L, n - 1))];
  };
  for (long i = 0; i < (closed ? n : n - 1); ++i) {
    const Point p0 = at(i - 1), p1 = at(i), p2 = at(i + 1), p3 = at(i + 2);
    cairo_curve_to(cr, p1.x + (p2.x - p0.x) / 6, p1.y + (p2.y - p0.y) / 6, p2.x - (p3.x - p1.x) / 6,
                   p2.y - (p3.y - p1.y) / 6, p2.x, p2.y);
  }
  if (closed) cairo_close_path(cr);
}

void spline(cairo_t* cr, std::span<const Point> points, bool closed) {
  cairo_move_to(cr, points[0].x, points[0].y);
  curve_through(cr, points, closed);
}

// A lip contour as a closed path with sharp corners: upper half, then lower half.
void lip_path(cairo_t* cr, const LipContour& c) {
  const std::array<Point, 5> upper{c[0], c[1], c[2], c[3], c[4]};
  const std::array<Point, 5> lower{c[4], c[5], c[6], c[7], c[0]};
  spline(cr, upper, false);
  curve_through(cr, lower, false);
  cairo_close_path(cr);
}

// The eye's opening between its lids, in the eye's own frame (centre at 0, 0).
void eye_path(cairo_t* cr, const Eye& eye) {
  const double w = eye.half_width;
  cairo_move_to(cr, -w, 0);
  cairo_curve_to(cr, -w / 2, 4.0 / 3 * eye.upper_lid, w / 2, 4.0 / 3 * eye.upper_lid, w, 0);
  cairo_curve_to(cr, w / 2, 4.0 / 3 * eye.lower_lid, -w / 2, 4.0 / 3 * eye.lower_lid, -w, 0);
  cairo_close_path(cr);
}

struct Palette {
  Rgb background, skin, skin_line, hair, lips, mouth, teeth, iris, line, blush;
  bool filled;
};

Palette palette(Style style, const FacePose& pose) {
  if (style == Style::kLine) {
    const Rgb white{1, 1, 1}, black{0.08, 0.08, 0.08};
    return {white, white, black, white, white, black, white, white, black, white, false};
  }
  // Anger and disgust redden the skin, fear and sadness pale it.
  const Rgb skin{0.96, 0.80, 0.66};
  Rgb shaded =
      mix(skin, {0.93, 0.55, 0.48}, 0.6 * std::max(pose.expressions[2], 0.6 * pose.expressions[4]));
  shaded = mix(shaded, {0.88, 0.88, 0.86},
               0.5 * std::max(pose.expressions[3], 0.6 * pose.expressions[1]));
  return {{0.80, 0.86, 0.92},
          shaded,
          {0.55, 0.36, 0.27},
          {0.30, 0.19, 0.12},
          {0.78, 0.33, 0.36},
          {0.33, 0.06, 0.09},
          {0.97, 0.96, 0.92},
          {0.25, 0.45, 0.62},
          {0.20, 0.12, 0.08},
          {0.95, 0.50, 0.52},
          true};
}

// The neck, then the hair behind the head.
void draw_neck_and_hair(cairo_t* cr, const FacePose& pose, const Palette& p) {
  cairo_save(cr);
  cairo_translate(cr, pose.head_center.x, 0);
  cairo_rotate(cr, -pose.roll / 2);
  cairo_rectangle(cr, -0.13, 0.3, 0.26, 0.5);
  set_color(cr, mix(p.skin, p.skin_line, p.filled ? 0.25 : 0));
  cairo_fill_preserve(cr);
  set_color(cr, p.skin_line);
  cairo_stroke(cr);
  cairo_restore(cr);
  if (p.filled) {
    cairo_save(cr);
    cairo_translate(cr, pose.head_center.x, pose.head_center.y);
    cairo_rotate(cr, -pose.roll);
    cairo_scale(cr, 0.40, 0.50);
    cairo_arc(cr, 0, -0.06, 1, 0, 2 * std::numbers::pi);
    cairo_restore(cr);
    set_color(cr, p.hair);
    cairo_fill(cr);
  }
}

// The head, and a fringe over its forehead.
void draw_head(cairo_t* cr, const FacePose& pose, const Palette& p) {
  spline(cr, pose.outline, true);
  set_color(cr, p.skin);
  cairo_fill_preserve(cr);
  set_color(cr, p.skin_line);
  cairo_stroke(cr);

  // A fringe over the forehead, inside it.
  cairo_save(cr);
  spline(cr, pose.outline, true);
  cairo_clip(cr);
  cairo_save(cr);
  cairo_translate(cr, pose.head_center.x, pose.head_center.y);
  cairo_rotate(cr, -pose.roll);
  cairo_move_to(cr, -0.5, -0.6);
  cairo_line_to(cr, 0.5, -0.6);
  cairo_line_to(cr, 0.5, -0.30);
  cairo_curve_to(cr, 0.2, -0.36, -0.1, -0.26, -0.5, -0.34);
  cairo_close_path(cr);
  cairo_restore(cr);
  if (p.filled) {
    set_color(cr, p.hair);
    cairo_fill(cr);
  } else {
    set_color(cr, p.line);
    cairo_stroke(cr);
  }
  cairo_restore(cr);
}

// Cheeks: a blush that grows when puffed and rises when lifted.
void draw_cheeks(cairo_t* cr, const FacePose& pose, const Palette& p) {
  for (int side : {kLeft, kRight}) {
    const Point c = pose.cheeks[side];
    const double r = 0.055 + pose.cheek_puff[side];
    if (p.filled) {
      cairo_pattern_t* blush = cairo_pattern_create_radial(c.x, c.y, 0, c.x, c.y, r);
      const double strength = 0.35 + 0.3 * pose.expressions[0];
      cairo_pattern_add_color_stop_rgba(blush, 0, p.blush.r, p.blush.g, p.blush.b, strength);
      cairo_pattern_add_color_stop_rgba(blush, 1, p.blush.r, p.blush.g, p.blush.b, 0);
      cairo_set_source(cr, blush);
      cairo_arc(cr, c.x, c.y, r, 0, 2 * std::numbers::pi);
      cairo_fill(cr);
      cairo_pattern_destroy(blush);
    } else {
      const double sign = side == kLeft ? 1 : -1;
      cairo_arc(cr, c.x, c.y, r, sign > 0 ? -0.6 : std::numbers::pi - 0.2,
                sign > 0 ? 0.2 : std::numbers::pi + 0.6);
      set_color(cr, p.line);
      cairo_stroke(cr);
    }
  }
}

// Eyes: white between the lids, the iris clipped by them, then the lids' lines.
void draw_eyes(cairo_t* cr, const FacePose& pose, const Palette& p) {
  for (const Eye& eye : pose.eyes) {
    cairo_save(cr);
    cairo_translate(cr, eye.center.x, eye.center.y);
    cairo_rotate(cr, -pose.roll);
    eye_path(cr, eye);
    if (eye.lower_lid - eye.upper_lid > 1e-4) {
      cairo_save(cr);
      cairo_clip_preserve(cr);
      set_color(cr, {1, 1, 1});
      cairo_fill(cr);
      cairo_arc(cr, eye.pupil.x, eye.pupil.y, eye.iris_radius, 0, 2 * std::numbers::pi);
      set_color(cr, p.iris);
      cairo_fill_preserve(cr);
      set_color(cr, p.line);
      cairo_set_line_width(cr, cairo_get_line_width(cr) * 0.6);
      cairo_stroke(cr);
      cairo_arc(cr, eye.pupil.x, eye.pupil.y, eye.iris_radius * 0.45, 0, 2 * std::numbers::pi);
      set_color(cr, {0.02, 0.02, 0.02});
      cairo_fill(cr);
      if (p.filled) {
        cairo_arc(cr, eye.pupil.x + eye.iris_radius * 0.35, eye.pupil.y - eye.iris_radius * 0.35,
                  eye.iris_radius * 0.2, 0, 2 * std::numbers::pi);
        set_color(cr, {1, 1, 1}, 0.9);
        cairo_fill(cr);
      }
      cairo_restore(cr);
    }
    eye_path(cr, eye);
    set_color(cr, p.line);
    cairo_stroke(cr);
    cairo_restore(cr);
  }
}

void draw_brows(cairo_t* cr, const FacePose& pose, const Palette& p) {
  for (const Brow& brow : pose.brows) {
    spline(cr, brow.points, false);
    cairo_save(cr);
    cairo_set_line_width(cr, 0.018);
    set_color(cr, p.filled ? p.hair : p.line);
    cairo_stroke(cr);
    cairo_restore(cr);
  }
}

// Nose: the line under its tip and one side.
void draw_nose(cairo_t* cr, const FacePose& pose, const Palette& p) {
  const Point n = pose.nose;
  cairo_move_to(cr, n.x - 0.035, n.y - 0.005);
  cairo_curve_to(cr, n.x - 0.02, n.y + 0.02, n.x + 0.02, n.y + 0.02, n.x + 0.035, n.y - 0.005);
  cairo_move_to(cr, n.x + 0.012, n.y - 0.10);
  cairo_curve_to(cr, n.x + 0.02, n.y - 0.05, n.x + 0.035, n.y - 0.03, n.x + 0.03, n.y - 0.01);
  set_color(cr, p.skin_line);
  cairo_stroke(cr);
}

// Mouth: the opening with teeth and tongue, then the lips around it.
void draw_mouth(cairo_t* cr, const FacePose& pose, const Palette& p) {
  lip_path(cr, pose.inner_lips);
  set_color(cr, p.mouth);
  cairo_fill_preserve(cr);
  if (p.filled) {
    cairo_save(cr);
    cairo_clip(cr);
    const Point top = pose.inner_lips[2], bottom = pose.inner_lips[6];
    cairo_rectangle(cr, top.x - 0.2, top.y - 0.05, 0.4, 0.05 + 0.022);
    set_color(cr, p.teeth);
    cairo_fill(cr);
    cairo_save(cr);
    cairo_translate(cr, bottom.x, bottom.y);
    cairo_scale(cr, 0.075, 0.03);
    cairo_arc(cr, 0, 0, 1, 0, 2 * std::numbers::pi);
    cairo_restore(cr);
    set_color(cr, {0.80, 0.38, 0.42});
    cairo_fill(cr);
    cairo_restore(cr);
  }
  cairo_new_path(cr);
  lip_path(cr, pose.outer_lips);
  lip_path(cr, pose.inner_lips);
  cairo_set_fill_rule(cr, CAIRO_FILL_RULE_EVEN_ODD);
  set_color(cr, p.lips);
  cairo_fill(cr);
  cairo_set_fill_rule(cr, CAIRO_FILL_RULE_WINDING);
  lip_path(cr, pose.outer_lips);
  set_color(cr, p.filled ? mix(p.lips, p.line, 0.5) : p.line);
  cairo_stroke(cr);
  lip_path(cr, pose.inner_lips);
  set_color(cr, p.line);
  cairo_stroke(cr);
}

void draw_face(cairo_t* cr, const FacePose& pose, Style style, double unit) {
  const Palette p = palette(style, pose);
  const double line = style == Style::kLine ? 0.008 : 0.006;
  cairo_set_line_width(cr, std::max(line, 1.0 / unit));
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);

  draw_neck_and_hair(cr, pose, p);
  draw_head(cr, pose, p);
  draw_cheeks(cr, pose, p);
  draw_eyes(cr, pose, p);
  draw_brows(cr, pose, p);
  draw_nose(cr, pose, p);
  draw_mouth(cr, pose, p);
}

// Breaks `text` at spaces into lines no wider than `width`.
std::vector<std::string> wrap(cairo_t* cr, std::string_view text, double width) {
  std::vector<std::string> lines;
  std::string current;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(' ', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string word(text.substr(start, end - start));
    const std::string candidate = current.empty() ? word : current + " " + word;
    cairo_text_extents_t extents;
    cairo_text_extents(cr, candidate.c_str(), &extents);
    if (extents.x_advance > width && !current.empty()) {
      lines.push_back(current);
      current = word;
    } else {
      current = candidate;
    }
    start = end + 1;
  }
  if (!current.empty()) lines.push_back(current);
  return lines;
}

void draw_overlay(cairo_t* cr, std::string_view text, int width, int height) {
  const double size = std::max(9.0, height / 28.0);
  cairo_select_font_face(cr, "monospace", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  const double margin = size / 3;
  const std::vector<std::string> lines = wrap(cr, text, width - 2 * margin);
  cairo_rectangle(cr, 0, 0, width, margin * 2 + size * 1.2 * static_cast<double>(lines.size()));
  cairo_set_source_rgba(cr, 0, 0, 0, 0.6);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 1, 1, 1);
  for (size_t i = 0; i < lines.size(); ++i) {
    cairo_move_to(cr, margin, margin + size * (1.2 * static_cast<double>(i) + 0.95));
    cairo_show_text(cr, lines[i].c_str());
  }
}

}  // namespace

void render(const FacePose& pose, Style style, std::string_view overlay, const Frame& frame) {
  cairo_surface_t* surface = cairo_image_surface_create_for_data(
      frame.data, frame.alpha ? CAIRO_FORMAT_ARGB32 : CAIRO_FORMAT_RGB24, frame.width, frame.height,
      frame.stride);
  cairo_t* cr = cairo_create(surface);

  const Palette colours = palette(style, pose);
  set_color(cr, colours.background);
  cairo_paint(cr);

  // Face units to pixels: the head (1 high, 0.72 wide, more with hair and a dropped jaw)
  // centred.
  const double unit = std::min(0.78 * frame.height, 0.9 * frame.width / 0.8);
  cairo_save(cr);
  cairo_translate(cr, frame.width / 2.0, frame.height / 2.0);
  cairo_scale(cr, unit, unit);
  draw_face(cr, pose, style, unit);
  cairo_restore(cr);

  if (!overlay.empty()) draw_overlay(cr, overlay, frame.width, frame.height);

  cairo_destroy(cr);
  cairo_surface_flush(surface);
  cairo_surface_destroy(surface);
}

}  // namespace pfap::face

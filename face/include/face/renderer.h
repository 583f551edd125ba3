// SPDX-License-Identifier: LGPL-2.1-or-later
// Draws a FacePose with cairo into a frame of 32-bit pixels (docs/face.md, "Styles").
#pragma once

#include <cstdint>
#include <string_view>

#include "face/model.h"

namespace pfap::face {

enum class Style {
  kCartoon,  // flat colours: skin, hair, lips, eyes, shaded by the expressions
  kLine,     // black lines on white, like a sketch
};

// A frame to draw into: rows of `width` pixels of 4 bytes, cairo's CAIRO_FORMAT_RGB24
// (`alpha` false: GStreamer's BGRx on little-endian machines) or CAIRO_FORMAT_ARGB32
// (`alpha` true: BGRA, premultiplied and here always opaque).
struct Frame {
  uint8_t* data;
  int width;
  int height;
  int stride;  // bytes per row, at least 4 * width and a multiple of 4
  bool alpha;
};

// Draws `pose` centred in `frame`, the head's neutral height 78 % of the smaller side's room,
// over a plain background. `overlay`, when not empty, is written at the top left in white on a
// dark band (wrapped at word boundaries to the width).
void render(const FacePose& pose, Style style, std::string_view overlay, const Frame& frame);

}  // namespace pfap::face

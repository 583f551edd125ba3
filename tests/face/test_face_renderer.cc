// SPDX-License-Identifier: LGPL-2.1-or-later
// Drawing: a face on a background, the styles differ, the alpha format stays opaque, the
// overlay writes text. Pictures themselves are compared in tests/gst/test_pfapface.cc.
#include <cairo.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "face/renderer.h"
#include "release_fonts.h"

namespace pfap::face {
namespace {

constexpr int kWidth = 160, kHeight = 120, kStride = kWidth * 4 + 16;

struct Picture {
  std::vector<uint8_t> pixels = std::vector<uint8_t>(kStride * kHeight, 0xab);
  Frame frame(bool alpha) { return {pixels.data(), kWidth, kHeight, kStride, alpha}; }
  uint32_t at(int x, int y) const {
    const uint8_t* p = &pixels[y * kStride + x * 4];
    return p[0] | p[1] << 8 | p[2] << 16 | uint32_t{p[3]} << 24;
  }
};

Picture draw(const FacePose& pose, Style style, std::string_view overlay = {}, bool alpha = false) {
  Picture picture;
  render(pose, style, overlay, picture.frame(alpha));
  return picture;
}

int differing_pixels(const Picture& a, const Picture& b, int y0 = 0, int y1 = kHeight) {
  int count = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < kWidth; ++x) count += (a.at(x, y) & 0xffffff) != (b.at(x, y) & 0xffffff);
  }
  return count;
}

TEST(Renderer, FaceOnBackground) {
  const Picture picture = draw(pose_from_faps({}), Style::kCartoon);
  EXPECT_EQ(picture.at(0, 0), picture.at(kWidth - 1, 0)) << "plain background";
  EXPECT_NE(picture.at(kWidth / 2, kHeight / 2) & 0xffffff, picture.at(0, 0) & 0xffffff);
  // Padding past each row's pixels is left alone.
  EXPECT_EQ(picture.pixels[kWidth * 4], 0xab);
}

TEST(Renderer, StylesLookDifferent) {
  const FacePose pose = pose_from_faps({});
  const Picture cartoon = draw(pose, Style::kCartoon), line = draw(pose, Style::kLine);
  EXPECT_GT(differing_pixels(cartoon, line), kWidth * kHeight / 2);
  EXPECT_EQ(line.at(0, 0) & 0xffffff, 0xffffffu) << "white paper";
}

TEST(Renderer, AlphaFormatIsOpaque) {
  const Picture picture = draw(pose_from_faps({}), Style::kLine, "overlay", true);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) ASSERT_EQ(picture.at(x, y) >> 24, 0xffu) << x << "," << y;
  }
}

TEST(Renderer, OverlayWritesAtTheTop) {
  const FacePose pose = pose_from_faps({});
  const Picture plain = draw(pose, Style::kCartoon);
  const Picture text = draw(pose, Style::kCartoon, "AA 3:120 69:40");
  EXPECT_GT(differing_pixels(plain, text, 0, 12), 100);
  EXPECT_EQ(differing_pixels(plain, text, kHeight / 2, kHeight), 0);
}

TEST(Renderer, LongOverlayWraps) {
  const FacePose pose = pose_from_faps({});
  const Picture one = draw(pose, Style::kCartoon, "AA");
  const Picture many = draw(pose, Style::kCartoon,
                            "AA 3:120 4:-20 5:30 6:40 7:40 12:80 13:80 16:90 17:90 31:140 32:140");
  EXPECT_GT(differing_pixels(one, many, 16, 30), 50) << "a second line";
}

}  // namespace
}  // namespace pfap::face

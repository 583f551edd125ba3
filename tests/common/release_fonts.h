// SPDX-License-Identifier: LGPL-2.1-or-later
// For tests that draw text with cairo: its toy-font cache and fontconfig's configuration live
// as long as the process. Including this header releases both when the tests end, so that
// LeakSanitizer reports only real leaks.
#pragma once

#include <cairo.h>
#include <fontconfig/fontconfig.h>
#include <gtest/gtest.h>

namespace pfap::testing {

class ReleaseFonts : public ::testing::Environment {
 public:
  void TearDown() override {
    cairo_debug_reset_static_data();
    FcFini();
  }
};

inline const ::testing::Environment* const kReleaseFonts =
    ::testing::AddGlobalTestEnvironment(new ReleaseFonts);

}  // namespace pfap::testing

// SPDX-License-Identifier: LGPL-2.1-or-later
// main() for element tests: GoogleTest with GStreamer initialised once; the plugin is found
// through GST_PLUGIN_PATH, which meson sets to the build's gst/ directory.
#include <gst/gst.h>
#include <gtest/gtest.h>

int main(int argc, char** argv) {
  gst_init(&argc, &argv);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

// SPDX-License-Identifier: LGPL-2.1-or-later
// main() for element tests: GoogleTest with GStreamer initialised once; the plugin is found
// through GST_PLUGIN_PATH, which meson sets to the build's gst/ directory.
#include <gst/gst.h>
#include <gtest/gtest.h>

int main(int argc, char** argv) {
  gst_init(&argc, &argv);
  // GLib ends a pool thread after 15 s idle. A thread that ends while LeakSanitizer stops the
  // world at exit crashes LeakSanitizer's tracer ("Tracer caught signal 11"), so in tests no
  // idle thread ends on its own: all of them are still parked when the process exits.
  g_thread_pool_set_max_idle_time(0);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

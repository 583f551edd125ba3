// SPDX-License-Identifier: LGPL-2.1-or-later
// The one harness-plus-bus fixture of the element tests: an element in a GstHarness with a bus
// of its own, since the harness alone drops the element's messages (warnings, errors).
#pragma once

#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pipeline.h"

namespace pfap::testing {

// The bytes of every buffer the harness holds now, in order: a writer's text.
inline std::string pull_text(GstHarness* h) {
  std::string text;
  while (GstBuffer* b = gst_harness_try_pull(h)) {
    GstMapInfo map;
    gst_buffer_map(b, &map, GST_MAP_READ);
    text.append(reinterpret_cast<const char*>(map.data), map.size);
    gst_buffer_unmap(b, &map);
    gst_buffer_unref(b);
  }
  return text;
}

class ElementHarness {
 public:
  // `factory` in a harness of its own.
  explicit ElementHarness(const char* factory) : ElementHarness(gst_harness_new(factory)) {}
  // Takes `h` (e.g. from gst_harness_new_with_padnames).
  explicit ElementHarness(GstHarness* h) : h_(h), bus_(gst_bus_new()) {
    gst_element_set_bus(h_->element, bus_);
  }
  ~ElementHarness() {
    gst_harness_teardown(h_);
    gst_bus_set_flushing(bus_, TRUE);  // its messages hold the element
    gst_object_unref(bus_);
  }
  ElementHarness(const ElementHarness&) = delete;
  ElementHarness& operator=(const ElementHarness&) = delete;

  GstHarness* harness() const { return h_; }
  GstElement* element() const { return h_->element; }
  GstBus* bus() const { return bus_; }

  // A guint64 field of the element's stats property; a missing field fails the test.
  guint64 stat(const char* field) const {
    GstStructure* stats = nullptr;
    g_object_get(h_->element, "stats", &stats, nullptr);
    guint64 value = G_MAXUINT64;
    EXPECT_TRUE(stats != nullptr && gst_structure_get_uint64(stats, field, &value)) << field;
    if (stats != nullptr) gst_structure_free(stats);
    return value;
  }

  // The messages of the warnings posted so far, taken off the bus.
  std::vector<std::string> warnings() const { return pop_messages(bus_, GST_MESSAGE_WARNING); }
  std::vector<std::string> errors() const { return pop_messages(bus_, GST_MESSAGE_ERROR); }

 protected:
  GstHarness* const h_;
  GstBus* const bus_;
};

}  // namespace pfap::testing

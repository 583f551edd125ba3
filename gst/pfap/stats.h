/* SPDX-License-Identifier: LGPL-2.1-or-later */
// The `stats` property of the plugins' elements: one GstStructure of guint64 counters, the
// same name for the same thing on every element (docs/elements.md, "Counters").
#pragma once

#include <gst/gst.h>

// A copy of the `stats` structure of `object`'s class `owner` (GstRTPBasePayload,
// GstRTPBaseDepayload), whose property a subclass overrides
// (g_object_class_override_property) to add its counters to the base's instead of hiding
// them. Without such a property (a GStreamer that lacks it), an empty structure.
inline GstStructure* pfap_owner_stats(GObject* object, GType owner) {
  GObjectClass* klass = G_OBJECT_CLASS(g_type_class_peek(owner));
  GParamSpec* pspec = g_object_class_find_property(klass, "stats");
  if (pspec == nullptr || pspec->owner_type != owner) {
    return gst_structure_new_empty("application/x-pfap-stats");
  }
  GValue value = G_VALUE_INIT;
  g_value_init(&value, GST_TYPE_STRUCTURE);
  klass->get_property(object, pspec->param_id, &value, pspec);
  auto* stats = static_cast<GstStructure*>(g_value_dup_boxed(&value));
  g_value_unset(&value);
  return stats;
}

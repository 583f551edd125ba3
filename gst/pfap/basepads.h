/* SPDX-License-Identifier: LGPL-2.1-or-later */
// The pads of the base classes (baseparse.h, baseenc.h), made from the subclass's "sink" and
// "src" templates: in constructed, as instance init cannot see the subclass's class yet.
#pragma once

#include <gst/gst.h>

// Adds a sink pad with `chain` and `event` and a src pad with fixed caps to `element`.
inline void pfap_base_add_pads(GstElement* element, GstPadChainFunction chain,
                               GstPadEventFunction event, GstPad** sinkpad, GstPad** srcpad) {
  GstElementClass* klass = GST_ELEMENT_GET_CLASS(element);
  *sinkpad = gst_pad_new_from_template(gst_element_class_get_pad_template(klass, "sink"), "sink");
  gst_pad_set_chain_function(*sinkpad, chain);
  gst_pad_set_event_function(*sinkpad, event);
  gst_element_add_pad(element, *sinkpad);

  *srcpad = gst_pad_new_from_template(gst_element_class_get_pad_template(klass, "src"), "src");
  gst_pad_use_fixed_caps(*srcpad);
  gst_element_add_pad(element, *srcpad);
}

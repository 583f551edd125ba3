// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include <gst/base/gstaggregator.h>
#include <gst/gst.h>

G_BEGIN_DECLS

#define GST_TYPE_PFAP_FACE (gst_pfap_face_get_type())
G_DECLARE_FINAL_TYPE(GstPfapFace, gst_pfap_face, GST, PFAP_FACE, GstAggregator)

// The values of GstPfapFace:style, pfap::face::Style's looks.
#define GST_TYPE_PFAP_FACE_STYLE (gst_pfap_face_style_get_type())
GType gst_pfap_face_style_get_type(void);

GST_ELEMENT_REGISTER_DECLARE(pfapface);

G_END_DECLS

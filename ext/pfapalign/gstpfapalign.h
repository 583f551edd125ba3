// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include <gst/gst.h>

G_BEGIN_DECLS

#define GST_TYPE_PFAP_ALIGN (gst_pfap_align_get_type())
G_DECLARE_FINAL_TYPE(GstPfapAlign, gst_pfap_align, GST, PFAP_ALIGN, GstElement)

GST_ELEMENT_REGISTER_DECLARE(pfapalign);

G_END_DECLS

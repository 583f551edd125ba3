// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include <gst/gst.h>

G_BEGIN_DECLS

#define GST_TYPE_PFAP_TTS (gst_pfap_tts_get_type())
G_DECLARE_FINAL_TYPE(GstPfapTts, gst_pfap_tts, GST, PFAP_TTS, GstElement)

GST_ELEMENT_REGISTER_DECLARE(pfaptts);

G_END_DECLS

// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include "baseenc.h"

G_BEGIN_DECLS

#define GST_TYPE_PFAP_MARKS_ENC (gst_pfap_marks_enc_get_type())
G_DECLARE_FINAL_TYPE(GstPfapMarksEnc, gst_pfap_marks_enc, GST, PFAP_MARKS_ENC, GstPfapBaseEnc)

GST_ELEMENT_REGISTER_DECLARE(pfapmarksenc);

G_END_DECLS

// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include "baseenc.h"

G_BEGIN_DECLS

#define GST_TYPE_PFAP_TEXT_ENC (gst_pfap_text_enc_get_type())
G_DECLARE_FINAL_TYPE(GstPfapTextEnc, gst_pfap_text_enc, GST, PFAP_TEXT_ENC, GstPfapBaseEnc)

GST_ELEMENT_REGISTER_DECLARE(pfaptextenc);

G_END_DECLS

// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include "baseenc.h"

G_BEGIN_DECLS

#define GST_TYPE_PFAP_FAP_ENC (gst_pfap_fap_enc_get_type())
G_DECLARE_FINAL_TYPE(GstPfapFapEnc, gst_pfap_fap_enc, GST, PFAP_FAP_ENC, GstPfapBaseEnc)

GST_ELEMENT_REGISTER_DECLARE(pfapfapenc);

G_END_DECLS

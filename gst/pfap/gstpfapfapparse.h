// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include "baseparse.h"

G_BEGIN_DECLS

#define GST_TYPE_PFAP_FAP_PARSE (gst_pfap_fap_parse_get_type())
G_DECLARE_FINAL_TYPE(GstPfapFapParse, gst_pfap_fap_parse, GST, PFAP_FAP_PARSE, GstPfapBaseParse)

GST_ELEMENT_REGISTER_DECLARE(pfapfapparse);

G_END_DECLS

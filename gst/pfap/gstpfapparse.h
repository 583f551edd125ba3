// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include "baseparse.h"

G_BEGIN_DECLS

#define GST_TYPE_PFAP_PARSE (gst_pfap_parse_get_type())
G_DECLARE_FINAL_TYPE(GstPfapParse, gst_pfap_parse, GST, PFAP_PARSE, GstPfapBaseParse)

GST_ELEMENT_REGISTER_DECLARE(pfaptextparse);

G_END_DECLS

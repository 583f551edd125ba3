// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include "baseparse.h"

G_BEGIN_DECLS

#define GST_TYPE_PFAP_TEXT_PARSE (gst_pfap_text_parse_get_type())
G_DECLARE_FINAL_TYPE(GstPfapTextParse, gst_pfap_text_parse, GST, PFAP_TEXT_PARSE, GstPfapBaseParse)

GST_ELEMENT_REGISTER_DECLARE(pfaptextparse);

G_END_DECLS

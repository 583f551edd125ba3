// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include "baseparse.h"

G_BEGIN_DECLS

#define GST_TYPE_PFAP_MARKS_PARSE (gst_pfap_marks_parse_get_type())
G_DECLARE_FINAL_TYPE(GstPfapMarksParse, gst_pfap_marks_parse, GST, PFAP_MARKS_PARSE,
                     GstPfapBaseParse)

GST_ELEMENT_REGISTER_DECLARE(pfapmarksparse);

G_END_DECLS

// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include <gst/gst.h>

G_BEGIN_DECLS

// The media type of .pfap text (docs/text-format.md), found by the typefinder "pfap" and read
// by pfaptextparse.
#define PFAP_TEXT_CAPS "text/x-pfap"

GST_TYPE_FIND_REGISTER_DECLARE(pfap);

G_END_DECLS

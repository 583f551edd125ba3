// SPDX-License-Identifier: LGPL-2.1-or-later
// The pfapalign plugin: PFAP from recorded speech and its text, by forced alignment against
// espeak-ng's speech of the text (aubio MFCCs, dynamic time warping).
#include <gst/gst.h>

#include "gstpfapalign.h"

static gboolean plugin_init(GstPlugin* plugin) { return GST_ELEMENT_REGISTER(pfapalign, plugin); }

GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, pfapalign,
                  "PFAP from recorded speech and its text by forced alignment (espeak-ng, aubio)",
                  plugin_init, VERSION, "LGPL", GST_PACKAGE_NAME, GST_PACKAGE_ORIGIN)

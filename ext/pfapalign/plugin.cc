// SPDX-License-Identifier: LGPL-2.1-or-later
// The pfapalign plugin: PFAP from recorded speech, by forced alignment of its text against
// espeak-ng's speech of it (aubio MFCCs, dynamic time warping), or without a text by
// recognition (pocketsphinx, when built with -Drecognition).
#include <gst/gst.h>

#include "gstpfapalign.h"

static gboolean plugin_init(GstPlugin* plugin) { return GST_ELEMENT_REGISTER(pfapalign, plugin); }

GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, pfapalign,
                  "PFAP from recorded speech: its text aligned (espeak-ng, aubio), or recognized "
                  "without one (pocketsphinx, or the viseme detector)",
                  plugin_init, VERSION, "LGPL", GST_PACKAGE_NAME, GST_PACKAGE_ORIGIN)

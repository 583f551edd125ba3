// SPDX-License-Identifier: LGPL-2.1-or-later
// The pfaptts plugin: text to speech with PFAP markup, through espeak-ng and aubio.
#include <gst/gst.h>

#include "gstpfaptts.h"

static gboolean plugin_init(GstPlugin* plugin) { return GST_ELEMENT_REGISTER(pfaptts, plugin); }

GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, pfaptts,
                  "Text to speech with its phonemes and facial animation parameters (espeak-ng)",
                  plugin_init, VERSION, "LGPL", GST_PACKAGE_NAME, GST_PACKAGE_ORIGIN)

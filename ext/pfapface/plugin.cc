// SPDX-License-Identifier: LGPL-2.1-or-later
// The pfapface plugin: a talking head drawn with cairo from a PFAP stream.
#include <gst/gst.h>

#include "gstpfapface.h"

static gboolean plugin_init(GstPlugin* plugin) { return GST_ELEMENT_REGISTER(pfapface, plugin); }

GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, pfapface,
                  "A talking head rendered from phonemes and facial animation parameters (cairo)",
                  plugin_init, VERSION, "LGPL", GST_PACKAGE_NAME, GST_PACKAGE_ORIGIN)

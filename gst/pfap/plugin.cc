// SPDX-License-Identifier: LGPL-2.1-or-later
// The pfap plugin: RTP payloading of PFAP streams (draft-ietf-avt-rtp-pfap-00), and their
// readers and writers of .pfap text, MPEG-4 FAP files and speech marks. Needs only GStreamer
// core, base and rtp.
#include <gst/gst.h>

#include "gstfapparse.h"
#include "gstpfapfapenc.h"
#include "gstpfapmarksenc.h"
#include "gstpfapmarksparse.h"
#include "gstpfapparse.h"
#include "gstpfaptextenc.h"
#include "gstpfaptypefind.h"
#include "gstrtppfapdepay.h"
#include "gstrtppfappay.h"

static gboolean plugin_init(GstPlugin* plugin) {
  gboolean ok = TRUE;
  ok &= GST_ELEMENT_REGISTER(rtppfappay, plugin);
  ok &= GST_ELEMENT_REGISTER(rtppfapdepay, plugin);
  ok &= GST_ELEMENT_REGISTER(pfapparse, plugin);
  ok &= GST_ELEMENT_REGISTER(pfaptextenc, plugin);
  ok &= GST_ELEMENT_REGISTER(fapparse, plugin);
  ok &= GST_ELEMENT_REGISTER(pfapfapenc, plugin);
  ok &= GST_TYPE_FIND_REGISTER(pfap, plugin);
  ok &= GST_ELEMENT_REGISTER(pfapmarksenc, plugin);
  ok &= GST_ELEMENT_REGISTER(pfapmarksparse, plugin);
  return ok;
}

GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, pfap,
                  "Phoneme and facial animation parameter (PFAP) streams: RTP payloading, "
                  ".pfap text, MPEG-4 FAP files and speech marks",
                  plugin_init, VERSION, "LGPL", GST_PACKAGE_NAME, GST_PACKAGE_ORIGIN)

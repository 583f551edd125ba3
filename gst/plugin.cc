// The pfap plugin: RTP payloading of PFAP streams (draft-ietf-avt-rtp-pfap-00), text markup
// and a talking-head renderer.
#include <gst/gst.h>

#include "gstpfapface.h"
#include "gstpfapparse.h"
#include "gstpfaptextenc.h"
#include "gstpfaptts.h"
#include "gstrtppfapdepay.h"
#include "gstrtppfappay.h"

static gboolean plugin_init(GstPlugin* plugin) {
  gboolean ok = TRUE;
  ok &= GST_ELEMENT_REGISTER(rtppfappay, plugin);
  ok &= GST_ELEMENT_REGISTER(rtppfapdepay, plugin);
  ok &= GST_ELEMENT_REGISTER(pfapparse, plugin);
  ok &= GST_ELEMENT_REGISTER(pfaptextenc, plugin);
  ok &= GST_ELEMENT_REGISTER(pfaptts, plugin);
  ok &= GST_ELEMENT_REGISTER(pfapface, plugin);
  return ok;
}

GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, pfap,
                  "Phoneme and facial animation parameter (PFAP) streams: RTP payloading, text "
                  "markup, text-to-speech and a talking head",
                  plugin_init, VERSION, "LGPL", GST_PACKAGE_NAME, GST_PACKAGE_ORIGIN)

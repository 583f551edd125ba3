// SPDX-License-Identifier: LGPL-2.1-or-later
// The pfap plugin: RTP payloading of PFAP streams (draft-ietf-avt-rtp-pfap-00), and their
// readers and writers of .pfap text, MPEG-4 FAP files and speech marks. Needs only GStreamer
// core, base and rtp.
#include <gst/gst.h>

#include <string>

#include "gstpfapfapenc.h"
#include "gstpfapfapparse.h"
#include "gstpfapmarksenc.h"
#include "gstpfapmarksparse.h"
#include "gstpfaptextenc.h"
#include "gstpfaptextparse.h"
#include "gstpfaptypefind.h"
#include "gstrtppfapdepay.h"
#include "gstrtppfappay.h"

GST_DEBUG_CATEGORY_STATIC(pfap_plugin_debug);
#define GST_CAT_DEFAULT pfap_plugin_debug

namespace {

// A factory name the readers had before they were named pfap<format>parse, as the writers
// are pfap<format>enc (docs/elements.md, "Names").
// Its type keeps the old type name, so that an element made by the old name gets the old
// default object name (`pfapparse0`).
struct DeprecatedName {
  const char* name;
  const char* replacement;
  const char* type_name;
};

constexpr DeprecatedName kPfapParse{"pfapparse", "pfaptextparse", "GstPfapParse"};
constexpr DeprecatedName kFapParse{"fapparse", "pfapfapparse", "GstFapParse"};

void deprecated_class_init(gpointer klass, gpointer data) {
  const auto* names = static_cast<const DeprecatedName*>(data);
  const std::string description = std::string("Deprecated name of ") + names->replacement +
                                  ": the same element with rank none; use " + names->replacement;
  gst_element_class_add_metadata(GST_ELEMENT_CLASS(klass), GST_ELEMENT_METADATA_DESCRIPTION,
                                 description.c_str());
}

void deprecated_instance_init(GTypeInstance* instance, gpointer klass) {
  const auto* names = static_cast<const DeprecatedName*>(
      g_type_get_qdata(G_TYPE_FROM_CLASS(klass), g_quark_from_static_string("pfap-deprecated")));
  GST_WARNING_OBJECT(instance, "%s is a deprecated name: use %s", names->name, names->replacement);
}

// Registers `names.name` as a subclass of `type` that adds nothing, with rank none, so that
// pipelines and programs that name it go on working while autoplugging picks the new name.
// A subclass rather than the same type under a second name: each factory then has its own
// description, and gst_element_get_factory() names the one the element was made from.
gboolean register_deprecated_name(GstPlugin* plugin, const DeprecatedName& names, GType type) {
  GTypeQuery query;
  g_type_query(type, &query);
  GType deprecated = g_type_from_name(names.type_name);
  if (deprecated == 0) {
    const GTypeInfo info = {static_cast<guint16>(query.class_size),
                            nullptr,
                            nullptr,
                            deprecated_class_init,
                            nullptr,
                            &names,
                            static_cast<guint16>(query.instance_size),
                            0,
                            deprecated_instance_init,
                            nullptr};
    deprecated = g_type_register_static(type, names.type_name, &info, GTypeFlags(0));
    g_type_set_qdata(deprecated, g_quark_from_static_string("pfap-deprecated"),
                     const_cast<DeprecatedName*>(&names));
  }
  return gst_element_register(plugin, names.name, GST_RANK_NONE, deprecated);
}

}  // namespace

static gboolean plugin_init(GstPlugin* plugin) {
  GST_DEBUG_CATEGORY_INIT(pfap_plugin_debug, "pfap", 0, "pfap plugin");
  gboolean ok = TRUE;
  ok &= GST_ELEMENT_REGISTER(rtppfappay, plugin);
  ok &= GST_ELEMENT_REGISTER(rtppfapdepay, plugin);
  ok &= GST_ELEMENT_REGISTER(pfaptextparse, plugin);
  ok &= GST_ELEMENT_REGISTER(pfaptextenc, plugin);
  ok &= GST_ELEMENT_REGISTER(pfapfapparse, plugin);
  ok &= GST_ELEMENT_REGISTER(pfapfapenc, plugin);
  ok &= GST_TYPE_FIND_REGISTER(pfap, plugin);
  ok &= GST_ELEMENT_REGISTER(pfapmarksenc, plugin);
  ok &= GST_ELEMENT_REGISTER(pfapmarksparse, plugin);
  ok &= register_deprecated_name(plugin, kPfapParse, GST_TYPE_PFAP_TEXT_PARSE);
  ok &= register_deprecated_name(plugin, kFapParse, GST_TYPE_PFAP_FAP_PARSE);
  return ok;
}

GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, pfap,
                  "Phoneme and facial animation parameter (PFAP) streams: RTP payloading, "
                  ".pfap text, MPEG-4 FAP files and speech marks",
                  plugin_init, VERSION, "LGPL", GST_PACKAGE_NAME, GST_PACKAGE_ORIGIN)

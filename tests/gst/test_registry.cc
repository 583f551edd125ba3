// SPDX-License-Identifier: LGPL-2.1-or-later
// The reference in docs/elements.md ("Registry reference") against the registry: every
// plugin's details, every element's metadata, rank, pad templates and own properties, and the
// typefinders, as GStreamer holds them. The reference cannot drift: a change to any of them
// fails this test until the docs say the same. On failure the test prints the block the
// registry gives, to be pasted in.
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "documented_commands.h"

namespace {

constexpr const char* kPlugins[] = {"pfap", "pfaptts", "pfapface", "pfapalign"};
constexpr const char* kSection = "## Registry reference";

std::string rank_name(guint rank) {
  switch (rank) {
    case GST_RANK_NONE:
      return "none";
    case GST_RANK_MARGINAL:
      return "marginal";
    case GST_RANK_SECONDARY:
      return "secondary";
    case GST_RANK_PRIMARY:
      return "primary";
    default:
      return std::to_string(rank);
  }
}

std::string take(gchar* text) {
  std::string s = text != nullptr ? text : "";
  g_free(text);
  return s;
}

// When a property may be set: GStreamer's mutability flags as gst-inspect words them.
std::string mutability(const GParamSpec* pspec) {
  if ((pspec->flags & G_PARAM_WRITABLE) == 0) return "read-only";
  if (pspec->flags & GST_PARAM_MUTABLE_PLAYING) return "changeable in PLAYING";
  if (pspec->flags & GST_PARAM_MUTABLE_PAUSED) return "changeable up to PAUSED";
  if (pspec->flags & GST_PARAM_MUTABLE_READY) return "changeable up to READY";
  return "changeable in NULL";
}

// A property's type, range and default, as "TYPE [MIN..MAX] default D".
std::string value_summary(GParamSpec* pspec) {
  std::ostringstream out;
  const GValue* def = g_param_spec_get_default_value(pspec);
  if (G_IS_PARAM_SPEC_INT(pspec)) {
    const auto* p = G_PARAM_SPEC_INT(pspec);
    out << "int " << p->minimum << ".." << p->maximum << ", default " << p->default_value;
  } else if (G_IS_PARAM_SPEC_UINT(pspec)) {
    const auto* p = G_PARAM_SPEC_UINT(pspec);
    out << "uint " << p->minimum << ".." << p->maximum << ", default " << p->default_value;
  } else if (G_IS_PARAM_SPEC_BOOLEAN(pspec)) {
    out << "boolean, default " << (g_value_get_boolean(def) ? "true" : "false");
  } else if (G_IS_PARAM_SPEC_STRING(pspec)) {
    const gchar* s = g_value_get_string(def);
    out << "string, default " << (s != nullptr ? std::string("\"") + s + "\"" : "none");
  } else if (G_IS_PARAM_SPEC_ENUM(pspec)) {
    GEnumClass* e = G_PARAM_SPEC_ENUM(pspec)->enum_class;
    out << "enum " << g_type_name(pspec->value_type) << " {";
    for (guint i = 0; i < e->n_values; ++i) {
      out << (i ? ", " : " ") << e->values[i].value_nick << " (" << e->values[i].value << ")";
    }
    out << " }, default " << g_enum_get_value(e, g_value_get_enum(def))->value_nick;
  } else if (GST_IS_PARAM_SPEC_FRACTION(pspec)) {
    const auto* p = GST_PARAM_SPEC_FRACTION(pspec);
    out << "fraction " << p->min_num << "/" << p->min_den << ".." << p->max_num << "/" << p->max_den
        << ", default " << p->def_num << "/" << p->def_den;
  } else {
    out << g_type_name(pspec->value_type);
  }
  return out.str();
}

std::string element_block(GstElementFactory* factory) {
  std::ostringstream out;
  auto meta = [factory](const char* key) {
    const gchar* v = gst_element_factory_get_metadata(factory, key);
    return std::string(v != nullptr ? v : "");
  };
  out << "element " << GST_OBJECT_NAME(factory) << ": " << meta(GST_ELEMENT_METADATA_LONGNAME)
      << "\n  class: " << meta(GST_ELEMENT_METADATA_KLASS)
      << "\n  rank: " << rank_name(gst_plugin_feature_get_rank(GST_PLUGIN_FEATURE(factory)))
      << "\n  description: " << meta(GST_ELEMENT_METADATA_DESCRIPTION)
      << "\n  author: " << meta(GST_ELEMENT_METADATA_AUTHOR) << "\n";
  // Templates sink first, then by name: the registry cache does not keep the order the
  // element added them in.
  std::vector<const GstStaticPadTemplate*> templates;
  for (const GList* l = gst_element_factory_get_static_pad_templates(factory); l; l = l->next) {
    templates.push_back(static_cast<const GstStaticPadTemplate*>(l->data));
  }
  std::sort(templates.begin(), templates.end(), [](const auto* a, const auto* b) {
    if (a->direction != b->direction) return a->direction == GST_PAD_SINK;
    return std::string(a->name_template) < b->name_template;
  });
  for (const GstStaticPadTemplate* t : templates) {
    GstCaps* caps = gst_static_caps_get(const_cast<GstStaticCaps*>(&t->static_caps));
    out << "  pad " << t->name_template << ": "
        << (t->direction == GST_PAD_SRC ? "src" : "sink") << ", "
        << (t->presence == GST_PAD_ALWAYS     ? "always"
            : t->presence == GST_PAD_SOMETIMES ? "sometimes"
                                                : "request")
        << ", " << take(gst_caps_to_string(caps)) << "\n";
    gst_caps_unref(caps);
  }
  // The element's own properties, by name; those of its base classes are GStreamer's.
  GstElement* element = gst_element_factory_create(factory, nullptr);
  EXPECT_NE(element, nullptr) << GST_OBJECT_NAME(factory);
  if (element == nullptr) return out.str();
  guint n = 0;
  GParamSpec** specs = g_object_class_list_properties(G_OBJECT_GET_CLASS(element), &n);
  std::vector<GParamSpec*> own;
  for (guint i = 0; i < n; ++i) {
    if (specs[i]->owner_type == G_OBJECT_TYPE(element)) own.push_back(specs[i]);
  }
  std::sort(own.begin(), own.end(), [](GParamSpec* a, GParamSpec* b) {
    return std::string(a->name) < b->name;
  });
  for (GParamSpec* p : own) {
    out << "  property " << p->name << ": " << value_summary(p) << ", " << mutability(p) << "\n";
  }
  g_free(specs);
  gst_object_unref(element);
  return out.str();
}

// The whole reference: plugins in kPlugins order, then their features by name.
std::string registry_reference() {
  std::ostringstream out;
  GstRegistry* registry = gst_registry_get();
  for (const char* name : kPlugins) {
    GstPlugin* plugin = gst_registry_find_plugin(registry, name);
    EXPECT_NE(plugin, nullptr) << "no plugin " << name << "; GST_PLUGIN_PATH?";
    if (plugin == nullptr) continue;
    out << "plugin " << name << ": " << gst_plugin_get_description(plugin)
        << "\n  license: " << gst_plugin_get_license(plugin)
        << "\n  source: " << gst_plugin_get_source(plugin)
        << "\n  package: " << gst_plugin_get_package(plugin)
        << "\n  origin: " << gst_plugin_get_origin(plugin) << "\n";
    gst_object_unref(plugin);

    GList* features = gst_registry_get_feature_list_by_plugin(registry, name);
    features = g_list_sort(features, [](gconstpointer a, gconstpointer b) {
      return g_strcmp0(GST_OBJECT_NAME(a), GST_OBJECT_NAME(b));
    });
    for (GList* l = features; l; l = l->next) {
      if (GST_IS_ELEMENT_FACTORY(l->data)) {
        out << element_block(GST_ELEMENT_FACTORY(l->data));
      } else if (GST_IS_TYPE_FIND_FACTORY(l->data)) {
        auto* find = GST_TYPE_FIND_FACTORY(l->data);
        const gchar* const* ext = gst_type_find_factory_get_extensions(find);
        out << "typefinder " << GST_OBJECT_NAME(find) << ": "
            << take(gst_caps_to_string(gst_type_find_factory_get_caps(find))) << "\n  rank: "
            << rank_name(gst_plugin_feature_get_rank(GST_PLUGIN_FEATURE(find)))
            << "\n  extensions: " << take(ext != nullptr ? g_strjoinv(", ", const_cast<gchar**>(ext)) : nullptr)
            << "\n";
      }
    }
    gst_plugin_feature_list_free(features);
  }
  return out.str();
}

// The first fenced block under kSection in docs/elements.md.
std::string documented_reference() {
  std::string block;
  bool in_block = false;
  for (const std::string& line : pfap::testing::doc_section("docs/elements.md", kSection)) {
    if (line.starts_with("```")) {
      if (in_block) return block;
      in_block = true;
    } else if (in_block) {
      block += line + "\n";
    }
  }
  return "";
}

TEST(RegistryReference, DocsSayWhatTheRegistryHolds) {
  const std::string registry = registry_reference();
  const std::string docs = documented_reference();
  EXPECT_FALSE(docs.empty()) << "no text block under \"" << kSection << "\" in docs/elements.md";
  if (registry == docs) return;
  std::istringstream r(registry), d(docs);
  std::string rl, dl;
  int n = 0;
  while (true) {
    const bool more_r = static_cast<bool>(std::getline(r, rl));
    const bool more_d = static_cast<bool>(std::getline(d, dl));
    ++n;
    if (!more_r && !more_d) break;
    if (!more_r || !more_d || rl != dl) {
      ADD_FAILURE() << "docs/elements.md, registry reference line " << n << ":\n  docs:     "
                    << (more_d ? dl : "(end)") << "\n  registry: " << (more_r ? rl : "(end)");
      break;
    }
  }
  std::cout << "The registry's reference, for docs/elements.md:\n" << registry;
}

// The reference checks what it should: every element and the typefinder are in it.
TEST(RegistryReference, CoversEveryElementAndTheTypefinder) {
  const std::string registry = registry_reference();
  for (const char* name :
       {"rtppfappay", "rtppfapdepay", "pfaptextparse", "pfaptextenc", "pfaptts", "pfapface"}) {
    EXPECT_NE(registry.find(std::string("\nelement ") + name + ":"), std::string::npos) << name;
  }
  EXPECT_NE(registry.find("\ntypefinder text/x-pfap:"), std::string::npos);
  EXPECT_EQ(registry.find("example.invalid"), std::string::npos);
}

// gst-inspect's "Binary package" and "Origin URL" are what the build was configured with
// (-Dpackage-name, -Dpackage-origin; debian/rules sets its own), on every plugin.
TEST(RegistryReference, PluginsCarryThePackageOptions) {
  for (const char* name : kPlugins) {
    GstPlugin* plugin = gst_registry_find_plugin(gst_registry_get(), name);
    ASSERT_NE(plugin, nullptr) << "no plugin " << name << "; GST_PLUGIN_PATH?";
    EXPECT_STREQ(gst_plugin_get_package(plugin), PFAP_PACKAGE_NAME) << name;
    EXPECT_STREQ(gst_plugin_get_origin(plugin), PFAP_PACKAGE_ORIGIN) << name;
    gst_object_unref(plugin);
  }
}

}  // namespace

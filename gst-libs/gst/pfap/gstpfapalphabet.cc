/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 *
 * GstPfapAlphabet is libpfap's pfap::PhonemeAlphabet (pfap/phoneme_table.h), which is static.
 */
#include "gst/pfap/gstpfapalphabet.h"

#include <string>
#include <string_view>

#include "pfap/phoneme_table.h"

static_assert(std::string_view(GST_PFAP_ALPHABET_ARPABET) == pfap::kArpabetAlphabet);
static_assert(int{GST_PFAP_VISEME_NONE} == int(pfap::Viseme::kNone));
static_assert(int{GST_PFAP_VISEME_U} == int(pfap::Viseme::kU));

// A GstPfapAlphabet pointer is a pfap::PhonemeAlphabet pointer under another name: the type
// stays incomplete, and lib() turns the pointer back into what find_alphabet() gave.

static GstPfapAlphabet *alphabet_copy(GstPfapAlphabet *alphabet) { return alphabet; }

static void alphabet_free(GstPfapAlphabet *) {}

G_DEFINE_BOXED_TYPE(GstPfapAlphabet, gst_pfap_alphabet, alphabet_copy, alphabet_free)

static const pfap::PhonemeAlphabet &lib(const GstPfapAlphabet *alphabet) {
  return *reinterpret_cast<const pfap::PhonemeAlphabet *>(alphabet);
}

// libpfap's names are std::string_views; interned once here, they are C strings that live
// as long as the process, as the alphabets do.
static const gchar *c_string(std::string_view name) {
  return g_intern_string(std::string(name).c_str());
}

const GstPfapAlphabet *gst_pfap_alphabet_find(const gchar *name) {
  g_return_val_if_fail(name != nullptr, nullptr);
  return reinterpret_cast<const GstPfapAlphabet *>(pfap::find_alphabet(name));
}

const gchar *gst_pfap_alphabet_get_name(const GstPfapAlphabet *alphabet) {
  g_return_val_if_fail(alphabet != nullptr, nullptr);
  return c_string(lib(alphabet).name);
}

guint gst_pfap_alphabet_get_n_symbols(const GstPfapAlphabet *alphabet) {
  g_return_val_if_fail(alphabet != nullptr, 0);
  return static_cast<guint>(lib(alphabet).symbols.size());
}

const gchar *gst_pfap_alphabet_get_phoneme_name(const GstPfapAlphabet *alphabet, guint8 symbol) {
  g_return_val_if_fail(alphabet != nullptr, nullptr);
  const pfap::PhonemeInfo *info = pfap::find_phoneme(lib(alphabet), symbol);
  return info != nullptr ? c_string(info->name) : nullptr;
}

GstPfapViseme gst_pfap_alphabet_get_viseme(const GstPfapAlphabet *alphabet, guint8 symbol) {
  g_return_val_if_fail(alphabet != nullptr, GST_PFAP_VISEME_NONE);
  const pfap::PhonemeInfo *info = pfap::find_phoneme(lib(alphabet), symbol);
  return info != nullptr ? static_cast<GstPfapViseme>(info->viseme) : GST_PFAP_VISEME_NONE;
}

gboolean gst_pfap_alphabet_lookup_symbol(const GstPfapAlphabet *alphabet, const gchar *name,
                                         guint8 *symbol) {
  g_return_val_if_fail(alphabet != nullptr, FALSE);
  g_return_val_if_fail(name != nullptr, FALSE);
  const std::optional<uint8_t> found = pfap::find_symbol(lib(alphabet), name);
  if (found && symbol != nullptr) *symbol = *found;
  return found.has_value();
}

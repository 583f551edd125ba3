// SPDX-License-Identifier: LGPL-2.1-or-later
// The typefinder of .pfap text: decodebin (playbin, gst-play-1.0 file.pfap) learns from it
// that a file is .pfap text, text/x-pfap, and plugs pfaptextparse for it. The rule of what reads
// as .pfap is pfap::count_text_events (lib/src/text.cc).
#include "gstpfaptypefind.h"

#include <algorithm>
#include <string_view>

#include "pfap/text.h"

namespace {

// Enough for dozens of lines; the files are short-lined text.
constexpr guint64 kPeekBytes = 4096;

void pfap_type_find(GstTypeFind* find, gpointer) {
  const guint64 length = gst_type_find_get_length(find);  // 0 when unknown
  const guint64 size = length > 0 ? std::min(length, kPeekBytes) : kPeekBytes;
  const guint8* data = gst_type_find_peek(find, 0, static_cast<guint>(size));
  if (data == nullptr) return;
  const size_t events = pfap::count_text_events(
      std::string_view(reinterpret_cast<const char*>(data), size), size == length);
  // A line or two of numbers could be other text; three event lines in a row are .pfap. Both
  // are above the plain-text typefinder's guess for the same bytes.
  if (events >= 3) {
    gst_type_find_suggest_empty_simple(find, GST_TYPE_FIND_NEARLY_CERTAIN, PFAP_TEXT_CAPS);
  } else if (events > 0) {
    gst_type_find_suggest_empty_simple(find, GST_TYPE_FIND_LIKELY, PFAP_TEXT_CAPS);
  }
}

}  // namespace

// What GST_TYPE_FIND_REGISTER_DEFINE makes, with caps it can release (it takes them as a
// plain pointer, and the registry copies them).
gboolean gst_type_find_register_pfap(GstPlugin* plugin) {
  GstCaps* caps = gst_caps_new_empty_simple(PFAP_TEXT_CAPS);
  const gboolean ok = gst_type_find_register(plugin, PFAP_TEXT_CAPS, GST_RANK_SECONDARY,
                                             pfap_type_find, "pfap", caps, nullptr, nullptr);
  gst_caps_unref(caps);
  return ok;
}

/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 *
 * Bookmarks as libpfap parses and formats them (pfap/bookmark.h); its statuses become the
 * GST_PFAP_BOOKMARK_ERROR codes.
 */
#include "gst/pfap/gstpfapbookmark.h"

#include <string>
#include <vector>

#include "gstpfap-private.h"
#include "pfap/bookmark.h"

static_assert(GST_PFAP_MAX_BOOKMARKS == pfap::kMaxBookmarksPerPhoneme);
static_assert(int{GST_PFAP_BOOKMARK_ERROR_NOT_A_BOOKMARK} ==
              int(pfap::BookmarkStatus::kNotABookmark));
static_assert(int{GST_PFAP_BOOKMARK_ERROR_UNEXPECTED_TEXT} ==
              int(pfap::BookmarkStatus::kUnexpectedText));

G_DEFINE_QUARK(gst - pfap - bookmark - error - quark, gst_pfap_bookmark_error)

GList *gst_pfap_bookmarks_parse(const gchar *text, guint max_bookmarks, GError **error) {
  g_return_val_if_fail(text != nullptr, nullptr);
  std::vector<pfap::Fap> faps;
  const pfap::BookmarkResult result = pfap::parse_bookmarks(text, faps, max_bookmarks);
  if (!result.ok()) {
    g_set_error(error, GST_PFAP_BOOKMARK_ERROR, static_cast<gint>(result.status), "at byte %zu: %s",
                result.position, pfap::to_string(result.status));
    return nullptr;
  }
  return gst_pfap_faps_from_lib(faps);
}

gchar *gst_pfap_bookmarks_format(const GList *faps) {
  std::vector<pfap::Fap> lib_faps;
  for (const GList *l = faps; l != nullptr; l = l->next)
    lib_faps.push_back(gst_pfap_fap_to_lib(*static_cast<const GstPfapFap *>(l->data)));
  std::string out;
  pfap::format_bookmarks(lib_faps, out);
  return g_strndup(out.data(), out.size());
}

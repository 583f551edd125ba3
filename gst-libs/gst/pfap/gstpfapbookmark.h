/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 */
#ifndef __GST_PFAP_BOOKMARK_H__
#define __GST_PFAP_BOOKMARK_H__

#include <gst/pfap/gstpfapevent.h>
#include <gst/pfap/pfap-prelude.h>

G_BEGIN_DECLS

/**
 * SECTION:gstpfapbookmark
 * @title: Bookmarks
 * @short_description: MPEG-4 bookmarks `<FAP n FAPfield T C>` from and to FAPs
 *
 * The bookmarks of ISO/IEC 14496-2 Annex C that a TTS text carries before a phoneme
 * (docs/format.md): `<FAP 2 e1 a1 e2 a2 T C>` for two expressions, `<FAP n a T C>` for one
 * FAP. A transition over 16383 ms is refused, not clamped.
 */

/**
 * GST_PFAP_BOOKMARK_ERROR:
 *
 * The #GError domain of bookmarks that cannot be parsed. The message starts with the byte
 * offset in the text where the problem is: "at byte 12: ...".
 */
#define GST_PFAP_BOOKMARK_ERROR (gst_pfap_bookmark_error_quark())

/**
 * GstPfapBookmarkError:
 * @GST_PFAP_BOOKMARK_ERROR_NOT_A_BOOKMARK: the text at the position does not start with "<FAP"
 * @GST_PFAP_BOOKMARK_ERROR_UNTERMINATED: "<FAP" without a closing '>'
 * @GST_PFAP_BOOKMARK_ERROR_BAD_NUMBER: a field that is not a decimal integer, or too many or
 *   too few fields
 * @GST_PFAP_BOOKMARK_ERROR_UNKNOWN_FAP: n outside 2..74
 * @GST_PFAP_BOOKMARK_ERROR_EXPRESSION_OUT_OF_RANGE: an expression outside 1..6 (or 0 with a
 *   non-zero amplitude)
 * @GST_PFAP_BOOKMARK_ERROR_AMPLITUDE_OUT_OF_RANGE: |a| over %GST_PFAP_MAX_AMPLITUDE
 * @GST_PFAP_BOOKMARK_ERROR_TRANSITION_OUT_OF_RANGE: T below 0 or over
 *   %GST_PFAP_MAX_TRANSITION_MS
 * @GST_PFAP_BOOKMARK_ERROR_CURVE_OUT_OF_RANGE: C outside 1..3
 * @GST_PFAP_BOOKMARK_ERROR_TOO_MANY_BOOKMARKS: more consecutive bookmarks than allowed
 * @GST_PFAP_BOOKMARK_ERROR_UNEXPECTED_TEXT: something other than white space between
 *   bookmarks
 *
 * Why bookmarks could not be parsed.
 */
typedef enum {
  GST_PFAP_BOOKMARK_ERROR_NOT_A_BOOKMARK = 1,
  GST_PFAP_BOOKMARK_ERROR_UNTERMINATED,
  GST_PFAP_BOOKMARK_ERROR_BAD_NUMBER,
  GST_PFAP_BOOKMARK_ERROR_UNKNOWN_FAP,
  GST_PFAP_BOOKMARK_ERROR_EXPRESSION_OUT_OF_RANGE,
  GST_PFAP_BOOKMARK_ERROR_AMPLITUDE_OUT_OF_RANGE,
  GST_PFAP_BOOKMARK_ERROR_TRANSITION_OUT_OF_RANGE,
  GST_PFAP_BOOKMARK_ERROR_CURVE_OUT_OF_RANGE,
  GST_PFAP_BOOKMARK_ERROR_TOO_MANY_BOOKMARKS,
  GST_PFAP_BOOKMARK_ERROR_UNEXPECTED_TEXT,
} GstPfapBookmarkError;

GST_PFAP_API
GQuark gst_pfap_bookmark_error_quark(void);

/**
 * GST_PFAP_MAX_BOOKMARKS:
 *
 * How many consecutive bookmarks MPEG-4 allows before one phoneme.
 */
#define GST_PFAP_MAX_BOOKMARKS 40

/**
 * gst_pfap_bookmarks_parse:
 * @text: a run of bookmarks separated by optional white space, the whole text
 * @max_bookmarks: how many bookmarks it may hold; %GST_PFAP_MAX_BOOKMARKS as MPEG-4 allows
 * @error: a #GError in the %GST_PFAP_BOOKMARK_ERROR domain
 *
 * Returns: (transfer full) (element-type GstPfapFap) (nullable): the FAPs of the bookmarks
 * in order (a `<FAP 2 ...>` gives up to two), or %NULL on error or when there are none; free
 * with g_list_free_full() and gst_pfap_fap_free()
 */
GST_PFAP_API
GList *gst_pfap_bookmarks_parse(const gchar *text, guint max_bookmarks, GError **error);

/**
 * gst_pfap_bookmarks_format:
 * @faps: (element-type GstPfapFap) (nullable): FAP targets
 *
 * Formats @faps as bookmarks in the transformed single-amplitude form `<FAP n a T C>`, one
 * per FAP, with no space between them. Values out of range are written as they are:
 * gst_pfap_bookmarks_parse() refuses them.
 *
 * Returns: (transfer full): the bookmarks
 */
GST_PFAP_API
gchar *gst_pfap_bookmarks_format(const GList *faps);

G_END_DECLS

#endif /* __GST_PFAP_BOOKMARK_H__ */

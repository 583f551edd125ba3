/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 */
#ifndef __GST_PFAP_EVENT_H__
#define __GST_PFAP_EVENT_H__

#include <gst/pfap/pfap-prelude.h>

G_BEGIN_DECLS

/**
 * SECTION:gstpfapevent
 * @title: GstPfapEvent
 * @short_description: One application/x-pfap buffer as an event
 *
 * Each application/x-pfap buffer holds one event of the MPEG-4 TtsFAPInterface
 * (docs/markup.md): a phoneme with the FAPs (bookmarks) that start with it, the FAP targets
 * restored by recovery after a loss, or the whole FAP state. The buffer's PTS is the event's
 * time (a phoneme's start), its duration a phoneme's duration.
 *
 * gst_pfap_event_new_from_buffer() reads a buffer from appsink;
 * gst_pfap_event_to_buffer() makes one for appsrc.
 */

/**
 * GST_PFAP_CAPS:
 *
 * The media type of PFAP markup buffers, for caps and appsink/appsrc.
 */
#define GST_PFAP_CAPS "application/x-pfap"

/**
 * GST_PFAP_MIN_FAP_INDEX:
 *
 * The lowest FAP index an event carries (FAPs 1 and 2, viseme and expression, are not FAP
 * targets).
 */
#define GST_PFAP_MIN_FAP_INDEX 3

/**
 * GST_PFAP_MAX_FAP_INDEX:
 *
 * The highest FAP index; 69..74 are the MPEG-4 expressions 1..6 (joy, sadness, anger, fear,
 * disgust, surprise).
 */
#define GST_PFAP_MAX_FAP_INDEX 74

/**
 * GST_PFAP_MAX_AMPLITUDE:
 *
 * The largest |amplitude| of a FAP.
 */
#define GST_PFAP_MAX_AMPLITUDE 2529600

/**
 * GST_PFAP_MAX_TRANSITION_MS:
 *
 * The longest FAP transition, in milliseconds.
 */
#define GST_PFAP_MAX_TRANSITION_MS 16383

/**
 * GST_PFAP_MAX_DURATION_MS:
 *
 * The longest phoneme, in milliseconds.
 */
#define GST_PFAP_MAX_DURATION_MS 4095

/**
 * GstPfapEventKind:
 * @GST_PFAP_EVENT_KIND_PHONEME: a phoneme and the FAPs that start with it
 * @GST_PFAP_EVENT_KIND_RECOVERED: FAP targets restored by recovery information after a loss;
 *   each transition is the time still remaining at the buffer's time
 * @GST_PFAP_EVENT_KIND_COMPLETE: the whole FAP state; every FAP not listed is 0
 *
 * What an event is.
 */
typedef enum {
  GST_PFAP_EVENT_KIND_PHONEME = 1,
  GST_PFAP_EVENT_KIND_RECOVERED = 2,
  GST_PFAP_EVENT_KIND_COMPLETE = 3,
} GstPfapEventKind;

/**
 * GstPfapEventFlags:
 * @GST_PFAP_EVENT_FLAG_NONE: no flag
 * @GST_PFAP_EVENT_FLAG_STRESS: the phoneme is stressed
 * @GST_PFAP_EVENT_FLAG_WORD_BEGIN: the phoneme begins a word
 * @GST_PFAP_EVENT_FLAG_END_OF_TEXT: the text ends after this phoneme
 * @GST_PFAP_EVENT_FLAG_SENTENCE_START: the first phoneme of a sentence (the RTP marker bit)
 * @GST_PFAP_EVENT_FLAG_UNCERTAIN: the receiver's FAP state may be incomplete after a loss
 *
 * An event's flags. Stress, word begin and end of text belong to a phoneme: a state event
 * carries them as they are given.
 */
typedef enum /*< flags >*/ {
  GST_PFAP_EVENT_FLAG_NONE = 0,
  GST_PFAP_EVENT_FLAG_STRESS = 1 << 0,
  GST_PFAP_EVENT_FLAG_WORD_BEGIN = 1 << 1,
  GST_PFAP_EVENT_FLAG_END_OF_TEXT = 1 << 2,
  GST_PFAP_EVENT_FLAG_SENTENCE_START = 1 << 3,
  GST_PFAP_EVENT_FLAG_UNCERTAIN = 1 << 4,
} GstPfapEventFlags;

/**
 * GstPfapCurve:
 * @GST_PFAP_CURVE_LINEAR: straight to the target over the transition
 * @GST_PFAP_CURVE_TRIANGLE: to the target over half the transition, back over the other half
 * @GST_PFAP_CURVE_SPLINE: smoothly (cubic Hermite) to the target over the transition
 *
 * How a FAP moves to its target (docs/format.md).
 */
typedef enum {
  GST_PFAP_CURVE_LINEAR = 1,
  GST_PFAP_CURVE_TRIANGLE = 2,
  GST_PFAP_CURVE_SPLINE = 3,
} GstPfapCurve;

/**
 * GST_PFAP_EVENT_ERROR:
 *
 * The #GError domain of events that cannot be read or written.
 */
#define GST_PFAP_EVENT_ERROR (gst_pfap_event_error_quark())

/**
 * GstPfapEventError:
 * @GST_PFAP_EVENT_ERROR_MALFORMED: the bytes are not a valid application/x-pfap event
 * @GST_PFAP_EVENT_ERROR_OUT_OF_RANGE: a value of the event is out of its range
 *
 * Why an event could not be read or written.
 */
typedef enum {
  GST_PFAP_EVENT_ERROR_MALFORMED,
  GST_PFAP_EVENT_ERROR_OUT_OF_RANGE,
} GstPfapEventError;

GST_PFAP_API
GQuark gst_pfap_event_error_quark(void);

/**
 * GstPfapFap:
 * @index: the FAP, %GST_PFAP_MIN_FAP_INDEX..%GST_PFAP_MAX_FAP_INDEX
 * @curve: how it moves to @amplitude
 * @transition_ms: how long it takes, 0..%GST_PFAP_MAX_TRANSITION_MS
 * @amplitude: the target, in the FAP's own units, |amplitude| <= %GST_PFAP_MAX_AMPLITUDE
 *
 * One FAP target: a bookmark's effect on one FAP, or a recovered FAP.
 */
typedef struct {
  guint8 index;
  GstPfapCurve curve;
  guint16 transition_ms;
  gint32 amplitude;
} GstPfapFap;

#define GST_TYPE_PFAP_FAP (gst_pfap_fap_get_type())

GST_PFAP_API
GType gst_pfap_fap_get_type(void);

/**
 * gst_pfap_fap_new: (constructor)
 * @index: the FAP
 * @amplitude: its target
 * @transition_ms: how long it takes to reach it
 * @curve: how it moves
 *
 * Returns: (transfer full): a new FAP target. Values are checked where they are used (an
 * event written, a bookmark formatted), not here.
 */
GST_PFAP_API
GstPfapFap *gst_pfap_fap_new(guint8 index, gint32 amplitude, guint16 transition_ms,
                             GstPfapCurve curve);

/**
 * gst_pfap_fap_copy:
 * @fap: a #GstPfapFap
 *
 * Returns: (transfer full): a copy of @fap
 */
GST_PFAP_API
GstPfapFap *gst_pfap_fap_copy(const GstPfapFap *fap);

/**
 * gst_pfap_fap_free:
 * @fap: (transfer full): a #GstPfapFap
 */
GST_PFAP_API
void gst_pfap_fap_free(GstPfapFap *fap);

/**
 * GstPfapEvent:
 *
 * One application/x-pfap event; opaque, read and changed with the functions below.
 */
typedef struct _GstPfapEvent GstPfapEvent;

#define GST_TYPE_PFAP_EVENT (gst_pfap_event_get_type())

GST_PFAP_API
GType gst_pfap_event_get_type(void);

/**
 * gst_pfap_event_new: (constructor)
 * @kind: what the event is
 *
 * Returns: (transfer full): an event of @kind with no flags, no FAPs, and (for a phoneme)
 * symbol, duration and f0 0.
 */
GST_PFAP_API
GstPfapEvent *gst_pfap_event_new(GstPfapEventKind kind);

/**
 * gst_pfap_event_new_from_data: (constructor)
 * @data: (array length=size) (element-type guint8): the bytes of one event
 * @size: their number
 * @error: a #GError for a %GST_PFAP_EVENT_ERROR_MALFORMED event
 *
 * Reads an event from its bytes, the whole of @data.
 *
 * Returns: (transfer full) (nullable): the event, or %NULL when the bytes are not a valid
 * event (an unknown kind or flag, a size that does not match the number of FAPs, a value out
 * of range).
 */
GST_PFAP_API
GstPfapEvent *gst_pfap_event_new_from_data(const guint8 *data, gsize size, GError **error);

/**
 * gst_pfap_event_new_from_buffer: (constructor)
 * @buffer: an application/x-pfap buffer, from appsink for example
 * @error: a #GError for a %GST_PFAP_EVENT_ERROR_MALFORMED event
 *
 * Reads the event in @buffer. Its time is the buffer's: GST_BUFFER_PTS().
 *
 * Returns: (transfer full) (nullable): the event, or %NULL when @buffer does not hold a
 * valid event.
 */
GST_PFAP_API
GstPfapEvent *gst_pfap_event_new_from_buffer(GstBuffer *buffer, GError **error);

/**
 * gst_pfap_event_to_buffer:
 * @event: a #GstPfapEvent
 * @error: a #GError for a %GST_PFAP_EVENT_ERROR_OUT_OF_RANGE value
 *
 * Writes @event into a new buffer for appsrc, after gst_init(). A phoneme's buffer has the
 * phoneme's duration; set its PTS to the phoneme's start. A state event's symbol, duration and f0
 * are written as 0.
 *
 * Returns: (transfer full) (nullable): the buffer, or %NULL when a value is out of range
 * (the message says which).
 */
GST_PFAP_API
GstBuffer *gst_pfap_event_to_buffer(const GstPfapEvent *event, GError **error);

/**
 * gst_pfap_event_copy:
 * @event: a #GstPfapEvent
 *
 * Returns: (transfer full): a copy of @event
 */
GST_PFAP_API
GstPfapEvent *gst_pfap_event_copy(const GstPfapEvent *event);

/**
 * gst_pfap_event_free:
 * @event: (transfer full): a #GstPfapEvent
 */
GST_PFAP_API
void gst_pfap_event_free(GstPfapEvent *event);

/**
 * gst_pfap_event_get_kind:
 * @event: a #GstPfapEvent
 *
 * Returns: what @event is
 */
GST_PFAP_API
GstPfapEventKind gst_pfap_event_get_kind(const GstPfapEvent *event);

/**
 * gst_pfap_event_set_kind:
 * @event: a #GstPfapEvent
 * @kind: what it is
 */
GST_PFAP_API
void gst_pfap_event_set_kind(GstPfapEvent *event, GstPfapEventKind kind);

/**
 * gst_pfap_event_get_flags:
 * @event: a #GstPfapEvent
 *
 * Returns: the flags of @event
 */
GST_PFAP_API
GstPfapEventFlags gst_pfap_event_get_flags(const GstPfapEvent *event);

/**
 * gst_pfap_event_set_flags:
 * @event: a #GstPfapEvent
 * @flags: its flags
 */
GST_PFAP_API
void gst_pfap_event_set_flags(GstPfapEvent *event, GstPfapEventFlags flags);

/**
 * gst_pfap_event_get_symbol:
 * @event: a #GstPfapEvent
 *
 * Returns: the phoneme's symbol in the stream's alphabet (gst_pfap_alphabet_find())
 */
GST_PFAP_API
guint8 gst_pfap_event_get_symbol(const GstPfapEvent *event);

/**
 * gst_pfap_event_set_symbol:
 * @event: a #GstPfapEvent
 * @symbol: the phoneme's symbol
 */
GST_PFAP_API
void gst_pfap_event_set_symbol(GstPfapEvent *event, guint8 symbol);

/**
 * gst_pfap_event_get_duration_ms:
 * @event: a #GstPfapEvent
 *
 * Returns: the phoneme's duration in milliseconds
 */
GST_PFAP_API
guint16 gst_pfap_event_get_duration_ms(const GstPfapEvent *event);

/**
 * gst_pfap_event_set_duration_ms:
 * @event: a #GstPfapEvent
 * @duration_ms: the phoneme's duration, 0..%GST_PFAP_MAX_DURATION_MS
 */
GST_PFAP_API
void gst_pfap_event_set_duration_ms(GstPfapEvent *event, guint16 duration_ms);

/**
 * gst_pfap_event_get_f0:
 * @event: a #GstPfapEvent
 *
 * Returns: the phoneme's average fundamental frequency in units of 2 Hz, as the wire
 * carries it (0: unknown or unvoiced)
 */
GST_PFAP_API
guint8 gst_pfap_event_get_f0(const GstPfapEvent *event);

/**
 * gst_pfap_event_set_f0:
 * @event: a #GstPfapEvent
 * @f0: the phoneme's average fundamental frequency in units of 2 Hz
 */
GST_PFAP_API
void gst_pfap_event_set_f0(GstPfapEvent *event, guint8 f0);

/**
 * gst_pfap_event_get_n_faps:
 * @event: a #GstPfapEvent
 *
 * Returns: the number of FAPs of @event
 */
GST_PFAP_API
guint gst_pfap_event_get_n_faps(const GstPfapEvent *event);

/**
 * gst_pfap_event_get_fap:
 * @event: a #GstPfapEvent
 * @i: which, from 0
 *
 * Returns: (transfer full) (nullable): a copy of FAP @i of @event, or %NULL past the last
 */
GST_PFAP_API
GstPfapFap *gst_pfap_event_get_fap(const GstPfapEvent *event, guint i);

/**
 * gst_pfap_event_get_faps:
 * @event: a #GstPfapEvent
 *
 * Returns: (transfer full) (element-type GstPfapFap): copies of the FAPs of @event, in order;
 * free with g_list_free_full() and gst_pfap_fap_free()
 */
GST_PFAP_API
GList *gst_pfap_event_get_faps(const GstPfapEvent *event);

/**
 * gst_pfap_event_add_fap:
 * @event: a #GstPfapEvent
 * @fap: a FAP target to append
 */
GST_PFAP_API
void gst_pfap_event_add_fap(GstPfapEvent *event, const GstPfapFap *fap);

/**
 * gst_pfap_event_clear_faps:
 * @event: a #GstPfapEvent
 *
 * Removes every FAP from @event.
 */
GST_PFAP_API
void gst_pfap_event_clear_faps(GstPfapEvent *event);

G_DEFINE_AUTOPTR_CLEANUP_FUNC(GstPfapFap, gst_pfap_fap_free)
G_DEFINE_AUTOPTR_CLEANUP_FUNC(GstPfapEvent, gst_pfap_event_free)

G_END_DECLS

#endif /* __GST_PFAP_EVENT_H__ */

/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 *
 * GstPfapEvent wraps pfap::MarkupEvent: the byte layout and its rules stay in libpfap
 * (pfap/markup.h), and buffers are read and written as the plugins do (markupbuffer.h); this
 * file only converts types and turns refusals into GErrors.
 */
#include "gst/pfap/gstpfapevent.h"

#include <string_view>

#include "gstpfap-private.h"
#include "markupbuffer.h"
#include "pfap/markup.h"
#include "pfap/model.h"

// The C API names the values libpfap defines: one definition each, checked here.
static_assert(std::string_view(GST_PFAP_CAPS) == PFAP_MARKUP_CAPS);
static_assert(GST_PFAP_MIN_FAP_INDEX == pfap::kMinFapIndex);
static_assert(GST_PFAP_MAX_FAP_INDEX == pfap::kMaxFapIndex);
static_assert(GST_PFAP_MAX_AMPLITUDE == pfap::kMaxAmplitude);
static_assert(GST_PFAP_MAX_TRANSITION_MS == pfap::kMaxTransitionMs);
static_assert(GST_PFAP_MAX_DURATION_MS == pfap::kMaxPhonemeDurationMs);
static_assert(int{GST_PFAP_EVENT_KIND_PHONEME} == PFAP_EVENT_PHONEME);
static_assert(int{GST_PFAP_EVENT_KIND_RECOVERED} == PFAP_EVENT_RECOVERED);
static_assert(int{GST_PFAP_EVENT_KIND_COMPLETE} == PFAP_EVENT_COMPLETE);
static_assert(int{GST_PFAP_EVENT_FLAG_STRESS} == PFAP_FLAG_STRESS);
static_assert(int{GST_PFAP_EVENT_FLAG_WORD_BEGIN} == PFAP_FLAG_WORD_BEGIN);
static_assert(int{GST_PFAP_EVENT_FLAG_END_OF_TEXT} == PFAP_FLAG_END_OF_TEXT);
static_assert(int{GST_PFAP_EVENT_FLAG_SENTENCE_START} == PFAP_FLAG_SENTENCE_START);
static_assert(int{GST_PFAP_EVENT_FLAG_UNCERTAIN} == PFAP_FLAG_UNCERTAIN);
static_assert(int{GST_PFAP_CURVE_LINEAR} == int(pfap::Curve::kLinear));
static_assert(int{GST_PFAP_CURVE_TRIANGLE} == int(pfap::Curve::kTriangle));
static_assert(int{GST_PFAP_CURVE_SPLINE} == int(pfap::Curve::kSpline));

G_DEFINE_QUARK(gst - pfap - event - error - quark, gst_pfap_event_error)

G_DEFINE_BOXED_TYPE(GstPfapFap, gst_pfap_fap, gst_pfap_fap_copy, gst_pfap_fap_free)
G_DEFINE_BOXED_TYPE(GstPfapEvent, gst_pfap_event, gst_pfap_event_copy, gst_pfap_event_free)

pfap::Fap gst_pfap_fap_to_lib(const GstPfapFap &fap) {
  return {fap.index, fap.amplitude, fap.transition_ms, static_cast<pfap::Curve>(fap.curve)};
}

GstPfapFap *gst_pfap_fap_from_lib(const pfap::Fap &fap) {
  return gst_pfap_fap_new(fap.index, fap.amplitude, fap.transition_ms,
                          static_cast<GstPfapCurve>(fap.curve));
}

gchar *gst_pfap_fap_out_of_range(const pfap::Fap &fap) {
  return g_strdup_printf(
      "index %u, amplitude %d, transition %u ms, curve %u is out of range "
      "(index %d..%d, |amplitude| <= %d, transition <= %u ms, curve 1..3)",
      fap.index, fap.amplitude, fap.transition_ms, unsigned(fap.curve), pfap::kMinFapIndex,
      pfap::kMaxFapIndex, pfap::kMaxAmplitude, unsigned{pfap::kMaxTransitionMs});
}

GstPfapFap *gst_pfap_fap_new(guint8 index, gint32 amplitude, guint16 transition_ms,
                             GstPfapCurve curve) {
  GstPfapFap *fap = g_new(GstPfapFap, 1);
  *fap = {index, curve, transition_ms, amplitude};
  return fap;
}

GstPfapFap *gst_pfap_fap_copy(const GstPfapFap *fap) {
  g_return_val_if_fail(fap != nullptr, nullptr);
  return static_cast<GstPfapFap *>(g_memdup2(fap, sizeof *fap));
}

void gst_pfap_fap_free(GstPfapFap *fap) { g_free(fap); }

GstPfapEvent *gst_pfap_event_new(GstPfapEventKind kind) {
  auto *event = new GstPfapEvent;
  event->event.kind = static_cast<PfapEventKind>(kind);
  return event;
}

GstPfapEvent *gst_pfap_event_new_from_data(const guint8 *data, gsize size, GError **error) {
  g_return_val_if_fail(data != nullptr || size == 0, nullptr);
  auto *event = new GstPfapEvent;
  if (!pfap::read_markup({data, size}, event->event)) {
    delete event;
    g_set_error(error, GST_PFAP_EVENT_ERROR, GST_PFAP_EVENT_ERROR_MALFORMED,
                "%" G_GSIZE_FORMAT " bytes are not a valid " GST_PFAP_CAPS
                " event (an unknown "
                "kind or flag, a size that does not match the number of FAPs, or a value out "
                "of range)",
                size);
    return nullptr;
  }
  return event;
}

GstPfapEvent *gst_pfap_event_new_from_buffer(GstBuffer *buffer, GError **error) {
  g_return_val_if_fail(GST_IS_BUFFER(buffer), nullptr);
  const PfapBufferBytes bytes(buffer);
  if (!bytes.mapped()) {
    g_set_error(error, GST_PFAP_EVENT_ERROR, GST_PFAP_EVENT_ERROR_MALFORMED,
                "the buffer cannot be mapped for reading");
    return nullptr;
  }
  return gst_pfap_event_new_from_data(bytes.bytes().data(), bytes.bytes().size(), error);
}

// Why write_markup refuses `event`, in words, or nullptr if it does not. The ranges are
// libpfap's (is_valid); this only says which value broke one.
static gchar *out_of_range(const pfap::MarkupEvent &event) {
  const gint kind = event.kind;
  if (kind < PFAP_EVENT_PHONEME || kind > PFAP_EVENT_COMPLETE)
    return g_strdup_printf("unknown event kind %d", kind);
  if (event.kind == PFAP_EVENT_PHONEME && !pfap::is_valid(event.phoneme))
    return g_strdup_printf("phoneme duration %u ms is over %u ms", event.phoneme.duration_ms,
                           unsigned{pfap::kMaxPhonemeDurationMs});
  if (event.faps.size() > G_MAXUINT16)
    return g_strdup_printf("%zu FAPs are more than an event holds (%u)", event.faps.size(),
                           unsigned{G_MAXUINT16});
  for (size_t i = 0; i < event.faps.size(); ++i) {
    if (!pfap::is_valid(event.faps[i])) {
      gchar *why = gst_pfap_fap_out_of_range(event.faps[i]);
      gchar *message = g_strdup_printf("FAP %zu: %s", i, why);
      g_free(why);
      return message;
    }
  }
  return nullptr;
}

GstBuffer *gst_pfap_event_to_buffer(const GstPfapEvent *event, GError **error) {
  g_return_val_if_fail(event != nullptr, nullptr);
  // GStreamer's allocator exists only after gst_init(): say so rather than crash in it.
  g_return_val_if_fail(gst_is_initialized(), nullptr);
  const pfap::MarkupEvent &e = event->event;
  GstBuffer *buffer = pfap_buffer_new(e);
  if (buffer == nullptr) {
    gchar *why = out_of_range(e);
    g_set_error(error, GST_PFAP_EVENT_ERROR, GST_PFAP_EVENT_ERROR_OUT_OF_RANGE,
                "the event cannot be written: %s",
                why != nullptr ? why : "a value is out of range");
    g_free(why);
    return nullptr;
  }
  if (e.kind == PFAP_EVENT_PHONEME)
    GST_BUFFER_DURATION(buffer) = e.phoneme.duration_ms * GST_MSECOND;
  return buffer;
}

GstPfapEvent *gst_pfap_event_copy(const GstPfapEvent *event) {
  g_return_val_if_fail(event != nullptr, nullptr);
  return new GstPfapEvent(*event);
}

void gst_pfap_event_free(GstPfapEvent *event) { delete event; }

GstPfapEventKind gst_pfap_event_get_kind(const GstPfapEvent *event) {
  g_return_val_if_fail(event != nullptr, GST_PFAP_EVENT_KIND_PHONEME);
  return static_cast<GstPfapEventKind>(event->event.kind);
}

void gst_pfap_event_set_kind(GstPfapEvent *event, GstPfapEventKind kind) {
  g_return_if_fail(event != nullptr);
  event->event.kind = static_cast<PfapEventKind>(kind);
}

GstPfapEventFlags gst_pfap_event_get_flags(const GstPfapEvent *event) {
  g_return_val_if_fail(event != nullptr, GST_PFAP_EVENT_FLAG_NONE);
  const pfap::MarkupEvent &e = event->event;
  guint flags = 0;
  if (e.phoneme.stress) flags |= GST_PFAP_EVENT_FLAG_STRESS;
  if (e.phoneme.word_begin) flags |= GST_PFAP_EVENT_FLAG_WORD_BEGIN;
  if (e.phoneme.end_of_text) flags |= GST_PFAP_EVENT_FLAG_END_OF_TEXT;
  if (e.sentence_start) flags |= GST_PFAP_EVENT_FLAG_SENTENCE_START;
  if (e.uncertain) flags |= GST_PFAP_EVENT_FLAG_UNCERTAIN;
  return static_cast<GstPfapEventFlags>(flags);
}

void gst_pfap_event_set_flags(GstPfapEvent *event, GstPfapEventFlags flags) {
  g_return_if_fail(event != nullptr);
  pfap::MarkupEvent &e = event->event;
  e.phoneme.stress = (flags & GST_PFAP_EVENT_FLAG_STRESS) != 0;
  e.phoneme.word_begin = (flags & GST_PFAP_EVENT_FLAG_WORD_BEGIN) != 0;
  e.phoneme.end_of_text = (flags & GST_PFAP_EVENT_FLAG_END_OF_TEXT) != 0;
  e.sentence_start = (flags & GST_PFAP_EVENT_FLAG_SENTENCE_START) != 0;
  e.uncertain = (flags & GST_PFAP_EVENT_FLAG_UNCERTAIN) != 0;
}

guint8 gst_pfap_event_get_symbol(const GstPfapEvent *event) {
  g_return_val_if_fail(event != nullptr, 0);
  return event->event.phoneme.symbol;
}

void gst_pfap_event_set_symbol(GstPfapEvent *event, guint8 symbol) {
  g_return_if_fail(event != nullptr);
  event->event.phoneme.symbol = symbol;
}

guint16 gst_pfap_event_get_duration_ms(const GstPfapEvent *event) {
  g_return_val_if_fail(event != nullptr, 0);
  return event->event.phoneme.duration_ms;
}

void gst_pfap_event_set_duration_ms(GstPfapEvent *event, guint16 duration_ms) {
  g_return_if_fail(event != nullptr);
  event->event.phoneme.duration_ms = duration_ms;
}

guint8 gst_pfap_event_get_f0(const GstPfapEvent *event) {
  g_return_val_if_fail(event != nullptr, 0);
  return event->event.phoneme.f0;
}

void gst_pfap_event_set_f0(GstPfapEvent *event, guint8 f0) {
  g_return_if_fail(event != nullptr);
  event->event.phoneme.f0 = f0;
}

guint gst_pfap_event_get_n_faps(const GstPfapEvent *event) {
  g_return_val_if_fail(event != nullptr, 0);
  return static_cast<guint>(event->event.faps.size());
}

GstPfapFap *gst_pfap_event_get_fap(const GstPfapEvent *event, guint i) {
  g_return_val_if_fail(event != nullptr, nullptr);
  if (i >= event->event.faps.size()) return nullptr;
  return gst_pfap_fap_from_lib(event->event.faps[i]);
}

GList *gst_pfap_event_get_faps(const GstPfapEvent *event) {
  g_return_val_if_fail(event != nullptr, nullptr);
  return gst_pfap_faps_from_lib(event->event.faps);
}

GList *gst_pfap_faps_from_lib(const std::vector<pfap::Fap> &faps) {
  GList *out = nullptr;
  for (auto f = faps.rbegin(); f != faps.rend(); ++f)
    out = g_list_prepend(out, gst_pfap_fap_from_lib(*f));
  return out;
}

void gst_pfap_event_add_fap(GstPfapEvent *event, const GstPfapFap *fap) {
  g_return_if_fail(event != nullptr);
  g_return_if_fail(fap != nullptr);
  event->event.faps.push_back(gst_pfap_fap_to_lib(*fap));
}

void gst_pfap_event_clear_faps(GstPfapEvent *event) {
  g_return_if_fail(event != nullptr);
  event->event.faps.clear();
}

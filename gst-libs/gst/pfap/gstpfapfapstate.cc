/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 *
 * GstPfapFapState wraps pfap::FapState, which holds the curves' rules; events are applied as
 * pfap::apply_markup says.
 */
#include "gst/pfap/gstpfapfapstate.h"

#include "gstpfap-private.h"
#include "pfap/fap_state.h"
#include "pfap/model.h"

// The lock lets an appsink callback apply events on the streaming thread while the
// application's own thread asks amplitudes.
struct _GstPfapFapState {
  GObject parent;
  GMutex lock;
  pfap::FapState *state;
};

G_DEFINE_TYPE(GstPfapFapState, gst_pfap_fap_state, G_TYPE_OBJECT)

static void gst_pfap_fap_state_finalize(GObject *object) {
  GstPfapFapState *self = GST_PFAP_FAP_STATE(object);
  delete self->state;
  g_mutex_clear(&self->lock);
  G_OBJECT_CLASS(gst_pfap_fap_state_parent_class)->finalize(object);
}

static void gst_pfap_fap_state_class_init(GstPfapFapStateClass *klass) {
  G_OBJECT_CLASS(klass)->finalize = gst_pfap_fap_state_finalize;
}

static void gst_pfap_fap_state_init(GstPfapFapState *self) {
  g_mutex_init(&self->lock);
  self->state = new pfap::FapState;
}

GstPfapFapState *gst_pfap_fap_state_new(void) {
  return GST_PFAP_FAP_STATE(g_object_new(GST_TYPE_PFAP_FAP_STATE, nullptr));
}

// libpfap's FapState takes only valid FAPs (it indexes its tracks by FAP index).
static gboolean check_fap(const pfap::Fap &fap, GError **error) {
  if (pfap::is_valid(fap)) return TRUE;
  gchar *why = gst_pfap_fap_out_of_range(fap);
  g_set_error(error, GST_PFAP_EVENT_ERROR, GST_PFAP_EVENT_ERROR_OUT_OF_RANGE, "FAP %s", why);
  g_free(why);
  return FALSE;
}

static int64_t to_ns(GstClockTime time) {
  return static_cast<int64_t>(MIN(time, static_cast<GstClockTime>(G_MAXINT64)));
}

gboolean gst_pfap_fap_state_apply_event(GstPfapFapState *state, const GstPfapEvent *event,
                                        GstClockTime time, GError **error) {
  g_return_val_if_fail(GST_IS_PFAP_FAP_STATE(state), FALSE);
  g_return_val_if_fail(event != nullptr, FALSE);
  g_return_val_if_fail(GST_CLOCK_TIME_IS_VALID(time), FALSE);
  for (const pfap::Fap &fap : event->event.faps) {
    if (!check_fap(fap, error)) return FALSE;
  }
  g_mutex_lock(&state->lock);
  pfap::apply_markup(event->event, to_ns(time), *state->state);
  g_mutex_unlock(&state->lock);
  return TRUE;
}

gboolean gst_pfap_fap_state_apply_fap(GstPfapFapState *state, const GstPfapFap *fap,
                                      GstClockTime time, GError **error) {
  g_return_val_if_fail(GST_IS_PFAP_FAP_STATE(state), FALSE);
  g_return_val_if_fail(fap != nullptr, FALSE);
  g_return_val_if_fail(GST_CLOCK_TIME_IS_VALID(time), FALSE);
  const pfap::Fap f = gst_pfap_fap_to_lib(*fap);
  if (!check_fap(f, error)) return FALSE;
  g_mutex_lock(&state->lock);
  state->state->apply(f, to_ns(time));
  g_mutex_unlock(&state->lock);
  return TRUE;
}

#define VALID_INDEX(index) ((index) >= GST_PFAP_MIN_FAP_INDEX && (index) <= GST_PFAP_MAX_FAP_INDEX)

gdouble gst_pfap_fap_state_get_amplitude(GstPfapFapState *state, guint index, GstClockTime time) {
  g_return_val_if_fail(GST_IS_PFAP_FAP_STATE(state), 0.0);
  g_return_val_if_fail(VALID_INDEX(index), 0.0);
  g_return_val_if_fail(GST_CLOCK_TIME_IS_VALID(time), 0.0);
  g_mutex_lock(&state->lock);
  const gdouble amplitude = state->state->amplitude(static_cast<int>(index), to_ns(time));
  g_mutex_unlock(&state->lock);
  return amplitude;
}

gint32 gst_pfap_fap_state_get_settled(GstPfapFapState *state, guint index) {
  g_return_val_if_fail(GST_IS_PFAP_FAP_STATE(state), 0);
  g_return_val_if_fail(VALID_INDEX(index), 0);
  g_mutex_lock(&state->lock);
  const gint32 settled = state->state->settled(static_cast<int>(index));
  g_mutex_unlock(&state->lock);
  return settled;
}

gboolean gst_pfap_fap_state_is_at_rest(GstPfapFapState *state, guint index, GstClockTime time) {
  g_return_val_if_fail(GST_IS_PFAP_FAP_STATE(state), TRUE);
  g_return_val_if_fail(VALID_INDEX(index), TRUE);
  g_return_val_if_fail(GST_CLOCK_TIME_IS_VALID(time), TRUE);
  g_mutex_lock(&state->lock);
  const gboolean at_rest = state->state->at_rest(static_cast<int>(index), to_ns(time));
  g_mutex_unlock(&state->lock);
  return at_rest;
}

void gst_pfap_fap_state_reset(GstPfapFapState *state) {
  g_return_if_fail(GST_IS_PFAP_FAP_STATE(state));
  g_mutex_lock(&state->lock);
  state->state->reset();
  g_mutex_unlock(&state->lock);
}

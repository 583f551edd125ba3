/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 */
#ifndef __GST_PFAP_FAP_STATE_H__
#define __GST_PFAP_FAP_STATE_H__

#include <gst/pfap/gstpfapevent.h>
#include <gst/pfap/pfap-prelude.h>

G_BEGIN_DECLS

/**
 * SECTION:gstpfapfapstate
 * @title: GstPfapFapState
 * @short_description: The amplitude of every FAP over time at a receiver
 *
 * Apply each event at its buffer's time, then ask the amplitude of any FAP at any later time
 * to drive an avatar, as pfapface does. Each FAP moves from the amplitude it had reached to
 * its target along its curve (docs/format.md). Times are in nanoseconds, on one clock: the
 * buffers' PTS, or running time. One state may be used from several threads: an appsink
 * callback applying events while the application's thread draws.
 */

#define GST_TYPE_PFAP_FAP_STATE (gst_pfap_fap_state_get_type())

GST_PFAP_API
G_DECLARE_FINAL_TYPE(GstPfapFapState, gst_pfap_fap_state, GST, PFAP_FAP_STATE, GObject)

/**
 * gst_pfap_fap_state_new: (constructor)
 *
 * Returns: (transfer full): a state with every FAP at 0
 */
GST_PFAP_API
GstPfapFapState *gst_pfap_fap_state_new(void);

/**
 * gst_pfap_fap_state_apply_event:
 * @state: a #GstPfapFapState
 * @event: an event
 * @time: its time (its buffer's PTS), in nanoseconds
 * @error: a #GError for a %GST_PFAP_EVENT_ERROR_OUT_OF_RANGE FAP
 *
 * Applies @event: a complete state first returns every FAP to 0, then each FAP of @event
 * starts its transition at @time. Events must come in time order. An event with a FAP out
 * of range (only one built by hand can have one) changes nothing.
 *
 * Returns: whether @event was applied
 */
GST_PFAP_API
gboolean gst_pfap_fap_state_apply_event(GstPfapFapState *state, const GstPfapEvent *event,
                                        GstClockTime time, GError **error);

/**
 * gst_pfap_fap_state_apply_fap:
 * @state: a #GstPfapFapState
 * @fap: a FAP target
 * @time: when its transition starts, in nanoseconds
 * @error: a #GError for a %GST_PFAP_EVENT_ERROR_OUT_OF_RANGE FAP
 *
 * Starts the transition of one FAP. Targets of one FAP must come in time order.
 *
 * Returns: whether @fap was applied: %FALSE, changing nothing, when it is out of range
 */
GST_PFAP_API
gboolean gst_pfap_fap_state_apply_fap(GstPfapFapState *state, const GstPfapFap *fap,
                                      GstClockTime time, GError **error);

/**
 * gst_pfap_fap_state_get_amplitude:
 * @state: a #GstPfapFapState
 * @index: a FAP, %GST_PFAP_MIN_FAP_INDEX..%GST_PFAP_MAX_FAP_INDEX
 * @time: when, in nanoseconds, at or after the start of the last target of @index
 *
 * Returns: the amplitude of FAP @index at @time
 */
GST_PFAP_API
gdouble gst_pfap_fap_state_get_amplitude(GstPfapFapState *state, guint index, GstClockTime time);

/**
 * gst_pfap_fap_state_get_settled:
 * @state: a #GstPfapFapState
 * @index: a FAP, %GST_PFAP_MIN_FAP_INDEX..%GST_PFAP_MAX_FAP_INDEX
 *
 * Returns: what FAP @index holds once its transition is over: its target, or for a triangle
 * what it held before
 */
GST_PFAP_API
gint32 gst_pfap_fap_state_get_settled(GstPfapFapState *state, guint index);

/**
 * gst_pfap_fap_state_is_at_rest:
 * @state: a #GstPfapFapState
 * @index: a FAP, %GST_PFAP_MIN_FAP_INDEX..%GST_PFAP_MAX_FAP_INDEX
 * @time: when, in nanoseconds
 *
 * Returns: whether FAP @index has no transition running at @time
 */
GST_PFAP_API
gboolean gst_pfap_fap_state_is_at_rest(GstPfapFapState *state, guint index, GstClockTime time);

/**
 * gst_pfap_fap_state_reset:
 * @state: a #GstPfapFapState
 *
 * Returns every FAP to 0 with no transition running, as a new state.
 */
GST_PFAP_API
void gst_pfap_fap_state_reset(GstPfapFapState *state);

G_END_DECLS

#endif /* __GST_PFAP_FAP_STATE_H__ */

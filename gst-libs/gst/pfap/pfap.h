/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 *
 * libgstpfap: application/x-pfap events, phoneme alphabets, MPEG-4 bookmarks and a
 * receiver's FAP state for applications, in C and through GObject-Introspection
 * (GstPfap-1.0) in Python, JavaScript, Rust and Vala. docs/apps.md shows how.
 */
#ifndef __GST_PFAP_H__
#define __GST_PFAP_H__

#include <gst/pfap/gstpfapalphabet.h>
#include <gst/pfap/gstpfapbookmark.h>
#include <gst/pfap/gstpfapevent.h>
#include <gst/pfap/gstpfapfapstate.h>
#include <gst/pfap/pfap-enumtypes.h>
#include <gst/pfap/pfap-prelude.h>

#endif /* __GST_PFAP_H__ */

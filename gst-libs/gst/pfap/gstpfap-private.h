/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 *
 * What the library's files share and applications do not see: the boxed types' insides and
 * the conversions to and from libpfap's types.
 */
#pragma once

#include <vector>

#include "gst/pfap/gstpfapevent.h"
#include "pfap/markup_event.h"

struct _GstPfapEvent {
  pfap::MarkupEvent event;
};

pfap::Fap gst_pfap_fap_to_lib(const GstPfapFap& fap);
GstPfapFap* gst_pfap_fap_from_lib(const pfap::Fap& fap);
// Why libpfap refuses `fap` (pfap::is_valid is false), in words: its values and the ranges.
gchar* gst_pfap_fap_out_of_range(const pfap::Fap& fap);
// A list of new GstPfapFaps.
GList* gst_pfap_faps_from_lib(const std::vector<pfap::Fap>& faps);

/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 *
 * What every public header of libgstpfap includes first: the export macro.
 */
#ifndef __GST_PFAP_PRELUDE_H__
#define __GST_PFAP_PRELUDE_H__

#include <gst/gst.h>

#ifndef GST_PFAP_API
#ifdef BUILDING_GST_PFAP
#define GST_PFAP_API GST_API_EXPORT
#else
#define GST_PFAP_API GST_API_IMPORT
#endif
#endif

#endif /* __GST_PFAP_PRELUDE_H__ */

// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include <gst/gst.h>
#include <gst/rtp/gstrtpbasedepayload.h>

G_BEGIN_DECLS

#define GST_TYPE_RTP_PFAP_DEPAY (gst_rtp_pfap_depay_get_type())
G_DECLARE_FINAL_TYPE(GstRtpPfapDepay, gst_rtp_pfap_depay, GST, RTP_PFAP_DEPAY, GstRTPBaseDepayload)

GST_ELEMENT_REGISTER_DECLARE(rtppfapdepay);

G_END_DECLS

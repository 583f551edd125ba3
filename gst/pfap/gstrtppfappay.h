// SPDX-License-Identifier: LGPL-2.1-or-later
#pragma once

#include <gst/gst.h>
#include <gst/rtp/gstrtpbasepayload.h>

G_BEGIN_DECLS

#define GST_TYPE_RTP_PFAP_PAY (gst_rtp_pfap_pay_get_type())
G_DECLARE_FINAL_TYPE(GstRtpPfapPay, gst_rtp_pfap_pay, GST, RTP_PFAP_PAY, GstRTPBasePayload)

// The values of GstRtpPfapPay:recovery-depth: 0 and the coverages the draft's PP field can
// signal (1, 2, 4, 7, 15, 25, 40), each value its own number; nicks none, 1-packet,
// 2-packets, ... 40-packets.
#define GST_TYPE_RTP_PFAP_RECOVERY_DEPTH (gst_rtp_pfap_recovery_depth_get_type())
GType gst_rtp_pfap_recovery_depth_get_type(void);

GST_ELEMENT_REGISTER_DECLARE(rtppfappay);

G_END_DECLS

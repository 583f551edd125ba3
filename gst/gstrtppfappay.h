#pragma once

#include <gst/gst.h>
#include <gst/rtp/gstrtpbasepayload.h>

G_BEGIN_DECLS

#define GST_TYPE_RTP_PFAP_PAY (gst_rtp_pfap_pay_get_type())
G_DECLARE_FINAL_TYPE(GstRtpPfapPay, gst_rtp_pfap_pay, GST, RTP_PFAP_PAY, GstRTPBasePayload)

GST_ELEMENT_REGISTER_DECLARE(rtppfappay);

G_END_DECLS

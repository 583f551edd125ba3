// SPDX-License-Identifier: LGPL-2.1-or-later
// The one set of rtpbin pipeline builders of the pipeline tests: gst-launch fragments for one
// RTP session of an rtpbin named `rtpbin`, sending or receiving over UDP on 127.0.0.1. The
// elements are named after `prefix` (`<prefix>rtp`, `<prefix>rtcp`, `<prefix>rr`) so that a
// test can link the ports: udpsrc's bind to port 0 and the test points the udpsinks at them.
#pragma once

#include <string>

namespace pfap::testing {

// Session `n` sending: `payloader` (a fragment that ends with the payloader) into rtpbin, RTP
// and RTCP out by udpsinks, the receiver's RTCP reports in by a udpsrc. `sync_rtp`: whether
// the RTP udpsink syncs on the clock (a live sender that must keep its pace).
inline std::string rtpbin_send_session(int n, const std::string& prefix,
                                       const std::string& payloader, bool sync_rtp = false) {
  const std::string s = std::to_string(n);
  return payloader + " ! rtpbin.send_rtp_sink_" + s + " rtpbin.send_rtp_src_" + s +
         " ! udpsink name=" + prefix + "rtp host=127.0.0.1 " + (sync_rtp ? "" : "sync=false ") +
         "async=false rtpbin.send_rtcp_src_" + s + " ! udpsink name=" + prefix +
         "rtcp host=127.0.0.1 sync=false async=false udpsrc name=" + prefix +
         "rr address=127.0.0.1 port=0 ! rtpbin.recv_rtcp_sink_" + s + " ";
}

// Session `n` receiving RTP of `caps` and RTCP by udpsrcs, and sending RTCP reports back by a
// udpsink. The depayloader is linked by the caller (`rtpbin. ! ...`, or on pad-added).
inline std::string rtpbin_receive_session(int n, const std::string& prefix,
                                          const std::string& caps) {
  const std::string s = std::to_string(n);
  return "udpsrc name=" + prefix + "rtp address=127.0.0.1 port=0 caps=\"" + caps +
         "\" ! rtpbin.recv_rtp_sink_" + s + " udpsrc name=" + prefix +
         "rtcp address=127.0.0.1 port=0 ! rtpbin.recv_rtcp_sink_" + s + " rtpbin.send_rtcp_src_" +
         s + " ! udpsink name=" + prefix + "rr host=127.0.0.1 sync=false async=false ";
}

}  // namespace pfap::testing

// SPDX-License-Identifier: LGPL-2.1-or-later
// webrtcbin's transport bins against its ICE transports, before its pipeline goes to NULL
// (docs/performance.md, "Sessions that come and go"). pfap-web's close_session stops its
// pipeline with stop_webrtc_pipeline, and so does the test (tests/web).
//
// Each receive and send bin of webrtcbin 1.22 (TransportReceiveBin, TransportSendBin:
// gst-plugins-bad's ext/webrtc/transportreceivebin.c and transportsendbin.c) connects a
// handler to its ICE transport's notify::state when it is made and never disconnects it.
// The receive bin's sets the bin's receive state again; while ICE is neither connected nor
// completed, that blocks the bin's input with a pad probe that holds a reference to the bin.
// The bin frees its probes only in its READY to NULL. So an ICE state change between the bin's
// NULL and webrtcbin's disposal (on whichever thread libnice emits it) leaves the bin, with its
// nicesrc, dtlsdec, srtpdec and 5 fds, for ever. The send bin's runs on a freed bin when the
// ICE transport outlives webrtcbin: a crash. Upstream has the same code today (the GStreamer
// monorepo at 4cdf9d9796).
#pragma once

#ifndef GST_USE_UNSTABLE_API
#define GST_USE_UNSTABLE_API
#endif
#include <gst/gst.h>
#include <gst/webrtc/webrtc.h>

#include <algorithm>
#include <cstring>
#include <vector>

namespace webrtc_transport_bins {

// Adds `dtls`'s ICE transport to `ice` (once), taking `dtls`'s reference.
inline void add_ice_transport(GstWebRTCDTLSTransport* dtls, std::vector<GObject*>& ice) {
  if (dtls == nullptr) return;
  GObject* transport = nullptr;
  g_object_get(dtls, "transport", &transport, nullptr);
  gst_object_unref(dtls);
  if (transport == nullptr) return;
  if (std::find(ice.begin(), ice.end(), transport) != ice.end()) {
    g_object_unref(transport);
  } else {
    ice.push_back(transport);
  }
}

// The ICE transports of `webrtc`'s transceivers and of its SCTP transport, referenced. A
// receive bin's transport is one of them: webrtcbin gives each transport stream's DTLS
// transport to the transceivers and the data channels it carries.
inline std::vector<GObject*> ice_transports(GstElement* webrtc) {
  std::vector<GObject*> ice;
  GArray* transceivers = nullptr;
  g_signal_emit_by_name(webrtc, "get-transceivers", &transceivers);
  for (guint i = 0; transceivers != nullptr && i < transceivers->len; ++i) {
    GstWebRTCRTPTransceiver* transceiver = g_array_index(transceivers, GstWebRTCRTPTransceiver*, i);
    for (const char* end : {"receiver", "sender"}) {
      GObject* object = nullptr;
      g_object_get(transceiver, end, &object, nullptr);
      if (object == nullptr) continue;
      GstWebRTCDTLSTransport* dtls = nullptr;
      g_object_get(object, "transport", &dtls, nullptr);
      g_object_unref(object);
      add_ice_transport(dtls, ice);
    }
  }
  if (transceivers != nullptr) g_array_unref(transceivers);
  GObject* sctp = nullptr;
  g_object_get(webrtc, "sctp-transport", &sctp, nullptr);
  if (sctp != nullptr) {
    GstWebRTCDTLSTransport* dtls = nullptr;
    g_object_get(sctp, "transport", &dtls, nullptr);
    g_object_unref(sctp);
    add_ice_transport(dtls, ice);
  }
  return ice;
}

// `webrtc`'s transport bins (its children of the private types TransportReceiveBin and
// TransportSendBin), referenced.
inline std::vector<GstElement*> transport_bins(GstElement* webrtc) {
  std::vector<GstElement*> bins;
  GstIterator* children = gst_bin_iterate_elements(GST_BIN(webrtc));
  gst_iterator_foreach(
      children,
      [](const GValue* value, gpointer data) {
        auto* element = GST_ELEMENT(g_value_get_object(value));
        auto& found = *static_cast<std::vector<GstElement*>*>(data);
        const char* type = G_OBJECT_TYPE_NAME(element);
        if ((std::strcmp(type, "TransportReceiveBin") == 0 ||
             std::strcmp(type, "TransportSendBin") == 0) &&
            std::find(found.begin(), found.end(), element) == found.end()) {
          found.push_back(GST_ELEMENT(gst_object_ref(element)));
        }
      },
      &bins);
  gst_iterator_free(children);
  return bins;
}

// Disconnects every handler on `webrtc`'s ICE transports whose data is one of its transport
// bins, so that no ICE state change can block a receive bin after its NULL or reach a send bin
// after its disposal. For a webrtcbin that is not to play again (its bins no longer follow ICE),
// just before its pipeline goes to NULL (stop_webrtc_pipeline). Returns how many handlers it
// disconnected.
//
// A handler that another thread has already entered runs to its end: it blocks a receive bin
// for good only if its few instructions end after the bin's READY to NULL, which comes after
// every element of the pipeline has gone from PLAYING to READY, so that thread would have to
// stand still inside the handler for all of it. A bin that webrtcbin's thread makes after this
// call keeps its handler: that takes a session closed while webrtcbin is still making its
// offer, before a peer could have answered.
inline guint detach_from_ice(GstElement* webrtc) {
  std::vector<GObject*> ice = ice_transports(webrtc);
  std::vector<GstElement*> bins = transport_bins(webrtc);
  guint disconnected = 0;
  for (GObject* transport : ice) {
    for (GstElement* bin : bins) {
      disconnected += g_signal_handlers_disconnect_matched(transport, G_SIGNAL_MATCH_DATA, 0, 0,
                                                           nullptr, nullptr, bin);
    }
    g_object_unref(transport);
  }
  for (GstElement* bin : bins) gst_object_unref(bin);
  return disconnected;
}

}  // namespace webrtc_transport_bins

// Takes `pipeline`, which holds `webrtc` and is not to play again, to NULL, `webrtc`'s
// transport bins detached from its ICE transports first. Returns how many handlers it
// disconnected.
inline guint stop_webrtc_pipeline(GstElement* pipeline, GstElement* webrtc) {
  guint disconnected = webrtc_transport_bins::detach_from_ice(webrtc);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  return disconnected;
}

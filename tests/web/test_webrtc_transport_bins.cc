// SPDX-License-Identifier: LGPL-2.1-or-later
// tools/webrtc_transport_bins.h: an ICE state change after a session's pipeline's NULL leaves
// no receive bin behind, whether the answer was set or not, and one after the session is gone
// reaches no freed send bin (docs/performance.md, "Sessions that come and go"). Two webrtcbins
// in one process make the offer and the answer as pfap-web and a page do; the ICE state change
// that libnice would make on some thread, by luck, is emitted here by hand (g_object_notify on
// the public ICE transports). Without the detach in stop_webrtc_pipeline every receive bin is
// left, and the send bins' handler runs on freed memory. No ICE candidate is exchanged, so nothing
// is sent; the test still runs in a network namespace with only lo (unshare -n, as root;
// skipped elsewhere), as every WebRTC test does, so that ICE gathers on lo alone.
#include <gst/gst.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <vector>

#include "webrtc_transport_bins.h"

namespace {

// The audio and the data channel of a pfap-web session, with its bundle policy.
constexpr const char* kOfferer =
    "audiotestsrc is-live=true wave=silence ! opusenc ! rtpopuspay pt=111 "
    "! application/x-rtp,media=audio,encoding-name=OPUS,clock-rate=48000,payload=111 "
    "! webrtcbin name=webrtc bundle-policy=max-bundle";
constexpr const char* kAnswerer = "webrtcbin name=webrtc bundle-policy=max-bundle";

GstElement* launch(const char* description) {
  GError* error = nullptr;
  GstElement* pipeline = gst_parse_launch(description, &error);
  if (error != nullptr) {
    ADD_FAILURE() << error->message;
    g_error_free(error);
  }
  if (pipeline == nullptr || GST_IS_PIPELINE(pipeline)) return pipeline;
  GstElement* alone = pipeline;  // a description of one element makes no pipeline
  pipeline = gst_pipeline_new(nullptr);
  gst_bin_add(GST_BIN(pipeline), alone);
  return pipeline;
}

GstElement* webrtc_of(GstElement* pipeline) {
  GstElement* webrtc = gst_bin_get_by_name(GST_BIN(pipeline), "webrtc");
  gst_object_unref(webrtc);  // the pipeline keeps it
  return webrtc;
}

// The offer or answer that `signal` ("create-offer", "create-answer") makes, set as `webrtc`'s
// local description; null if none came.
GstWebRTCSessionDescription* create_and_set_local(GstElement* webrtc, const char* signal,
                                                  const char* field) {
  GstPromise* promise = gst_promise_new();
  g_signal_emit_by_name(webrtc, signal, nullptr, promise);
  EXPECT_EQ(gst_promise_wait(promise), GST_PROMISE_RESULT_REPLIED);
  const GstStructure* reply = gst_promise_get_reply(promise);
  GstWebRTCSessionDescription* sdp = nullptr;
  if (reply != nullptr) {
    gst_structure_get(reply, field, GST_TYPE_WEBRTC_SESSION_DESCRIPTION, &sdp, nullptr);
  }
  gst_promise_unref(promise);
  if (sdp == nullptr) return nullptr;
  promise = gst_promise_new();
  g_signal_emit_by_name(webrtc, "set-local-description", sdp, promise);
  EXPECT_EQ(gst_promise_wait(promise), GST_PROMISE_RESULT_REPLIED);
  gst_promise_unref(promise);
  return sdp;
}

// Sets `sdp` as `webrtc`'s remote description and waits until webrtcbin's thread has set it.
void set_remote(GstElement* webrtc, GstWebRTCSessionDescription* sdp) {
  GstPromise* promise = gst_promise_new();
  g_signal_emit_by_name(webrtc, "set-remote-description", sdp, promise);
  EXPECT_EQ(gst_promise_wait(promise), GST_PROMISE_RESULT_REPLIED);
  gst_promise_unref(promise);
}

void count_finalized(gpointer finalized, GObject*) { ++*static_cast<int*>(finalized); }

// pfap-web's side: its audio and its data channel, PLAYING, its offer made and set. Null if
// the pipeline cannot be made; `offer` is null if no offer came.
GstElement* offering(GstWebRTCSessionDescription** offer) {
  *offer = nullptr;
  GstElement* pipeline = launch(kOfferer);
  if (pipeline == nullptr) return nullptr;
  GstElement* webrtc = webrtc_of(pipeline);
  gst_element_set_state(pipeline, GST_STATE_READY);
  GObject* channel = nullptr;
  g_signal_emit_by_name(webrtc, "create-data-channel", "pfap", nullptr, &channel);
  EXPECT_NE(channel, nullptr);
  if (channel != nullptr) g_object_unref(channel);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  *offer = create_and_set_local(webrtc, "create-offer", "offer");
  return pipeline;
}

// Takes `pipeline` to NULL as pfap-web's close_session does (stop_webrtc_pipeline); changes
// the state of each ICE transport, as libnice may before webrtcbin is disposed; unrefs the
// pipeline. Returns how many of its transport bins were left (not finalized).
int bins_left_after_close(GstElement* pipeline) {
  GstElement* webrtc = webrtc_of(pipeline);
  std::vector<GstElement*> bins = webrtc_transport_bins::transport_bins(webrtc);
  std::vector<GObject*> ice = webrtc_transport_bins::ice_transports(webrtc);
  EXPECT_FALSE(bins.empty());
  EXPECT_FALSE(ice.empty());
  int finalized = 0;
  for (GstElement* bin : bins) {
    g_object_weak_ref(G_OBJECT(bin), count_finalized, &finalized);
    gst_object_unref(bin);
  }
  EXPECT_EQ(stop_webrtc_pipeline(pipeline, webrtc), bins.size());
  EXPECT_EQ(GST_STATE(pipeline), GST_STATE_NULL);
  for (GObject* transport : ice) g_object_notify(transport, "state");
  gst_object_unref(pipeline);
  for (GObject* transport : ice) g_object_unref(transport);
  return static_cast<int>(bins.size()) - finalized;
}

// A page's session: pfap-web's offer and the page's answer, each set on both sides. False
// (with a failure) if either did not come.
bool answered(GstElement** offerer, GstElement** answerer) {
  GstWebRTCSessionDescription* offer = nullptr;
  *offerer = offering(&offer);
  *answerer = launch(kAnswerer);
  if (*offerer == nullptr || offer == nullptr || *answerer == nullptr) {
    ADD_FAILURE() << "no offer";
    return false;
  }
  gst_element_set_state(*answerer, GST_STATE_PLAYING);
  set_remote(webrtc_of(*answerer), offer);
  gst_webrtc_session_description_free(offer);
  GstWebRTCSessionDescription* answer =
      create_and_set_local(webrtc_of(*answerer), "create-answer", "answer");
  if (answer == nullptr) {
    ADD_FAILURE() << "no answer";
    return false;
  }
  set_remote(webrtc_of(*offerer), answer);
  gst_webrtc_session_description_free(answer);
  return true;
}

TEST(WebRtcTransportBins, AnIceStateChangeAfterNullLeavesNoReceiveBinOnceAnswered) {
  GstElement *offerer = nullptr, *answerer = nullptr;
  ASSERT_TRUE(answered(&offerer, &answerer));
  EXPECT_EQ(bins_left_after_close(offerer), 0);
  EXPECT_EQ(bins_left_after_close(answerer), 0);
}

// The ICE transport can outlive webrtcbin (here the test holds it, as libnice's thread may
// while it emits): a state change then must not reach a freed send bin (without the detach,
// a crash in the normal build, and AddressSanitizer's SEGV in the sanitizer build).
TEST(WebRtcTransportBins, AnIceStateChangeAfterTheSessionReachesNoFreedSendBin) {
  GstElement *offerer = nullptr, *answerer = nullptr;
  ASSERT_TRUE(answered(&offerer, &answerer));
  for (GstElement* pipeline : {offerer, answerer}) {
    GstElement* webrtc = webrtc_of(pipeline);
    std::vector<GObject*> ice = webrtc_transport_bins::ice_transports(webrtc);
    EXPECT_FALSE(ice.empty());
    stop_webrtc_pipeline(pipeline, webrtc);
    gst_object_unref(pipeline);
    for (GObject* transport : ice) {
      g_object_notify(transport, "state");
      g_object_unref(transport);
    }
  }
}

// A session that never has its answer (pfap-web closes it after --connect-timeout): the
// receive bin starts blocked, and the handler blocks it again as well.
TEST(WebRtcTransportBins, AnIceStateChangeAfterNullLeavesNoReceiveBinOfAnOfferNotAnswered) {
  GstWebRTCSessionDescription* offer = nullptr;
  GstElement* offerer = offering(&offer);
  ASSERT_NE(offerer, nullptr);
  ASSERT_NE(offer, nullptr);
  gst_webrtc_session_description_free(offer);
  EXPECT_EQ(bins_left_after_close(offerer), 0);
}

}  // namespace

// Runs the tests again inside a network namespace with only lo, or skips (77).
int main(int argc, char** argv) {
  if (g_getenv("PFAP_WEBRTC_NETNS") == nullptr) {
    if (geteuid() != 0) {
      g_print(
          "SKIP: needs root: unshare -n makes the network namespace with only lo that "
          "WebRTC runs in (CI runs as root)\n");
      return 77;
    }
    g_setenv("PFAP_WEBRTC_NETNS", "1", TRUE);
    // The sanitizer build preloads its runtimes into every test process (tests/meson.build):
    // not into unshare, sh and ip, which are not ours; this test links its own.
    g_unsetenv("LD_PRELOAD");
    std::vector<char*> args = {const_cast<char*>("unshare"), const_cast<char*>("-n"),
                               const_cast<char*>("sh"), const_cast<char*>("-c"),
                               const_cast<char*>("ip link set lo up && exec \"$0\" \"$@\"")};
    for (int i = 0; i < argc; ++i) args.push_back(argv[i]);
    args.push_back(nullptr);
    execvp("unshare", args.data());
    g_printerr("SKIP: cannot run unshare (scripts/install-deps installs util-linux)\n");
    return 77;
  }
  gst_init(&argc, &argv);
  g_thread_pool_set_max_idle_time(0);  // as tests/gst/gst_main.cc: for LeakSanitizer
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

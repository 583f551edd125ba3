// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap-web: the talking head in a browser (docs/web.md). Serves the page (web/live/, which
// uses pfap.js from web/src/) over HTTP and, for each browser that connects to its WebSocket,
// runs a WebRTC session of its own:
//
//   audiotestsrc is-live wave=silence ! audiomixer ! opusenc ! rtpopuspay ! valve ! webrtcbin
//   pfaptts ! audio ! ...................... ^ (one per text said, added while playing)
//           ! pfap  ! rtppfappay ! appsink ! data channel "pfap" (ordered=false,
//                                                                 max-retransmits=0)
//
// Each PFAP RTP packet, header included, is one data-channel message. Both payloaders stamp
// their packets from the same running time, with timestamp offsets the server chooses and
// tells the page on the WebSocket, so the page maps the audio it plays to PFAP time. The
// WebSocket also carries the SDP offer and answer, ICE candidates, the texts to say and, at
// the end of each, the sender's FAP state and counts (the page compares them with its own),
// and the speech's level, which the page finds in the audio it plays to know what it hears.
#include <glib-unix.h>
#include <gst/app/gstappsink.h>
#include <gst/gst.h>
#include <gst/rtp/gstrtpbuffer.h>
#include <gst/sdp/sdp.h>
#include <gst/video/video-event.h>
#define GST_USE_UNSTABLE_API
#include <gst/webrtc/webrtc.h>
#include <json-glib/json-glib.h>
#include <libsoup/soup.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include "launch_value.h"
#include "pfap/model.h"
#include "pfap/payload.h"
#include "pfap/recovery.h"
#include "speech_level.h"

namespace {

constexpr const char* kDefaultText =
    "Hello! <FAP 2 1 40 0 0 800 3> I am a talking head in your browser. "
    "<FAP 48 6000 400 2> My voice comes over WebRTC, <FAP 2 6 50 0 0 300 2> and my face on a "
    "data channel, in step with it. <FAP 2 1 50 0 0 800 3> Type something for me to say!";
constexpr uint32_t kAudioClockRate = 48000;  // Opus's RTP clock rate, whatever the audio's
constexpr uint32_t kPfapClockRate = 44100;   // the draft's default
// A new text starts this far ahead of the running time it is added at, so that its first
// audio reaches the mixer in time (the mixer drops what comes after its output has passed).
constexpr GstClockTime kSpeakLead = 300 * GST_MSECOND;
// PFAP packets go this far ahead of their time: the page holds their events until the audio
// reaches them, and what comes late is drawn late.
constexpr GstClockTimeDiff kPfapLead = 400 * GST_MSECOND;

struct Options {
  int port = 8080;
  std::string text = kDefaultText;
  double drop = 0.0;
  uint32_t seed = 1;
  std::string web_dir;
};

void usage(FILE* out) {
  std::fprintf(out,
               "usage: pfap-web [--port=N] [--text=TEXT] [--drop=P] [--seed=S] [--web-dir=DIR]\n"
               "Serves the talking head on http://127.0.0.1:N/ (default 8080; 0 picks a free\n"
               "port) and prints the URL. Each browser that opens it gets its own WebRTC\n"
               "session: TEXT (or what the page asks for) spoken by pfaptts, the speech as\n"
               "Opus audio, the PFAP stream as RTP packets on an unordered, unreliable data\n"
               "channel, of which a share P (0 to 1) is dropped, seeded by S (each session\n"
               "adds its number). DIR holds the page (live/) and pfap.js (src/): by default\n"
               "$PFAP_WEB_DIR, else the installed one.\n");
}

// A WebRTC session with one browser. Lives on the main thread; GStreamer's threads post
// what they have to say there (post()).
struct Session : std::enable_shared_from_this<Session> {
  int id = 0;
  SoupWebsocketConnection* ws = nullptr;
  GstElement* pipeline = nullptr;
  GstElement* webrtc = nullptr;
  GstElement* mixer = nullptr;
  GstElement* pay = nullptr;
  GstWebRTCDataChannel* channel = nullptr;
  GstElement* speaker = nullptr;  // the pfaptts bin of the text being said
  GstPad* speaker_mixer_pad = nullptr;
  bool channel_open = false;
  bool playing = false;  // the page says it plays the audio track
  bool audio_flowing = false;
  bool closed = false;
  std::string pending_text;  // said when the audio starts or the current text ends
  uint32_t audio_ts_offset = 0;
  uint32_t pfap_ts_offset = 0;

  // Touched by the appsink's thread: the loss, and the state as sent (every packet, before
  // the loss, through libpfap's receiver: what a lossless receiver holds).
  std::mutex mutex;
  std::mt19937 rng;
  double drop = 0.0;
  pfap::RecoveryReceiver sent;
  pfap::Packet packet;
  uint64_t packets = 0;
  uint64_t dropped = 0;
  uint64_t phonemes = 0;
  int last_seqnum = -1;
};

std::string text_of(JsonNode* node) {
  gchar* s = json_to_string(node, FALSE);
  std::string out = s;
  g_free(s);
  json_node_unref(node);
  return out;
}

void send_json(Session& s, JsonBuilder* b) {
  JsonNode* node = json_builder_get_root(b);
  g_object_unref(b);
  const std::string text = text_of(node);
  if (s.closed || soup_websocket_connection_get_state(s.ws) != SOUP_WEBSOCKET_STATE_OPEN) return;
  soup_websocket_connection_send_text(s.ws, text.c_str());
}

JsonBuilder* message(const char* type) {
  JsonBuilder* b = json_builder_new();
  json_builder_begin_object(b);
  json_builder_set_member_name(b, "type");
  json_builder_add_string_value(b, type);
  return b;
}

void member(JsonBuilder* b, const char* name, const char* value) {
  json_builder_set_member_name(b, name);
  json_builder_add_string_value(b, value);
}

void member(JsonBuilder* b, const char* name, int64_t value) {
  json_builder_set_member_name(b, name);
  json_builder_add_int_value(b, value);
}

void finish(Session& s, JsonBuilder* b) {
  json_builder_end_object(b);
  send_json(s, b);
}

// Runs `f` on the main thread if the session is still open then.
void post(const std::shared_ptr<Session>& session, std::function<void(Session&)> f) {
  struct Call {
    std::shared_ptr<Session> session;
    std::function<void(Session&)> f;
  };
  g_main_context_invoke_full(
      nullptr, G_PRIORITY_DEFAULT,
      [](gpointer data) -> gboolean {
        auto* call = static_cast<Call*>(data);
        if (!call->session->closed) call->f(*call->session);
        return G_SOURCE_REMOVE;
      },
      new Call{session, std::move(f)}, [](gpointer data) { delete static_cast<Call*>(data); });
}

std::shared_ptr<Session> session_of(gpointer data) {
  return static_cast<std::weak_ptr<Session>*>(data)->lock();
}

gpointer weak(const std::shared_ptr<Session>& s) { return new std::weak_ptr<Session>(s); }

void free_weak(gpointer data, GClosure*) { delete static_cast<std::weak_ptr<Session>*>(data); }

// -- Signalling ---------------------------------------------------------------------------

// With a promise: given none, webrtcbin 1.22 leaks the reply it would have given it.
void set_description(GstElement* webrtc, const char* signal, GstWebRTCSessionDescription* sdp) {
  GstPromise* promise = gst_promise_new();
  g_signal_emit_by_name(webrtc, signal, sdp, promise);
  gst_promise_unref(promise);
}

void on_offer_created(GstPromise* promise, gpointer data) {
  std::shared_ptr<Session> session = session_of(data);
  delete static_cast<std::weak_ptr<Session>*>(data);
  const GstStructure* reply = gst_promise_get_reply(promise);
  GstWebRTCSessionDescription* offer = nullptr;
  if (reply != nullptr) {
    gst_structure_get(reply, "offer", GST_TYPE_WEBRTC_SESSION_DESCRIPTION, &offer, nullptr);
  }
  gst_promise_unref(promise);
  if (session == nullptr || offer == nullptr) {
    if (offer != nullptr) gst_webrtc_session_description_free(offer);
    return;
  }
  set_description(session->webrtc, "set-local-description", offer);
  gchar* sdp = gst_sdp_message_as_text(offer->sdp);
  std::string text = sdp;
  g_free(sdp);
  gst_webrtc_session_description_free(offer);
  post(session, [text](Session& s) {
    JsonBuilder* b = message("offer");
    member(b, "sdp", text.c_str());
    finish(s, b);
  });
}

void on_negotiation_needed(GstElement* webrtc, gpointer data) {
  std::shared_ptr<Session> session = session_of(data);
  if (session == nullptr) return;
  GstPromise* promise = gst_promise_new_with_change_func(on_offer_created, weak(session), nullptr);
  g_signal_emit_by_name(webrtc, "create-offer", nullptr, promise);
}

void on_ice_candidate(GstElement*, guint mline, gchar* candidate, gpointer data) {
  std::shared_ptr<Session> session = session_of(data);
  if (session == nullptr) return;
  std::string text = candidate;
  post(session, [mline, text](Session& s) {
    JsonBuilder* b = message("ice");
    member(b, "candidate", text.c_str());
    member(b, "sdpMLineIndex", mline);
    finish(s, b);
  });
}

void set_answer(Session& s, const char* sdp_text) {
  GstSDPMessage* sdp = nullptr;
  if (gst_sdp_message_new_from_text(sdp_text, &sdp) != GST_SDP_OK) {
    g_printerr("pfap-web: session %d: unreadable SDP answer\n", s.id);
    if (sdp != nullptr) gst_sdp_message_free(sdp);
    return;
  }
  GstWebRTCSessionDescription* answer =
      gst_webrtc_session_description_new(GST_WEBRTC_SDP_TYPE_ANSWER, sdp);
  set_description(s.webrtc, "set-remote-description", answer);
  gst_webrtc_session_description_free(answer);
}

// -- The PFAP stream ----------------------------------------------------------------------

// The sender's FAP state and counts, after the last packet of a text or a complete state.
void send_state(Session& s, const char* type) {
  JsonBuilder* b = message(type);
  std::lock_guard lock(s.mutex);
  member(b, "packets", static_cast<int64_t>(s.packets));
  member(b, "dropped", static_cast<int64_t>(s.dropped));
  member(b, "phonemes", static_cast<int64_t>(s.phonemes));
  member(b, "lastSequenceNumber", s.last_seqnum);
  json_builder_set_member_name(b, "settled");
  json_builder_begin_array(b);
  for (int i = pfap::kMinFapIndex; i <= pfap::kMaxFapIndex; ++i) {
    json_builder_add_int_value(b, s.sent.state().settled(i));
  }
  json_builder_end_array(b);
  finish(s, b);
}

// Each packet rtppfappay makes, at its time (less kPfapLead): recorded as sent, then lost
// or sent whole on the data channel.
GstFlowReturn on_pfap_packet(GstAppSink* sink, gpointer data) {
  GstSample* sample = gst_app_sink_pull_sample(sink);
  if (sample == nullptr) return GST_FLOW_EOS;
  std::shared_ptr<Session> session = session_of(data);
  GstBuffer* buffer = gst_sample_get_buffer(sample);
  GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
  if (session != nullptr && gst_rtp_buffer_map(buffer, GST_MAP_READ, &rtp)) {
    Session& s = *session;
    const uint16_t seqnum = gst_rtp_buffer_get_seq(&rtp);
    const uint32_t timestamp = gst_rtp_buffer_get_timestamp(&rtp);
    std::span<const uint8_t> payload(static_cast<const uint8_t*>(gst_rtp_buffer_get_payload(&rtp)),
                                     gst_rtp_buffer_get_payload_len(&rtp));
    bool lose = false;
    {
      std::lock_guard lock(s.mutex);
      if (pfap::decode_payload(payload, s.packet).ok()) {
        const int64_t time_ns = static_cast<int64_t>(
            gst_util_uint64_scale_int(timestamp - s.pfap_ts_offset, GST_SECOND, kPfapClockRate));
        s.sent.receive(s.packet, seqnum, time_ns);
        s.phonemes += s.packet.phonemes.size();
      }
      ++s.packets;
      s.last_seqnum = seqnum;
      lose = std::uniform_real_distribution<double>(0.0, 1.0)(s.rng) < s.drop;
      if (lose) ++s.dropped;
    }
    gst_rtp_buffer_unmap(&rtp);
    if (!lose && s.channel != nullptr) {
      GstMapInfo map;
      if (gst_buffer_map(buffer, &map, GST_MAP_READ)) {
        GBytes* bytes = g_bytes_new(map.data, map.size);
        g_signal_emit_by_name(s.channel, "send-data", bytes);
        g_bytes_unref(bytes);
        gst_buffer_unmap(buffer, &map);
      }
    }
  }
  gst_sample_unref(sample);
  return GST_FLOW_OK;
}

void say(Session& s, const std::string& text);

// The text said ends: its bin goes, the page gets the sender's state, the next text starts.
void speaker_done(Session& s) {
  if (s.speaker == nullptr) return;
  GstElement* speaker = s.speaker;
  s.speaker = nullptr;
  gst_element_set_state(speaker, GST_STATE_NULL);
  gst_bin_remove(GST_BIN(s.pipeline), speaker);
  gst_element_release_request_pad(s.mixer, s.speaker_mixer_pad);
  gst_object_unref(s.speaker_mixer_pad);
  s.speaker_mixer_pad = nullptr;
  send_state(s, "done");
  if (!s.pending_text.empty()) {
    std::string text;
    text.swap(s.pending_text);
    say(s, text);
  }
}

// The speaker's EOS never reaches the mixer or the payloader, which go on with the next text:
// the audio's is dropped (the mixer goes on with silence), the PFAP's becomes a GAP, which
// sends the payloader's pending packet. The GAP reaching the appsink means every packet of
// the text has been sent.
GstPadProbeReturn on_speaker_eos(GstPad*, GstPadProbeInfo* info, gpointer) {
  if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) != GST_EVENT_EOS) return GST_PAD_PROBE_OK;
  return GST_PAD_PROBE_DROP;
}

GstPadProbeReturn on_pfap_eos(GstPad*, GstPadProbeInfo* info, gpointer) {
  GstEvent* event = GST_PAD_PROBE_INFO_EVENT(info);
  if (GST_EVENT_TYPE(event) != GST_EVENT_EOS) return GST_PAD_PROBE_OK;
  gst_event_unref(event);
  GstEvent* gap = gst_event_new_gap(0, 0);
  // Tells the appsink's probe that this GAP ends a text.
  gst_structure_set(gst_event_writable_structure(gap), "pfap-web-end", G_TYPE_BOOLEAN, TRUE,
                    nullptr);
  GST_PAD_PROBE_INFO_DATA(info) = gap;
  return GST_PAD_PROBE_OK;
}

GstPadProbeReturn on_sink_gap(GstPad*, GstPadProbeInfo* info, gpointer data) {
  GstEvent* event = GST_PAD_PROBE_INFO_EVENT(info);
  if (GST_EVENT_TYPE(event) != GST_EVENT_GAP ||
      !gst_structure_has_field(gst_event_get_structure(event), "pfap-web-end")) {
    return GST_PAD_PROBE_OK;
  }
  if (std::shared_ptr<Session> session = session_of(data)) post(session, speaker_done);
  return GST_PAD_PROBE_OK;
}

// The speech's level, sent to the page as it leaves the speaker (up to a second before it is
// played): the RMS of each millisecond at its running time, which the page finds again in the
// audio it plays to learn which running time it is hearing (docs/web.md, Timing).
struct Envelope {
  std::weak_ptr<Session> session;
  GstClockTime offset = 0;  // the speaker's pad offset: its running time in the pipeline's
  GstClockTime start = GST_CLOCK_TIME_NONE;  // running time of the first level waiting
  SpeechLevel level;
};

void send_envelope(Envelope& e) {
  if (e.level.empty()) return;
  const std::vector<int64_t> levels = e.level.take();
  const bool silent = std::all_of(levels.begin(), levels.end(), [](int64_t v) { return v == 0; });
  std::shared_ptr<Session> session = e.session.lock();
  if (!silent && session != nullptr) {
    post(session, [start = e.start, levels](Session& s) {
      JsonBuilder* b = message("envelope");
      member(b, "runningTimeNs", static_cast<int64_t>(start));
      json_builder_set_member_name(b, "rms");
      json_builder_begin_array(b);
      for (int64_t v : levels) json_builder_add_int_value(b, v);
      json_builder_end_array(b);
      finish(s, b);
    });
  }
  e.start += levels.size() * GST_MSECOND;
}

GstPadProbeReturn on_speech(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
  auto& e = *static_cast<Envelope*>(data);
  if ((info->type & GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM) != 0) {
    if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) == GST_EVENT_EOS) send_envelope(e);
    return GST_PAD_PROBE_OK;
  }
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  if (e.start == GST_CLOCK_TIME_NONE) {
    GstEvent* event = gst_pad_get_sticky_event(pad, GST_EVENT_SEGMENT, 0);
    if (event == nullptr || !GST_BUFFER_PTS_IS_VALID(buffer)) {
      if (event != nullptr) gst_event_unref(event);
      return GST_PAD_PROBE_OK;
    }
    const GstSegment* segment = nullptr;
    gst_event_parse_segment(event, &segment);
    const GstClockTime running =
        gst_segment_to_running_time(segment, GST_FORMAT_TIME, GST_BUFFER_PTS(buffer));
    gst_event_unref(event);
    if (!GST_CLOCK_TIME_IS_VALID(running)) return GST_PAD_PROBE_OK;
    e.start = running + e.offset;
  }
  GstMapInfo map;
  if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) return GST_PAD_PROBE_OK;
  e.level.add({reinterpret_cast<const int16_t*>(map.data), map.size / 2},
              [&] { send_envelope(e); });
  gst_buffer_unmap(buffer, &map);
  return GST_PAD_PROBE_OK;
}

// Starts saying `text` now, or after the text being said.
void say(Session& s, const std::string& text) {
  if (s.speaker != nullptr || !s.audio_flowing) {
    s.pending_text = text;
    return;
  }
  GError* error = nullptr;
  const std::string description =
      "pfaptts name=tts skip-bad-bookmarks=true text=" + quoted(text) +
      " tts.audio ! queue ! audioconvert ! audioresample ! "
      "audio/x-raw,format=S16LE,rate=48000,channels=1 ! queue name=audio "
      "tts.pfap ! queue name=pfap";
  GstElement* speaker = gst_parse_bin_from_description(description.c_str(), FALSE, &error);
  if (speaker == nullptr) {
    g_printerr("pfap-web: session %d: %s\n", s.id, error->message);
    g_error_free(error);
    return;
  }
  auto ghost = [&](const char* name) {
    GstElement* last = gst_bin_get_by_name(GST_BIN(speaker), name);
    GstPad* src = gst_element_get_static_pad(last, "src");
    GstPad* pad = gst_ghost_pad_new(name, src);
    gst_object_unref(src);
    gst_object_unref(last);
    gst_element_add_pad(speaker, pad);
    return pad;
  };
  GstPad* audio = ghost("audio");
  GstPad* pfap = ghost("pfap");
  gst_pad_add_probe(audio, GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM, on_speaker_eos, nullptr, nullptr);
  gst_pad_add_probe(pfap, GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM, on_pfap_eos, nullptr, nullptr);
  // Both start kSpeakLead from now in running time: the timestamps of the audio the mixer
  // sends and of the PFAP packets come from the same running time.
  GstClock* clock = gst_element_get_clock(s.pipeline);
  const GstClockTime now = gst_clock_get_time(clock) - gst_element_get_base_time(s.pipeline);
  gst_object_unref(clock);
  gst_pad_set_offset(audio, static_cast<gint64>(now + kSpeakLead));
  gst_pad_set_offset(pfap, static_cast<gint64>(now + kSpeakLead));
  // Its level, as early as the speaker makes it (the queue before the mixer fills ahead).
  GstElement* queue = gst_bin_get_by_name(GST_BIN(speaker), "audio");
  GstPad* queue_sink = gst_element_get_static_pad(queue, "sink");
  auto* envelope = new Envelope;
  envelope->session = s.weak_from_this();
  envelope->offset = now + kSpeakLead;
  gst_pad_add_probe(
      queue_sink, GstPadProbeType(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM),
      on_speech, envelope, [](gpointer data) { delete static_cast<Envelope*>(data); });
  gst_object_unref(queue_sink);
  gst_object_unref(queue);

  gst_bin_add(GST_BIN(s.pipeline), speaker);
  s.speaker = speaker;
  s.speaker_mixer_pad = gst_element_request_pad_simple(s.mixer, "sink_%u");
  GstPad* pay_sink = gst_element_get_static_pad(s.pay, "sink");
  gst_pad_link(audio, s.speaker_mixer_pad);
  gst_pad_link(pfap, pay_sink);
  gst_object_unref(pay_sink);
  gst_element_sync_state_with_parent(speaker);

  JsonBuilder* b = message("saying");
  member(b, "text", text.c_str());
  member(b, "runningTimeNs", static_cast<int64_t>(now + kSpeakLead));
  finish(s, b);
}

// The audio flows, and the first text is said, once the data channel is open and the page
// plays the audio track: what the pipeline made before would reach the browser's jitter
// buffer before anything takes audio out of it, which then plays faster until it has caught
// up (a first version lost 1 s of a 2.7 s text that way; docs/web.md).
void start_when_ready(Session& s) {
  if (!s.channel_open || !s.playing || s.audio_flowing) return;
  s.audio_flowing = true;
  GstElement* gate = gst_bin_get_by_name(GST_BIN(s.pipeline), "gate");
  g_object_set(gate, "drop", FALSE, nullptr);
  gst_object_unref(gate);
  std::string text;
  text.swap(s.pending_text);
  if (!text.empty()) say(s, text);
}

void on_channel_open(GstWebRTCDataChannel*, gpointer data) {
  if (std::shared_ptr<Session> session = session_of(data)) {
    post(session, [](Session& s) {
      s.channel_open = true;
      start_when_ready(s);
    });
  }
}

// A request for a complete state (the page lost packets that nothing after them recovers):
// rtppfappay answers an upstream GstForceKeyUnit at once when idle.
void request_complete(Session& s) {
  GstPad* src = gst_element_get_static_pad(s.pay, "src");
  gst_pad_send_event(src, gst_video_event_new_upstream_force_key_unit(GST_CLOCK_TIME_NONE, TRUE, 0));
  gst_object_unref(src);
  send_state(s, "state");
}

// -- Sessions -----------------------------------------------------------------------------

struct Server {
  Options options;
  int sessions = 0;
  std::vector<std::weak_ptr<Session>> open;  // stopped when the server stops
};

gboolean on_bus(GstBus*, GstMessage* m, gpointer data) {
  std::shared_ptr<Session> session = session_of(data);
  if (session == nullptr) return G_SOURCE_REMOVE;
  if (GST_MESSAGE_TYPE(m) == GST_MESSAGE_ERROR || GST_MESSAGE_TYPE(m) == GST_MESSAGE_WARNING) {
    GError* error = nullptr;
    gchar* debug = nullptr;
    if (GST_MESSAGE_TYPE(m) == GST_MESSAGE_ERROR) {
      gst_message_parse_error(m, &error, &debug);
    } else {
      gst_message_parse_warning(m, &error, &debug);
    }
    g_printerr("pfap-web: session %d: %s: %s (%s)\n", session->id, GST_OBJECT_NAME(m->src),
               error->message, debug != nullptr ? debug : "");
    g_error_free(error);
    g_free(debug);
  }
  return G_SOURCE_CONTINUE;
}

void close_session(const std::shared_ptr<Session>& s) {
  if (s->closed) return;
  s->closed = true;
  gst_element_set_state(s->pipeline, GST_STATE_NULL);
  gst_bus_remove_watch(GST_ELEMENT_BUS(s->pipeline));
  if (s->speaker_mixer_pad != nullptr) gst_object_unref(s->speaker_mixer_pad);
  if (s->channel != nullptr) g_object_unref(s->channel);
  gst_object_unref(s->pipeline);
  g_object_unref(s->ws);
  g_print("pfap-web: session %d closed\n", s->id);
}

std::shared_ptr<Session> open_session(Server& server, SoupWebsocketConnection* ws) {
  auto s = std::make_shared<Session>();
  s->id = ++server.sessions;
  s->ws = SOUP_WEBSOCKET_CONNECTION(g_object_ref(ws));
  s->drop = server.options.drop;
  s->rng.seed(server.options.seed + static_cast<uint32_t>(s->id));
  s->audio_ts_offset = g_random_int();
  s->pfap_ts_offset = g_random_int();
  GError* error = nullptr;
  s->pipeline = gst_parse_launch(
      "webrtcbin name=webrtc bundle-policy=max-bundle "
      "audiotestsrc is-live=true wave=silence samplesperbuffer=480 "
      "! audio/x-raw,format=S16LE,rate=48000,channels=1 ! audiomixer name=mix "
      "! audio/x-raw,format=S16LE,rate=48000,channels=1 ! opusenc frame-size=10 "
      "! rtpopuspay name=apay pt=111 "
      "! application/x-rtp,media=audio,encoding-name=OPUS,clock-rate=48000,payload=111 "
      "! valve name=gate drop=true drop-mode=forward-sticky-events ! webrtc. "
      "rtppfappay name=pay pt=96 ! application/x-rtp,clock-rate=44100 "
      "! appsink name=pfapsink sync=true async=false",
      &error);
  if (s->pipeline == nullptr) {
    g_printerr("pfap-web: %s\n", error->message);
    g_error_free(error);
    g_object_unref(ws);
    return nullptr;
  }
  auto by_name = [&](const char* name) {
    GstElement* e = gst_bin_get_by_name(GST_BIN(s->pipeline), name);
    gst_object_unref(e);  // the pipeline keeps it
    return e;
  };
  s->webrtc = by_name("webrtc");
  s->mixer = by_name("mix");
  s->pay = by_name("pay");
  g_object_set(by_name("apay"), "timestamp-offset", s->audio_ts_offset, nullptr);
  g_object_set(s->pay, "timestamp-offset", s->pfap_ts_offset, nullptr);
  GstElement* sink = by_name("pfapsink");
  g_object_set(sink, "ts-offset", -kPfapLead, nullptr);
  GstAppSinkCallbacks callbacks{};
  callbacks.new_sample = on_pfap_packet;
  gst_app_sink_set_callbacks(GST_APP_SINK(sink), &callbacks, weak(s),
                             [](gpointer data) { delete static_cast<std::weak_ptr<Session>*>(data); });
  GstPad* sink_pad = gst_element_get_static_pad(sink, "sink");
  gst_pad_add_probe(sink_pad, GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM, on_sink_gap, weak(s),
                    [](gpointer data) { delete static_cast<std::weak_ptr<Session>*>(data); });
  gst_object_unref(sink_pad);

  // ICE on 127.0.0.1 only, as the HTTP server: the page is on this machine (a browser offers
  // its loopback candidate with --allow-loopback-in-peer-connection, docs/web.md), and no
  // packet goes to another address.
  GObject* ice = nullptr;
  g_object_get(s->webrtc, "ice-agent", &ice, nullptr);
  gboolean added = FALSE;
  g_signal_emit_by_name(ice, "add-local-ip-address", "127.0.0.1", &added);
  g_object_unref(ice);
  if (!added) g_printerr("pfap-web: session %d: ICE cannot use 127.0.0.1\n", s->id);

  // Send only: the page has nothing to send but its answer.
  GArray* transceivers = nullptr;
  g_signal_emit_by_name(s->webrtc, "get-transceivers", &transceivers);
  for (guint i = 0; transceivers != nullptr && i < transceivers->len; ++i) {
    g_object_set(g_array_index(transceivers, GstWebRTCRTPTransceiver*, i), "direction",
                 GST_WEBRTC_RTP_TRANSCEIVER_DIRECTION_SENDONLY, nullptr);
  }
  if (transceivers != nullptr) g_array_unref(transceivers);

  g_signal_connect_data(s->webrtc, "on-negotiation-needed", G_CALLBACK(on_negotiation_needed),
                        weak(s), free_weak, GConnectFlags(0));
  g_signal_connect_data(s->webrtc, "on-ice-candidate", G_CALLBACK(on_ice_candidate), weak(s),
                        free_weak, GConnectFlags(0));
  gst_bus_add_watch_full(GST_ELEMENT_BUS(s->pipeline), G_PRIORITY_DEFAULT, on_bus, weak(s),
                         [](gpointer data) { delete static_cast<std::weak_ptr<Session>*>(data); });

  gst_element_set_state(s->pipeline, GST_STATE_READY);
  GstStructure* options = gst_structure_new("options", "ordered", G_TYPE_BOOLEAN, FALSE,
                                            "max-retransmits", G_TYPE_INT, 0, nullptr);
  g_signal_emit_by_name(s->webrtc, "create-data-channel", "pfap", options, &s->channel);
  gst_structure_free(options);
  if (s->channel == nullptr) {
    g_printerr("pfap-web: session %d: webrtcbin made no data channel\n", s->id);
  } else {
    g_signal_connect_data(s->channel, "on-open", G_CALLBACK(on_channel_open), weak(s), free_weak,
                          GConnectFlags(0));
  }
  s->pending_text = server.options.text;

  JsonBuilder* b = message("timing");
  member(b, "audioClockRate", kAudioClockRate);
  member(b, "audioTimestampOffset", s->audio_ts_offset);
  member(b, "pfapClockRate", kPfapClockRate);
  member(b, "pfapTimestampOffset", s->pfap_ts_offset);
  member(b, "drop", static_cast<int64_t>(server.options.drop * 1000));
  finish(*s, b);

  gst_element_set_state(s->pipeline, GST_STATE_PLAYING);
  g_print("pfap-web: session %d opened\n", s->id);
  return s;
}

void on_ws_message(SoupWebsocketConnection*, gint type, GBytes* bytes, gpointer data) {
  std::shared_ptr<Session> session = *static_cast<std::shared_ptr<Session>*>(data);
  if (session->closed || type != SOUP_WEBSOCKET_DATA_TEXT) return;
  Session& s = *session;
  gsize size = 0;
  const char* text = static_cast<const char*>(g_bytes_get_data(bytes, &size));
  JsonParser* parser = json_parser_new();
  if (!json_parser_load_from_data(parser, text, static_cast<gssize>(size), nullptr) ||
      !JSON_NODE_HOLDS_OBJECT(json_parser_get_root(parser))) {
    g_printerr("pfap-web: session %d: a message that is not a JSON object\n", s.id);
    g_object_unref(parser);
    return;
  }
  JsonObject* m = json_node_get_object(json_parser_get_root(parser));
  const char* kind = json_object_get_string_member_with_default(m, "type", "");
  if (std::strcmp(kind, "answer") == 0) {
    set_answer(s, json_object_get_string_member_with_default(m, "sdp", ""));
  } else if (std::strcmp(kind, "ice") == 0) {
    const char* candidate = json_object_get_string_member_with_default(m, "candidate", "");
    const gint64 mline = json_object_get_int_member_with_default(m, "sdpMLineIndex", 0);
    if (*candidate != '\0') {
      g_signal_emit_by_name(s.webrtc, "add-ice-candidate", static_cast<guint>(mline), candidate);
    }
  } else if (std::strcmp(kind, "say") == 0) {
    const char* said = json_object_get_string_member_with_default(m, "text", "");
    if (*said != '\0') say(s, said);
  } else if (std::strcmp(kind, "playing") == 0) {
    s.playing = true;
    start_when_ready(s);
  } else if (std::strcmp(kind, "complete") == 0) {
    request_complete(s);
  } else {
    g_printerr("pfap-web: session %d: unknown message type \"%s\"\n", s.id, kind);
  }
  g_object_unref(parser);
}

void on_ws_closed(SoupWebsocketConnection*, gpointer data) {
  close_session(*static_cast<std::shared_ptr<Session>*>(data));
}

void on_websocket(SoupServer*, SoupServerMessage*, const char*, SoupWebsocketConnection* ws,
                  gpointer data) {
  Server& server = *static_cast<Server*>(data);
  std::shared_ptr<Session> session = open_session(server, ws);
  if (session == nullptr) return;
  std::erase_if(server.open, [](const std::weak_ptr<Session>& s) { return s.expired(); });
  server.open.push_back(session);
  // The connection's handlers own the session (released when they are disconnected).
  auto* holder = new std::shared_ptr<Session>(session);
  g_signal_connect_data(ws, "message", G_CALLBACK(on_ws_message), holder, nullptr,
                        GConnectFlags(0));
  g_signal_connect_data(
      ws, "closed", G_CALLBACK(on_ws_closed), holder,
      [](gpointer d, GClosure*) { delete static_cast<std::shared_ptr<Session>*>(d); },
      GConnectFlags(0));
}

// -- HTTP ---------------------------------------------------------------------------------

const char* content_type(const std::string& path) {
  if (g_str_has_suffix(path.c_str(), ".html")) return "text/html; charset=utf-8";
  if (g_str_has_suffix(path.c_str(), ".js")) return "text/javascript; charset=utf-8";
  if (g_str_has_suffix(path.c_str(), ".css")) return "text/css; charset=utf-8";
  return "application/octet-stream";
}

// "/" is the page; only live/ and src/ are served, and no path goes up.
void on_http(SoupServer*, SoupServerMessage* msg, const char* path, GHashTable*, gpointer data) {
  const Server& server = *static_cast<Server*>(data);
  std::string file = path;
  if (file == "/") file = "/live/index.html";
  const bool allowed = (g_str_has_prefix(file.c_str(), "/live/") ||
                        g_str_has_prefix(file.c_str(), "/src/")) &&
                       file.find("..") == std::string::npos;
  gchar* contents = nullptr;
  gsize length = 0;
  if (!allowed || soup_server_message_get_method(msg) != std::string("GET") ||
      !g_file_get_contents((server.options.web_dir + file).c_str(), &contents, &length, nullptr)) {
    soup_server_message_set_status(msg, SOUP_STATUS_NOT_FOUND, nullptr);
    return;
  }
  soup_server_message_set_status(msg, SOUP_STATUS_OK, nullptr);
  soup_server_message_set_response(msg, content_type(file), SOUP_MEMORY_TAKE, contents, length);
}

// PFAP_WEB_DIR (set by `meson devenv` and scripts/serve to the source tree's web/), else the
// installed copy.
std::string default_web_dir() {
  const char* dir = g_getenv("PFAP_WEB_DIR");
  return dir != nullptr && *dir != '\0' ? dir : PFAP_WEB_INSTALL_DIR;
}

// 0 when the arguments are good, -1 after --help, 2 on a usage error.
int parse_options(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](const char* name) -> const char* {
      const size_t n = std::strlen(name);
      return arg.compare(0, n, name) == 0 ? argv[i] + n : nullptr;
    };
    char* end = nullptr;
    if (arg == "--help" || arg == "-h") {
      usage(stdout);
      return -1;
    }
    if (const char* v = value("--port=")) {
      o.port = static_cast<int>(std::strtol(v, &end, 10));
      if (end == v || *end != '\0' || o.port < 0 || o.port > 65535) {
        std::fprintf(stderr, "pfap-web: --port wants 0..65535: %s\n", v);
        return 2;
      }
    } else if (const char* v = value("--drop=")) {
      o.drop = std::strtod(v, &end);
      if (end == v || *end != '\0' || !(o.drop >= 0.0 && o.drop < 1.0)) {
        std::fprintf(stderr, "pfap-web: --drop wants a probability in [0, 1): %s\n", v);
        return 2;
      }
    } else if (const char* v = value("--seed=")) {
      o.seed = static_cast<uint32_t>(std::strtoul(v, &end, 10));
      if (end == v || *end != '\0') {
        std::fprintf(stderr, "pfap-web: --seed wants a number: %s\n", v);
        return 2;
      }
    } else if (const char* v = value("--text=")) {
      o.text = v;
    } else if (const char* v = value("--web-dir=")) {
      o.web_dir = v;
    } else {
      std::fprintf(stderr, "pfap-web: unknown argument %s\n", arg.c_str());
      usage(stderr);
      return 2;
    }
  }
  if (o.web_dir.empty()) o.web_dir = default_web_dir();
  return 0;
}

// Ctrl-C or SIGTERM: each session's pipeline stops, its browser is told, and what the
// sessions and the server hold is freed.
void stop(Server& server, SoupServer* soup) {
  for (const std::weak_ptr<Session>& weak : server.open) {
    std::shared_ptr<Session> s = weak.lock();
    if (s == nullptr) continue;
    auto* ws = SOUP_WEBSOCKET_CONNECTION(g_object_ref(s->ws));
    close_session(s);
    s.reset();
    // Its handlers hold the session: disconnecting them frees it.
    g_signal_handlers_disconnect_matched(ws, G_SIGNAL_MATCH_FUNC, 0, 0, nullptr,
                                         reinterpret_cast<gpointer>(on_ws_message), nullptr);
    g_signal_handlers_disconnect_matched(ws, G_SIGNAL_MATCH_FUNC, 0, 0, nullptr,
                                         reinterpret_cast<gpointer>(on_ws_closed), nullptr);
    if (soup_websocket_connection_get_state(ws) == SOUP_WEBSOCKET_STATE_OPEN) {
      soup_websocket_connection_close(ws, SOUP_WEBSOCKET_CLOSE_GOING_AWAY, "server stopped");
    }
    g_object_unref(ws);
  }
  server.open.clear();
  soup_server_disconnect(soup);
  g_object_unref(soup);
  // What the closing left to do (the close frames, finalizing the connections).
  while (g_main_context_iteration(nullptr, FALSE)) {
  }
}

}  // namespace

int main(int argc, char** argv) {
  gst_init(&argc, &argv);
  Server server;
  if (int status = parse_options(argc, argv, server.options); status != 0) {
    return status < 0 ? 0 : status;
  }
  for (const char* element : {"webrtcbin", "pfaptts", "rtppfappay", "opusenc", "rtpopuspay"}) {
    GstElementFactory* factory = gst_element_factory_find(element);
    if (factory == nullptr) {
      std::fprintf(stderr, "pfap-web: no %s element (GST_PLUGIN_PATH, docs/web.md)\n", element);
      return 1;
    }
    gst_object_unref(factory);
  }
  SoupServer* soup = soup_server_new("server-header", "pfap-web", nullptr);
  soup_server_add_websocket_handler(soup, "/ws", nullptr, nullptr, on_websocket, &server, nullptr);
  soup_server_add_handler(soup, nullptr, on_http, &server, nullptr);
  GError* error = nullptr;
  // Loopback only: the page and its sessions are for this machine.
  GInetAddress* loopback = g_inet_address_new_loopback(G_SOCKET_FAMILY_IPV4);
  GSocketAddress* address = g_inet_socket_address_new(loopback, static_cast<guint16>(server.options.port));
  g_object_unref(loopback);
  const bool listening = soup_server_listen(soup, address, SoupServerListenOptions(0), &error);
  g_object_unref(address);
  if (!listening) {
    std::fprintf(stderr, "pfap-web: cannot listen on 127.0.0.1:%d: %s\n", server.options.port,
                 error->message);
    g_error_free(error);
    g_object_unref(soup);
    return 1;
  }
  // The port from the listening socket (libsoup 3.2's soup_server_get_uris leaks an address).
  GSList* listeners = soup_server_get_listeners(soup);
  GSocketAddress* local = g_socket_get_local_address(G_SOCKET(listeners->data), nullptr);
  g_slist_free(listeners);
  const guint16 port =
      local != nullptr ? g_inet_socket_address_get_port(G_INET_SOCKET_ADDRESS(local)) : 0;
  if (local != nullptr) g_object_unref(local);
  g_print("pfap-web: open http://127.0.0.1:%u/ in a browser (Ctrl-C stops)\n", port);
  GMainLoop* loop = g_main_loop_new(nullptr, FALSE);
  auto quit = [](gpointer loop) -> gboolean {
    g_main_loop_quit(static_cast<GMainLoop*>(loop));
    return G_SOURCE_CONTINUE;  // removed below
  };
  const guint on_sigint = g_unix_signal_add(SIGINT, quit, loop);
  const guint on_sigterm = g_unix_signal_add(SIGTERM, quit, loop);
  g_main_loop_run(loop);
  g_source_remove(on_sigint);
  g_source_remove(on_sigterm);
  stop(server, soup);
  g_main_loop_unref(loop);
  gst_deinit();
  g_print("pfap-web: stopped\n");
  return 0;
}

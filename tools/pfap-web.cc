// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap-web: the talking head in a browser (docs/web.md). Serves the page (web/live/, which
// uses pfap.js from web/src/) over HTTP and, for each browser that connects to its WebSocket,
// runs a WebRTC session of its own:
//
//                       audiomixer force-live=true ! opusenc ! rtpopuspay ! valve ! webrtcbin
//   pfaptts ! audio ! ^ (one per text said, added while playing)
//           ! pfap  ! rtppfappay ! appsink ! data channel "pfap" (ordered=false,
//                                                                 max-retransmits=0)
//
// Each PFAP RTP packet, header included, is one data-channel message. Both payloaders stamp
// their packets from the same running time, with timestamp offsets the server chooses and
// tells the page on the WebSocket, so the page maps the audio it plays to PFAP time. The
// WebSocket also carries the SDP offer and answer, ICE candidates, the texts to say and, at
// the end of each, the sender's FAP state and counts (the page compares them with its own),
// and the speech's level, which the page finds in the audio it plays to know what it hears.
//
// What a page sends is checked against its schema before anything acts on it
// (pfap-web-signal.h); a WebSocket is accepted only from the server's own origin and those
// allowed; sessions are capped by the file descriptors they take, and one that does not connect
// in time is closed (docs/security.md, "pfap-web"). A STUN server beside the HTTP one gives
// the page its own address when the browser hides it (pfap-web-stun.h, docs/web.md).
#include <glib-unix.h>
#include <gst/app/gstappsink.h>
#include <gst/app/gstappsrc.h>
#include <gst/gst.h>
#include <gst/sdp/sdp.h>
#include <gst/video/video-event.h>
#define GST_USE_UNSTABLE_API
#include <gst/webrtc/webrtc.h>
#include <json-glib/json-glib.h>
#include <libsoup/soup.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "command_line.h"
#include "launch_value.h"
#include "pfap-web-signal.h"
#include "pfap-web-stun.h"
#include "pfap/model.h"
#include "ratelimit.h"
#include "sent_pfap.h"
#include "speech_level.h"
#include "speech_opus.h"
#include "webrtc_transport_bins.h"

namespace {

constexpr const char* kDefaultText =
    "Hello! <FAP 2 1 40 0 0 800 3> I am a talking head in your browser. "
    "<FAP 48 6000 400 2> My voice comes over WebRTC, <FAP 2 6 50 0 0 300 2> and my face on a "
    "data channel, in step with it. <FAP 2 1 50 0 0 800 3> Type something for me to say!";
constexpr uint32_t kAudioClockRate = 48000;  // Opus's RTP clock rate, whatever the audio's
constexpr uint32_t kPfapClockRate = 44100;   // the draft's default
// A new text starts this far ahead of the running time its first audio is ready for the mixer
// at, so that the audio reaches the mixer in time (the mixer drops what comes after its output
// has passed).
constexpr GstClockTime kSpeakLead = 300 * GST_MSECOND;
// PFAP packets go this far ahead of their time: the page holds their events until the audio
// reaches them, and what comes late is drawn late.
constexpr GstClockTimeDiff kPfapLead = 400 * GST_MSECOND;
// The file descriptors one session takes at most (measured, docs/security.md: 16 waiting for
// the answer, up to 24.1 connected and speaking), and those kept for the server itself (its
// listening sockets, the page's HTTP connections, GLib's and GStreamer's own) when the
// session cap is derived from the limit.
constexpr int kFdsPerSession = 25;
constexpr int kReservedFds = 64;

struct Options {
  int port = 8080;
  std::string text = kDefaultText;
  double drop = 0.0;
  uint32_t seed = 1;
  std::string web_dir;
  int max_sessions = 0;  // 0: as many as the file descriptor limit allows
  double connect_timeout_s = 30.0;
  double stop_timeout_s = 10.0;
  std::vector<std::string> allowed_origins;  // besides the server's own
};

// Set at SIGINT or SIGTERM: the calls still queued for the main loop are dropped (post()), so
// that the main loop quits at once; the stop closes their sessions. Run, they held the quit
// back: in the sanitizer build a text starting took 0.7 s of the main thread, and with 20
// sessions saying short texts one after another the stop began 46 s after the signal.
std::atomic<bool> stopping{false};

// SIGINT and SIGTERM, and a bound on stopping (docs/web.md, "Stopping"). The signals are taken
// on a thread of its own, not by the main loop: the main thread may be what blocks. The SCTP
// of webrtcbin 1.22 (usrsctp, bundled with gst-plugins-bad) has been seen to block a
// pipeline's change to NULL for good, as a session closed when its page left. At a signal the
// watch quits the main loop, which then stops the sessions, and gives the whole stop
// `seconds`; if it has not finished by then, the watch names what the main thread was doing
// and ends the process with status 3, skipping the exit handlers, which could block as well.
// A server that never exits is worse than one that exits without finishing.
class StopWatch {
 public:
  StopWatch(GMainLoop* loop, double seconds)
      : loop_(loop), seconds_(seconds), thread_([this] { watch(); }) {}
  // Once the stop has finished.
  ~StopWatch() {
    {
      std::lock_guard lock(mutex_);
      finished_ = true;
    }
    changed_.notify_one();
    g_main_context_wakeup(context_);
    thread_.join();
    g_main_context_unref(context_);
  }
  StopWatch(const StopWatch&) = delete;
  StopWatch& operator=(const StopWatch&) = delete;

  // What the main thread is doing now, and what it has yet to do, as the message would say.
  void now(std::string what) {
    std::lock_guard lock(mutex_);
    what_ = std::move(what);
  }
  void yet(std::string rest) {
    std::lock_guard lock(mutex_);
    rest_ = std::move(rest);
  }

 private:
  void watch() {
    bool signalled = false;
    for (int signal : {SIGINT, SIGTERM}) {
      GSource* source = g_unix_signal_source_new(signal);
      g_source_set_callback(
          source,
          [](gpointer signalled) -> gboolean {
            *static_cast<bool*>(signalled) = true;
            return G_SOURCE_CONTINUE;
          },
          &signalled, nullptr);
      g_source_attach(source, context_);
      g_source_unref(source);
    }
    while (!signalled && !finished()) g_main_context_iteration(context_, TRUE);
    if (!signalled) return;
    stopping = true;
    g_main_loop_quit(loop_);
    std::unique_lock lock(mutex_);
    if (changed_.wait_for(lock, std::chrono::duration<double>(seconds_),
                          [this] { return finished_; })) {
      return;
    }
    char s[G_ASCII_DTOSTR_BUF_SIZE];
    g_ascii_dtostr(s, sizeof s, seconds_);
    std::fprintf(stderr,
                 "pfap-web: not stopped within %s s (--stop-timeout), at %s%s; exiting anyway "
                 "(docs/web.md, \"Stopping\")\n",
                 s, what_.c_str(), rest_.c_str());
    std::fflush(stderr);
    std::_Exit(3);
  }

  bool finished() {
    std::lock_guard lock(mutex_);
    return finished_;
  }

  GMainLoop* loop_;
  double seconds_;
  GMainContext* context_ = g_main_context_new();
  std::mutex mutex_;
  std::condition_variable changed_;
  bool finished_ = false;
  std::string what_ = "the main loop";
  std::string rest_;
  std::thread thread_;  // last: it starts once the rest is made
};

struct Server;

// A WebRTC session with one browser. Lives on the main thread; GStreamer's threads post
// what they have to say there (post()).
struct Session : std::enable_shared_from_this<Session> {
  int id = 0;
  Server* server = nullptr;
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
  bool answered = false;
  GstPromise* answer_set = nullptr;  // the last answer's, until the session closes
  guint connect_timer = 0;           // until the data channel opens
  std::string pending_text;          // said when the audio starts or the current text ends
  uint32_t audio_ts_offset = 0;
  uint32_t pfap_ts_offset = 0;

  SentPfap sent;  // the appsink's thread, and the main loop's state messages
};

std::string text_of(JsonNode* node) {
  gchar* s = json_to_string(node, FALSE);
  std::string out = s;
  g_free(s);
  json_node_unref(node);
  return out;
}

// Sends the message `b` holds, if `ws` is open, and frees `b`.
void send_message(SoupWebsocketConnection* ws, JsonBuilder* b) {
  JsonNode* node = json_builder_get_root(b);
  g_object_unref(b);
  const std::string text = text_of(node);
  if (soup_websocket_connection_get_state(ws) != SOUP_WEBSOCKET_STATE_OPEN) return;
  soup_websocket_connection_send_text(ws, text.c_str());
}

void send_json(Session& s, JsonBuilder* b) {
  if (s.closed) {
    g_object_unref(b);
    return;
  }
  send_message(s.ws, b);
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

// The thread of main(), where the sessions live.
const std::thread::id kMainThread = std::this_thread::get_id();

// Runs `f` on the main thread, from its main loop, if the session is still open and the server
// not stopping then. Never
// at once, as g_main_context_invoke would: called from the main thread, `f` would run inside a
// GStreamer call; called from a streaming thread while the main loop is not running (as the
// stop closes the sessions one by one), it would run on that thread, beside close_session
// (a speaker bin started that way on a pipeline going to NULL was disposed in PAUSED).
void post(const std::shared_ptr<Session>& session, std::function<void(Session&)> f) {
  struct Call {
    std::shared_ptr<Session> session;
    std::function<void(Session&)> f;
  };
  GSource* source = g_idle_source_new();
  g_source_set_priority(source, G_PRIORITY_DEFAULT);
  g_source_set_callback(
      source,
      [](gpointer data) -> gboolean {
        auto* call = static_cast<Call*>(data);
        if (std::this_thread::get_id() != kMainThread) {
          g_critical("pfap-web: session %d: a call for the main thread ran on another",
                     call->session->id);
        }
        if (!call->session->closed && !stopping) call->f(*call->session);
        return G_SOURCE_REMOVE;
      },
      new Call{session, std::move(f)}, [](gpointer data) { delete static_cast<Call*>(data); });
  g_source_attach(source, nullptr);
  g_source_unref(source);
}

std::shared_ptr<Session> session_of(gpointer data) {
  return static_cast<std::weak_ptr<Session>*>(data)->lock();
}

gpointer weak(const std::shared_ptr<Session>& s) { return new std::weak_ptr<Session>(s); }

void free_weak_data(gpointer data) { delete static_cast<std::weak_ptr<Session>*>(data); }

void free_weak(gpointer data, GClosure*) { free_weak_data(data); }

// -- Signalling ---------------------------------------------------------------------------

// With a promise: given none, webrtcbin 1.22 leaks the reply it would have given it. The
// promise is returned, replied once webrtcbin's thread has set the description.
GstPromise* set_description(GstElement* webrtc, const char* signal,
                            GstWebRTCSessionDescription* sdp) {
  GstPromise* promise = gst_promise_new();
  g_signal_emit_by_name(webrtc, signal, sdp, promise);
  return promise;
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
  gst_promise_unref(set_description(session->webrtc, "set-local-description", offer));
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

// False when the SDP cannot be read or has no media (GstSDP reads any text, skipping lines it
// does not know).
bool set_answer(Session& s, const std::string& sdp_text) {
  GstSDPMessage* sdp = nullptr;
  if (gst_sdp_message_new_from_text(sdp_text.c_str(), &sdp) != GST_SDP_OK ||
      gst_sdp_message_medias_len(sdp) == 0) {
    if (sdp != nullptr) gst_sdp_message_free(sdp);
    return false;
  }
  GstWebRTCSessionDescription* answer =
      gst_webrtc_session_description_new(GST_WEBRTC_SDP_TYPE_ANSWER, sdp);
  if (s.answer_set != nullptr) gst_promise_unref(s.answer_set);
  s.answer_set = set_description(s.webrtc, "set-remote-description", answer);
  gst_webrtc_session_description_free(answer);
  return true;
}

// -- The PFAP stream ----------------------------------------------------------------------

// The sender's FAP state and counts, after the last packet of a text or a complete state.
void send_state(Session& s, const char* type) {
  JsonBuilder* b = message(type);
  s.sent.read([&](const SentPfap::Counts& c, const pfap::FapState& state) {
    member(b, "packets", static_cast<int64_t>(c.packets));
    member(b, "dropped", static_cast<int64_t>(c.dropped));
    member(b, "phonemes", static_cast<int64_t>(c.phonemes));
    member(b, "lastSequenceNumber", c.last_seqnum);
    json_builder_set_member_name(b, "settled");
    json_builder_begin_array(b);
    for (int i = pfap::kMinFapIndex; i <= pfap::kMaxFapIndex; ++i) {
      json_builder_add_int_value(b, state.settled(i));
    }
    json_builder_end_array(b);
  });
  finish(s, b);
}

// Each packet rtppfappay makes, at its time (less kPfapLead): recorded as sent, then lost
// or sent whole on the data channel.
GstFlowReturn on_pfap_packet(GstAppSink* sink, gpointer data) {
  GstSample* sample = gst_app_sink_pull_sample(sink);
  if (sample == nullptr) return GST_FLOW_EOS;
  std::shared_ptr<Session> session = session_of(data);
  GstBuffer* buffer = gst_sample_get_buffer(sample);
  GstMapInfo map;
  if (session != nullptr && session->sent.take(buffer, kPfapClockRate) &&
      session->channel != nullptr && gst_buffer_map(buffer, &map, GST_MAP_READ)) {
    GBytes* bytes = g_bytes_new(map.data, map.size);
    g_signal_emit_by_name(session->channel, "send-data", bytes);
    g_bytes_unref(bytes);
    gst_buffer_unmap(buffer, &map);
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
void send_envelope(Session& s, GstClockTime start, const std::vector<int64_t>& levels) {
  JsonBuilder* b = message("envelope");
  member(b, "runningTimeNs", static_cast<int64_t>(start));
  member(b, "level", encode_levels(levels).c_str());
  finish(s, b);
}

// When a text starts: kSpeakLead of running time after its first audio is ready for the mixer
// (or the speaker ends without any), not after the text is asked for. A start fixed when it
// was asked for lost a short text's audio whole when the speaker took longer than the lead to
// begin (three sessions starting at once in the sanitizer build, where the first audio's
// conversion and negotiation took over a second): the mixer dropped it as late, while the
// PFAP stream went on (docs/web.md, Timing). Both of the speaker's branches get the same pad
// offset then.
//
// The audio's offset is set on the pad the first converted buffer is leaving, from its own
// probe: that pad sends its sticky events again, with the offset, before the buffer. Set on a
// pad another thread pushes through (the ghost pad after the queue), it was lost when that
// thread was sending the segment at the time: GstPad marks the segment sent once its push
// returns, over gst_pad_set_offset()'s mark, so the segment went without the offset and the
// mixer dropped the whole text as late (2 runs in 5 of "three browsers at once" in the normal
// build, and in CI).
//
// The PFAP branch is held until then at its queue's source pad, so nothing has passed its
// ghost pad when that gets its offset; a pipeline going to NULL sets that pad flushing first,
// letting the hold go (held at the ghost pad, the queue's thread could not be stopped: a stop
// hung at a speaker's pipeline going to NULL).
struct SpeechStart {
  GstElement* speaker;  // the speaker bin and its pads, which outlive its data flow
  GstPad* pfap;         // the PFAP ghost pad
  GstPad* pfap_queue;   // the PFAP queue's source pad, held
  gulong pfap_hold;
};

GstPadProbeReturn hold(GstPad*, GstPadProbeInfo*, gpointer) { return GST_PAD_PROBE_OK; }

GstPadProbeReturn on_speaker_audio(GstPad* converted, GstPadProbeInfo* info, gpointer data) {
  if ((info->type & GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM) != 0 &&
      GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) != GST_EVENT_EOS) {
    return GST_PAD_PROBE_OK;
  }
  const auto& start = *static_cast<SpeechStart*>(data);
  GstClock* clock = gst_element_get_clock(start.speaker);
  if (clock == nullptr) return GST_PAD_PROBE_OK;  // not in the playing pipeline (yet)
  const GstClockTime now = gst_clock_get_time(clock) - gst_element_get_base_time(start.speaker);
  gst_object_unref(clock);
  gst_pad_set_offset(converted, static_cast<gint64>(now + kSpeakLead));
  gst_pad_set_offset(start.pfap, static_cast<gint64>(now + kSpeakLead));
  gst_pad_remove_probe(start.pfap_queue, start.pfap_hold);
  return GST_PAD_PROBE_REMOVE;
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
  // Both branches start from the same running time, decided as the first audio, converted,
  // enters the queue before the mixer: the timestamps of the audio the mixer sends and of the
  // PFAP packets agree.
  GstElement* queue = gst_bin_get_by_name(GST_BIN(speaker), "audio");
  GstPad* queue_sink = gst_element_get_static_pad(queue, "sink");
  GstElement* pfap_queue = gst_bin_get_by_name(GST_BIN(speaker), "pfap");
  GstPad* pfap_queue_src = gst_element_get_static_pad(pfap_queue, "src");
  auto* start = new SpeechStart{speaker, pfap, pfap_queue_src, 0};
  start->pfap_hold = gst_pad_add_probe(pfap_queue_src, GST_PAD_PROBE_TYPE_BLOCK_DOWNSTREAM, hold,
                                       nullptr, nullptr);
  gst_object_unref(pfap_queue_src);  // the queue keeps it
  gst_object_unref(pfap_queue);
  GstPad* converted = gst_pad_get_peer(queue_sink);
  gst_pad_add_probe(
      converted, GstPadProbeType(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM),
      on_speaker_audio, start, [](gpointer data) { delete static_cast<SpeechStart*>(data); });
  gst_object_unref(converted);
  // Its level, as early as the speaker makes it (the queue before the mixer fills ahead), at
  // running times from the start above (the segment the queue gets has the offset).
  add_speech_level_probe(
      queue_sink, [session = s.weak_from_this()](GstClockTime start, std::vector<int64_t> levels) {
        if (std::shared_ptr<Session> locked = session.lock()) {
          post(locked, [start, levels = std::move(levels)](Session& s) {
            send_envelope(s, start, levels);
          });
        }
      });
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
      if (s.connect_timer != 0) g_source_remove(s.connect_timer);
      s.connect_timer = 0;
      start_when_ready(s);
    });
  }
}

// A request for a complete state (the page lost packets that nothing after them recovers):
// rtppfappay answers an upstream GstForceKeyUnit at once when idle.
void request_complete(Session& s) {
  GstPad* src = gst_element_get_static_pad(s.pay, "src");
  gst_pad_send_event(src,
                     gst_video_event_new_upstream_force_key_unit(GST_CLOCK_TIME_NONE, TRUE, 0));
  gst_object_unref(src);
  send_state(s, "state");
}

// -- Sessions -----------------------------------------------------------------------------

struct Server {
  Options options;
  StopWatch* stop_watch = nullptr;  // from the main loop's start to the end of the stop
  int sessions = 0;
  std::vector<std::weak_ptr<Session>> open;  // stopped when the server stops
  int max_sessions = 0;
  std::vector<std::string> origins;  // accepted Origin headers: its own and those allowed
  // What was refused, each logged at its 1st, 2nd, 4th, ... (pfap_warn_at).
  uint64_t bad_messages = 0;
  uint64_t foreign_origins = 0;
  uint64_t full = 0;
  uint64_t not_connected = 0;
  // The STUN server the page is given (pfap-web-stun.h).
  GSocket* stun = nullptr;
  GSource* stun_source = nullptr;
  guint16 stun_port = 0;
};

// Logs a refusal of a kind that a client can repeat at will, rate-limited: `count` counts
// that kind.
void warn_refused(uint64_t& count, const std::string& what) {
  if (pfap_warn_at(++count)) {
    g_printerr("pfap-web: %s (%" G_GUINT64_FORMAT " of this kind so far)\n", what.c_str(), count);
  }
}

// Tells the page why, then closes its WebSocket with `code` (1008, policy violation, for every
// refusal but a binary message's 1003: libsoup 3.2 sends 1002 for the registry's later codes,
// such as 1013 "try again later").
void send_error_and_close(SoupWebsocketConnection* ws, const std::string& why, gushort code) {
  if (soup_websocket_connection_get_state(ws) != SOUP_WEBSOCKET_STATE_OPEN) return;
  JsonBuilder* b = message("error");
  member(b, "message", why.c_str());
  json_builder_end_object(b);
  send_message(ws, b);
  soup_websocket_connection_close(ws, code, nullptr);
}

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

// webrtcbin 1.22 leaks the ERROR message that its data channel's appsrc posts when a push
// fails, and with it the appsrc: the data channel's bin takes the message and never unrefs
// it (WebRTCErrorIgnoreBin in gst-plugins-bad's webrtcdatachannel.c; fixed upstream later).
// A push fails when the peer leaves mid-sentence: its SCTP association is gone while PFAP
// packets still flow, until the WebSocket closes and the session with it. So the appsrc's
// buffers go downstream through this probe, and a failed push ends its task quietly, as a
// flushing pad does. What failed is not hidden: sctpenc posts its own error to the bus.
GstPadProbeReturn push_without_error(GstPad* pad, GstPadProbeInfo* info, gpointer) {
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  GST_PAD_PROBE_INFO_DATA(info) = nullptr;
  GstPad* peer = gst_pad_get_peer(pad);
  GstFlowReturn flow = GST_FLOW_NOT_LINKED;
  if (peer != nullptr) {
    flow = gst_pad_chain(peer, buffer);
    gst_object_unref(peer);
  } else {
    gst_buffer_unref(buffer);
  }
  GST_PAD_PROBE_INFO_FLOW_RETURN(info) =
      flow == GST_FLOW_NOT_LINKED || flow < GST_FLOW_EOS ? GST_FLOW_FLUSHING : flow;
  return GST_PAD_PROBE_HANDLED;
}

// webrtcbin adds the data channel's appsrc once the channel is linked to SCTP.
void on_webrtc_element_added(GstBin*, GstBin*, GstElement* element, gpointer) {
  if (!GST_IS_APP_SRC(element)) return;
  GstPad* src = gst_element_get_static_pad(element, "src");
  gst_pad_add_probe(src, GST_PAD_PROBE_TYPE_BUFFER, push_without_error, nullptr, nullptr);
  gst_object_unref(src);
}

void close_session(const std::shared_ptr<Session>& s) {
  if (s->closed) return;
  s->closed = true;
  if (s->connect_timer != 0) g_source_remove(s->connect_timer);
  s->connect_timer = 0;
  StopWatch* watch = s->server->stop_watch;
  if (watch != nullptr)
    watch->now("session " + std::to_string(s->id) + "'s pipeline going to NULL");
  // webrtcbin 1.22 sets the answer on its own thread, which it stops only after its children
  // have gone to NULL. Set in between, the answer blocks the receive bin's input again (ICE
  // not yet connected) with a probe that holds the bin: the bin, its nicesrc, dtlsdec and
  // srtpdec and their 5 fds would outlive the session (docs/performance.md, "Sessions that
  // come and go"). So the answer is set first.
  if (s->answer_set != nullptr) {
    gst_promise_wait(s->answer_set);
    gst_promise_unref(s->answer_set);
    s->answer_set = nullptr;
  }
  // A change of ICE state after the bin's NULL would block it the same way, and one after
  // webrtcbin's disposal would reach its freed send bins: both follow their ICE transport
  // from handlers that webrtcbin 1.22 never disconnects. So the handlers go first
  // (webrtc_transport_bins.h).
  stop_webrtc_pipeline(s->pipeline, s->webrtc);
  if (watch != nullptr) watch->now("the main loop");
  gst_bus_remove_watch(GST_ELEMENT_BUS(s->pipeline));
  if (s->speaker_mixer_pad != nullptr) gst_object_unref(s->speaker_mixer_pad);
  if (s->channel != nullptr) g_object_unref(s->channel);
  gst_object_unref(s->pipeline);
  g_object_unref(s->ws);
  g_print("pfap-web: session %d closed\n", s->id);
}

// Ends a session the server will not go on with: the page is told why, the WebSocket closes
// with `code`, the pipeline stops; the server and the other sessions go on.
void refuse_session(const std::shared_ptr<Session>& s, uint64_t& count, const std::string& why,
                    gushort code) {
  warn_refused(count, "session " + std::to_string(s->id) + " closed: " + why);
  send_error_and_close(s->ws, why, code);
  close_session(s);
}

gboolean on_connect_timeout(gpointer data) {
  std::shared_ptr<Session> s = session_of(data);
  if (s == nullptr || s->closed) return G_SOURCE_REMOVE;
  s->connect_timer = 0;
  char seconds[G_ASCII_DTOSTR_BUF_SIZE];
  g_ascii_dtostr(seconds, sizeof seconds, s->server->options.connect_timeout_s);
  refuse_session(
      s, s->server->not_connected,
      std::string(s->answered ? "no data channel opened in " : "no answer to the offer in ") +
          seconds + " s",
      SOUP_WEBSOCKET_CLOSE_POLICY_VIOLATION);
  return G_SOURCE_REMOVE;
}

// One session's pipeline. The mixer makes the audio's pace alone (force-live: it mixes on the
// clock with no live source upstream), silence between the texts, so no silent source runs
// beside it. Its output buffers are one Opus frame each (speech_opus.h).
std::string session_pipeline() {
  return "webrtcbin name=webrtc bundle-policy=max-bundle "
         "audiomixer name=mix force-live=true output-buffer-duration=" +
         std::to_string(kOpusFrame) + " ! audio/x-raw,format=S16LE,rate=48000,channels=1 ! " +
         opus_encoder_description() +
         " ! rtpopuspay name=apay pt=111 "
         "! application/x-rtp,media=audio,encoding-name=OPUS,clock-rate=48000,payload=111 "
         "! valve name=gate drop=true drop-mode=forward-sticky-events ! webrtc. "
         "rtppfappay name=pay pt=96 ! application/x-rtp,clock-rate=44100 "
         "! appsink name=pfapsink sync=true async=false";
}

// The session's pipeline, its elements found and set: false if it cannot be made.
bool make_pipeline(Session& s) {
  GError* error = nullptr;
  s.pipeline = gst_parse_launch(session_pipeline().c_str(), &error);
  if (s.pipeline == nullptr) {
    g_printerr("pfap-web: %s\n", error->message);
    g_error_free(error);
    return false;
  }
  auto by_name = [&](const char* name) {
    GstElement* e = gst_bin_get_by_name(GST_BIN(s.pipeline), name);
    gst_object_unref(e);  // the pipeline keeps it
    return e;
  };
  s.webrtc = by_name("webrtc");
  s.mixer = by_name("mix");
  s.pay = by_name("pay");
  g_object_set(by_name("apay"), "timestamp-offset", s.audio_ts_offset, nullptr);
  g_object_set(s.pay, "timestamp-offset", s.pfap_ts_offset, nullptr);
  GstElement* sink = by_name("pfapsink");
  g_object_set(sink, "ts-offset", -kPfapLead, nullptr);
  GstAppSinkCallbacks callbacks{};
  callbacks.new_sample = on_pfap_packet;
  gst_app_sink_set_callbacks(GST_APP_SINK(sink), &callbacks, weak(s.shared_from_this()),
                             free_weak_data);
  GstPad* sink_pad = gst_element_get_static_pad(sink, "sink");
  gst_pad_add_probe(sink_pad, GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM, on_sink_gap,
                    weak(s.shared_from_this()), free_weak_data);
  gst_object_unref(sink_pad);
  return true;
}

// ICE on 127.0.0.1 only, as the HTTP server: the page is on this machine (a browser offers
// its loopback candidate with --allow-loopback-in-peer-connection, docs/web.md), and no
// packet goes to another address: so no UPnP either, which would ask the LAN's router for a
// port mapping by multicast from every address, in every session. Send only: the page has
// nothing to send but its answer.
void configure_webrtc(Session& s) {
  GObject* ice = nullptr;
  g_object_get(s.webrtc, "ice-agent", &ice, nullptr);
  gboolean added = FALSE;
  g_signal_emit_by_name(ice, "add-local-ip-address", "127.0.0.1", &added);
  GObject* agent = nullptr;
  g_object_get(ice, "agent", &agent, nullptr);
  g_object_set(agent, "upnp", FALSE, nullptr);
  g_object_unref(agent);
  g_object_unref(ice);
  if (!added) g_printerr("pfap-web: session %d: ICE cannot use 127.0.0.1\n", s.id);

  GArray* transceivers = nullptr;
  g_signal_emit_by_name(s.webrtc, "get-transceivers", &transceivers);
  for (guint i = 0; transceivers != nullptr && i < transceivers->len; ++i) {
    g_object_set(g_array_index(transceivers, GstWebRTCRTPTransceiver*, i), "direction",
                 GST_WEBRTC_RTP_TRANSCEIVER_DIRECTION_SENDONLY, nullptr);
  }
  if (transceivers != nullptr) g_array_unref(transceivers);

  const std::shared_ptr<Session> session = s.shared_from_this();
  g_signal_connect_data(s.webrtc, "on-negotiation-needed", G_CALLBACK(on_negotiation_needed),
                        weak(session), free_weak, GConnectFlags(0));
  g_signal_connect_data(s.webrtc, "on-ice-candidate", G_CALLBACK(on_ice_candidate), weak(session),
                        free_weak, GConnectFlags(0));
  g_signal_connect(s.webrtc, "deep-element-added", G_CALLBACK(on_webrtc_element_added), nullptr);
}

// The "pfap" data channel, unordered and unreliable; made in READY, before the offer.
void create_data_channel(Session& s) {
  GstStructure* options = gst_structure_new("options", "ordered", G_TYPE_BOOLEAN, FALSE,
                                            "max-retransmits", G_TYPE_INT, 0, nullptr);
  g_signal_emit_by_name(s.webrtc, "create-data-channel", "pfap", options, &s.channel);
  gst_structure_free(options);
  if (s.channel == nullptr) {
    g_printerr("pfap-web: session %d: webrtcbin made no data channel\n", s.id);
    return;
  }
  g_signal_connect_data(s.channel, "on-open", G_CALLBACK(on_channel_open),
                        weak(s.shared_from_this()), free_weak, GConnectFlags(0));
}

// What the page needs to map the audio it plays to PFAP time (docs/web.md, Timing).
void send_timing(Session& s) {
  JsonBuilder* b = message("timing");
  member(b, "audioClockRate", kAudioClockRate);
  member(b, "audioTimestampOffset", s.audio_ts_offset);
  member(b, "pfapClockRate", kPfapClockRate);
  member(b, "pfapTimestampOffset", s.pfap_ts_offset);
  member(b, "drop", static_cast<int64_t>(s.server->options.drop * 1000));
  member(b, "stunPort", s.server->stun_port);
  finish(s, b);
}

std::shared_ptr<Session> open_session(Server& server, SoupWebsocketConnection* ws) {
  auto s = std::make_shared<Session>();
  s->id = ++server.sessions;
  s->server = &server;
  s->audio_ts_offset = g_random_int();
  s->pfap_ts_offset = g_random_int();
  s->sent.configure(server.options.drop, server.options.seed + static_cast<uint32_t>(s->id),
                    s->pfap_ts_offset);
  if (!make_pipeline(*s)) return nullptr;
  s->ws = SOUP_WEBSOCKET_CONNECTION(g_object_ref(ws));
  configure_webrtc(*s);
  gst_bus_add_watch_full(GST_ELEMENT_BUS(s->pipeline), G_PRIORITY_DEFAULT, on_bus, weak(s),
                         free_weak_data);
  gst_element_set_state(s->pipeline, GST_STATE_READY);
  create_data_channel(*s);
  s->pending_text = server.options.text;
  s->connect_timer = g_timeout_add_full(
      G_PRIORITY_DEFAULT, static_cast<guint>(std::lround(server.options.connect_timeout_s * 1000)),
      on_connect_timeout, weak(s), free_weak_data);
  send_timing(*s);
  gst_element_set_state(s->pipeline, GST_STATE_PLAYING);
  g_print("pfap-web: session %d opened\n", s->id);
  return s;
}

void on_ws_message(SoupWebsocketConnection*, gint type, GBytes* bytes, gpointer data) {
  const std::shared_ptr<Session>& session = *static_cast<std::shared_ptr<Session>*>(data);
  if (session->closed) return;
  Session& s = *session;
  Server& server = *s.server;
  if (type != SOUP_WEBSOCKET_DATA_TEXT) {
    refuse_session(session, server.bad_messages, "a binary message",
                   SOUP_WEBSOCKET_CLOSE_UNSUPPORTED_DATA);
    return;
  }
  gsize size = 0;
  const char* text = static_cast<const char*>(g_bytes_get_data(bytes, &size));
  pfap_web::Signal m;
  std::string error;
  if (!pfap_web::parse_signal(std::string_view(text, size), m, error)) {
    refuse_session(session, server.bad_messages, "a bad message: " + error,
                   SOUP_WEBSOCKET_CLOSE_POLICY_VIOLATION);
    return;
  }
  switch (m.kind) {
    case pfap_web::SignalKind::kAnswer:
      if (!set_answer(s, m.sdp)) {
        refuse_session(session, server.bad_messages, "a bad message: an unreadable SDP answer",
                       SOUP_WEBSOCKET_CLOSE_POLICY_VIOLATION);
        return;
      }
      s.answered = true;
      break;
    case pfap_web::SignalKind::kIce:
      if (!m.candidate.empty()) {
        g_signal_emit_by_name(s.webrtc, "add-ice-candidate", m.mline, m.candidate.c_str());
      }
      break;
    case pfap_web::SignalKind::kSay:
      if (!m.text.empty()) say(s, m.text);
      break;
    case pfap_web::SignalKind::kPlaying:
      s.playing = true;
      start_when_ready(s);
      break;
    case pfap_web::SignalKind::kComplete:
      request_complete(s);
      break;
  }
}

void on_ws_closed(SoupWebsocketConnection*, gpointer data) {
  close_session(*static_cast<std::shared_ptr<Session>*>(data));
}

void on_websocket(SoupServer*, SoupServerMessage*, const char*, SoupWebsocketConnection* ws,
                  gpointer data) {
  Server& server = *static_cast<Server*>(data);
  std::erase_if(server.open, [](const std::weak_ptr<Session>& w) {
    const std::shared_ptr<Session> s = w.lock();
    return s == nullptr || s->closed;
  });
  if (static_cast<int>(server.open.size()) >= server.max_sessions) {
    const std::string why = "the server is full: " + std::to_string(server.max_sessions) +
                            " sessions at once (try again later)";
    warn_refused(server.full, "a connection refused: " + why);
    send_error_and_close(ws, why, SOUP_WEBSOCKET_CLOSE_POLICY_VIOLATION);
    return;
  }
  std::shared_ptr<Session> session = open_session(server, ws);
  if (session == nullptr) return;
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

// -- STUN ---------------------------------------------------------------------------------

// A datagram on the STUN socket: a binding request is answered, anything else dropped.
gboolean on_stun(GSocket* socket, GIOCondition, gpointer) {
  uint8_t buffer[548];  // RFC 8489's smallest MTU's worth; a longer request is cut, dropped
  GSocketAddress* from = nullptr;
  const gssize n = g_socket_receive_from(socket, &from, reinterpret_cast<gchar*>(buffer),
                                         sizeof buffer, nullptr, nullptr);
  if (n >= 0 && from != nullptr && G_IS_INET_SOCKET_ADDRESS(from)) {
    auto* inet = G_INET_SOCKET_ADDRESS(from);
    GInetAddress* address = g_inet_socket_address_get_address(inet);
    if (g_inet_address_get_family(address) == G_SOCKET_FAMILY_IPV4) {
      const guint8* a = g_inet_address_to_bytes(address);
      const uint32_t ipv4 = static_cast<uint32_t>(a[0]) << 24 | static_cast<uint32_t>(a[1]) << 16 |
                            static_cast<uint32_t>(a[2]) << 8 | a[3];
      const auto response =
          pfap_web::stun_binding_response(std::span<const uint8_t>(buffer, static_cast<size_t>(n)),
                                          ipv4, g_inet_socket_address_get_port(inet));
      if (response.has_value()) {
        g_socket_send_to(socket, from, reinterpret_cast<const gchar*>(response->data()),
                         response->size(), nullptr, nullptr);
      }
    }
  }
  if (from != nullptr) g_object_unref(from);
  return G_SOURCE_CONTINUE;
}

// Listens for STUN on 127.0.0.1, UDP, on the HTTP port's number if it is free, else on any.
// False when it cannot.
bool start_stun(Server& server, guint16 http_port) {
  GSocket* socket =
      g_socket_new(G_SOCKET_FAMILY_IPV4, G_SOCKET_TYPE_DATAGRAM, G_SOCKET_PROTOCOL_UDP, nullptr);
  if (socket == nullptr) return false;
  GInetAddress* loopback = g_inet_address_new_loopback(G_SOCKET_FAMILY_IPV4);
  bool bound = false;
  for (const guint16 port : {http_port, guint16{0}}) {
    GSocketAddress* address = g_inet_socket_address_new(loopback, port);
    bound = g_socket_bind(socket, address, FALSE, nullptr);
    g_object_unref(address);
    if (bound) break;
  }
  g_object_unref(loopback);
  GSocketAddress* local = bound ? g_socket_get_local_address(socket, nullptr) : nullptr;
  if (local == nullptr) {
    g_object_unref(socket);
    return false;
  }
  server.stun_port = g_inet_socket_address_get_port(G_INET_SOCKET_ADDRESS(local));
  g_object_unref(local);
  g_socket_set_blocking(socket, FALSE);
  server.stun = socket;
  server.stun_source = g_socket_create_source(socket, G_IO_IN, nullptr);
  g_source_set_callback(server.stun_source, G_SOURCE_FUNC(on_stun), nullptr, nullptr);
  g_source_attach(server.stun_source, nullptr);
  return true;
}

// -- HTTP ---------------------------------------------------------------------------------

// The WebSocket's request, before libsoup's handshake: a browser says which page opens it in
// Origin, and only the server's own page and those allowed may (any page the user visits
// could open ws://127.0.0.1:8080/ws otherwise). A 403 here stops the handshake. A client that
// sends no Origin is not a browser, which always sends one: it could send any.
void on_ws_request(SoupServer*, SoupServerMessage* msg, const char*, GHashTable*, gpointer data) {
  Server& server = *static_cast<Server*>(data);
  const char* origin =
      soup_message_headers_get_one(soup_server_message_get_request_headers(msg), "Origin");
  if (origin == nullptr ||
      std::find(server.origins.begin(), server.origins.end(), origin) != server.origins.end()) {
    return;
  }
  warn_refused(server.foreign_origins, "a WebSocket refused: a page of another origin");
  static constexpr char kForbidden[] =
      "pfap-web: this origin may not open the WebSocket (pfap-web --allow-origin)\n";
  soup_server_message_set_status(msg, SOUP_STATUS_FORBIDDEN, nullptr);
  soup_server_message_set_response(msg, "text/plain; charset=utf-8", SOUP_MEMORY_STATIC, kForbidden,
                                   sizeof kForbidden - 1);
}

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
  const bool allowed =
      (g_str_has_prefix(file.c_str(), "/live/") || g_str_has_prefix(file.c_str(), "/src/")) &&
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

// 0 when the arguments are good, else the exit status. GStreamer is initialized by the parse.
int parse_options(int* argc, char*** argv, Options& o) {
  gint port = o.port;
  gint64 seed = o.seed;
  gdouble drop = o.drop;
  gint max_sessions = -1;  // not given
  gdouble connect_timeout_s = o.connect_timeout_s;
  gdouble stop_timeout_s = o.stop_timeout_s;
  gchar *text = nullptr, *web_dir = nullptr;
  gchar** origins = nullptr;
  const GOptionEntry entries[] = {
      {"port", 0, 0, G_OPTION_ARG_INT, &port,
       "The HTTP port on 127.0.0.1, 0..65535 (default 8080; 0 picks a free one)", "N"},
      {"text", 0, 0, G_OPTION_ARG_STRING, &text, "The text to speak when the page asks for none",
       "TEXT"},
      {"drop", 0, 0, G_OPTION_ARG_DOUBLE, &drop,
       "The share of PFAP packets dropped, in [0, 1) (default 0)", "P"},
      {"seed", 0, 0, G_OPTION_ARG_INT64, &seed,
       "The seed of the drops (default 1; each session adds its number)", "S"},
      {"web-dir", 0, 0, G_OPTION_ARG_FILENAME, &web_dir,
       "The page (live/) and pfap.js (src/) (default $PFAP_WEB_DIR, else the installed one)",
       "DIR"},
      {"max-sessions", 0, 0, G_OPTION_ARG_INT, &max_sessions,
       "At most N sessions at once, 1..1000000 (default: as many as the open file limit allows)",
       "N"},
      {"connect-timeout", 0, 0, G_OPTION_ARG_DOUBLE, &connect_timeout_s,
       "Close a session whose page has not answered the offer and opened the data channel in S "
       "seconds, above 0 up to 86400 (default 30)",
       "S"},
      {"stop-timeout", 0, 0, G_OPTION_ARG_DOUBLE, &stop_timeout_s,
       "On SIGTERM or SIGINT, exit with status 3 if the sessions have not stopped in S seconds, "
       "naming those that did not, above 0 up to 3600 (default 10)",
       "S"},
      {"allow-origin", 0, 0, G_OPTION_ARG_STRING_ARRAY, &origins,
       "Accept WebSockets from ORIGIN (scheme://host[:port], or null) besides the page's own "
       "(http://127.0.0.1:N, http://localhost:N) and clients that send none; repeatable",
       "ORIGIN"},
      {}};
  int status = parse_command_line(
      argc, argv, "",
      "Serves the talking head on http://127.0.0.1:N/ and prints the URL. Each browser\n"
      "that opens it gets its own WebRTC session: TEXT (or what the page asks for)\n"
      "spoken by pfaptts, the speech as Opus audio, the PFAP stream as RTP packets on an\n"
      "unordered, unreliable data channel, of which a share P is dropped.",
      entries, gst_init_get_option_group());
  if (status == 0) {
    if (port < 0 || port > 65535) {
      status = usage_error("--port wants 0..65535: %d", port);
    } else if (!(drop >= 0.0 && drop < 1.0)) {
      status = usage_error("--drop wants a probability in [0, 1): %g", drop);
    } else if (seed < 0 || seed > G_MAXUINT32) {
      status = usage_error("--seed wants 0..%u: %" G_GINT64_FORMAT, G_MAXUINT32, seed);
    } else if (max_sessions != -1 && (max_sessions < 1 || max_sessions > 1000000)) {
      status = usage_error("--max-sessions wants 1..1000000: %d", max_sessions);
    } else if (!(connect_timeout_s > 0 && connect_timeout_s <= 86400)) {
      status = usage_error("--connect-timeout wants seconds, above 0 up to 86400: %g",
                           connect_timeout_s);
    } else if (!(stop_timeout_s > 0 && stop_timeout_s <= 3600)) {
      status = usage_error("--stop-timeout wants seconds, above 0 up to 3600: %g", stop_timeout_s);
    } else if (*argc > 1) {
      status = usage_error("takes no operands: %s", (*argv)[1]);
    }
    for (gchar** v = origins; status == 0 && v != nullptr && *v != nullptr; ++v) {
      // scheme://host[:port] as browsers send it, or "null" (sandboxed and file: pages).
      const char* host = std::strstr(*v, "://");
      if (std::strcmp(*v, "null") != 0 && (host == nullptr || host == *v || host[3] == '\0' ||
                                           std::strchr(host + 3, '/') != nullptr)) {
        status = usage_error("--allow-origin wants scheme://host[:port]: %s", *v);
      } else {
        o.allowed_origins.emplace_back(*v);
      }
    }
    o.port = port;
    o.max_sessions = max_sessions == -1 ? 0 : max_sessions;
    o.connect_timeout_s = connect_timeout_s;
    o.stop_timeout_s = stop_timeout_s;
    o.drop = drop;
    o.seed = static_cast<uint32_t>(seed);
    if (text != nullptr) o.text = text;
    o.web_dir = web_dir != nullptr && *web_dir != '\0' ? web_dir : default_web_dir();
  }
  g_free(text);
  g_free(web_dir);
  g_strfreev(origins);
  return status;
}

// The sessions the open file limit leaves room for, kReservedFds kept; `wanted` (if not 0)
// when it is fewer, since a session past the limit would abort the whole server (GLib cannot
// make a GWakeup's pipe).
int session_cap(int wanted) {
  rlimit limit{};
  rlim_t fds = 1024;
  if (getrlimit(RLIMIT_NOFILE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    fds = limit.rlim_cur;
  }
  const rlim_t room = fds > kReservedFds ? (fds - kReservedFds) / kFdsPerSession : 0;
  const int allowed = static_cast<int>(std::clamp<rlim_t>(room, 1, 1000000));
  if (wanted != 0 && wanted > allowed) {
    g_printerr(
        "pfap-web: --max-sessions=%d lowered to %d: the open file limit (ulimit -n) is %lu, "
        "a session takes up to %d\n",
        wanted, allowed, static_cast<unsigned long>(fds), kFdsPerSession);
  }
  return wanted != 0 ? std::min(wanted, allowed) : allowed;
}

// "; sessions 4, 7 not stopped yet", or nothing.
std::string not_stopped_yet(const std::vector<int>& ids) {
  if (ids.empty()) return "";
  std::string rest = ids.size() == 1 ? "; session " : "; sessions ";
  for (size_t i = 0; i < ids.size(); ++i) rest += (i == 0 ? "" : ", ") + std::to_string(ids[i]);
  return rest + " not stopped yet";
}

// The threads of this process (/proc/self/status), or -1.
int thread_count() {
  gchar* status = nullptr;
  int threads = -1;
  if (g_file_get_contents("/proc/self/status", &status, nullptr, nullptr)) {
    if (const char* line = std::strstr(status, "\nThreads:")) threads = std::atoi(line + 9);
  }
  g_free(status);
  return threads;
}

// Ends the streaming threads that the sessions left idle in GLib's shared thread pool, and
// waits until they are gone (their number unchanged for 20 ms). Left to end on their own,
// some ended while the exit handlers ran, and their thread-exit destructors used what
// OpenSSL's exit handler (DTLS) had freed: the heap was corrupted, SIGABRT or SIGSEGV at
// exit, in 2 of 14 stops with 45 sessions open (docs/web.md, "Stopping").
void end_idle_threads() {
  g_thread_pool_set_max_unused_threads(0);
  g_thread_pool_stop_unused_threads();
  while (g_thread_pool_get_num_unused_threads() > 0) g_usleep(1000);
  for (int last = thread_count(), unchanged = 0; unchanged < 20;) {
    g_usleep(1000);
    const int now = thread_count();
    unchanged = now == last ? unchanged + 1 : 0;
    last = now;
  }
}

// Ctrl-C or SIGTERM: each session's pipeline stops, its browser is told, and what the
// sessions and the server hold is freed.
void stop(Server& server, SoupServer* soup) {
  // A session closed before has given its WebSocket back: only the open ones.
  std::vector<std::shared_ptr<Session>> open;
  for (const std::weak_ptr<Session>& weak : server.open) {
    std::shared_ptr<Session> s = weak.lock();
    if (s != nullptr && !s->closed) open.push_back(std::move(s));
  }
  server.open.clear();
  for (size_t i = 0; i < open.size(); ++i) {
    std::vector<int> after;
    for (size_t j = i + 1; j < open.size(); ++j) after.push_back(open[j]->id);
    server.stop_watch->yet(not_stopped_yet(after));
    std::shared_ptr<Session> s = std::move(open[i]);
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
  server.stop_watch->yet("");
  server.stop_watch->now("the HTTP and STUN servers closing");
  g_source_destroy(server.stun_source);
  g_source_unref(server.stun_source);
  g_object_unref(server.stun);
  soup_server_disconnect(soup);
  g_object_unref(soup);
  // What the closing left to do (the close frames, finalizing the connections).
  while (g_main_context_iteration(nullptr, FALSE)) {
  }
}

}  // namespace

int main(int argc, char** argv) {
  Server server;
  if (int status = parse_options(&argc, &argv, server.options); status != 0) return status;
  for (const char* element : {"webrtcbin", "pfaptts", "rtppfappay", "opusenc", "rtpopuspay"}) {
    GstElementFactory* factory = gst_element_factory_find(element);
    if (factory == nullptr) {
      std::fprintf(stderr, "pfap-web: no %s element (GST_PLUGIN_PATH, docs/web.md)\n", element);
      return 1;
    }
    gst_object_unref(factory);
  }
  SoupServer* soup = soup_server_new("server-header", "pfap-web", nullptr);
  soup_server_add_handler(soup, "/ws", on_ws_request, &server, nullptr);
  soup_server_add_websocket_handler(soup, "/ws", nullptr, nullptr, on_websocket, &server, nullptr);
  soup_server_add_handler(soup, nullptr, on_http, &server, nullptr);
  GError* error = nullptr;
  // Loopback only: the page and its sessions are for this machine.
  GInetAddress* loopback = g_inet_address_new_loopback(G_SOCKET_FAMILY_IPV4);
  GSocketAddress* address =
      g_inet_socket_address_new(loopback, static_cast<guint16>(server.options.port));
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
  if (!start_stun(server, port)) {
    std::fprintf(stderr, "pfap-web: cannot listen for STUN on 127.0.0.1 (UDP)\n");
    soup_server_disconnect(soup);
    g_object_unref(soup);
    return 1;
  }
  server.origins = {"http://127.0.0.1:" + std::to_string(port),
                    "http://localhost:" + std::to_string(port)};
  server.origins.insert(server.origins.end(), server.options.allowed_origins.begin(),
                        server.options.allowed_origins.end());
  server.max_sessions = session_cap(server.options.max_sessions);
  g_print("pfap-web: at most %d sessions at once\n", server.max_sessions);
  g_print("pfap-web: open http://127.0.0.1:%u/ in a browser (Ctrl-C stops)\n", port);
  GMainLoop* loop = g_main_loop_new(nullptr, FALSE);
  {
    StopWatch watch(loop, server.options.stop_timeout_s);
    server.stop_watch = &watch;
    g_main_loop_run(loop);
    stop(server, soup);
    g_main_loop_unref(loop);
    watch.now("GStreamer deinitializing (gst_deinit)");
    gst_deinit();
    watch.now("the sessions' idle streaming threads ending");
    end_idle_threads();
  }
  g_print("pfap-web: stopped\n");
  return 0;
}

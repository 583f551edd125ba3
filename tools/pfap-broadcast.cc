// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap-broadcast: the sender of a talking head broadcast through Janus's streaming plugin
// (docs/web.md, "Broadcast through Janus"). Any source of speech and its PFAP stream (pfaptts by
// default, or a launch description: a .pfap file with its audio, pfapalign) is sent in real
// time as plain UDP to 127.0.0.1:
//
//   SOURCE.audio ! audioconvert ! audioresample ! queue ! opusenc ! rtpopuspay ! udpsink :AUDIO
//   SOURCE.pfap  ! rtppfappay ! appsink (sync) ─(a share P dropped)─ one datagram each ─▶ :DATA
//
// Janus rewrites the audio's RTP timestamps per viewer, so the viewer page cannot map the
// audio it plays to PFAP time by them. The data port also carries, as datagrams whose first
// byte cannot start an RTP packet, what the page needs instead: the speech's level by PFAP
// timestamp (binary level messages, speech_level.h, sent ahead as pfap-web's "envelope"), and
// as JSON the PFAP timestamp of the audio as it leaves ("clock", the page's first estimate)
// and, at the end, the state as sent ("done", compared by the page). Janus relays each
// datagram as one binary data-channel message.
#include <gio/gio.h>
#include <glib-unix.h>
#include <gst/app/gstappsink.h>
#include <gst/gst.h>
#include <gst/video/video-event.h>

#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "command_line.h"
#include "launch_value.h"
#include "pad_time.h"
#include "pfap/model.h"
#include "sent_pfap.h"
#include "speech_level.h"
#include "speech_opus.h"

namespace {

constexpr const char* kDefaultText =
    "Hello! <FAP 2 1 40 0 0 800 3> I am a talking head, broadcast to many. "
    "<FAP 48 6000 400 2> My voice and my face reach every viewer through Janus, "
    "<FAP 2 6 50 0 0 300 2> in step with each other. <FAP 2 1 50 0 0 800 3> Goodbye!";
constexpr uint32_t kPfapClockRate = 44100;
// PFAP packets go this far ahead of their time (as pfap-web's): the page holds their events
// until the audio reaches them.
constexpr GstClockTimeDiff kPfapLead = 400 * GST_MSECOND;
// A "clock" message every this many audio packets (one Opus frame each): every 100 ms.
constexpr int kClockEvery = static_cast<int>(100 * GST_MSECOND / kOpusFrame);

struct Options {
  int audio_port = 0;
  int data_port = 0;
  std::string text = kDefaultText;
  std::string source;
  double drop = 0.0;
  uint32_t seed = 1;
};

// 0 when the arguments are good, else the exit status. GStreamer is initialized by the parse.
int parse_options(int* argc, char*** argv, Options& o) {
  gint audio_port = 0, data_port = 0, seed = 1;
  gdouble drop = 0.0;
  gchar* text = nullptr;
  gchar* source = nullptr;
  const GOptionEntry entries[] = {
      {"audio-port", 0, 0, G_OPTION_ARG_INT, &audio_port, "Janus's audio port (Opus RTP)", "N"},
      {"data-port", 0, 0, G_OPTION_ARG_INT, &data_port,
       "Janus's data port (PFAP RTP packets, the level, and the clock and state as JSON)", "N"},
      {"text", 0, 0, G_OPTION_ARG_STRING, &text, "What pfaptts says (MPEG-4 bookmarks welcome)",
       "TEXT"},
      {"source", 0, 0, G_OPTION_ARG_STRING, &source,
       "A launch description instead, whose elements named 'audio' and 'pfap' give raw audio "
       "and application/x-pfap",
       "DESC"},
      {"drop", 0, 0, G_OPTION_ARG_DOUBLE, &drop, "The share of PFAP packets dropped (0 to 1)", "P"},
      {"seed", 0, 0, G_OPTION_ARG_INT, &seed, "The seed of the drops (default 1)", "S"},
      {}};
  const int status = parse_command_line(
      argc, argv, "",
      "Speaks TEXT with pfaptts (or plays DESC) in real time and sends it to Janus's streaming\n"
      "plugin on 127.0.0.1: Opus RTP to the audio port, each PFAP RTP packet as one datagram\n"
      "to the data port, with the speech's level and clock beside them. At the end it\n"
      "prints the state as sent (JSON) and exits.",
      entries, gst_init_get_option_group());
  if (text != nullptr) o.text = text;
  if (source != nullptr) o.source = source;
  g_free(text);
  g_free(source);
  if (status != 0) return status;
  if (*argc != 1) return usage_error("takes no operand: %s", (*argv)[1]);
  if (audio_port <= 0 || audio_port > 65535 || data_port <= 0 || data_port > 65535) {
    return usage_error("--audio-port and --data-port are needed (1 to 65535)");
  }
  if (!(drop >= 0.0 && drop <= 1.0)) return usage_error("--drop wants 0 to 1: %g", drop);
  o.audio_port = audio_port;
  o.data_port = data_port;
  o.drop = drop;
  o.seed = static_cast<uint32_t>(seed);
  return 0;
}

struct Sender {
  GMainLoop* loop = nullptr;
  GstElement* pipeline = nullptr;
  GstElement* pay = nullptr;
  GSocket* socket = nullptr;
  GSocketAddress* data_address = nullptr;
  uint32_t ssrc = 0;
  uint32_t pfap_ts_offset = 0;
  int exit_status = 0;

  int audio_packets = 0;  // the audio sink's thread

  SentPfap sent;  // the appsink's thread, and the main loop's `done`
};

void send_datagram(Sender& s, const void* data, size_t size) {
  GError* error = nullptr;
  if (g_socket_send_to(s.socket, s.data_address, static_cast<const gchar*>(data), size, nullptr,
                       &error) < 0) {
    g_printerr("pfap-broadcast: sending to the data port: %s\n", error->message);
    g_error_free(error);
  }
}

void send_text(Sender& s, const std::string& json) { send_datagram(s, json.data(), json.size()); }

uint32_t pfap_timestamp(const Sender& s, GstClockTime running) {
  return s.pfap_ts_offset +
         static_cast<uint32_t>(gst_util_uint64_scale_int(running, kPfapClockRate, GST_SECOND));
}

// -- The level: the RMS of each ms by PFAP timestamp, sent as the audio enters the queue ------

void send_levels(Sender& s, GstClockTime start, const std::vector<int64_t>& levels) {
  const std::vector<uint8_t> message = level_message(s.ssrc, pfap_timestamp(s, start), levels);
  send_datagram(s, message.data(), message.size());
}

// -- The clock: the PFAP timestamp of the audio as it goes to the audio port -----------------

// The udpsink's pad sees each packet as the sink begins to wait for its time: at most one
// packet (one Opus frame) before it leaves.
GstPadProbeReturn on_audio_packet(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
  auto& s = *static_cast<Sender*>(data);
  if (s.audio_packets++ % kClockEvery != 0) return GST_PAD_PROBE_OK;
  const GstClockTime running = running_time_of(pad, GST_PAD_PROBE_INFO_BUFFER(info));
  if (running == GST_CLOCK_TIME_NONE) return GST_PAD_PROBE_OK;
  send_text(s, "{\"type\":\"clock\",\"ssrc\":" + std::to_string(s.ssrc) +
                   ",\"timestamp\":" + std::to_string(pfap_timestamp(s, running)) + "}");
  return GST_PAD_PROBE_OK;
}

// -- The PFAP stream ---------------------------------------------------------------------

std::string state_json(Sender& s) {
  std::string json = "{\"type\":\"done\",\"ssrc\":" + std::to_string(s.ssrc);
  s.sent.read([&](const SentPfap::Counts& c, const pfap::FapState& state) {
    json += ",\"packets\":" + std::to_string(c.packets) + ",\"dropped\":" +
            std::to_string(c.dropped) + ",\"phonemes\":" + std::to_string(c.phonemes) +
            ",\"phonemesDropped\":" + std::to_string(c.phonemes_dropped) +
            ",\"lastSequenceNumber\":" + std::to_string(c.last_seqnum) + ",\"settled\":[";
    for (int i = pfap::kMinFapIndex; i <= pfap::kMaxFapIndex; ++i) {
      json += (i == pfap::kMinFapIndex ? "" : ",") + std::to_string(state.settled(i));
    }
  });
  return json + "]}";
}

// Each packet rtppfappay makes, at its time (less kPfapLead): recorded as sent, then lost or
// sent whole as one datagram.
GstFlowReturn on_pfap_packet(GstAppSink* sink, gpointer data) {
  auto& s = *static_cast<Sender*>(data);
  GstSample* sample = gst_app_sink_pull_sample(sink);
  if (sample == nullptr) return GST_FLOW_EOS;
  GstBuffer* buffer = gst_sample_get_buffer(sample);
  GstMapInfo map;
  if (s.sent.take(buffer, kPfapClockRate) && gst_buffer_map(buffer, &map, GST_MAP_READ)) {
    send_datagram(s, map.data, map.size);
    gst_buffer_unmap(buffer, &map);
  }
  gst_sample_unref(sample);
  return GST_FLOW_OK;
}

// A broadcast has no way back from the viewers (Janus's streaming plugin relays one way), so
// no viewer can ask for the complete state after losing the last packets: the stream ends
// with one. The request has to come from another thread: rtppfappay serves a request from
// the thread that holds its stream lock at once, here before the last data packet, which it
// sends at EOS; from another thread it marks the request, which the EOS handler serves after
// sending that packet. That complete state is never dropped: without a way back, it is the
// stream's last word on the face's state.
GstPadProbeReturn on_pfap_eos(GstPad*, GstPadProbeInfo* info, gpointer data) {
  if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) != GST_EVENT_EOS) return GST_PAD_PROBE_OK;
  static_cast<Sender*>(data)->sent.keep_closing_state();
  GThread* thread = g_thread_new(
      "request-complete",
      [](gpointer pay) -> gpointer {
        GstPad* src = gst_element_get_static_pad(static_cast<GstElement*>(pay), "src");
        gst_pad_send_event(
            src, gst_video_event_new_upstream_force_key_unit(GST_CLOCK_TIME_NONE, TRUE, 0));
        gst_object_unref(src);
        return nullptr;
      },
      static_cast<Sender*>(data)->pay);
  g_thread_join(thread);
  return GST_PAD_PROBE_OK;
}

gboolean on_bus(GstBus*, GstMessage* m, gpointer data) {
  auto& s = *static_cast<Sender*>(data);
  switch (GST_MESSAGE_TYPE(m)) {
    case GST_MESSAGE_ERROR: {
      GError* error = nullptr;
      gchar* debug = nullptr;
      gst_message_parse_error(m, &error, &debug);
      g_printerr("pfap-broadcast: %s: %s (%s)\n", GST_OBJECT_NAME(m->src), error->message,
                 debug != nullptr ? debug : "");
      g_error_free(error);
      g_free(debug);
      s.exit_status = 1;
      g_main_loop_quit(s.loop);
      break;
    }
    case GST_MESSAGE_EOS: {
      const std::string done = state_json(s);
      send_text(s, done);
      std::printf("%s\n", done.c_str());
      std::fflush(stdout);
      g_main_loop_quit(s.loop);
      break;
    }
    default:
      break;
  }
  return G_SOURCE_CONTINUE;
}

gboolean on_signal(gpointer data) {
  auto& s = *static_cast<Sender*>(data);
  s.exit_status = 0;
  g_main_loop_quit(s.loop);
  return G_SOURCE_CONTINUE;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (const int status = parse_options(&argc, &argv, o); status != 0) return status;
  Sender s;
  s.ssrc = g_random_int();
  s.pfap_ts_offset = g_random_int();
  s.sent.configure(o.drop, o.seed, s.pfap_ts_offset);

  const std::string source =
      !o.source.empty() ? o.source
                        : "pfaptts name=tts skip-bad-bookmarks=true text=" + quoted(o.text) +
                              " tts.audio ! queue name=audio tts.pfap ! queue name=pfap";
  const std::string description =
      source +
      " audio. ! audioconvert ! audioresample ! audio/x-raw,format=S16LE,rate=48000,channels=1 "
      "! queue name=level ! " +
      opus_encoder_description() + " ! rtpopuspay pt=111 "
      "! udpsink name=audiosink host=127.0.0.1 port=" +
      std::to_string(o.audio_port) +
      " pfap. ! rtppfappay name=pay pt=96 ! application/x-rtp,clock-rate=44100 "
      "! appsink name=pfapsink sync=true";
  GError* error = nullptr;
  s.pipeline = gst_parse_launch(description.c_str(), &error);
  if (s.pipeline == nullptr || error != nullptr) {
    g_printerr("pfap-broadcast: %s\n", error != nullptr ? error->message : "no pipeline");
    if (error != nullptr) g_error_free(error);
    return 1;
  }
  auto by_name = [&](const char* name) {
    GstElement* e = gst_bin_get_by_name(GST_BIN(s.pipeline), name);
    if (e != nullptr) gst_object_unref(e);  // the pipeline keeps it
    return e;
  };
  s.pay = by_name("pay");
  g_object_set(s.pay, "timestamp-offset", s.pfap_ts_offset, "ssrc", s.ssrc, nullptr);
  GstElement* sink = by_name("pfapsink");
  g_object_set(sink, "ts-offset", -kPfapLead, nullptr);
  GstAppSinkCallbacks callbacks{};
  callbacks.new_sample = on_pfap_packet;
  gst_app_sink_set_callbacks(GST_APP_SINK(sink), &callbacks, &s, nullptr);

  auto probe = [&](const char* element, const char* pad_name, GstPadProbeType type,
                   GstPadProbeCallback callback) {
    GstPad* pad = gst_element_get_static_pad(by_name(element), pad_name);
    gst_pad_add_probe(pad, type, callback, &s, nullptr);
    gst_object_unref(pad);
  };
  GstPad* level_pad = gst_element_get_static_pad(by_name("level"), "sink");
  add_speech_level_probe(level_pad, [&s](GstClockTime start, std::vector<int64_t> levels) {
    send_levels(s, start, levels);
  });
  gst_object_unref(level_pad);
  probe("audiosink", "sink", GST_PAD_PROBE_TYPE_BUFFER, on_audio_packet);
  probe("pay", "sink", GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM, on_pfap_eos);

  s.socket =
      g_socket_new(G_SOCKET_FAMILY_IPV4, G_SOCKET_TYPE_DATAGRAM, G_SOCKET_PROTOCOL_UDP, &error);
  if (s.socket == nullptr) {
    g_printerr("pfap-broadcast: %s\n", error->message);
    g_error_free(error);
    return 1;
  }
  s.data_address = g_inet_socket_address_new_from_string("127.0.0.1", o.data_port);

  s.loop = g_main_loop_new(nullptr, FALSE);
  GstBus* bus = gst_element_get_bus(s.pipeline);
  gst_bus_add_watch(bus, on_bus, &s);
  g_unix_signal_add(SIGINT, on_signal, &s);
  g_unix_signal_add(SIGTERM, on_signal, &s);
  gst_element_set_state(s.pipeline, GST_STATE_PLAYING);
  g_printerr("pfap-broadcast: sending to 127.0.0.1: audio port %d, data port %d\n", o.audio_port,
             o.data_port);
  g_main_loop_run(s.loop);
  gst_element_set_state(s.pipeline, GST_STATE_NULL);
  gst_bus_remove_watch(bus);
  gst_object_unref(bus);
  gst_object_unref(s.pipeline);
  g_object_unref(s.data_address);
  g_object_unref(s.socket);
  g_main_loop_unref(s.loop);
  return s.exit_status;
}

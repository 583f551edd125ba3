// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap-story: the whole story on one machine (scripts/demo). A text is spoken by pfaptts, its
// audio and PFAP streams go out as two RTP sessions of one rtpbin, the PFAP packets lose some
// of their number on the way (netsim), and the receiver's rtpbin gives the audio and the
// phonemes, which rtppfapdepay repairs by the draft's recovery, to pfapface; the talking head
// and the speech are muxed into a WebM file.
//
//   sender:   pfaptts ! audio ! rtpL16pay  ! rtpbin ! udpsink
//                     ! pfap  ! rtppfappay ! rtpbin ! netsim drop-probability=P ! udpsink
//   receiver: udpsrc ! rtpbin ! rtpL16depay ! vorbisenc ............................ ! webmmux
//             udpsrc ! rtpbin ! rtppfapdepay ! pfapface ! vp8enc ..................... ! webmmux
//             (and, with --frames=DIR, every frame as DIR/NNNN.png)
//
// Both pipelines run in real time: the sender's udpsinks sync to the clock, as a server
// speaks, and the receiver is live. Every socket is on 127.0.0.1 and bound to a free port.
// RTCP flows both ways (AVPF, so that the depayloader's requests for a complete state reach
// the payloader as PLI). Once both payloaders have seen EOS and the receiver's jitterbuffer
// latency has passed, EOS goes into the receiver, which then finishes the file. A summary of
// what was sent, lost and repaired goes to standard output.
#include <gst/gst.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "command_line.h"
#include "launch_value.h"

namespace {

constexpr const char* kDefaultText =
    "Hello! <FAP 2 1 40 0 0 800 3> I am a talking head. <FAP 2 0 0 0 0 600 3> "
    "My face moves with the phonemes, <FAP 48 6000 400 2> sent over RTP next to my voice. "
    "<FAP 2 6 50 0 0 300 2> Some packets are lost on the way, and the receiver recovers "
    "them. <FAP 2 1 50 0 0 800 3> Goodbye!";
constexpr guint kLatencyMs = 200;  // the receiving rtpbin's jitterbuffer

struct Options {
  std::string text = kDefaultText;
  std::string out = "story.webm";
  std::string frames;  // empty: no PNG frames
  double drop = 0.1;
  guint width = 320, height = 240;
};

struct Story {
  GMainLoop* loop = nullptr;
  GstElement* sender = nullptr;
  GstElement* receiver = nullptr;
  std::atomic<int> payloaders_done{0};
  std::atomic<guint64> pfap_packets{0};  // into netsim
  std::atomic<guint64> pfap_passed{0};   // out of netsim
  std::atomic<guint64> pfap_arrived{0};  // into rtppfapdepay
  std::atomic<guint64> frames{0};
  gint64 payloaders_done_us = 0;  // when the main loop first saw both payloaders' EOS
  bool eos_sent = false;
  bool done = false;
  std::string failure;
};

// 0 when the arguments are good, else the exit status. GStreamer is initialized by the parse.
int parse_options(int* argc, char*** argv, Options& options) {
  gchar *text = nullptr, *out = nullptr, *frames = nullptr, *size = nullptr;
  gdouble drop = options.drop;
  const GOptionEntry entries[] = {
      {"text", 0, 0, G_OPTION_ARG_STRING, &text, "The text to speak", "TEXT"},
      {"out", 0, 0, G_OPTION_ARG_FILENAME, &out, "The video to write (default story.webm)",
       "FILE.webm"},
      {"drop", 0, 0, G_OPTION_ARG_DOUBLE, &drop,
       "The share of PFAP packets lost, in [0, 1) (default 0.1)", "PROBABILITY"},
      {"size", 0, 0, G_OPTION_ARG_STRING, &size, "The video's size (default 320x240)",
       "WIDTHxHEIGHT"},
      {"frames", 0, 0, G_OPTION_ARG_FILENAME, &frames, "Also write each frame as DIR/NNNN.png",
       "DIR"},
      {}};
  int status = parse_command_line(
      argc, argv, "",
      "Speaks TEXT with pfaptts, sends audio and PFAP over loopback RTP losing PFAP\n"
      "packets with PROBABILITY, and renders what arrives with pfapface into FILE.webm,\n"
      "beside the audio.",
      entries, gst_init_get_option_group());
  if (status == 0) {
    if (text != nullptr) options.text = text;
    if (out != nullptr) options.out = out;
    if (frames != nullptr) options.frames = frames;
    options.drop = drop;
    if (!(drop >= 0 && drop < 1)) {
      status = usage_error("--drop wants a probability in [0, 1): %g", drop);
    } else if (size != nullptr &&
               (std::sscanf(size, "%ux%u", &options.width, &options.height) != 2 ||
                options.width < 16 || options.height < 16)) {
      status = usage_error("--size wants WIDTHxHEIGHT, each 16 or more: %s", size);
    } else if (*argc > 1) {
      status = usage_error("takes no operands: %s", (*argv)[1]);
    }
  }
  g_free(text);
  g_free(out);
  g_free(frames);
  g_free(size);
  return status;
}

std::string sender_description(const Options& o) {
  return "rtpbin name=rtpbin rtp-profile=avpf rtcp-sync-send-time=false "
         "pfaptts name=tts text=" +
         quoted(o.text) +
         " tts.audio ! queue ! audioconvert ! rtpL16pay name=apay pt=96 "
         "! rtpbin.send_rtp_sink_0 "
         "rtpbin.send_rtp_src_0 ! udpsink name=artp host=127.0.0.1 "
         "rtpbin.send_rtcp_src_0 ! udpsink name=artcp host=127.0.0.1 sync=false async=false "
         "udpsrc name=arr address=127.0.0.1 port=0 ! rtpbin.recv_rtcp_sink_0 "
         "tts.pfap ! queue ! rtppfappay name=pay pt=97 ! rtpbin.send_rtp_sink_1 "
         "rtpbin.send_rtp_src_1 ! netsim name=loss drop-probability=" +
         std::to_string(o.drop) +
         " ! udpsink name=prtp host=127.0.0.1 "
         "rtpbin.send_rtcp_src_1 ! udpsink name=prtcp host=127.0.0.1 sync=false async=false "
         "udpsrc name=prr address=127.0.0.1 port=0 ! rtpbin.recv_rtcp_sink_1";
}

std::string receiver_description(const Options& o) {
  std::string video = "rtppfapdepay name=depay ! pfapface name=face ! video/x-raw,width=" +
                      std::to_string(o.width) + ",height=" + std::to_string(o.height) +
                      ",framerate=25/1 ! tee name=frames "
                      "frames. ! queue ! videoconvert ! vp8enc deadline=1 ! queue ! mux. ";
  if (!o.frames.empty()) {
    video += "frames. ! queue ! videoconvert ! pngenc ! multifilesink location=" +
             quoted(o.frames + "/%04d.png") + " ";
  }
  return "rtpbin name=rtpbin rtp-profile=avpf latency=" + std::to_string(kLatencyMs) +
         " udpsrc name=artp address=127.0.0.1 port=0 caps=\"application/x-rtp,media=audio,"
         "clock-rate=22050,encoding-name=L16,channels=1,payload=96\" ! rtpbin.recv_rtp_sink_0 "
         "udpsrc name=artcp address=127.0.0.1 port=0 ! rtpbin.recv_rtcp_sink_0 "
         "rtpbin.send_rtcp_src_0 ! udpsink name=arr host=127.0.0.1 sync=false async=false "
         "udpsrc name=prtp address=127.0.0.1 port=0 caps=\"application/x-rtp,"
         "media=application,clock-rate=44100,encoding-name=PFAP,payload=97,"
         "alphabet=x-pfap-arpabet\" ! rtpbin.recv_rtp_sink_1 "
         "udpsrc name=prtcp address=127.0.0.1 port=0 ! rtpbin.recv_rtcp_sink_1 "
         "rtpbin.send_rtcp_src_1 ! udpsink name=prr host=127.0.0.1 sync=false async=false "
         "rtpL16depay name=adepay ! audioconvert ! audioresample ! vorbisenc ! queue ! mux. " +
         video + "webmmux name=mux ! filesink location=" + quoted(o.out);
}

GstElement* by_name(GstElement* pipeline, const char* name) {
  GstElement* element = gst_bin_get_by_name(GST_BIN(pipeline), name);
  gst_object_unref(element);  // the pipeline keeps it
  return element;
}

void add_probe(GstElement* element, const char* pad_name, GstPadProbeType type,
               GstPadProbeCallback callback, gpointer data) {
  GstPad* pad = gst_element_get_static_pad(element, pad_name);
  gst_pad_add_probe(pad, type, callback, data, nullptr);
  gst_object_unref(pad);
}

guint64 buffers_in(GstPadProbeInfo* info) {
  if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_BUFFER_LIST) {
    return gst_buffer_list_length(GST_PAD_PROBE_INFO_BUFFER_LIST(info));
  }
  return 1;
}

GstPadProbeReturn on_payloader_eos(GstPad*, GstPadProbeInfo* info, gpointer data) {
  if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) == GST_EVENT_EOS) {
    static_cast<Story*>(data)->payloaders_done += 1;
  }
  return GST_PAD_PROBE_OK;
}

// Adds the buffers passing to the std::atomic<guint64> `data`.
GstPadProbeReturn count_buffers(GstPad*, GstPadProbeInfo* info, gpointer data) {
  *static_cast<std::atomic<guint64>*>(data) += buffers_in(info);
  return GST_PAD_PROBE_OK;
}

void fail(Story& story, const std::string& why) {
  if (story.failure.empty()) story.failure = why;
  g_main_loop_quit(story.loop);
}

gboolean on_bus(GstBus*, GstMessage* message, gpointer data) {
  auto* story = static_cast<Story*>(data);
  const bool from_receiver = message->src == GST_OBJECT(story->receiver);
  switch (GST_MESSAGE_TYPE(message)) {
    case GST_MESSAGE_ERROR: {
      GError* error = nullptr;
      gchar* debug = nullptr;
      gst_message_parse_error(message, &error, &debug);
      fail(*story, std::string(GST_OBJECT_NAME(message->src)) + ": " + error->message +
                       (debug != nullptr ? std::string(" (") + debug + ")" : ""));
      g_error_free(error);
      g_free(debug);
      break;
    }
    case GST_MESSAGE_WARNING: {
      GError* error = nullptr;
      gst_message_parse_warning(message, &error, nullptr);
      std::fprintf(stderr, "pfap-story: warning from %s: %s\n", GST_OBJECT_NAME(message->src),
                   error->message);
      g_error_free(error);
      break;
    }
    case GST_MESSAGE_EOS:
      if (from_receiver) {
        story->done = true;
        g_main_loop_quit(story->loop);
      }
      break;
    default:
      break;
  }
  return G_SOURCE_CONTINUE;
}

// After both payloaders' EOS, once the last packets have had the jitterbuffer's latency to
// come out: EOS into the receiver's sources.
gboolean on_tick(gpointer data) {
  auto* story = static_cast<Story*>(data);
  if (story->eos_sent || story->payloaders_done.load() < 2) return G_SOURCE_CONTINUE;
  if (story->payloaders_done_us == 0) story->payloaders_done_us = g_get_monotonic_time();
  if (g_get_monotonic_time() - story->payloaders_done_us < (kLatencyMs + 800) * 1000) {
    return G_SOURCE_CONTINUE;
  }
  story->eos_sent = true;
  gst_element_send_event(story->receiver, gst_event_new_eos());
  return G_SOURCE_CONTINUE;
}

gboolean on_deadline(gpointer data) {
  fail(*static_cast<Story*>(data), "no end within the time the speech allows");
  return G_SOURCE_REMOVE;
}

guint64 depay_stat(GstElement* depay, const char* field) {
  GstStructure* stats = nullptr;
  g_object_get(depay, "stats", &stats, nullptr);
  guint64 value = 0;
  if (stats != nullptr) {
    gst_structure_get_uint64(stats, field, &value);
    gst_structure_free(stats);
  }
  return value;
}

// rtpbin's receive pads are recv_rtp_src_<session>_<ssrc>_<pt>: session 0 is the audio,
// session 1 the PFAP stream.
void on_rtpbin_pad(GstElement*, GstPad* pad, gpointer data) {
  auto* story = static_cast<Story*>(data);
  guint session = 0, ssrc = 0, pt = 0;
  if (std::sscanf(GST_PAD_NAME(pad), "recv_rtp_src_%u_%u_%u", &session, &ssrc, &pt) != 3) return;
  GstElement* depay = by_name(story->receiver, session == 0 ? "adepay" : "depay");
  GstPad* sink = gst_element_get_static_pad(depay, "sink");
  if (gst_pad_is_linked(sink) || gst_pad_link(pad, sink) != GST_PAD_LINK_OK) {
    std::fprintf(stderr, "pfap-story: cannot link %s\n", GST_PAD_NAME(pad));
  }
  gst_object_unref(sink);
}

bool connect_ports(Story& story) {
  // Each udpsrc bound a free port in READY; its peer udpsink gets it.
  struct Link {
    GstElement* from;
    GstElement* to;
    const char* name;
  };
  const Link links[] = {
      {story.receiver, story.sender, "artp"}, {story.receiver, story.sender, "artcp"},
      {story.receiver, story.sender, "prtp"}, {story.receiver, story.sender, "prtcp"},
      {story.sender, story.receiver, "arr"},  {story.sender, story.receiver, "prr"}};
  for (const Link& link : links) {
    gint port = 0;
    g_object_get(by_name(link.from, link.name), "port", &port, nullptr);
    if (port == 0) return false;
    g_object_set(by_name(link.to, link.name), "port", port, nullptr);
  }
  return true;
}

GstElement* parse(const std::string& description, const char* what) {
  GError* error = nullptr;
  GstElement* pipeline = gst_parse_launch(description.c_str(), &error);
  if (error != nullptr) {
    std::fprintf(stderr, "pfap-story: cannot make the %s: %s\n", what, error->message);
    g_error_free(error);
    if (pipeline != nullptr) gst_object_unref(pipeline);
    return nullptr;
  }
  return pipeline;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (const int status = parse_options(&argc, &argv, options); status != 0) return status;

  Story story;
  story.sender = parse(sender_description(options), "sender");
  story.receiver = parse(receiver_description(options), "receiver");
  if (story.sender == nullptr || story.receiver == nullptr) return 1;
  story.loop = g_main_loop_new(nullptr, FALSE);
  for (GstElement* pipeline : {story.sender, story.receiver}) {
    GstBus* bus = gst_element_get_bus(pipeline);
    gst_bus_add_watch(bus, on_bus, &story);
    gst_object_unref(bus);
  }
  g_signal_connect(by_name(story.receiver, "rtpbin"), "pad-added", G_CALLBACK(on_rtpbin_pad),
                   &story);
  add_probe(by_name(story.sender, "apay"), "src", GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM,
            on_payloader_eos, &story);
  add_probe(by_name(story.sender, "pay"), "src", GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM,
            on_payloader_eos, &story);
  const auto buffers =
      static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_BUFFER_LIST);
  add_probe(by_name(story.sender, "loss"), "sink", buffers, count_buffers, &story.pfap_packets);
  add_probe(by_name(story.sender, "loss"), "src", buffers, count_buffers, &story.pfap_passed);
  add_probe(by_name(story.receiver, "depay"), "sink", buffers, count_buffers, &story.pfap_arrived);
  add_probe(by_name(story.receiver, "face"), "src", GST_PAD_PROBE_TYPE_BUFFER, count_buffers,
            &story.frames);

  bool started =
      gst_element_set_state(story.receiver, GST_STATE_READY) != GST_STATE_CHANGE_FAILURE &&
      gst_element_set_state(story.sender, GST_STATE_READY) != GST_STATE_CHANGE_FAILURE;
  if (started && !connect_ports(story)) {
    story.failure = "a udpsrc bound no port";
    started = false;
  }
  started = started &&
            gst_element_set_state(story.receiver, GST_STATE_PLAYING) != GST_STATE_CHANGE_FAILURE &&
            gst_element_set_state(story.sender, GST_STATE_PLAYING) != GST_STATE_CHANGE_FAILURE;
  if (started) {
    g_timeout_add(50, on_tick, &story);
    // Speech runs at about 15 characters a second; anything far slower is stuck.
    g_timeout_add_seconds(20 + options.text.size() / 5, on_deadline, &story);
    g_main_loop_run(story.loop);
  } else if (story.failure.empty()) {
    story.failure = "a pipeline did not start (GST_DEBUG=*:3 tells why)";
  }

  GstElement* depay = by_name(story.receiver, "depay");
  const guint64 lost = depay_stat(depay, "lost");
  const guint64 recovered = depay_stat(depay, "recovered");
  const guint64 complete = depay_stat(depay, "complete-states");
  const guint64 requests = depay_stat(depay, "requests");
  const guint64 phonemes = depay_stat(depay, "phonemes");
  gst_element_set_state(story.sender, GST_STATE_NULL);
  gst_element_set_state(story.receiver, GST_STATE_NULL);
  gst_object_unref(story.sender);
  gst_object_unref(story.receiver);
  g_main_loop_unref(story.loop);

  if (!story.done) {
    std::fprintf(stderr, "pfap-story: %s\n", story.failure.c_str());
    return 1;
  }
  const guint64 sent = story.pfap_packets.load();
  const guint64 dropped = sent - story.pfap_passed.load();
  // rtpbin may keep back a packet of its own accord (a source on probation drops a packet
  // that does not follow the one before), so the depayloader's count of lost packets is
  // against what reached it.
  std::printf("PFAP packets sent: %" G_GUINT64_FORMAT ", dropped on the way: %" G_GUINT64_FORMAT
              "\n"
              "receiver: %" G_GUINT64_FORMAT " packets reached the depayloader, %" G_GUINT64_FORMAT
              " phonemes, %" G_GUINT64_FORMAT " packets found lost, %" G_GUINT64_FORMAT
              " FAP states recovered, %" G_GUINT64_FORMAT " complete states (%" G_GUINT64_FORMAT
              " asked for)\n"
              "wrote %s: %" G_GUINT64_FORMAT " frames (%.2f s at 25 fps) and the speech\n",
              sent, dropped, story.pfap_arrived.load(), phonemes, lost, recovered, complete,
              requests, options.out.c_str(), story.frames.load(), story.frames.load() / 25.0);
  return 0;
}

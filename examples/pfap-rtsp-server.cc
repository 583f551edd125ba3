// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap-rtsp-server: an RTSP server that streams a talking head's data, audio plus the PFAP
// phonemes and FAPs of a .pfap file, as one RTSP presentation (gst-rtsp-server).
//
//   pfap-rtsp-server FILE.pfap [PORT]      (PORT 0 or none: any free port)
//
// It listens on 127.0.0.1 only, prints the URL, rtsp://127.0.0.1:PORT/pfap, on one line of
// standard output, and serves until SIGINT or SIGTERM (exit status 0). Each client gets its
// own media, made from this launch description:
//
//   ( audiotestsrc name=audio is-live=true wave=ticks tick-interval=500000000
//       ! audioconvert ! audio/x-raw,rate=44100,channels=1 ! rtpL16pay name=pay0 pt=96
//     filesrc name=file ! pfaptextparse alphabet=x-pfap-arpabet ! identity sync=true
//       ! rtppfappay name=pay1 pt=97 )
//
//  - audiotestsrc stands for the speech; a real server has its TTS audio here. Its ticks,
//    one every 500 ms from the start, let a listener hear where the phoneme times are, and
//    let tests/gst/test_examples.cc (PlayStream.*) measure lip sync in playbin.
//  - identity sync=true paces the file's events in real time from PLAY on, as a live TTS
//    source would produce them; the audio is live too. Its first sample is put at running
//    time 0, the file's time 0 (AudioFromZero): a live source stamps it later.
//  - Both streams end together, when the file's last phoneme ends: the audio is cut there
//    and ends too (EndAudioWithMarkup). Each session then sends its RTCP
//    BYE, and a client sees the presentation end: rtspsrc and playbin post EOS, and a client
//    that reads for a fixed time (ffmpeg -t 3) is not left waiting on a stream that ended
//    while another went on.
//  - pfaptextparse's alphabet names the phoneme alphabet in the caps (a .pfap file has symbol
//    numbers only). rtppfappay copies it to its RTP caps, and
//    gst-rtsp-server writes RTP caps fields to the SDP, so clients see
//    "a=fmtp:97 alphabet=x-pfap-arpabet" and rtspsrc gives it back as a caps field.
//    x-pfap-arpabet is the symbol table of docs/examples/README.md.
//
// Client, for example (docs/elements.md has the tested lines):
//   gst-launch-1.0 rtspsrc location=rtsp://127.0.0.1:8554/pfap name=src
//     src. ! rtppfapdepay ! pfaptextenc ! fdsink  src. ! rtpL16depay ! fakesink
//
// The plugins are found where GStreamer looks: installed, or in GST_PLUGIN_PATH (from a build
// tree GST_PLUGIN_PATH=$PWD/build/gst:$PWD/build/ext in the checkout, as scripts/demo and
// `meson devenv` set it).
#include <glib-unix.h>
#include <gst/gst.h>
#include <gst/rtsp-server/rtsp-server.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <memory>

#include "command_line.h"
#include "pad_time.h"

namespace {

constexpr const char* kLaunch =
    "( audiotestsrc name=audio is-live=true wave=ticks tick-interval=500000000 ! audioconvert "
    "! audio/x-raw,rate=44100,channels=1 ! rtpL16pay name=pay0 pt=96 "
    "filesrc name=file ! pfaptextparse alphabet=x-pfap-arpabet ! identity sync=true "
    "! rtppfappay name=pay1 pt=97 )";

// Ends the audio where the markup's last phoneme ends, so that one media's streams end
// together. That end (a running time: the file's segment starts at 0 and identity keeps it)
// is known at the markup's EOS; audio from there on is dropped and the audio source sent EOS.
class EndAudioWithMarkup {
 public:
  // Both probes share the object; the last one removed deletes it.
  static void attach(GstElement* audio_source, GstPad* markup_pad, GstPad* audio_pad) {
    auto self = std::make_shared<EndAudioWithMarkup>(audio_source);
    gst_pad_add_probe(markup_pad,
                      static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER |
                                                   GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM),
                      on_markup, new Ref(self), release);
    gst_pad_add_probe(audio_pad, GST_PAD_PROBE_TYPE_BUFFER, on_audio, new Ref(self), release);
  }
  explicit EndAudioWithMarkup(GstElement* audio_source)
      : source_(GST_ELEMENT(gst_object_ref(audio_source))) {}
  EndAudioWithMarkup(const EndAudioWithMarkup&) = delete;
  EndAudioWithMarkup& operator=(const EndAudioWithMarkup&) = delete;
  ~EndAudioWithMarkup() { gst_object_unref(source_); }

 private:
  using Ref = std::shared_ptr<EndAudioWithMarkup>;
  static void release(gpointer ref) { delete static_cast<Ref*>(ref); }

  static GstPadProbeReturn on_markup(GstPad*, GstPadProbeInfo* info, gpointer data) {
    EndAudioWithMarkup* self = static_cast<Ref*>(data)->get();
    if (info->type & GST_PAD_PROBE_TYPE_BUFFER) {
      GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
      if (GST_BUFFER_PTS_IS_VALID(buffer)) {
        const GstClockTime end = GST_BUFFER_PTS(buffer) + (GST_BUFFER_DURATION_IS_VALID(buffer)
                                                               ? GST_BUFFER_DURATION(buffer)
                                                               : 0);
        self->markup_end_ = std::max(self->markup_end_.load(), end);
      }
    } else if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) == GST_EVENT_EOS) {
      self->markup_ended_ = true;
    }
    return GST_PAD_PROBE_OK;
  }

  static GstPadProbeReturn on_audio(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
    EndAudioWithMarkup* self = static_cast<Ref*>(data)->get();
    if (!self->markup_ended_) return GST_PAD_PROBE_OK;
    const GstClockTime start = running_time_of(pad, GST_PAD_PROBE_INFO_BUFFER(info));
    if (!GST_CLOCK_TIME_IS_VALID(start) || start < self->markup_end_) return GST_PAD_PROBE_OK;
    if (!self->audio_ended_.exchange(true)) {
      gst_element_send_event(self->source_, gst_event_new_eos());
    }
    return GST_PAD_PROBE_DROP;
  }

  GstElement* source_;
  std::atomic<GstClockTime> markup_end_{0};
  std::atomic<bool> markup_ended_{false};
  std::atomic<bool> audio_ended_{false};
};

// Puts the audio's first sample at running time 0, where the markup's time 0 is. A live
// audiotestsrc stamps its first buffer with the running time at which it made it, after PLAY:
// 1 to 13 ms here, 26 ms with the cores busy. The file's events count from 0 (identity keeps
// the segment), so without this the phonemes went out that much ahead of the speech they
// describe, in their RTP timestamps and so in the RTCP reports: no client could undo it. The
// first buffer's running time, once known, becomes a negative offset on the pad into the
// audio payloader (GStreamer's own way to move a stream's running time).
class AudioFromZero {
 public:
  static void attach(GstElement* audio_source, GstPad* payloader_sink) {
    GstPad* src = gst_element_get_static_pad(audio_source, "src");
    gst_pad_add_probe(src, GST_PAD_PROBE_TYPE_BUFFER, on_first_buffer,
                      gst_pad_get_peer(payloader_sink), gst_object_unref);
    gst_object_unref(src);
  }

 private:
  static GstPadProbeReturn on_first_buffer(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
    const GstClockTime start = running_time_of(pad, GST_PAD_PROBE_INFO_BUFFER(info));
    if (!GST_CLOCK_TIME_IS_VALID(start)) return GST_PAD_PROBE_OK;  // no segment or PTS yet
    gst_pad_set_offset(static_cast<GstPad*>(data), -static_cast<gint64>(start));
    return GST_PAD_PROBE_REMOVE;
  }
};

GstPad* sink_pad_of(GstElement* bin, const char* name) {
  GstElement* element = gst_bin_get_by_name(GST_BIN(bin), name);
  GstPad* pad = gst_element_get_static_pad(element, "sink");
  gst_object_unref(element);
  return pad;
}

// RTCP sender reports every ~100 ms instead of rtpbin's 5 s: a client puts audio and phonemes
// on one timeline (lip sync) from the reports, and before the first one it has only arrival
// times, which may put the face tens of ms off its speech. With reports from the start, the
// face is within a video frame of the audio at once (PlayStream.* in test_examples.cc). The
// cost is a few dozen bytes per stream each 100 ms.
constexpr guint64 kRtcpIntervalNs = 100'000'000;

// Sender reports map RTP time to the buffers' capture time, not to when they are sent
// (rtpbin's rtcp-sync-send-time=false): rtppfappay holds phonemes up to max-delay before it
// sends them, and a busy server sends late, so with send time the reports said the phonemes
// were later than their audio, and the client's lip sync moved them back by that much
// (120 ms under load: the third phoneme of hello.pfap at 250 ms instead of 130).
void on_media_prepared(GstRTSPMedia* media, gpointer) {
  for (guint i = 0; i < gst_rtsp_media_n_streams(media); ++i) {
    GObject* session = gst_rtsp_stream_get_rtpsession(gst_rtsp_media_get_stream(media, i));
    if (session == nullptr) continue;
    g_object_set(session, "rtcp-min-interval", kRtcpIntervalNs, nullptr);
    g_object_unref(session);
  }
  GstElement* element = gst_rtsp_media_get_element(media);
  GstObject* pipeline = gst_object_get_parent(GST_OBJECT(element));
  gst_object_unref(element);
  if (pipeline == nullptr) return;
  GstIterator* it = gst_bin_iterate_all_by_element_factory_name(GST_BIN(pipeline), "rtpbin");
  GValue item = G_VALUE_INIT;
  while (gst_iterator_next(it, &item) == GST_ITERATOR_OK) {
    g_object_set(g_value_get_object(&item), "rtcp-sync-send-time", FALSE, nullptr);
    g_value_reset(&item);
  }
  g_value_unset(&item);
  gst_iterator_free(it);
  gst_object_unref(pipeline);
}

// Sets the .pfap file on each new media's filesrc (no quoting of paths in kLaunch) and ties
// the end of its audio to the end of its markup.
void on_media_configure(GstRTSPMediaFactory*, GstRTSPMedia* media, gpointer file) {
  GstElement* bin = gst_rtsp_media_get_element(media);
  GstElement* filesrc = gst_bin_get_by_name(GST_BIN(bin), "file");
  g_object_set(filesrc, "location", static_cast<const char*>(file), nullptr);
  gst_object_unref(filesrc);
  GstElement* audio = gst_bin_get_by_name(GST_BIN(bin), "audio");
  GstPad* markup_pad = sink_pad_of(bin, "pay1");
  GstPad* audio_pad = sink_pad_of(bin, "pay0");
  AudioFromZero::attach(audio, audio_pad);
  EndAudioWithMarkup::attach(audio, markup_pad, audio_pad);
  g_signal_connect(media, "prepared", G_CALLBACK(on_media_prepared), nullptr);
  gst_object_unref(audio_pad);
  gst_object_unref(markup_pad);
  gst_object_unref(audio);
  gst_object_unref(bin);
}

}  // namespace

int main(int argc, char** argv) {
  // GOptionContext with GStreamer's option group, as GStreamer's own tools take theirs
  // (tools/command_line.h): --help, --help-gst, and GStreamer initialized by the parse.
  const GOptionEntry entries[] = {{}};
  if (const int status = parse_command_line(
          &argc, &argv, "FILE.pfap [PORT]",
          "Serves audio and the PFAP stream of FILE.pfap at rtsp://127.0.0.1:PORT/pfap, prints\n"
          "that URL, and serves until SIGINT or SIGTERM. PORT 0 or none: any free port. The\n"
          "pfap plugin must be installed or in GST_PLUGIN_PATH.",
          entries, gst_init_get_option_group());
      status != 0) {
    return status;
  }
  char* end = nullptr;
  const long port = argc == 3 ? std::strtol(argv[2], &end, 10) : 0;
  if (argc < 2 || argc > 3 || (argc == 3 && (*end != '\0' || port < 0 || port > 65535))) {
    return usage_error("wants FILE.pfap and, optionally, a PORT in 0..65535");
  }
  const char* file = argv[1];
  if (!g_file_test(file, G_FILE_TEST_IS_REGULAR)) {
    std::fprintf(stderr, "pfap-rtsp-server: %s: not a readable file\n", file);
    return 2;
  }
  for (const char* name : {"pfaptextparse", "rtppfappay"}) {
    GstElementFactory* factory = gst_element_factory_find(name);
    if (factory == nullptr) {
      std::fprintf(stderr,
                   "pfap-rtsp-server: no element %s: set GST_PLUGIN_PATH to the directories "
                   "of the pfap plugins (from a checkout: $PWD/build/gst:$PWD/build/ext)\n",
                   name);
      return 1;
    }
    gst_object_unref(factory);
  }

  GstRTSPServer* server = gst_rtsp_server_new();
  gst_rtsp_server_set_address(server, "127.0.0.1");
  gchar* service = g_strdup_printf("%ld", port);
  gst_rtsp_server_set_service(server, service);
  g_free(service);

  GstRTSPMediaFactory* factory = gst_rtsp_media_factory_new();
  gst_rtsp_media_factory_set_launch(factory, kLaunch);
  g_signal_connect(factory, "media-configure", G_CALLBACK(on_media_configure),
                   const_cast<char*>(file));
  GstRTSPMountPoints* mounts = gst_rtsp_server_get_mount_points(server);
  gst_rtsp_mount_points_add_factory(mounts, "/pfap", factory);  // takes the factory
  g_object_unref(mounts);

  GError* error = nullptr;
  GSource* source = gst_rtsp_server_create_source(server, nullptr, &error);
  if (source == nullptr) {
    std::fprintf(stderr, "pfap-rtsp-server: cannot listen on 127.0.0.1:%ld: %s\n", port,
                 error->message);
    g_clear_error(&error);
    g_object_unref(server);
    return 1;
  }
  g_source_attach(source, nullptr);

  // The port the system chose when asked for 0.
  std::printf("rtsp://127.0.0.1:%d/pfap\n", gst_rtsp_server_get_bound_port(server));
  std::fflush(stdout);

  GMainLoop* loop = g_main_loop_new(nullptr, FALSE);
  for (int signal : {SIGINT, SIGTERM}) {
    g_unix_signal_add(signal, G_SOURCE_FUNC(g_main_loop_quit), loop);
  }
  g_main_loop_run(loop);

  g_main_loop_unref(loop);
  g_source_destroy(source);
  g_source_unref(source);
  g_object_unref(server);
  return 0;
}

// pfap-rtsp-server: an RTSP server that streams a talking head's data, audio plus the PFAP
// phonemes and FAPs of a .pfap file, as one RTSP presentation (gst-rtsp-server).
//
//   pfap-rtsp-server FILE.pfap [PORT]      (PORT 0 or none: any free port)
//
// It listens on 127.0.0.1 only, prints the URL, rtsp://127.0.0.1:PORT/pfap, on one line of
// standard output, and serves until SIGINT or SIGTERM (exit status 0). Each client gets its
// own media, made from this launch description:
//
//   ( audiotestsrc is-live=true ! audioconvert ! audio/x-raw,rate=44100,channels=1
//       ! rtpL16pay name=pay0 pt=96
//     filesrc name=file ! pfapparse alphabet=x-pfap-arpabet ! identity sync=true
//       ! rtppfappay name=pay1 pt=97 )
//
//  - audiotestsrc stands for the speech; a real server has its TTS audio here.
//  - identity sync=true paces the file's events in real time from PLAY on, as a live TTS
//    source would produce them; the audio is live too, so both start at running time 0.
//    The file plays once; the audio goes on until the client leaves.
//  - pfapparse's alphabet names the phoneme alphabet in the caps (a .pfap file has symbol
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
// tree GST_PLUGIN_PATH=build/gst:build/ext, as scripts/demo and `meson devenv` set it).
#include <glib-unix.h>
#include <gst/gst.h>
#include <gst/rtsp-server/rtsp-server.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>

namespace {

constexpr const char* kLaunch =
    "( audiotestsrc is-live=true ! audioconvert ! audio/x-raw,rate=44100,channels=1 "
    "! rtpL16pay name=pay0 pt=96 "
    "filesrc name=file ! pfapparse alphabet=x-pfap-arpabet ! identity sync=true "
    "! rtppfappay name=pay1 pt=97 )";

// Sets the .pfap file on each new media's filesrc (no quoting of paths in kLaunch).
void on_media_configure(GstRTSPMediaFactory*, GstRTSPMedia* media, gpointer file) {
  GstElement* bin = gst_rtsp_media_get_element(media);
  GstElement* filesrc = gst_bin_get_by_name(GST_BIN(bin), "file");
  g_object_set(filesrc, "location", static_cast<const char*>(file), nullptr);
  gst_object_unref(filesrc);
  gst_object_unref(bin);
}

}  // namespace

int main(int argc, char** argv) {
  gst_init(&argc, &argv);

  if (argc == 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::printf(
        "usage: pfap-rtsp-server FILE.pfap [PORT]   (PORT 0: any free port)\n"
        "Serves audio and the PFAP stream of FILE.pfap at rtsp://127.0.0.1:PORT/pfap, prints\n"
        "that URL, and serves until SIGINT or SIGTERM. The pfap plugin must be installed or\n"
        "in GST_PLUGIN_PATH.\n");
    return 0;
  }
  char* end = nullptr;
  const long port = argc == 3 ? std::strtol(argv[2], &end, 10) : 0;
  if (argc < 2 || argc > 3 || (argc == 3 && (*end != '\0' || port < 0 || port > 65535))) {
    std::fprintf(stderr, "usage: pfap-rtsp-server FILE.pfap [PORT]   (PORT 0: any free port)\n");
    return 2;
  }
  const char* file = argv[1];
  if (!g_file_test(file, G_FILE_TEST_IS_REGULAR)) {
    std::fprintf(stderr, "pfap-rtsp-server: %s: not a readable file\n", file);
    return 2;
  }
  for (const char* name : {"pfapparse", "rtppfappay"}) {
    GstElementFactory* factory = gst_element_factory_find(name);
    if (factory == nullptr) {
      std::fprintf(stderr,
                   "pfap-rtsp-server: no element %s: set GST_PLUGIN_PATH to the directories "
                   "of the pfap plugins (for example build/gst:build/ext)\n",
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

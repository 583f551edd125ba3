// SPDX-License-Identifier: LGPL-2.1-or-later
// What users run, end to end: the sample sessions in docs/examples/, tools/pfap-loopback, the
// RTSP server example and the commands of docs/elements.md, "Text markup: sending and
// receiving a session".
//  - ExampleFiles.*: every docs/examples/*.pfap parses without a warning, reads back the same
//    through pfaptextparse ! pfaptextenc, and is described in docs/examples/README.md.
//  - Loopback.*: pfap-loopback returns every round-trip sample (all files without comments
//    or state lines) byte for byte, at several MTUs, and reports bad input.
//  - Rtsp.*: pfap-rtsp-server as a subprocess and an rtspsrc client: the SDP and the caps
//    carry the alphabet, audio arrives, every phoneme arrives; the audio's first sample and
//    the phonemes' time 0 are one instant in the RTCP reports.
//  - DocumentedLines.*: each command block of that docs section, run as written but with free
//    ports, the source tree's docs/examples/ and temporary output files.
//  - Readme.*: the pfaptts commands of README.md, "Text to speech", run the same way; its
//    pfapalign lines are checked to be those of docs/elements.md, which test_pfapalign* run,
//    and its "A recording" block is run as written. Every file a README command reads is
//    there, the Install section names the packages of the GStreamer tools it runs, and each
//    build tree GST_PLUGIN_PATH of README.md and docs/ finds the plugins from another
//    directory.
//  - InstallMd.*: docs/install.md's account of the packages against debian/.
//  - Story.*: pfap-story, the main job: speech over RTP with loss, rendered and muxed.
//  - PlayStream.*: generic players, no pipeline written by hand: playbin on the RTSP example
//    (rtppfapdepay and pfapface plugged by themselves, face within a video frame of the
//    audio), playbin on a .pfap file (the typefinder), other text left alone, and ffmpeg -t 3
//    against the example ending.
//
// meson passes PFAP_SOURCE_DIR, PFAP_BUILD_DIR, PFAP_LOOPBACK, PFAP_RTSP_SERVER and PFAP_STORY,
// and GST_PLUGIN_PATH in the environment (the subprocesses inherit it). Everything is on
// 127.0.0.1, on port 0 or on free ports found by binding port 0; every wait is bounded.
#include <arpa/inet.h>
#include <glib/gstdio.h>
#include <gst/gst.h>
#include <gst/rtp/gstrtcpbuffer.h>
#include <gst/sdp/gstsdpmessage.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <mutex>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "pfap/markup.h"
#include "documented_commands.h"
#include "pad_time.h"
#include "pfap_buffers.h"
#include "pipeline.h"
#include "temp_dir.h"
#include "udp_ports.h"

namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;
using pfap::testing::commands_in;
using pfap::testing::doc_section;
using pfap::testing::lines_of;
using pfap::testing::read_file;
using pfap::testing::replace_all;
using pfap::testing::source_path;

// The plugin's elements the examples use.
constexpr const char* kElements[] = {"pfaptextparse", "pfaptextenc", "rtppfappay", "rtppfapdepay"};
constexpr const char* kSection = "## Text markup: sending and receiving a session";
constexpr const char* kAlphabet = "x-pfap-arpabet";
// rtpbin and rtspsrc time phonemes from arrival times and RTCP; they may move a line by a ms
// or two on a loaded machine. (The sanitizer build runs the two tests that use this without
// LeakSanitizer: tests/gst/meson.build says why.)
constexpr int64_t kLiveToleranceMs = 20;
// Times from RTP timestamps: 44.1 kHz ticks, rounded to the ms by pfaptextenc.
constexpr int64_t kRtpToleranceMs = 1;

// ---------------------------------------------------------------------------------------------
// Files

// The lines that carry an event (not blank, not comment-only), each with its '\n'.
std::string event_lines(const std::string& text) {
  std::string out;
  for (const std::string& line : lines_of(text)) {
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    out += line + "\n";
  }
  return out;
}

size_t count_events(const std::string& text) { return lines_of(event_lines(text)).size(); }

std::string base_name(const std::string& path) { return path.substr(path.rfind('/') + 1); }

// docs/examples/*.pfap, full paths, sorted.
std::vector<std::string> example_files() {
  std::vector<std::string> files;
  const std::string dir = source_path("docs/examples");
  GDir* d = g_dir_open(dir.c_str(), 0, nullptr);
  if (d == nullptr) return files;
  while (const gchar* name = g_dir_read_name(d)) {
    if (g_str_has_suffix(name, ".pfap")) files.push_back(dir + "/" + name);
  }
  g_dir_close(d);
  std::sort(files.begin(), files.end());
  return files;
}

// A round-trip sample: canonical lines only, so no comments and no state lines (rtppfappay
// does not send state events yet).
bool is_round_trip_sample(const std::string& text) {
  return text.find('#') == std::string::npos && text.find(" state ") == std::string::npos;
}

std::vector<std::string> round_trip_samples() {
  std::vector<std::string> samples;
  for (const std::string& file : example_files()) {
    if (is_round_trip_sample(read_file(file))) samples.push_back(file);
  }
  return samples;
}

// Sessions compared line by line: the same events, times within `tolerance_ms`.
// With `from_first`, times count from each file's first line: a writer's times are the
// receiver's stream times, which start when the receiving pipeline does (docs/elements.md,
// "Times in the files written").
::testing::AssertionResult same_session(const std::string& got, const std::string& want,
                                        int64_t tolerance_ms, bool from_first = false) {
  const std::vector<std::string> g = lines_of(got);
  const std::vector<std::string> w = lines_of(want);
  if (g.size() != w.size()) {
    return ::testing::AssertionFailure() << g.size() << " lines, want " << w.size() << "; got:\n"
                                         << got;
  }
  const int64_t shift =
      from_first && !g.empty() ? std::atoll(g[0].c_str()) - std::atoll(w[0].c_str()) : 0;
  for (size_t i = 0; i < g.size(); ++i) {
    const size_t gs = g[i].find(' ');
    const size_t ws = w[i].find(' ');
    if (gs == std::string::npos || ws == std::string::npos || g[i].substr(gs) != w[i].substr(ws) ||
        std::llabs(std::atoll(g[i].c_str()) - shift - std::atoll(w[i].c_str())) > tolerance_ms) {
      return ::testing::AssertionFailure()
             << "line " << i + 1 << ": got\n  " << g[i] << "\nwant\n  " << w[i];
    }
  }
  return ::testing::AssertionSuccess();
}

// ---------------------------------------------------------------------------------------------
// Processes and ports

struct ProcessResult {
  int status = -1;  // exit status, -1 when it did not exit normally
  std::string out;
  std::string err;
};

ProcessResult run(const std::vector<std::string>& args) {
  std::vector<gchar*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<gchar*>(a.c_str()));
  argv.push_back(nullptr);
  ProcessResult r;
  gchar* out = nullptr;
  gchar* err = nullptr;
  gint wait_status = 0;
  GError* error = nullptr;
  if (!g_spawn_sync(nullptr, argv.data(), nullptr, G_SPAWN_DEFAULT, nullptr, nullptr, &out, &err,
                    &wait_status, &error)) {
    r.err = std::string("cannot run ") + args[0] + ": " + error->message;
    g_error_free(error);
    return r;
  }
  r.out = out;
  r.err = err;
  g_free(out);
  g_free(err);
  r.status = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1;
  return r;
}

// pfap-rtsp-server FILE 0 as a subprocess: the URL it prints, SIGTERM on stop().
class RtspServer {
 public:
  explicit RtspServer(const std::string& file) {
    std::string program = PFAP_RTSP_SERVER;
    std::string port = "0";
    std::string path = file;
    gchar* argv[] = {program.data(), path.data(), port.data(), nullptr};
    gint out_fd = -1;
    GError* error = nullptr;
    // In a sanitizer build the server runs with ASan but without LeakSanitizer, which would
    // unwind the stack of every allocation (tests/gst/meson.build) and hold up its live
    // streams by tens of ms: the client's times are what these tests check.
    gchar** envp = g_get_environ();
    if (g_environ_getenv(envp, "ASAN_OPTIONS") != nullptr) {
      envp = g_environ_setenv(envp, "ASAN_OPTIONS", "detect_leaks=0", TRUE);
    }
    const gboolean spawned =
        g_spawn_async_with_pipes(nullptr, argv, envp, G_SPAWN_DO_NOT_REAP_CHILD, nullptr, nullptr,
                                 &pid_, nullptr, &out_fd, nullptr, &error);
    g_strfreev(envp);
    if (!spawned) {
      ADD_FAILURE() << "cannot start " << program << ": " << error->message;
      g_error_free(error);
      return;
    }
    started_ = true;
    // The first line of standard output is the URL.
    const auto deadline = Clock::now() + 10s;
    std::string line;
    while (line.find('\n') == std::string::npos && Clock::now() < deadline) {
      pollfd p{out_fd, POLLIN, 0};
      if (poll(&p, 1, 100) <= 0) continue;
      char chunk[256];
      const ssize_t n = read(out_fd, chunk, sizeof chunk);
      if (n <= 0) break;
      line.append(chunk, static_cast<size_t>(n));
    }
    close(out_fd);
    if (line.find('\n') != std::string::npos) url_ = line.substr(0, line.find('\n'));
  }
  ~RtspServer() { stop(); }
  RtspServer(const RtspServer&) = delete;
  RtspServer& operator=(const RtspServer&) = delete;

  const std::string& url() const { return url_; }

  // Sends SIGTERM and returns the exit status (-1 if it had to be killed or did not exit).
  int stop() {
    if (!started_) return status_;
    started_ = false;
    kill(pid_, SIGTERM);
    int wait_status = 0;
    const auto deadline = Clock::now() + 5s;
    pid_t done = 0;
    while ((done = waitpid(pid_, &wait_status, WNOHANG)) == 0 && Clock::now() < deadline) {
      std::this_thread::sleep_for(10ms);
    }
    if (done == 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, &wait_status, 0);
      return status_ = -1;
    }
    g_spawn_close_pid(pid_);
    return status_ = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1;
  }

 private:
  GPid pid_ = 0;
  bool started_ = false;
  int status_ = -1;
  std::string url_;
};

// ---------------------------------------------------------------------------------------------
// Pipelines

using pfap::testing::free_udp_ports;
using pfap::testing::Pipeline;
using pfap::testing::plugin_available;
using pfap::testing::TempDir;

// What flows out of an element's src pad: the bytes (text from pfaptextenc) and a count.
struct Tap {
  std::mutex mutex;
  std::string bytes;
  size_t buffers = 0;
  size_t size = 0;

  void attach(GstElement* element, const char* pad_name = "src") {
    ASSERT_NE(element, nullptr);
    GstPad* pad = gst_element_get_static_pad(element, pad_name);
    gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, on_buffer, this, nullptr);
    gst_object_unref(pad);
  }

  std::string text() {
    std::lock_guard lock(mutex);
    return bytes;
  }
  size_t lines() {
    std::lock_guard lock(mutex);
    return static_cast<size_t>(std::count(bytes.begin(), bytes.end(), '\n'));
  }
  size_t count() {
    std::lock_guard lock(mutex);
    return buffers;
  }
  size_t total_size() {
    std::lock_guard lock(mutex);
    return size;
  }

 private:
  static GstPadProbeReturn on_buffer(GstPad*, GstPadProbeInfo* info, gpointer data) {
    auto* tap = static_cast<Tap*>(data);
    GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
    GstMapInfo map;
    if (gst_buffer_map(buffer, &map, GST_MAP_READ)) {
      std::lock_guard lock(tap->mutex);
      tap->bytes.append(reinterpret_cast<const char*>(map.data), map.size);
      tap->buffers += 1;
      tap->size += map.size;
      gst_buffer_unmap(buffer, &map);
    }
    return GST_PAD_PROBE_OK;
  }
};

// Waits until `done` holds, failing on a pipeline error or after `timeout`.
template <typename Done>
::testing::AssertionResult wait_until(std::vector<Pipeline*> pipelines, Done done,
                                      std::chrono::milliseconds timeout, const char* what) {
  const auto deadline = Clock::now() + timeout;
  while (!done()) {
    for (Pipeline* p : pipelines) {
      const std::string error = p->poll_error();
      if (!error.empty()) return ::testing::AssertionFailure() << error;
    }
    if (Clock::now() > deadline) return ::testing::AssertionFailure() << "timed out: " << what;
    std::this_thread::sleep_for(20ms);
  }
  return ::testing::AssertionSuccess();
}

// ---------------------------------------------------------------------------------------------
// The documented commands

// The commands under `heading` in `section` of `file` (a source path).
std::vector<std::string> documented_commands(const std::string& file, const std::string& section,
                                             const std::string& heading) {
  return commands_in(pfap::testing::section(doc_section(file, section), heading));
}

// Those of docs/elements.md, "Text markup: sending and receiving a session".
std::vector<std::string> documented_commands(const std::string& heading) {
  return documented_commands("docs/elements.md", kSection, heading);
}

const std::vector<std::string> kHeadings = {
    "### One process", "### Over UDP", "### Next to audio: one rtpbin on each side", "### RTSP"};

// A documented command made runnable here: documented ports mapped to free ones (the same
// documented port to the same free port), docs/examples/ to the source tree's, the output
// files to `dir`, the RTSP URL to `rtsp_url`.
class Substitution {
 public:
  Substitution(const TempDir& dir, std::string rtsp_url = "")
      : dir_(dir), rtsp_url_(std::move(rtsp_url)) {}

  std::string operator()(std::string command) {
    replace_all(command, "docs/examples/", source_path("docs/examples/"));
    replace_all(command, "received.pfap", dir_.file("received.pfap"));
    replace_all(command, "received.wav", dir_.file("received.wav"));
    replace_all(command, "speech.pfap", dir_.file("speech.pfap"));
    replace_all(command, "speech.wav", dir_.file("speech.wav"));
    if (!rtsp_url_.empty()) replace_all(command, "rtsp://127.0.0.1:8554/pfap", rtsp_url_);
    return free_ports_(command);
  }

  // The launch description of a gst-launch-1.0 command (without the program and -e).
  std::string launch(const std::string& command) {
    return pfap::testing::launch_description((*this)(command));
  }

 private:
  const TempDir& dir_;
  std::string rtsp_url_;
  pfap::testing::FreePorts free_ports_;
};

// ---------------------------------------------------------------------------------------------
// ExampleFiles

TEST(ExampleFiles, ThereAreRoundTripSamplesAndStates) {
  const std::vector<std::string> files = example_files();
  ASSERT_GE(files.size(), 5u) << "docs/examples/*.pfap";
  const std::vector<std::string> samples = round_trip_samples();
  EXPECT_EQ(samples.size(), files.size() - 1) << "every file but states.pfap is a round trip";
  EXPECT_FALSE(is_round_trip_sample(read_file(source_path("docs/examples/states.pfap"))));
}

TEST(ExampleFiles, DescribedInReadme) {
  const std::string readme = read_file(source_path("docs/examples/README.md"));
  for (const std::string& file : example_files()) {
    EXPECT_NE(readme.find("| `" + base_name(file) + "` |"), std::string::npos)
        << base_name(file) << " has no row in docs/examples/README.md";
  }
}

TEST(ExampleFiles, EveryFileParses) {
  ASSERT_TRUE(plugin_available(kElements));
  for (const std::string& file : example_files()) {
    SCOPED_TRACE(file);
    Pipeline p("filesrc name=file ! pfaptextparse name=parse ! fakesink");
    ASSERT_TRUE(p.error().empty()) << p.error();
    GstElement* filesrc = p.find("filesrc");
    g_object_set(filesrc, "location", file.c_str(), nullptr);
    Tap events;
    events.attach(p.find("pfaptextparse"));
    ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
    EXPECT_EQ(p.wait_eos(std::chrono::seconds(5), /*warnings=*/true), "");
    EXPECT_EQ(events.count(), count_events(read_file(file)));
  }
}

// Canonical lines read and written back unchanged; comments are not written.
TEST(ExampleFiles, ReadBackThroughTextEnc) {
  ASSERT_TRUE(plugin_available(kElements));
  for (const std::string& file : example_files()) {
    SCOPED_TRACE(file);
    Pipeline p("filesrc name=file ! pfaptextparse ! pfaptextenc ! fakesink");
    ASSERT_TRUE(p.error().empty()) << p.error();
    g_object_set(p.find("filesrc"), "location", file.c_str(), nullptr);
    Tap text;
    text.attach(p.find("pfaptextenc"));
    ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
    ASSERT_EQ(p.wait_eos(std::chrono::seconds(5), /*warnings=*/true), "");
    EXPECT_EQ(text.text(), event_lines(read_file(file)));
  }
}

// ---------------------------------------------------------------------------------------------
// Loopback: tools/pfap-loopback

TEST(Loopback, RoundTripIsByteIdentical) {
  const std::vector<std::string> samples = round_trip_samples();
  ASSERT_FALSE(samples.empty());
  // The default MTU, where max-delay makes the packets, and MTUs that split them further (at
  // 60 a few phonemes with many FAPs go alone in larger packets, with a warning).
  for (const char* mtu : {"", "--mtu=80", "--mtu=60"}) {
    for (const std::string& file : samples) {
      SCOPED_TRACE(file + " " + mtu);
      std::vector<std::string> args = {PFAP_LOOPBACK, "--timeout=10"};
      if (*mtu != '\0') args.push_back(mtu);
      args.push_back(file);
      const ProcessResult r = run(args);
      ASSERT_EQ(r.status, 0) << r.err;
      EXPECT_EQ(r.out, read_file(file)) << r.err;
      EXPECT_NE(r.err.find("(0 malformed, 0 lost)"), std::string::npos) << r.err;
    }
  }
}

TEST(Loopback, ReportsErrors) {
  TempDir dir;
  {
    const ProcessResult r = run({PFAP_LOOPBACK, dir.file("missing.pfap")});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("not a readable file"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
  }
  {
    const ProcessResult r = run({PFAP_LOOPBACK});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("pfap-loopback: wants one FILE.pfap"), std::string::npos) << r.err;
  }
  {
    const std::string bad = dir.file("bad.pfap");
    ASSERT_TRUE(g_file_set_contents(bad.c_str(), "0 16 60 118 W\n60 3 70 124 WS\n", -1, nullptr));
    const ProcessResult r = run({PFAP_LOOPBACK, "--timeout=10", bad});
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("sender: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("line 2"), std::string::npos) << r.err;
  }
}

// ---------------------------------------------------------------------------------------------
// Rtsp: examples/pfap-rtsp-server

struct Sdp {
  std::mutex mutex;
  std::string text;

  static void on_sdp(GstElement*, GstSDPMessage* message, gpointer data) {
    auto* sdp = static_cast<Sdp*>(data);
    gchar* text = gst_sdp_message_as_text(message);
    std::lock_guard lock(sdp->mutex);
    sdp->text = text;
    g_free(text);
  }
  std::string get() {
    std::lock_guard lock(mutex);
    return text;
  }
};

TEST(Rtsp, ServesAudioAndPhonemes) {
  ASSERT_TRUE(plugin_available(kElements));
  const std::string file = source_path("docs/examples/hello.pfap");
  const std::string want = read_file(file);
  RtspServer server(file);
  ASSERT_EQ(server.url().rfind("rtsp://127.0.0.1:", 0), 0u) << "URL: " << server.url();

  // Phoneme times from the RTP timestamps alone (buffer-mode=none, and no RTCP to move one
  // stream against the other for lip sync): they must come back to the ms, whatever holds up
  // the server or the client. DocumentedLines.Rtsp runs the documented client, with arrival
  // times and RTCP.
  Pipeline client("rtspsrc name=src buffer-mode=none do-rtcp=false location=" + server.url() +
                  " src. ! rtpL16depay ! fakesink sync=false"
                  " src. ! rtppfapdepay ! pfaptextenc ! fakesink sync=false");
  ASSERT_TRUE(client.error().empty()) << client.error();
  Sdp sdp;
  g_signal_connect(client.find("rtspsrc"), "on-sdp", G_CALLBACK(Sdp::on_sdp), &sdp);
  Tap audio, text;
  audio.attach(client.find("rtpL16depay"));
  text.attach(client.find("pfaptextenc"));
  ASSERT_EQ(client.set_state(GST_STATE_PLAYING), "");
  ASSERT_TRUE(wait_until(
      {&client}, [&] { return text.lines() >= count_events(want) && audio.count() >= 10; }, 15s,
      "every phoneme and 10 audio buffers"))
      << text.lines() << " lines, " << audio.count() << " audio buffers";

  // The alphabet in the SDP, the RTP caps and the depayloaded caps.
  const std::string description = sdp.get();
  EXPECT_NE(description.find("a=fmtp:97 alphabet=" + std::string(kAlphabet)), std::string::npos)
      << description;
  EXPECT_NE(description.find("a=rtpmap:97 PFAP/44100"), std::string::npos) << description;
  GstPad* pad = gst_element_get_static_pad(client.find("rtppfapdepay"), "src");
  GstCaps* caps = gst_pad_get_current_caps(pad);
  ASSERT_NE(caps, nullptr);
  const gchar* alphabet = gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet");
  EXPECT_STREQ(alphabet, kAlphabet);
  gst_caps_unref(caps);
  gst_object_unref(pad);

  EXPECT_TRUE(same_session(text.text(), want, kRtpToleranceMs));
  EXPECT_GT(audio.total_size(), 0u);
  gst_element_set_state(client.get(), GST_STATE_NULL);
  EXPECT_EQ(server.stop(), 0) << "the server ends with status 0 on SIGTERM";
}

// The sender's wall-clock time (NTP, ns) of each stream's first RTP timestamp, from its RTCP
// sender reports: per report, its NTP time less the RTP time elapsed since the first packet.
struct TimeZeros {
  std::mutex mutex;
  std::vector<int64_t> of[2];  // per session: 0 the audio, 1 the PFAP stream

  static void on_new_manager(GstElement*, GstElement* manager, gpointer data) {
    g_signal_connect(manager, "new-jitterbuffer", G_CALLBACK(on_new_jitterbuffer), data);
  }
  static void on_new_jitterbuffer(GstElement*, GstElement* jitterbuffer, guint session, guint,
                                  gpointer data) {
    if (session > 1) return;
    g_object_set_data(G_OBJECT(jitterbuffer), "session", GUINT_TO_POINTER(session));
    g_signal_connect(jitterbuffer, "handle-sync", G_CALLBACK(on_handle_sync), data);
  }
  static void on_handle_sync(GstElement* jitterbuffer, GstStructure* s, gpointer data) {
    auto* self = static_cast<TimeZeros*>(data);
    guint64 base = 0, sr_rtp = 0;
    guint rate = 0;
    const GValue* value = gst_structure_get_value(s, "sr-buffer");
    if (!gst_structure_get(s, "base-rtptime", G_TYPE_UINT64, &base, "sr-ext-rtptime", G_TYPE_UINT64,
                           &sr_rtp, "clock-rate", G_TYPE_UINT, &rate, nullptr) ||
        value == nullptr || rate == 0) {
      return;
    }
    GstRTCPBuffer rtcp = GST_RTCP_BUFFER_INIT;
    GstRTCPPacket packet;
    guint64 ntp = 0;
    if (!gst_rtcp_buffer_map(gst_value_get_buffer(value), GST_MAP_READ, &rtcp)) return;
    const bool sr = gst_rtcp_buffer_get_first_packet(&rtcp, &packet) &&
                    gst_rtcp_packet_get_type(&packet) == GST_RTCP_TYPE_SR;
    if (sr) gst_rtcp_packet_sr_get_sender_info(&packet, nullptr, &ntp, nullptr, nullptr, nullptr);
    gst_rtcp_buffer_unmap(&rtcp);
    if (!sr) return;
    const auto ntp_ns =
        static_cast<int64_t>(gst_util_uint64_scale(ntp, GST_SECOND, G_GUINT64_CONSTANT(1) << 32));
    const auto since_first =
        static_cast<int64_t>(gst_util_uint64_scale(sr_rtp - base, GST_SECOND, rate));
    const guint session = GPOINTER_TO_UINT(g_object_get_data(G_OBJECT(jitterbuffer), "session"));
    std::lock_guard lock(self->mutex);
    self->of[session].push_back(ntp_ns - since_first);
  }
  // The median of a stream's time zeros (one per report), or -1 with fewer than `n` reports.
  int64_t median(int session, size_t n) {
    std::lock_guard lock(mutex);
    std::vector<int64_t> v = of[session];
    if (v.size() < n) return -1;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  }
};

// The server's audio and phonemes count from one instant: the RTP timestamp of the first
// audio sample and that of the first phoneme (time 0 of the file) map, by each session's RTCP
// reports, to the same wall-clock time. Before, the audio's first sample went out stamped a
// few ms to tens of ms after the phonemes' zero (the running time at which the live source
// started), so every client put the face that much ahead of the speech.
TEST(Rtsp, AudioAndPhonemesShareTheirTimeZero) {
  ASSERT_TRUE(plugin_available(kElements));
  RtspServer server(source_path("docs/examples/hello.pfap"));
  ASSERT_EQ(server.url().rfind("rtsp://127.0.0.1:", 0), 0u) << "URL: " << server.url();
  Pipeline client("rtspsrc name=src buffer-mode=synced location=" + server.url() +
                  " src. ! rtpL16depay ! fakesink src. ! rtppfapdepay ! fakesink");
  ASSERT_TRUE(client.error().empty()) << client.error();
  TimeZeros zeros;
  g_signal_connect(client.find("rtspsrc"), "new-manager", G_CALLBACK(TimeZeros::on_new_manager),
                   &zeros);
  ASSERT_EQ(client.set_state(GST_STATE_PLAYING), "");
  constexpr size_t kReports = 5;  // the server sends one every ~100 ms per session
  ASSERT_TRUE(wait_until(
      {&client}, [&] { return zeros.median(0, kReports) >= 0 && zeros.median(1, kReports) >= 0; },
      15s, "RTCP sender reports of both sessions"));
  gst_element_set_state(client.get(), GST_STATE_NULL);
  EXPECT_EQ(server.stop(), 0);
  const int64_t difference = zeros.median(0, kReports) - zeros.median(1, kReports);
  EXPECT_LT(std::abs(difference), static_cast<int64_t>(GST_MSECOND))
      << "the audio's first sample is " << static_cast<double>(difference) / 1e6
      << " ms after the phonemes' time 0";
}

// ---------------------------------------------------------------------------------------------
// DocumentedLines: docs/elements.md, "Text markup: sending and receiving a session"

// Every command of the section is under a heading that a test below runs, and the examples'
// README shows no gst-launch-1.0 line of its own.
TEST(DocumentedLines, EveryCommandIsTested) {
  const std::vector<std::string> lines = doc_section("docs/elements.md", kSection);
  ASSERT_FALSE(lines.empty()) << kSection;
  size_t in_section = 0;
  bool in_block = false;
  for (const std::string& line : lines) {
    if (line.rfind("```", 0) == 0) in_block = !in_block;
    if (in_block && (line.rfind("gst-launch-1.0", 0) == 0 || line.rfind("build/", 0) == 0)) {
      ++in_section;
    }
  }
  size_t tested = 0;
  for (const std::string& heading : kHeadings) {
    const size_t n = documented_commands(heading).size();
    EXPECT_GT(n, 0u) << heading;
    tested += n;
  }
  EXPECT_EQ(tested, in_section);
  for (const std::string& line : lines_of(read_file(source_path("docs/examples/README.md")))) {
    EXPECT_NE(line.rfind("gst-launch-1.0", 0), 0u)
        << "untested in docs/examples/README.md: " << line;
  }
}

TEST(DocumentedLines, OneProcess) {
  const std::vector<std::string> commands = documented_commands(kHeadings[0]);
  ASSERT_EQ(commands.size(), 1u);
  TempDir dir;
  Substitution substitute(dir);
  std::vector<std::string> args;
  gchar** argv = g_strsplit(substitute(commands[0]).c_str(), " ", -1);
  for (gchar** a = argv; *a != nullptr; ++a) args.emplace_back(*a);
  g_strfreev(argv);
  ASSERT_EQ(args.size(), 2u) << commands[0];
  ASSERT_EQ(args[0], "build/tools/pfap-loopback");
  args[0] = PFAP_LOOPBACK;
  const ProcessResult r = run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, read_file(args[1]));
}

TEST(DocumentedLines, Udp) {
  ASSERT_TRUE(plugin_available(kElements));
  const std::vector<std::string> commands = documented_commands(kHeadings[1]);
  ASSERT_EQ(commands.size(), 2u);
  TempDir dir;
  Substitution substitute(dir);
  Pipeline receiver(substitute.launch(commands[0]));
  Pipeline sender(substitute.launch(commands[1]));
  ASSERT_TRUE(receiver.error().empty()) << receiver.error();
  ASSERT_TRUE(sender.error().empty()) << sender.error();
  const std::string want = read_file(source_path("docs/examples/hello.pfap"));
  Tap text;
  text.attach(receiver.find("pfaptextenc"));

  ASSERT_EQ(receiver.set_state(GST_STATE_PLAYING), "");  // bound once set_state returns
  ASSERT_EQ(sender.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(sender.wait_eos(std::chrono::seconds(10)), "") << "the sender sends in real time";
  ASSERT_TRUE(wait_until(
      {&receiver}, [&] { return text.lines() >= count_events(want); }, 5s, "every phoneme"));
  ASSERT_EQ(receiver.end(std::chrono::seconds(5)), "");
  EXPECT_EQ(read_file(dir.file("received.pfap")), want);
}

TEST(DocumentedLines, Rtpbin) {
  ASSERT_TRUE(plugin_available(kElements));
  const std::vector<std::string> commands = documented_commands(kHeadings[2]);
  ASSERT_EQ(commands.size(), 2u);
  TempDir dir;
  Substitution substitute(dir);
  Pipeline receiver(substitute.launch(commands[0]));
  Pipeline sender(substitute.launch(commands[1]));
  ASSERT_TRUE(receiver.error().empty()) << receiver.error();
  ASSERT_TRUE(sender.error().empty()) << sender.error();
  const std::string want = read_file(source_path("docs/examples/hello.pfap"));
  Tap text, audio;
  text.attach(receiver.find("pfaptextenc"));
  audio.attach(receiver.find("rtpL16depay"));

  ASSERT_EQ(receiver.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(sender.set_state(GST_STATE_PLAYING), "");
  ASSERT_TRUE(wait_until(
      {&receiver, &sender},
      [&] { return text.lines() >= count_events(want) && audio.count() >= 10; }, 10s,
      "every phoneme and 10 audio buffers"))
      << text.lines() << " lines, " << audio.count() << " audio buffers";
  ASSERT_EQ(receiver.end(std::chrono::seconds(5)), "");
  gst_element_set_state(sender.get(), GST_STATE_NULL);

  // rtpbin times the packets from their arrival, in the receiver's running time.
  EXPECT_TRUE(same_session(read_file(dir.file("received.pfap")), want, kLiveToleranceMs, true));
  const std::string wav = read_file(dir.file("received.wav"));
  EXPECT_EQ(wav.rfind("RIFF", 0), 0u);
  EXPECT_GT(wav.size(), 44u + 4410u * 2) << "at least 0.1 s of audio";
}

TEST(DocumentedLines, Rtsp) {
  ASSERT_TRUE(plugin_available(kElements));
  const std::vector<std::string> commands = documented_commands(kHeadings[3]);
  ASSERT_EQ(commands.size(), 2u);
  // The server command: the program, the file and the port, which becomes 0 (any free port).
  TempDir dir;
  Substitution files(dir);
  gchar** argv = g_strsplit(files(commands[0]).c_str(), " ", -1);
  ASSERT_EQ(g_strv_length(argv), 3u) << commands[0];
  EXPECT_STREQ(argv[0], "build/examples/pfap-rtsp-server");
  EXPECT_STREQ(argv[2], "8554");
  const std::string file = argv[1];
  g_strfreev(argv);
  RtspServer server(file);
  ASSERT_EQ(server.url().rfind("rtsp://127.0.0.1:", 0), 0u) << "URL: " << server.url();

  Substitution substitute(dir, server.url());
  Pipeline client(substitute.launch(commands[1]));
  ASSERT_TRUE(client.error().empty()) << client.error();
  const std::string want = read_file(file);
  Tap text, audio;
  text.attach(client.find("pfaptextenc"));
  audio.attach(client.find("rtpL16depay"));
  ASSERT_EQ(client.set_state(GST_STATE_PLAYING), "");
  ASSERT_TRUE(wait_until(
      {&client}, [&] { return text.lines() >= count_events(want) && audio.count() >= 10; }, 15s,
      "every phoneme and 10 audio buffers"))
      << text.lines() << " lines, " << audio.count() << " audio buffers";
  ASSERT_EQ(client.end(std::chrono::seconds(5)), "");

  EXPECT_TRUE(same_session(read_file(dir.file("received.pfap")), want, kLiveToleranceMs));
  const std::string wav = read_file(dir.file("received.wav"));
  EXPECT_EQ(wav.rfind("RIFF", 0), 0u);
  EXPECT_GT(wav.size(), 44u + 4410u * 2) << "at least 0.1 s of audio";
  gst_element_set_state(client.get(), GST_STATE_NULL);  // TEARDOWN while the server is there
  EXPECT_EQ(server.stop(), 0);
}

// ---------------------------------------------------------------------------------------------
// Readme: README.md, "Text to speech"

constexpr const char* kReadmeSection = "## Text to speech";

std::vector<std::string> readme_commands(const std::string& heading) {
  return documented_commands("README.md", kReadmeSection, heading);
}

std::vector<std::string> readme_align_commands() {
  std::vector<std::string> out;
  for (const char* heading : {"### A recording", "### Live"}) {
    for (std::string& c : documented_commands("README.md", "## PFAP from any speech", heading)) {
      out.push_back(std::move(c));
    }
  }
  return out;
}

// The .pfap lines as (start ms, duration ms, number of bookmarked FAPs).
struct PfapLine {
  long start_ms;
  long duration_ms;
  int faps;
};
std::vector<PfapLine> pfap_lines(const std::string& text) {
  std::vector<PfapLine> out;
  for (const std::string& line : lines_of(text)) {
    long start = 0, symbol = 0, duration = 0;
    if (std::sscanf(line.c_str(), "%ld %ld %ld", &start, &symbol, &duration) != 3) continue;
    int faps = 0;
    for (size_t at = line.find("<FAP"); at != std::string::npos; at = line.find("<FAP", at + 1)) {
      ++faps;
    }
    out.push_back({start, duration, faps});
  }
  return out;
}

TEST(Readme, EveryCommandIsTested) {
  const std::string readme = read_file(source_path("README.md"));
  size_t launch_lines = 0;
  bool in_block = false;
  for (const std::string& line : lines_of(readme)) {
    if (line.rfind("```", 0) == 0) in_block = !in_block;
    if (in_block && line.rfind("gst-launch-1.0", 0) == 0) ++launch_lines;
  }
  EXPECT_EQ(readme_commands("### Into files").size() + readme_commands("### Over RTP").size() +
                readme_align_commands().size(),
            launch_lines);
}

// README.md's pfapalign lines are docs/elements.md's, which test_pfapalign and
// test_pfapalign_live run.
TEST(Readme, AlignCommandsAreTheDocumentedOnes) {
  std::vector<std::string> readme = readme_align_commands();
  std::erase_if(readme, [](const std::string& c) { return c.find(" pfapalign ") == c.npos; });
  ASSERT_EQ(readme.size(), 2u);
  const std::vector<std::string> documented = doc_section("docs/elements.md", "## pfapalign");
  for (const std::string& command : readme) {
    EXPECT_NE(std::find(documented.begin(), documented.end(), command), documented.end())
        << command;
  }
}

// The README's commands grouped by the heading they are under, in order.
std::vector<std::vector<std::string>> readme_command_groups() {
  std::vector<std::vector<std::string>> groups;
  std::vector<std::string> lines;
  bool in_block = false;
  for (const std::string& line : lines_of(read_file(source_path("README.md")))) {
    if (line.starts_with("```")) in_block = !in_block;
    if (!in_block && pfap::testing::heading_level(line) > 0) {
      groups.push_back(commands_in(lines));
      lines.clear();
    }
    lines.push_back(line);
  }
  groups.push_back(commands_in(lines));
  return groups;
}

// Every file a README command reads (filesrc) is in the checkout or written (filesink) by a
// command before it under the same heading: the pfapalign line read a speech.wav that nothing
// in its section made, and the one "Into files" makes says something else.
TEST(Readme, EveryFileACommandReadsIsThere) {
  const std::regex reads("filesrc location=(\\S+)"), writes("filesink location=(\\S+)");
  size_t checked = 0;
  for (const std::vector<std::string>& group : readme_command_groups()) {
    std::vector<std::string> written;
    for (const std::string& command : group) {
      for (std::sregex_iterator m(command.begin(), command.end(), reads), end; m != end; ++m) {
        const std::string file = (*m)[1];
        ++checked;
        EXPECT_TRUE(g_file_test(source_path(file).c_str(), G_FILE_TEST_IS_REGULAR) ||
                    std::find(written.begin(), written.end(), file) != written.end())
            << file << ", read by: " << command;
      }
      for (std::sregex_iterator m(command.begin(), command.end(), writes), end; m != end; ++m) {
        written.push_back((*m)[1]);
      }
    }
  }
  EXPECT_GE(checked, 1u);
}

// The "A recording" block as written: the stand-in recording, then its phonemes.
TEST(Readme, RecordingBlockRuns) {
  ASSERT_TRUE(plugin_available(kElements));
  const std::vector<std::string> commands =
      documented_commands("README.md", "## PFAP from any speech", "### A recording");
  ASSERT_EQ(commands.size(), 2u);
  TempDir dir;
  Substitution substitute(dir);
  for (const std::string& command : commands) {
    Pipeline p(substitute.launch(command));
    ASSERT_TRUE(p.error().empty()) << p.error();
    ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
    ASSERT_EQ(p.wait_eos(60s), "") << command;
  }
  EXPECT_GT(pfap_lines(read_file(dir.file("speech.pfap"))).size(), 40u);
}

// The Install section names the Debian package of each GStreamer tool the README's commands
// run (gst-inspect-1.0 and the rest are in gstreamer1.0-tools, which a fresh Debian lacks).
TEST(Readme, InstallNamesThePackageOfEachToolItRuns) {
  const std::string install = [] {
    std::string text;
    for (const std::string& line : doc_section("README.md", "## Install")) text += line + "\n";
    return text;
  }();
  ASSERT_FALSE(install.empty());
  std::vector<std::string> programs;
  for (const std::vector<std::string>& group : readme_command_groups()) {
    for (const std::string& command : group) {
      const std::string program = command.substr(0, command.find(' '));
      if (program.starts_with("gst-") &&
          std::find(programs.begin(), programs.end(), program) == programs.end()) {
        programs.push_back(program);
      }
    }
  }
  ASSERT_GE(programs.size(), 3u) << "gst-launch-1.0, gst-inspect-1.0, gst-play-1.0";
  gchar* found = g_find_program_in_path("dpkg");
  const std::string dpkg = found != nullptr ? found : "";
  g_free(found);
  if (dpkg.empty()) GTEST_SKIP() << "no dpkg to ask which package holds each program";
  for (const std::string& program : programs) {
    gchar* path = g_find_program_in_path(program.c_str());
    if (path == nullptr) {
      ADD_FAILURE() << program << " is not installed: scripts/install-deps installs it";
      continue;
    }
    const ProcessResult owner = run({dpkg, "-S", path});
    g_free(path);
    ASSERT_EQ(owner.status, 0) << "dpkg -S: " << owner.err;
    const std::string package = owner.out.substr(0, owner.out.find(':'));
    EXPECT_NE(install.find("`" + package + "`"), std::string::npos)
        << program << " is in " << package << ", which README.md's Install section never names";
  }
}

// Each GST_PLUGIN_PATH the README and docs tell users to set for a build tree still finds the
// plugins from another directory (a user's next `cd`), as a shell would set it in the
// checkout: $PWD is the checkout, and its build/ this build tree.
TEST(Readme, BuildTreePluginPathsHoldAfterCd) {
  const std::string build_root = PFAP_BUILD_DIR;
  std::vector<std::string> texts;
  for (const char* file : {"README.md", "docs/apps.md", "docs/install.md"}) {
    texts.push_back(read_file(source_path(file)));
  }
  std::string playing;
  for (const std::string& line : doc_section("docs/elements.md", "## Playing a stream")) {
    playing += line + "\n";
  }
  texts.push_back(playing);
  const std::regex setting("GST_PLUGIN_PATH=([^\\s`]*build/[^\\s`]*)");
  std::vector<std::string> values;
  for (const std::string& text : texts) {
    for (std::sregex_iterator m(text.begin(), text.end(), setting), end; m != end; ++m) {
      if (std::find(values.begin(), values.end(), (*m)[1]) == values.end()) {
        values.push_back((*m)[1]);
      }
    }
  }
  // Each value starts from a copy of the tests' registry: a registry drops what the path no
  // longer finds, and a copy saves scanning every system plugin again (slow under ASan).
  const char* registry = g_getenv("GST_REGISTRY_1_0");
  const std::string cached = registry != nullptr ? read_file(registry) : "";
  TempDir elsewhere;
  size_t checked = 0;
  for (std::string value : values) {
    SCOPED_TRACE("GST_PLUGIN_PATH=" + value);
    std::ofstream(elsewhere.file("registry.bin"), std::ios::binary) << cached;
    replace_all(value, "$PWD/build/", build_root + "/");
    gchar** envp = g_get_environ();
    envp = g_environ_setenv(envp, "GST_PLUGIN_PATH", value.c_str(), TRUE);
    envp = g_environ_setenv(envp, "GST_REGISTRY_1_0", elsewhere.file("registry.bin").c_str(), TRUE);
    std::vector<std::string> elements = {"rtppfappay"};
    constexpr const char* kFace[] = {"pfapface"};
    if (value.find("/ext") != std::string::npos && plugin_available(kFace)) {
      elements.push_back("pfapface");
    }
    for (std::string& element : elements) {
      gchar* argv[] = {const_cast<gchar*>("gst-inspect-1.0"), element.data(), nullptr};
      gint status = -1;
      GError* error = nullptr;
      const gboolean ran =
          g_spawn_sync(elsewhere.path().c_str(), argv, envp,
                       static_cast<GSpawnFlags>(G_SPAWN_SEARCH_PATH | G_SPAWN_STDOUT_TO_DEV_NULL |
                                                G_SPAWN_STDERR_TO_DEV_NULL),
                       nullptr, nullptr, nullptr, nullptr, &status, &error);
      if (!ran) {
        ADD_FAILURE() << "cannot run gst-inspect-1.0: " << error->message;
        g_error_free(error);
        continue;
      }
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
          << "gst-inspect-1.0 " << element << " finds nothing from " << elsewhere.path();
      ++checked;
    }
    g_remove(elsewhere.file("registry.bin").c_str());
    g_strfreev(envp);
  }
  EXPECT_FALSE(values.empty());
  EXPECT_GE(checked, values.size());
}

// docs/install.md's account of the packages matches debian/: as many .deb files as stanzas in
// debian/control, and no lintian warning for manual pages that pfap-tools installs.
TEST(InstallMd, MatchesThePackaging) {
  const std::string install = read_file(source_path("docs/install.md"));
  const std::string control = read_file(source_path("debian/control"));
  size_t packages = 0;
  for (const std::string& line : lines_of(control)) packages += line.starts_with("Package: ");
  const std::vector<std::string> numbers = {"zero", "one",   "two",   "three", "four", "five",
                                            "six",  "seven", "eight", "nine",  "ten"};
  ASSERT_LT(packages, numbers.size());
  std::smatch said;
  ASSERT_TRUE(std::regex_search(install, said, std::regex("all (\\w+) `\\.deb` files")));
  EXPECT_EQ(said[1].str(), numbers[packages]) << packages << " packages in debian/control";
  if (read_file(source_path("debian/pfap-tools.install")).find("/man1/") != std::string::npos) {
    EXPECT_EQ(install.find("`no-manual-page` for"), std::string::npos)
        << "the tools' manual pages are installed";
  }
}

// Speech into a WAV file and its phonemes into a .pfap file: the phonemes cover the audio.
TEST(Readme, SpeaksIntoFiles) {
  ASSERT_TRUE(plugin_available(kElements));
  const std::vector<std::string> commands = readme_commands("### Into files");
  ASSERT_EQ(commands.size(), 1u);
  TempDir dir;
  Substitution substitute(dir);
  Pipeline p(substitute.launch(commands[0]));
  ASSERT_TRUE(p.error().empty()) << p.error();
  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(p.wait_eos(10s), "");
  const std::string wav = read_file(dir.file("speech.wav"));
  ASSERT_EQ(wav.rfind("RIFF", 0), 0u);
  const double audio_ms = (static_cast<double>(wav.size()) - 44) / 2 / 22050 * 1000;
  const std::vector<PfapLine> lines = pfap_lines(read_file(dir.file("speech.pfap")));
  ASSERT_GT(lines.size(), 10u);
  int faps = 0;
  long end = 0;
  for (const PfapLine& l : lines) {
    EXPECT_EQ(l.start_ms, end) << "phonemes follow each other";
    end = l.start_ms + l.duration_ms;
    faps += l.faps;
  }
  EXPECT_NEAR(static_cast<double>(end), audio_ms, 20.0);
  EXPECT_EQ(faps, 1);
}

// The same speech served over RTP, and a receiver writing both streams to files.
TEST(Readme, ServesOverRtp) {
  ASSERT_TRUE(plugin_available(kElements));
  const std::vector<std::string> commands = readme_commands("### Over RTP");
  ASSERT_EQ(commands.size(), 2u);
  TempDir dir;
  Substitution substitute(dir);
  Pipeline receiver(substitute.launch(commands[0]));
  Pipeline sender(substitute.launch(commands[1]));
  ASSERT_TRUE(receiver.error().empty()) << receiver.error();
  ASSERT_TRUE(sender.error().empty()) << sender.error();
  Tap sent, text;
  sent.attach(sender.find("pfaptts"), "pfap");
  text.attach(receiver.find("pfaptextenc"));
  // The end of the speech is EOS out of pfaptts; that the sender then ends by itself is
  // Readme.ServerLineEndsByItselfEveryTime's to check.
  std::atomic<bool> spoken{false};
  GstPad* pfap_pad = gst_element_get_static_pad(sender.find("pfaptts"), "pfap");
  gst_pad_add_probe(
      pfap_pad, GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM,
      [](GstPad*, GstPadProbeInfo* info, gpointer data) {
        if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) == GST_EVENT_EOS) {
          static_cast<std::atomic<bool>*>(data)->store(true);
        }
        return GST_PAD_PROBE_OK;
      },
      &spoken, nullptr);
  gst_object_unref(pfap_pad);
  ASSERT_EQ(receiver.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(sender.set_state(GST_STATE_PLAYING), "");
  ASSERT_TRUE(wait_until(
      {&receiver, &sender}, [&] { return spoken && text.lines() >= sent.count(); }, 20s,
      "all of the speech"))
      << text.lines() << " of " << sent.count();
  ASSERT_EQ(receiver.end(5s), "");
  gst_element_set_state(sender.get(), GST_STATE_NULL);

  const std::vector<PfapLine> lines = pfap_lines(read_file(dir.file("received.pfap")));
  EXPECT_EQ(lines.size(), sent.count());
  int faps = 0;
  for (const PfapLine& l : lines) faps += l.faps;
  EXPECT_EQ(faps, 1);
  const std::string wav = read_file(dir.file("received.wav"));
  EXPECT_EQ(wav.rfind("RIFF", 0), 0u);
  EXPECT_GT(wav.size(), 44u + 22050u * 2 / 2) << "at least 0.5 s of speech";
}

// The README's server line ends by itself, every time: 20 runs in a row, each within 10 s (a
// short text keeps each run under a second of speech). Before its receive-side branches, 1.22's
// rtpsession race kept it from ending in about half the runs (README.md, "Over RTP").
TEST(Readme, ServerLineEndsByItselfEveryTime) {
  ASSERT_TRUE(plugin_available(kElements));
  const std::vector<std::string> commands = readme_commands("### Over RTP");
  ASSERT_EQ(commands.size(), 2u);
  std::string server = commands[1];
  const std::regex text("text=\"[^\"]*\"");
  ASSERT_TRUE(std::regex_search(server, text)) << server;
  server = std::regex_replace(server, text, "text=\"Hello.\"");
  TempDir dir;
  Substitution substitute(dir);
  const std::string launch = substitute.launch(server);
  for (int run = 1; run <= 20; ++run) {
    Pipeline sender(launch);
    ASSERT_TRUE(sender.error().empty()) << sender.error();
    ASSERT_EQ(sender.set_state(GST_STATE_PLAYING), "");
    ASSERT_EQ(sender.wait_eos(10s), "") << "run " << run << " of 20 did not end by itself";
  }
}

// ---------------------------------------------------------------------------------------------
// The main job (scripts/demo): pfap-story speaks, sends with loss, recovers, renders and muxes.

// The number after `label` in `text`, or -1.
long long number_after(const std::string& text, const std::string& label) {
  const size_t at = text.find(label);
  return at == std::string::npos ? -1 : std::atoll(text.c_str() + at + label.size());
}

TEST(Story, SpeaksSendsWithLossRendersAndMuxes) {
  ASSERT_TRUE(plugin_available(kElements));
  TempDir dir;
  const ProcessResult r = run(
      {PFAP_STORY, "--text=Hello <FAP 2 1 40 0 0 500 1> world. How are you today?", "--drop=0.4",
       "--size=160x120", "--out=" + dir.file("story.webm"), "--frames=" + dir.path()});
  ASSERT_EQ(r.status, 0) << r.err;
  const long long sent = number_after(r.out, "PFAP packets sent: ");
  const long long dropped = number_after(r.out, "dropped on the way: ");
  const long long arrived = number_after(r.out, "receiver: ");
  const long long lost = number_after(r.out, "phonemes, ");  // packets found lost
  const long long frames = number_after(r.out, "story.webm: ");
  ASSERT_GT(sent, 5) << r.out;
  ASSERT_GE(arrived, 0) << r.out;
  ASSERT_GE(lost, 0) << r.out;
  // netsim drops (at 40 %, all of 15 packets pass once in 2000 runs), and rtpbin may keep
  // back more: a new source is on probation until two packets follow each other, and heavy
  // loss can keep it there. The depayloader counts by sequence number what did not reach it:
  // all of that but the packets before the first and after the last to arrive.
  EXPECT_GT(dropped, 0) << r.out;
  EXPECT_LE(arrived, sent - dropped) << r.out;
  EXPECT_LE(lost, sent - arrived) << r.out;

  // About 2.5 s of speech at 25 fps, each frame also written as a PNG file.
  EXPECT_GE(frames, 50) << r.out;
  int pngs = 0;
  for (int i = 0; i < frames + 5; ++i) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d.png", i);
    if (g_file_test(dir.file(name).c_str(), G_FILE_TEST_EXISTS)) ++pngs;
  }
  EXPECT_EQ(pngs, frames);

  // The file holds both: the video frames and the speech, decoded back.
  Pipeline check("filesrc location=\"" + dir.file("story.webm") +
                 "\" ! matroskademux name=d "
                 "d.video_0 ! queue ! vp8dec ! fakesink name=video "
                 "d.audio_0 ! queue ! vorbisdec ! fakesink name=audio");
  ASSERT_TRUE(check.ok()) << check.error();
  Tap video, audio;
  video.attach(check.by_name("video"), "sink");
  audio.attach(check.by_name("audio"), "sink");
  ASSERT_EQ(check.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(check.wait_eos(10s), "");
  EXPECT_EQ(static_cast<long long>(video.count()), frames);
  EXPECT_GT(audio.count(), 10u);
}


// ---------------------------------------------------------------------------------------------
// PlayStream: generic players on the RTSP example and on a .pfap file (docs/elements.md,
// "Playing a stream"), with no pipeline written by hand.

namespace play {

using pfap::testing::Event;

// playbin with fake sinks that sync, as a player's: the elements it plugs are reported as they
// come (deep-element-added), so that probes can be set on them before data flows.
class Player {
 public:
  explicit Player(const std::string& uri) : pipeline_("playbin uri=" + uri) {
    if (!pipeline_.ok()) return;
    GstElement* video = gst_element_factory_make("fakesink", "video");
    GstElement* audio = gst_element_factory_make("fakesink", "audio");
    g_object_set(video, "sync", TRUE, nullptr);
    g_object_set(audio, "sync", TRUE, nullptr);
    g_object_set(pipeline_.get(), "video-sink", video, "audio-sink", audio, nullptr);
    g_signal_connect(pipeline_.get(), "source-setup", G_CALLBACK(on_source_setup), nullptr);
    g_signal_connect(pipeline_.get(), "deep-element-added", G_CALLBACK(on_element_added), this);
  }
  Pipeline& pipeline() { return pipeline_; }

  // The factory names of the elements playbin plugged so far.
  std::vector<std::string> plugged() {
    std::lock_guard lock(mutex_);
    return plugged_;
  }
  bool has(const std::string& factory) {
    const std::vector<std::string> p = plugged();
    return std::find(p.begin(), p.end(), factory) != p.end();
  }
  // Called with each element as it is added, on the adding thread.
  std::function<void(GstElement*, const std::string&)> on_added;

 private:
  // rtspsrc's default 2 s of jitterbuffer latency would only make the test longer. Its
  // default buffer-mode, slave, times packets by their arrival, which a loaded machine
  // delays by tens of ms; synced times them by their RTP timestamps from the first packet
  // on, so what is measured is what the server sent (docs/elements.md, "Playing a stream").
  static void on_source_setup(GstElement*, GstElement* source, gpointer) {
    if (g_object_class_find_property(G_OBJECT_GET_CLASS(source), "latency") != nullptr) {
      g_object_set(source, "latency", 200u, nullptr);
      gst_util_set_object_arg(G_OBJECT(source), "buffer-mode", "synced");
    }
  }
  static void on_element_added(GstBin*, GstBin*, GstElement* element, gpointer data) {
    auto* self = static_cast<Player*>(data);
    GstElementFactory* factory = gst_element_get_factory(element);
    if (factory == nullptr) return;
    const std::string name = GST_OBJECT_NAME(factory);
    {
      std::lock_guard lock(self->mutex_);
      self->plugged_.push_back(name);
    }
    if (self->on_added) self->on_added(element, name);
  }

  Pipeline pipeline_;
  std::mutex mutex_;
  std::vector<std::string> plugged_;
};

// What pfapface takes in and puts out, in the order it happened: each phoneme with its running
// time, each frame with its own. A frame shows the phonemes pfapface had before drawing it
// whose time span holds the frame's running time.
struct FaceLog {
  struct Phoneme {
    uint64_t order;
    GstClockTime running_time, duration;
  };
  struct Frame {
    uint64_t order;
    GstClockTime running_time;
  };
  std::mutex mutex;
  uint64_t next = 0;
  std::vector<Phoneme> phonemes;
  std::vector<Frame> frames;

  void attach(GstElement* face) {
    GstPad* sink = gst_element_get_static_pad(face, "sink");
    gst_pad_add_probe(sink, GST_PAD_PROBE_TYPE_BUFFER, on_phoneme, this, nullptr);
    gst_object_unref(sink);
    GstPad* src = gst_element_get_static_pad(face, "src");
    gst_pad_add_probe(src, GST_PAD_PROBE_TYPE_BUFFER, on_frame, this, nullptr);
    gst_object_unref(src);
  }
  static GstPadProbeReturn on_phoneme(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
    auto* log = static_cast<FaceLog*>(data);
    GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
    if (gst_buffer_get_size(buffer) == 0) return GST_PAD_PROBE_OK;  // a GAP
    const Event e = pfap::testing::read_event(buffer);
    if (e.kind != PFAP_EVENT_PHONEME) return GST_PAD_PROBE_OK;
    std::lock_guard lock(log->mutex);
    log->phonemes.push_back({log->next++, running_time_of(pad, buffer), e.duration});
    return GST_PAD_PROBE_OK;
  }
  static GstPadProbeReturn on_frame(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
    auto* log = static_cast<FaceLog*>(data);
    GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
    std::lock_guard lock(log->mutex);
    log->frames.push_back({log->next++, running_time_of(pad, buffer)});
    return GST_PAD_PROBE_OK;
  }
  // The running time of the first frame that shows phoneme `p`, or NONE.
  GstClockTime first_frame_showing(const Phoneme& p) {
    for (const Frame& f : frames) {
      if (f.order > p.order && f.running_time >= p.running_time &&
          f.running_time < p.running_time + p.duration) {
        return f.running_time;
      }
    }
    return GST_CLOCK_TIME_NONE;
  }
};

// The example server's audio: audiotestsrc ticks, its first sample at sender running time 0.
// Each tick's first sample, found after depayloading, gives the receiver's running time of a
// known sender time (sent_tick_times).
constexpr const char* kServerAudio = "audiotestsrc wave=ticks tick-interval=500000000";
constexpr int kAudioRate = 44100;

struct TickLog {
  std::mutex mutex;
  GstClockTime first_buffer = GST_CLOCK_TIME_NONE;  // running time of the first audio
  std::vector<GstClockTime> onsets;                 // running times of tick starts
  size_t silent_run = kAudioRate;                   // zero samples seen in a row

  void attach(GstElement* depay) {
    GstPad* src = gst_element_get_static_pad(depay, "src");
    gst_pad_add_probe(src, GST_PAD_PROBE_TYPE_BUFFER, on_audio, this, nullptr);
    gst_object_unref(src);
  }
  // S16BE mono from rtpL16depay.
  static GstPadProbeReturn on_audio(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
    auto* log = static_cast<TickLog*>(data);
    GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
    const GstClockTime start = running_time_of(pad, buffer);
    if (!GST_CLOCK_TIME_IS_VALID(start)) return GST_PAD_PROBE_OK;
    GstMapInfo map;
    if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) return GST_PAD_PROBE_OK;
    std::lock_guard lock(log->mutex);
    if (!GST_CLOCK_TIME_IS_VALID(log->first_buffer)) log->first_buffer = start;
    for (size_t i = 0; i + 1 < map.size; i += 2) {
      const auto sample = static_cast<int16_t>((map.data[i] << 8) | map.data[i + 1]);
      if (sample == 0) {
        ++log->silent_run;
        continue;
      }
      // A tick's sine starts at 0: its first non-zero sample is its second. A tick is
      // 10 periods of 440 Hz, about 23 ms; a run of 10 ms of silence comes before each.
      if (log->silent_run >= kAudioRate / 100) {
        const size_t first = i / 2 == 0 ? 0 : i / 2 - 1;
        log->onsets.push_back(start + gst_util_uint64_scale(first, GST_SECOND, kAudioRate));
      }
      log->silent_run = 0;
    }
    gst_buffer_unmap(buffer, &map);
    return GST_PAD_PROBE_OK;
  }
};

// Where the server's audio has its ticks, in sender time: audiotestsrc with the server's
// settings, run here, not live. It puts them one buffer (1024 samples, 23.2 ms) before each
// interval's end and none at 0: 476.8, 976.8 ... ms. (Taking them to be at 500, 1000 ... ms
// put every phoneme 23 ms behind its sound in this test, on a machine that kept them in step.)
std::vector<GstClockTime> sent_tick_times(GstClockTime until) {
  Pipeline source(std::string(kServerAudio) + " ! audio/x-raw,format=S16BE,rate=" +
                  std::to_string(kAudioRate) + ",channels=1 ! identity ! fakesink");
  TickLog log;
  log.attach(source.find("identity"));
  g_object_set(source.find("audiotestsrc"), "num-buffers",
               static_cast<int>(gst_util_uint64_scale(until, kAudioRate, GST_SECOND * 1024)) + 1,
               nullptr);
  if (!source.set_state(GST_STATE_PLAYING).empty() || !source.wait_eos(10s).empty()) return {};
  std::lock_guard lock(log.mutex);
  return log.onsets;
}

// The start times (ms) of the phoneme lines of a .pfap text, in order.
std::vector<int64_t> phoneme_starts(const std::string& text) {
  std::vector<int64_t> out;
  for (const std::string& line : lines_of(event_lines(text))) {
    long start = 0;
    char second[32] = {};
    if (std::sscanf(line.c_str(), "%ld %31s", &start, second) == 2 &&
        std::string(second) != "state") {
      out.push_back(start);
    }
  }
  return out;
}

}  // namespace play

// playbin on the RTSP example plugs rtppfapdepay and pfapface by itself, plays the audio and
// shows the face, ends when the presentation ends, and keeps face and audio within one video
// frame (40 ms at the 25 fps pfapface picks): for every phoneme, the first frame that shows it
// against the receiver's running time of the audio at that phoneme's start.
TEST(PlayStream, PlaybinShowsTheTalkingHeadInSyncWithTheAudio) {
  ASSERT_TRUE(plugin_available(kElements));
  const std::string file = source_path("docs/examples/hello.pfap");
  const std::vector<int64_t> starts = play::phoneme_starts(read_file(file));
  ASSERT_GE(starts.size(), 10u);
  RtspServer server(file);
  ASSERT_EQ(server.url().rfind("rtsp://127.0.0.1:", 0), 0u) << "URL: " << server.url();

  play::Player player(server.url());
  ASSERT_TRUE(player.pipeline().ok()) << player.pipeline().error();
  play::FaceLog face;
  play::TickLog ticks;
  player.on_added = [&](GstElement* element, const std::string& factory) {
    if (factory == "pfapface") face.attach(element);
    if (factory == "rtpL16depay") ticks.attach(element);
  };
  ASSERT_EQ(player.pipeline().set_state(GST_STATE_PLAYING), "");
  // hello.pfap lasts 1.73 s; the stream ends with it (both sessions send BYE).
  ASSERT_EQ(player.pipeline().wait_eos(15s), "");
  player.pipeline().set_state(GST_STATE_NULL);
  EXPECT_EQ(server.stop(), 0);

  EXPECT_TRUE(player.has("rtppfapdepay"));
  EXPECT_TRUE(player.has("pfapface"));
  EXPECT_TRUE(player.has("rtpL16depay"));

  // The audio's offset, receiver running time minus sender time, at every tick: the first
  // audio is the stream's start (sender time 0, give or take a lost packet), which finds each
  // tick among the sent ones. rtpbin moves the streams by a few ms when the first RTCP
  // reports come.
  const std::vector<GstClockTime> sent_ticks = play::sent_tick_times(2 * GST_SECOND);
  ASSERT_GE(sent_ticks.size(), 3u);
  std::vector<std::pair<int64_t, int64_t>> audio_offsets;  // (sender time, offset)
  for (GstClockTime onset : ticks.onsets) {
    const auto since_start = static_cast<int64_t>(onset - ticks.first_buffer);
    const auto nearest =
        std::min_element(sent_ticks.begin(), sent_ticks.end(), [&](GstClockTime a, GstClockTime b) {
          return std::abs(static_cast<int64_t>(a) - since_start) <
                 std::abs(static_cast<int64_t>(b) - since_start);
        });
    const auto sent = static_cast<int64_t>(*nearest);
    audio_offsets.emplace_back(sent, static_cast<int64_t>(onset) - sent);
  }
  ASSERT_GE(audio_offsets.size(), 3u) << "ticks at 0.48, 0.98 and 1.48 s";
  // The offset of the audio at sender time `sent`: that of the last tick before it.
  auto audio_offset_at = [&](int64_t sent) {
    int64_t offset = audio_offsets.front().second;
    for (const auto& [tick, o] : audio_offsets) {
      if (tick <= sent) offset = o;
    }
    return offset;
  };

  ASSERT_EQ(face.phonemes.size(), starts.size()) << "every phoneme reached pfapface";
  ASSERT_GE(face.frames.size(), 40u) << "1.73 s at 25 fps";
  constexpr int64_t kFrame = 40 * static_cast<int64_t>(GST_MSECOND);
  int64_t worst_offset = 0, worst_shown = 0;
  for (size_t i = 0; i < starts.size(); ++i) {
    const play::FaceLog::Phoneme& p = face.phonemes[i];
    const int64_t sent = starts[i] * static_cast<int64_t>(GST_MSECOND);
    const int64_t heard = sent + audio_offset_at(sent);
    // Lip sync: the face has the phoneme at the running time the audio has its start.
    const int64_t offset = static_cast<int64_t>(p.running_time) - heard;
    EXPECT_LT(std::abs(offset), kFrame)
        << "phoneme " << i << " (" << starts[i] << " ms) reaches the face " << offset / 1000000
        << " ms after its sound";
    // Rendering: the first frame at or after that time shows it (it came in time to be drawn).
    const GstClockTime shown = face.first_frame_showing(p);
    ASSERT_TRUE(GST_CLOCK_TIME_IS_VALID(shown)) << "no frame shows phoneme " << i;
    EXPECT_LT(static_cast<int64_t>(shown - p.running_time), kFrame)
        << "phoneme " << i << " is drawn late";
    worst_offset = std::max(worst_offset, std::abs(offset));
    worst_shown = std::max(worst_shown, static_cast<int64_t>(shown) - heard);
  }
  std::printf("playbin: face against audio within %.1f ms; first frame showing a phoneme at most "
              "%.1f ms after its sound (%zu phonemes)\n",
              static_cast<double>(worst_offset) / 1e6, static_cast<double>(worst_shown) / 1e6,
              starts.size());
}

// gst-play-1.0 file.pfap: the typefinder names the file text/x-pfap, decodebin plugs pfaptextparse
// and pfapface, and the face plays to the end of the session.
TEST(PlayStream, PlaybinShowsAPfapFile) {
  ASSERT_TRUE(plugin_available(kElements));
  gchar* uri = gst_filename_to_uri(source_path("docs/examples/hello.pfap").c_str(), nullptr);
  play::Player player(uri);
  g_free(uri);
  play::FaceLog face;
  player.on_added = [&](GstElement* element, const std::string& factory) {
    if (factory == "pfapface") face.attach(element);
  };
  ASSERT_EQ(player.pipeline().set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(player.pipeline().wait_eos(15s), "");
  player.pipeline().set_state(GST_STATE_NULL);
  EXPECT_TRUE(player.has("pfaptextparse"));
  EXPECT_TRUE(player.has("pfapface"));
  // The last phoneme ends at 1.73 s, its expression's transition at 2.33 s: 59 frames at 25 fps.
  EXPECT_EQ(face.frames.size(), 59u);
}

// Where it should not win: a text file that is not .pfap is not given to pfaptextparse.
TEST(PlayStream, OtherTextIsNotTakenForPfap) {
  ASSERT_TRUE(plugin_available(kElements));
  gchar* uri = gst_filename_to_uri(source_path("README.md").c_str(), nullptr);
  play::Player player(uri);
  g_free(uri);
  ASSERT_EQ(player.pipeline().set_state(GST_STATE_PAUSED), "");
  player.pipeline().wait_eos(5s);  // an error: nothing plays text/plain to a video sink
  player.pipeline().set_state(GST_STATE_NULL);
  EXPECT_TRUE(player.has("typefind"));
  EXPECT_FALSE(player.has("pfaptextparse"));
  EXPECT_FALSE(player.has("pfapface"));
}

// Runs a program to its end, at most `timeout`: its exit status, or -1 when it had to be
// killed (or did not exit normally).
int run_bounded(std::vector<std::string> args, std::chrono::seconds timeout) {
  std::vector<gchar*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  GPid pid = 0;
  GError* error = nullptr;
  if (!g_spawn_async(nullptr, argv.data(), nullptr,
                     static_cast<GSpawnFlags>(G_SPAWN_DO_NOT_REAP_CHILD | G_SPAWN_SEARCH_PATH |
                                              G_SPAWN_STDOUT_TO_DEV_NULL),
                     nullptr, nullptr, &pid, &error)) {
    ADD_FAILURE() << "cannot run " << args[0] << ": " << error->message;
    g_error_free(error);
    return -1;
  }
  const auto deadline = Clock::now() + timeout;
  int status = 0;
  pid_t done = 0;
  while ((done = waitpid(pid, &status, WNOHANG)) == 0 && Clock::now() < deadline) {
    std::this_thread::sleep_for(20ms);
  }
  if (done == 0) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }
  g_spawn_close_pid(pid);
  return done != 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool installed(const char* program) {
  gchar* path = g_find_program_in_path(program);
  g_free(path);
  return path != nullptr;
}

// ffmpeg -t 3 against the example: a client that reads for a fixed time ends, because both
// streams end together (before, the PFAP stream ended alone and ffmpeg waited on).
TEST(PlayStream, FfmpegReadingForAFixedTimeEnds) {
  ASSERT_TRUE(installed("ffmpeg")) << "no ffmpeg: scripts/install-deps installs it";
  RtspServer server(source_path("docs/examples/hello.pfap"));
  ASSERT_EQ(server.url().rfind("rtsp://127.0.0.1:", 0), 0u) << "URL: " << server.url();
  EXPECT_EQ(run_bounded({"ffmpeg", "-nostdin", "-loglevel", "error", "-t", "3", "-i",
                         server.url(), "-map", "0", "-c", "copy", "-f", "null", "-"},
                        15s),
            0)
      << "ffmpeg -t 3 ends by itself with status 0";
  EXPECT_EQ(server.stop(), 0);
}

// The "play a stream" commands of README.md and docs/elements.md, with fake sinks: the server
// is started, and each player plays to its end and exits.
TEST(PlayStream, DocumentedCommandsPlayToTheirEnd) {
  ASSERT_TRUE(installed("gst-play-1.0")) << "no gst-play-1.0: scripts/install-deps installs it";
  const std::vector<std::pair<std::string, std::string>> sections = {
      {"README.md", "## Play a stream"}, {"docs/elements.md", "## Playing a stream"}};
  for (const auto& [file, section] : sections) {
    SCOPED_TRACE(file + ", " + section);
    const std::vector<std::string> commands = commands_in(doc_section(file, section));
    ASSERT_GE(commands.size(), 3u);
    std::unique_ptr<RtspServer> server;
    int players = 0;
    for (const std::string& command : commands) {
      SCOPED_TRACE(command);
      std::vector<std::string> words;
      gchar** argv = g_strsplit(command.c_str(), " ", -1);
      for (gchar** w = argv; *w != nullptr; ++w) {
        if (**w != '\0') words.emplace_back(*w);
      }
      g_strfreev(argv);
      if (words[0] == "export") continue;  // GST_PLUGIN_PATH: meson sets it
      if (words[0] == "build/examples/pfap-rtsp-server") {
        ASSERT_EQ(words.size(), 3u);
        server = std::make_unique<RtspServer>(source_path(words[1]));
        ASSERT_EQ(server->url().rfind("rtsp://127.0.0.1:", 0), 0u);
        continue;
      }
      ASSERT_NE(server, nullptr) << "the server comes first";
      ++players;
      auto local = [&](std::string s) {
        for (const char* from : {"rtsp://127.0.0.1:8554/pfap"}) {
          for (size_t at = s.find(from); at != std::string::npos; at = s.find(from)) {
            s.replace(at, std::string(from).size(), server->url());
          }
        }
        if (s.rfind("docs/", 0) == 0) s = source_path(s);
        return s;
      };
      if (words[0] == "gst-play-1.0") {
        ASSERT_EQ(words.size(), 2u);
        EXPECT_EQ(run_bounded({"gst-play-1.0", "--no-interactive",
                               "--videosink=fakesink sync=true", "--audiosink=fakesink sync=true",
                               local(words[1])},
                              15s),
                  0);
      } else {
        ASSERT_EQ(words[0], "gst-launch-1.0");
        std::string launch = local(command.substr(std::string("gst-launch-1.0 ").size()));
        for (const char* sink : {"autovideosink", "autoaudiosink"}) {
          for (size_t at = launch.find(sink); at != std::string::npos; at = launch.find(sink)) {
            launch.replace(at, std::string(sink).size(), "fakesink sync=true");
          }
        }
        Pipeline player(launch);
        ASSERT_TRUE(player.error().empty()) << player.error();
        ASSERT_EQ(player.set_state(GST_STATE_PLAYING), "");
        EXPECT_EQ(player.wait_eos(15s), "");
      }
    }
    EXPECT_GE(players, 2);
    if (server != nullptr) {
      EXPECT_EQ(server->stop(), 0);
    }
  }
}

}  // namespace

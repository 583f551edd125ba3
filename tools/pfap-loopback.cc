// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap-loopback: sends a .pfap text file as PFAP RTP packets over loopback UDP and prints, as
// .pfap text, what arrives. Sender and receiver run in this one process:
//
//   sender:   filesrc location=FILE ! pfaptextparse ! rtppfappay ! udpsink host=127.0.0.1 port=P
//   receiver: udpsrc address=127.0.0.1 port=P do-timestamp=false caps=application/x-rtp,...
//             ! rtpjitterbuffer mode=none max-dropout-time=0 max-misorder-time=0
//             ! rtppfapdepay ! pfaptextenc ! fdsink fd=1
//
// The receiver binds port 0 (the system picks a free port) and the sender is started on the
// port it got. Standard output gets the received session in canonical form, with times
// relative to the first event; for a file in canonical form whose first event is at 0 and
// without state lines (rtppfappay does not send those) it is the file, byte for byte
// (docs/examples/README.md). A summary goes to standard error.
//
// Timing. The sender does not wait for the clock (udpsink sync=false): the whole session
// goes out at once and the demo takes a fraction of a second. The times still come back
// exactly, because the receiver takes them from the RTP timestamps alone:
//  - rtpjitterbuffer mode=none makes each packet's PTS the first packet's plus the RTP
//    timestamp difference (no estimate of the sender's clock from arrival times, which
//    mean nothing when the sender does not pace itself); the 44.1 kHz RTP clock puts every
//    phoneme within 23 us of its ms, and pfaptextenc rounds to the nearest ms;
//  - udpsrc do-timestamp=false: in mode none, rtpjitterbuffer starts its timeline again
//    (PTS back to 0) when two consecutive packets are more than 3 s apart in RTP time and
//    the packet has a capture time. A pause over 3 s or a phoneme over 3 s long would trigger
//    it. Without capture times from udpsrc the jitterbuffer uses estimated times, and skips
//    that reset.
//
// Ending. Every packet udpsink sends and every datagram udpsrc reads is counted by pad
// probes. Once the sender's EOS has reached udpsink and every packet sent has been read, EOS
// is sent into udpsrc; it follows the packets through the jitterbuffer and the depayloader,
// and the program exits 0 when it reaches fdsink. An error message from either pipeline, or
// no progress for --timeout seconds, ends it with status 1 and a message saying what
// happened; a usage error is status 2.
//
// The plugins are found where GStreamer looks: installed, or in GST_PLUGIN_PATH (from a build
// tree GST_PLUGIN_PATH=build/gst:build/ext, as scripts/demo and `meson devenv` set it).
#include <gst/gst.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <string>

#include "command_line.h"

namespace {

constexpr const char* kRtpCaps =
    "application/x-rtp,media=application,clock-rate=44100,encoding-name=PFAP";

struct Options {
  const char* file = nullptr;
  guint mtu = 0;  // 0: the payloader's default
  guint timeout_s = 10;
};

struct Loopback {
  GMainLoop* loop = nullptr;
  GstElement* sender = nullptr;
  GstElement* receiver = nullptr;
  GstElement* udpsrc = nullptr;
  guint timeout_s = 10;

  // Written by the streaming threads, read by the main loop.
  std::atomic<guint64> sent{0};
  std::atomic<guint64> received{0};
  std::atomic<bool> sender_done{false};

  guint64 last_progress = 0;    // sent + received when the main loop last saw a change
  gint64 last_progress_us = 0;  // and when
  bool eos_sent = false;
  int status = 1;
  std::string failure;
};

// 0 when the arguments are good, else the exit status. GStreamer is initialized by the parse.
int parse_options(int* argc, char*** argv, Options& options) {
  gint mtu = -1, timeout_s = static_cast<gint>(options.timeout_s);  // -1: not given
  const GOptionEntry entries[] = {
      {"mtu", 0, 0, G_OPTION_ARG_INT, &mtu, "The payloader's MTU (28 or more; default its own)",
       "BYTES"},
      {"timeout", 0, 0, G_OPTION_ARG_INT, &timeout_s,
       "Give up when nothing has moved for this long (default 10)", "SECONDS"},
      {}};
  if (const int status = parse_command_line(
          argc, argv, "FILE.pfap",
          "Sends FILE through pfaptextparse ! rtppfappay ! udpsink to 127.0.0.1 and prints\n"
          "what udpsrc ! rtpjitterbuffer ! rtppfapdepay ! pfaptextenc receives.",
          entries, gst_init_get_option_group());
      status != 0) {
    return status;
  }
  if (mtu != -1 && mtu < 28) return usage_error("--mtu wants 28 bytes or more: %d", mtu);
  if (timeout_s <= 0) return usage_error("--timeout wants 1 second or more: %d", timeout_s);
  if (*argc != 2) return usage_error("wants one FILE.pfap");
  if (mtu != -1) options.mtu = static_cast<guint>(mtu);
  options.timeout_s = static_cast<guint>(timeout_s);
  options.file = (*argv)[1];
  return 0;
}

void fail(Loopback& lb, const std::string& why) {
  if (lb.failure.empty()) lb.failure = why;
  lb.status = 1;
  g_main_loop_quit(lb.loop);
}

// Counts what udpsink sends (buffers and buffer lists) and notes the sender's EOS.
GstPadProbeReturn on_sent(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* lb = static_cast<Loopback*>(data);
  if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_BUFFER) {
    lb->sent += 1;
  } else if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_BUFFER_LIST) {
    lb->sent += gst_buffer_list_length(GST_PAD_PROBE_INFO_BUFFER_LIST(info));
  } else if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM) {
    if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) == GST_EVENT_EOS) lb->sender_done = true;
  }
  return GST_PAD_PROBE_OK;
}

// Counts the datagrams udpsrc reads.
GstPadProbeReturn on_received(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* lb = static_cast<Loopback*>(data);
  if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_BUFFER) {
    lb->received += 1;
  } else if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_BUFFER_LIST) {
    lb->received += gst_buffer_list_length(GST_PAD_PROBE_INFO_BUFFER_LIST(info));
  }
  return GST_PAD_PROBE_OK;
}

void add_probe(GstElement* element, const char* pad_name, GstPadProbeType type,
               GstPadProbeCallback callback, Loopback* lb) {
  GstPad* pad = gst_element_get_static_pad(element, pad_name);
  gst_pad_add_probe(pad, type, callback, lb, nullptr);
  gst_object_unref(pad);
}

gboolean on_message(GstBus*, GstMessage* message, gpointer data) {
  auto* lb = static_cast<Loopback*>(data);
  const bool from_sender =
      GST_MESSAGE_SRC(message) != nullptr &&
      gst_object_has_as_ancestor(GST_MESSAGE_SRC(message), GST_OBJECT(lb->sender));
  const char* side = from_sender ? "sender" : "receiver";
  switch (GST_MESSAGE_TYPE(message)) {
    case GST_MESSAGE_ERROR:
    case GST_MESSAGE_WARNING: {
      GError* error = nullptr;
      gchar* debug = nullptr;
      const bool is_error = GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR;
      if (is_error) {
        gst_message_parse_error(message, &error, &debug);
      } else {
        gst_message_parse_warning(message, &error, &debug);
      }
      std::string text = std::string(side) + ": " + GST_OBJECT_NAME(GST_MESSAGE_SRC(message)) +
                         ": " + error->message;
      if (debug != nullptr) text += std::string(" (") + debug + ")";
      g_clear_error(&error);
      g_free(debug);
      if (is_error) {
        fail(*lb, text);
      } else {
        std::fprintf(stderr, "pfap-loopback: warning: %s\n", text.c_str());
      }
      break;
    }
    case GST_MESSAGE_EOS:
      // The sender's EOS is seen by the probe at udpsink; the receiver's ends the run.
      if (GST_MESSAGE_SRC(message) == GST_OBJECT(lb->receiver)) {
        lb->status = 0;
        g_main_loop_quit(lb->loop);
      }
      break;
    default:
      break;
  }
  return TRUE;
}

// Polled: ends the receiver once everything sent has arrived, and times out a stalled run.
gboolean on_tick(gpointer data) {
  auto* lb = static_cast<Loopback*>(data);
  const guint64 sent = lb->sent;
  const guint64 received = lb->received;
  const gint64 now = g_get_monotonic_time();
  if (sent + received != lb->last_progress) {
    lb->last_progress = sent + received;
    lb->last_progress_us = now;
  }
  if (!lb->eos_sent && lb->sender_done && received >= sent) {
    lb->eos_sent = true;
    lb->last_progress_us = now;
    gst_element_send_event(lb->udpsrc, gst_event_new_eos());
  }
  if (now - lb->last_progress_us > gint64{lb->timeout_s} * G_USEC_PER_SEC) {
    gchar* why =
        g_strdup_printf("timed out after %u s without progress: sender %s, %" G_GUINT64_FORMAT
                        " packets sent, %" G_GUINT64_FORMAT " received%s",
                        lb->timeout_s, lb->sender_done ? "finished" : "not finished", sent,
                        received, lb->eos_sent ? ", receiver did not reach EOS" : "");
    fail(*lb, why);
    g_free(why);
    return G_SOURCE_REMOVE;
  }
  return G_SOURCE_CONTINUE;
}

GstElement* launch(const char* description, const char* side) {
  GError* error = nullptr;
  GstElement* pipeline = gst_parse_launch(description, &error);
  if (pipeline == nullptr || error != nullptr) {
    std::fprintf(stderr, "pfap-loopback: cannot make the %s: %s\n", side,
                 error != nullptr ? error->message : "unknown error");
    g_clear_error(&error);
    if (pipeline != nullptr) gst_object_unref(pipeline);
    return nullptr;
  }
  return pipeline;
}

GstElement* by_name(GstElement* pipeline, const char* name) {
  return gst_bin_get_by_name(GST_BIN(pipeline), name);  // always there: our own descriptions
}

// The depayloader's counters, for the summary.
std::string depay_summary(GstElement* receiver) {
  GstElement* depay = by_name(receiver, "depay");
  GstStructure* stats = nullptr;
  g_object_get(depay, "stats", &stats, nullptr);
  gst_object_unref(depay);
  if (stats == nullptr) return "";
  guint64 packets = 0, phonemes = 0, malformed = 0, lost = 0;
  gst_structure_get_uint64(stats, "packets", &packets);
  gst_structure_get_uint64(stats, "phonemes", &phonemes);
  gst_structure_get_uint64(stats, "malformed", &malformed);
  gst_structure_get_uint64(stats, "lost", &lost);
  gst_structure_free(stats);
  gchar* text = g_strdup_printf(
      "%" G_GUINT64_FORMAT " phoneme%s in %" G_GUINT64_FORMAT " packet%s (%" G_GUINT64_FORMAT
      " malformed, %" G_GUINT64_FORMAT " lost)",
      phonemes, phonemes == 1 ? "" : "s", packets, packets == 1 ? "" : "s", malformed, lost);
  std::string out = text;
  g_free(text);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (const int status = parse_options(&argc, &argv, options); status != 0) return status;
  for (const char* name : {"pfaptextparse", "rtppfappay", "rtppfapdepay", "pfaptextenc"}) {
    GstElementFactory* factory = gst_element_factory_find(name);
    if (factory == nullptr) {
      std::fprintf(stderr,
                   "pfap-loopback: no element %s: set GST_PLUGIN_PATH to the directories of "
                   "the pfap plugins (for example build/gst:build/ext)\n",
                   name);
      return 1;
    }
    gst_object_unref(factory);
  }
  if (!g_file_test(options.file, G_FILE_TEST_IS_REGULAR)) {
    std::fprintf(stderr, "pfap-loopback: %s: not a readable file\n", options.file);
    return 2;
  }

  Loopback lb;
  lb.timeout_s = options.timeout_s;
  const std::string receiver_description =
      std::string("udpsrc name=udpsrc address=127.0.0.1 port=0 do-timestamp=false caps=\"") +
      kRtpCaps +
      "\" ! rtpjitterbuffer mode=none max-dropout-time=0 max-misorder-time=0 "
      "! rtppfapdepay name=depay ! pfaptextenc ! "
      "fdsink fd=1 sync=false";
  lb.receiver = launch(receiver_description.c_str(), "receiver");
  lb.sender = launch(
      "filesrc name=file ! pfaptextparse ! rtppfappay name=pay ! "
      "udpsink name=udpsink host=127.0.0.1 sync=false",
      "sender");
  if (lb.receiver == nullptr || lb.sender == nullptr) return 1;
  lb.udpsrc = by_name(lb.receiver, "udpsrc");

  GstElement* file = by_name(lb.sender, "file");
  g_object_set(file, "location", options.file, nullptr);
  gst_object_unref(file);
  if (options.mtu != 0) {
    GstElement* pay = by_name(lb.sender, "pay");
    g_object_set(pay, "mtu", options.mtu, nullptr);
    gst_object_unref(pay);
  }

  lb.loop = g_main_loop_new(nullptr, FALSE);
  GstBus* sender_bus = gst_element_get_bus(lb.sender);
  GstBus* receiver_bus = gst_element_get_bus(lb.receiver);
  gst_bus_add_watch(sender_bus, on_message, &lb);
  gst_bus_add_watch(receiver_bus, on_message, &lb);

  // The receiver first: READY binds its socket to a free port, which the sender then uses.
  int port = 0;
  if (gst_element_set_state(lb.receiver, GST_STATE_READY) == GST_STATE_CHANGE_FAILURE) {
    fail(lb, "receiver: cannot bind a UDP socket on 127.0.0.1");
  } else {
    g_object_get(lb.udpsrc, "port", &port, nullptr);
    GstElement* udpsink = by_name(lb.sender, "udpsink");
    g_object_set(udpsink, "port", port, nullptr);
    add_probe(
        udpsink, "sink",
        static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_BUFFER_LIST |
                                     GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM),
        on_sent, &lb);
    gst_object_unref(udpsink);
    add_probe(
        lb.udpsrc, "src",
        static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_BUFFER_LIST),
        on_received, &lb);

    // Live source: PLAYING completes when data arrives, so no waiting here. A failed state
    // change posts an error message, which the bus watch reports.
    gst_element_set_state(lb.receiver, GST_STATE_PLAYING);
    gst_element_set_state(lb.sender, GST_STATE_PLAYING);
    lb.last_progress_us = g_get_monotonic_time();
    g_timeout_add(10, on_tick, &lb);
    g_main_loop_run(lb.loop);
  }

  const std::string summary = depay_summary(lb.receiver);
  gst_element_set_state(lb.sender, GST_STATE_NULL);
  gst_element_set_state(lb.receiver, GST_STATE_NULL);
  std::fflush(stdout);
  if (lb.status == 0) {
    std::fprintf(stderr, "pfap-loopback: %s over 127.0.0.1:%d\n", summary.c_str(), port);
  } else {
    std::fprintf(stderr, "pfap-loopback: %s\n", lb.failure.empty() ? "failed" : lb.failure.c_str());
  }

  gst_bus_remove_watch(sender_bus);
  gst_bus_remove_watch(receiver_bus);
  gst_object_unref(sender_bus);
  gst_object_unref(receiver_bus);
  gst_object_unref(lb.udpsrc);
  gst_object_unref(lb.sender);
  gst_object_unref(lb.receiver);
  g_main_loop_unref(lb.loop);
  return lb.status;
}

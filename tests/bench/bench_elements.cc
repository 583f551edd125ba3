// SPDX-License-Identifier: LGPL-2.1-or-later
// Pipeline throughput of the PFAP elements beside GStreamer's own RTP payloaders for opaque
// data and for metadata:
//
//   appsrc ! rtppfappay ! rtppfapdepay ! fakesink     (N phoneme events)
//   appsrc ! rtpklvpay  ! rtpklvdepay  ! fakesink     (N KLV units, each holding one event)
//   appsrc ! rtpgstpay  ! rtpgstdepay  ! fakesink     (N buffers of the same bytes, sizes and
//                                                      timestamps)
//
// rtpgstpay carries any buffer as opaque bytes (one packet each here) and is the reference:
// what a payloader that parses nothing costs in the same pipeline. rtpklvpay (SMPTE ST 336
// KLV, RFC 6597) is how GStreamer carries timed metadata; rtpklvdepay checks each unit's key
// and BER length. A KLV unit is at least 17 bytes (16-byte universal label key, 1 length
// byte), more than most events (8 bytes, 24 with 2 FAPs), so it cannot have the event's
// size: each unit is the key, the BER length and the event's bytes as its value, what an
// application carrying these events in KLV would send. The runs rotate their order and each
// is timed from PLAYING to EOS: process CPU time
// (every thread: the application pushing into appsrc, and the streaming thread) and wall
// time. Printed: each run, then the medians, items/s and the ratio to rtpgst.
//
// Run: meson test -C build --benchmark --verbose elements
//  or: GST_PLUGIN_PATH=build/gst:build/ext build/tests/bench/bench_elements [N [repetitions
//      [ONLY]]]
// ONLY runs only the variant whose payloader is ONLY (e.g. "rtpklvpay", or "rtppfappay
// max-delay=0"), for profiling one pipeline (docs/performance.md).
#include <gst/gst.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <utility>
#include <vector>

#include "clocks.h"
#include "pfap/markup.h"
#include "random_markup.h"

namespace {

using pfap::testing::cpu_seconds;
using pfap::testing::median;
using pfap::testing::wall_seconds;

// The phoneme events of N phonemes of speech: contiguous, 40..150 ms each, sentences of
// 6..14 phonemes with a pause after each, one phoneme in four with two FAPs.
std::vector<GstBuffer*> speech(int n) {
  pfap::testing::RandomMarkup random(1);
  std::vector<GstBuffer*> buffers;
  GstClockTime t = 0;
  bool sentence_start = true;
  int in_sentence = 0;
  for (int i = 0; i < n; ++i) {
    const pfap::Phoneme p = random.phoneme();
    const bool end_of_text = ++in_sentence >= random.uniform(6, 14);
    std::vector<PfapFap> faps;
    if (i % 4 == 0) {
      for (int k = 0; k < 2; ++k) {
        const pfap::Fap f = random.fap();
        faps.push_back({f.index, static_cast<uint8_t>(f.curve), f.transition_ms, f.amplitude});
      }
    }
    const uint16_t duration_ms = static_cast<uint16_t>(random.uniform(40, 150));
    const PfapEventHeader header{
        PFAP_EVENT_PHONEME,
        static_cast<uint8_t>((p.stress ? PFAP_FLAG_STRESS : 0) |
                             (p.word_begin ? PFAP_FLAG_WORD_BEGIN : 0) |
                             (end_of_text ? PFAP_FLAG_END_OF_TEXT : 0) |
                             (sentence_start ? PFAP_FLAG_SENTENCE_START : 0)),
        p.symbol,
        p.f0,
        duration_ms,
        static_cast<uint16_t>(faps.size())};
    const size_t size = pfap_markup_size(header.n_faps);
    GstBuffer* buffer = gst_buffer_new_allocate(nullptr, size, nullptr);
    GstMapInfo map;
    gst_buffer_map(buffer, &map, GST_MAP_WRITE);
    if (pfap_markup_write(&header, faps.data(), map.data, size) != 0) {
      std::fprintf(stderr, "cannot write phoneme %d\n", i);
      std::exit(1);
    }
    gst_buffer_unmap(buffer, &map);
    GST_BUFFER_PTS(buffer) = t;
    GST_BUFFER_DURATION(buffer) = duration_ms * GST_MSECOND;
    buffers.push_back(buffer);
    t += duration_ms * GST_MSECOND;
    sentence_start = end_of_text;
    if (end_of_text) {
      in_sentence = 0;
      t += static_cast<GstClockTime>(random.uniform(100, 400)) * GST_MSECOND;
    }
  }
  return buffers;
}

// The same bytes, sizes and timestamps in buffers of their own.
std::vector<GstBuffer*> copies(const std::vector<GstBuffer*>& buffers) {
  std::vector<GstBuffer*> out;
  for (GstBuffer* b : buffers) out.push_back(gst_buffer_copy_deep(b));
  return out;
}

// Each buffer as the value of a KLV unit with the same timestamps: a SMPTE universal label
// key (06 0E 2B 34 ..., what rtpklvdepay looks for) and a BER short-form length.
std::vector<GstBuffer*> klv_units(const std::vector<GstBuffer*>& buffers) {
  static constexpr uint8_t kKey[16] = {0x06, 0x0E, 0x2B, 0x34, 0x02, 0x0B, 0x01, 0x01,
                                       0x0E, 0x01, 0x03, 0x01, 0x01, 0x00, 0x00, 0x00};
  std::vector<GstBuffer*> out;
  for (GstBuffer* b : buffers) {
    const gsize size = gst_buffer_get_size(b);
    if (size > 127) {
      std::fprintf(stderr, "an event of %zu bytes needs a long-form BER length\n", size);
      std::exit(1);
    }
    GstBuffer* unit = gst_buffer_new_allocate(nullptr, sizeof kKey + 1 + size, nullptr);
    GstMapInfo map;
    gst_buffer_map(unit, &map, GST_MAP_WRITE);
    std::memcpy(map.data, kKey, sizeof kKey);
    map.data[sizeof kKey] = static_cast<uint8_t>(size);
    gst_buffer_extract(b, 0, map.data + sizeof kKey + 1, size);
    gst_buffer_unmap(unit, &map);
    gst_buffer_copy_into(unit, b, GST_BUFFER_COPY_TIMESTAMPS, 0, static_cast<gsize>(-1));
    out.push_back(unit);
  }
  return out;
}

struct Timing {
  double cpu;
  double wall;
  long packets;  // RTP packets between payloader and depayloader
};

// Counts what reaches the sink, in buffers or buffer lists.
GstPadProbeReturn count_buffers(GstPad*, GstPadProbeInfo* info, gpointer data) {
  long n = 1;
  if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_BUFFER_LIST) {
    n = gst_buffer_list_length(GST_PAD_PROBE_INFO_BUFFER_LIST(info));
  }
  static_cast<std::atomic<long>*>(data)->fetch_add(n, std::memory_order_relaxed);
  return GST_PAD_PROBE_OK;
}

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "bench_elements: %s\n", what.c_str());
  std::exit(1);
}

// One run: the pipeline is made beforehand; timed from PLAYING to EOS.
Timing run(const char* caps, const char* payloader, const char* depayloader,
           const std::vector<GstBuffer*>& buffers) {
  const std::string description = std::string("appsrc name=src format=time max-bytes=0 caps=") +
                                  caps + " ! " + payloader + " ! " + depayloader +
                                  " name=depay ! fakesink name=sink sync=false";
  GError* error = nullptr;
  GstElement* pipeline = gst_parse_launch(description.c_str(), &error);
  if (error != nullptr) fail(std::string(error->message) + " in: " + description);
  GstElement* src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  GstElement* depay = gst_bin_get_by_name(GST_BIN(pipeline), "depay");
  std::atomic<long> out{0}, packets{0};
  const auto data =
      static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_BUFFER_LIST);
  GstPad* sink_pad = gst_element_get_static_pad(sink, "sink");
  gst_pad_add_probe(sink_pad, data, count_buffers, &out, nullptr);
  gst_object_unref(sink_pad);
  GstPad* depay_pad = gst_element_get_static_pad(depay, "sink");
  gst_pad_add_probe(depay_pad, data, count_buffers, &packets, nullptr);
  gst_object_unref(depay_pad);
  gst_object_unref(depay);
  GstBus* bus = gst_element_get_bus(pipeline);

  const double cpu0 = cpu_seconds();
  const double wall0 = wall_seconds();
  if (gst_element_set_state(pipeline, GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
    fail("cannot play " + description);
  }
  for (GstBuffer* b : buffers) {
    GstFlowReturn ret = GST_FLOW_ERROR;
    g_signal_emit_by_name(src, "push-buffer", b, &ret);  // takes its own reference
    if (ret != GST_FLOW_OK) fail("push-buffer failed in " + description);
  }
  GstFlowReturn ret = GST_FLOW_ERROR;
  g_signal_emit_by_name(src, "end-of-stream", &ret);
  GstMessage* m = gst_bus_timed_pop_filtered(
      bus, 120 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
  Timing t{cpu_seconds() - cpu0, wall_seconds() - wall0, 0};
  if (m == nullptr) fail("no EOS within 120 s: " + description);
  if (GST_MESSAGE_TYPE(m) == GST_MESSAGE_ERROR) {
    GError* e = nullptr;
    gst_message_parse_error(m, &e, nullptr);
    fail(std::string("error: ") + e->message + " in: " + description);
  }
  gst_message_unref(m);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  if (out.load() != static_cast<long>(buffers.size())) {
    fail(description + ": " + std::to_string(out.load()) + " buffers out for " +
         std::to_string(buffers.size()) + " in");
  }
  t.packets = packets.load();
  gst_object_unref(bus);
  gst_object_unref(src);
  gst_object_unref(sink);
  gst_object_unref(pipeline);
  return t;
}

}  // namespace

int main(int argc, char** argv) {
#ifdef PFAP_PLUGIN_DIR
  // Run by hand from the build tree: find the plugin there unless told otherwise.
  g_setenv("GST_PLUGIN_PATH", PFAP_PLUGIN_DIR, FALSE);
#endif
  gst_init(&argc, &argv);
  const int n = argc > 1 ? std::atoi(argv[1]) : 100000;
  const int repetitions = argc > 2 ? std::atoi(argv[2]) : 7;
  if (n <= 0 || repetitions <= 0) fail("usage: bench_elements [N [repetitions [ONLY]]]");
  const std::string only = argc > 3 ? argv[3] : "";
  for (const char* name :
       {"rtppfappay", "rtppfapdepay", "rtpklvpay", "rtpklvdepay", "rtpgstpay", "rtpgstdepay"}) {
    GstElementFactory* f = gst_element_factory_find(name);
    if (f == nullptr) fail(std::string("no element ") + name + " (GST_PLUGIN_PATH?)");
    gst_object_unref(f);
  }

  const std::vector<GstBuffer*> pfap = speech(n);
  const std::vector<GstBuffer*> klv = klv_units(pfap);
  const std::vector<GstBuffer*> plain = copies(pfap);
  size_t bytes = 0;
  for (GstBuffer* b : pfap) bytes += gst_buffer_get_size(b);
  std::printf(
      "%d phoneme events, %zu bytes (%.1f bytes each; as KLV units %.1f), %d repetitions, "
      "order rotating\n",
      n, bytes, static_cast<double>(bytes) / n, static_cast<double>(bytes) / n + 17, repetitions);

  // The reference last: ratios are to it. max-delay=0 makes one packet per phoneme, as
  // rtpgstpay does, so that row compares the cost per packet; the next one leaves out the
  // complete state sent each second (one more packet per second of speech), so that it has
  // rtpgstpay's packet count exactly.
  constexpr const char* kPfapCaps = "application/x-pfap";
  struct Variant {
    const char* name;
    const char* caps;
    const char* payloader;
    const char* depayloader;
    const std::vector<GstBuffer*>& buffers;
    std::vector<double> cpu, wall;
    long packets = 0;
  };
  std::vector<Variant> variants = {
      {"rtppfappay ! rtppfapdepay", kPfapCaps, "rtppfappay", "rtppfapdepay", pfap, {}, {}},
      {"  (max-delay=0)", kPfapCaps, "rtppfappay max-delay=0", "rtppfapdepay", pfap, {}, {}},
      {"  (same, no periodic complete)",
       kPfapCaps,
       "rtppfappay max-delay=0 complete-recovery-interval=0",
       "rtppfapdepay",
       pfap,
       {},
       {}},
      {"rtpklvpay ! rtpklvdepay",
       "meta/x-klv,parsed=true",
       "rtpklvpay",
       "rtpklvdepay",
       klv,
       {},
       {}},
      {"rtpgstpay ! rtpgstdepay", kPfapCaps, "rtpgstpay", "rtpgstdepay", plain, {}, {}},
  };
  auto selected = [&](const Variant& v) {
    return only.empty() || only == v.payloader;
  };
  // Warm-up: the registry, plugin loading and first allocations are not measured.
  for (Variant& v : variants) {
    if (selected(v)) run(v.caps, v.payloader, v.depayloader, v.buffers);
  }
  for (int r = 0; r < repetitions; ++r) {
    std::printf("run %d:", r + 1);
    // Rotate the order so that no variant always runs first or last.
    for (size_t k = 0; k < variants.size(); ++k) {
      Variant& v = variants[(k + static_cast<size_t>(r)) % variants.size()];
      if (!selected(v)) continue;
      const Timing t = run(v.caps, v.payloader, v.depayloader, v.buffers);
      v.cpu.push_back(t.cpu);
      v.wall.push_back(t.wall);
      v.packets = t.packets;
      std::printf(" | %s cpu %.4f s", v.payloader, t.cpu);
    }
    std::printf("\n");
  }

  const Variant& reference = variants.back();
  const double rc = selected(reference) ? median(reference.cpu) : 0;
  std::printf(
      "\nmedian of %d                      CPU time   items/s (CPU)   RTP packets   vs rtpgst "
      "(items/s)\n",
      repetitions);
  for (const Variant& v : variants) {
    if (!selected(v)) continue;
    const double c = median(v.cpu);
    std::printf("%-32s %8.4f s %13.0f %13ld %12.3f\n", v.name, c, n / c, v.packets, rc / c);
  }

  for (GstBuffer* b : pfap) gst_buffer_unref(b);
  for (GstBuffer* b : klv) gst_buffer_unref(b);
  for (GstBuffer* b : plain) gst_buffer_unref(b);
  return 0;
}

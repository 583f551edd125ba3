// SPDX-License-Identifier: LGPL-2.1-or-later
// rtppfapdepay in a GstHarness, fed RTP packets cut from the input. Each packet is
//   2 bytes   n, big endian: the length of what follows (cut to what the input has left)
//   1 byte    control: bit 0 the marker; bit 1 the second SSRC; bits 2-3 what comes before
//             the packet (0 nothing, 1 a flush, 2 rtpjitterbuffer's packet-lost event, 3 the
//             sequence number goes back); bits 4-7 j: the sequence number goes forward by
//             1 + j, or back by 101 + 100 j
//   n - 1     the payload
// GstRTPBaseDepayload drops duplicates and packets up to 100 back (its max-reorder) before
// the element sees them, so the harness makes none: each packet reaches the element.
// The element must not crash nor log a critical; every output buffer must be a valid x-pfap
// event; and its stats must count every packet, and every malformed one in its class (the
// harness decodes each payload itself to know which are).
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gst/rtp/gstrtpbuffer.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

#include "fuzz_check.h"
#include "pfap/markup_event.h"
#include "pfap/payload.h"
#include "rtp_packet.h"

namespace {

constexpr const char* kCaps =
    "application/x-rtp,media=application,clock-rate=44100,encoding-name=PFAP,payload=96";
constexpr guint32 kSsrcs[] = {0x5eed, 0xfeed};
constexpr GstClockTime kPacketSpacing = 20 * GST_MSECOND;

// GStreamer, once per process, with only this build's plugin: no system plugins to scan, no
// scanner subprocess (an unsanitized gst-plugin-scanner cannot load a sanitized plugin), and
// a registry of its own in the build tree.
void init_gstreamer() {
  static const bool done = [] {
    setenv("GST_PLUGIN_SYSTEM_PATH_1_0", "", 1);
    setenv("GST_PLUGIN_PATH_1_0", PFAP_PLUGIN_DIR, 1);
    setenv("GST_REGISTRY_1_0", PFAP_FUZZ_REGISTRY, 1);
    setenv("GST_REGISTRY_FORK", "no", 1);
    // A critical is a bug (a bad refcount, a failed precondition): crash on it.
    g_log_set_always_fatal(static_cast<GLogLevelFlags>(G_LOG_FATAL_MASK | G_LOG_LEVEL_CRITICAL));
    gst_init(nullptr, nullptr);
    GstElementFactory* factory = gst_element_factory_find("rtppfapdepay");
    FUZZ_CHECK(factory != nullptr);  // the plugin did not load from PFAP_PLUGIN_DIR
    gst_object_unref(factory);
    return true;
  }();
  (void)done;
}

guint64 stat(const GstStructure* stats, const char* field) {
  guint64 value = 0;
  FUZZ_CHECK(gst_structure_get_uint64(stats, field, &value));
  return value;
}

// The stats field of each malformed class, as the element documents them.
constexpr std::array<const char*, pfap::kDecodeStatusCount> kMalformedFields = {
    nullptr,
    "malformed-truncated",
    "malformed-reserved-recovery-type",
    "malformed-reserved-info-bits",
    "malformed-missing-coverage",
    "malformed-fap-index-out-of-range",
    "malformed-amplitude-out-of-range",
    "malformed-curve-zero",
    "malformed-missing-final-phoneme",
    "malformed-trailing-bytes",
    "malformed-data-in-complete-recovery",
    "malformed-unterminated-recovery",
    "malformed-empty-packet",
};

GstBuffer* rtp_packet(std::span<const uint8_t> payload, guint16 seqnum, guint32 ssrc,
                      bool marker, GstClockTime pts) {
  return pfap::testing::rtp_packet(payload,
                                   {.seqnum = seqnum,
                                    .timestamp = static_cast<guint32>(pts / GST_MSECOND * 441 / 10),
                                    .ssrc = ssrc,
                                    .marker = marker},
                                   pts);
}

GstEvent* packet_lost(guint16 seqnum, GstClockTime pts) {
  return gst_event_new_custom(
      GST_EVENT_CUSTOM_DOWNSTREAM,
      gst_structure_new("GstRTPPacketLost", "seqnum", G_TYPE_UINT, guint{seqnum}, "timestamp",
                        G_TYPE_UINT64, guint64{pts}, "duration", G_TYPE_UINT64,
                        guint64{kPacketSpacing}, nullptr));
}

// Pulls every buffer out so far, checking each is a valid x-pfap event; counts the phonemes.
void pull_all(GstHarness* h, guint64& phonemes) {
  pfap::MarkupEvent event;
  while (GstBuffer* buffer = gst_harness_try_pull(h)) {
    GstMapInfo map;
    FUZZ_CHECK(gst_buffer_map(buffer, &map, GST_MAP_READ));
    FUZZ_CHECK(pfap::read_markup(std::span<const uint8_t>(map.data, map.size), event));
    gst_buffer_unmap(buffer, &map);
    phonemes += event.kind == PFAP_EVENT_PHONEME;
    gst_buffer_unref(buffer);
  }
  while (GstEvent* e = gst_harness_try_pull_upstream_event(h)) gst_event_unref(e);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  init_gstreamer();
  GstHarness* h = gst_harness_new("rtppfapdepay");
  gst_harness_set_src_caps_str(h, kCaps);

  std::array<guint64, pfap::kDecodeStatusCount> expected{};  // per DecodeStatus
  guint64 packets = 0;
  guint64 phonemes = 0;
  guint16 seqnum = 1000;
  GstClockTime pts = 0;
  pfap::Packet scratch;
  std::span<const uint8_t> in(data, size);
  while (in.size() >= 3) {
    const size_t n = std::min<size_t>((size_t{in[0]} << 8 | in[1]), in.size() - 2);
    if (n == 0) break;
    const uint8_t control = in[2];
    const std::span<const uint8_t> payload = in.subspan(3, n - 1);
    in = in.subspan(2 + n);

    const unsigned before = (control >> 2) & 0b11;
    const unsigned jump = control >> 4;
    if (before == 1) {
      FUZZ_CHECK(gst_harness_push_event(h, gst_event_new_flush_start()));
      FUZZ_CHECK(gst_harness_push_event(h, gst_event_new_flush_stop(TRUE)));
      GstSegment segment;
      gst_segment_init(&segment, GST_FORMAT_TIME);
      FUZZ_CHECK(gst_harness_push_event(h, gst_event_new_segment(&segment)));
    } else if (before == 2) {
      // Refused (FALSE) until the element has output a segment: not the element's fault.
      gst_harness_push_event(h, packet_lost(static_cast<guint16>(seqnum + 1), pts));
    }
    seqnum = static_cast<guint16>(before == 3 ? seqnum - 101 - 100 * jump : seqnum + 1 + jump);
    pts += kPacketSpacing;

    FUZZ_CHECK(gst_harness_push(h, rtp_packet(payload, seqnum, kSsrcs[(control >> 1) & 1],
                                              (control & 1) != 0, pts)) == GST_FLOW_OK);
    ++packets;
    ++expected[static_cast<size_t>(pfap::decode_payload(payload, scratch).status)];
    pull_all(h, phonemes);
  }

  GstStructure* stats = nullptr;
  g_object_get(h->element, "stats", &stats, nullptr);
  FUZZ_CHECK(stats != nullptr);
  FUZZ_CHECK(stat(stats, "packets") == packets);
  guint64 malformed = 0;
  for (size_t i = 1; i < kMalformedFields.size(); ++i) {
    FUZZ_CHECK(stat(stats, kMalformedFields[i]) == expected[i]);
    malformed += expected[i];
  }
  FUZZ_CHECK(stat(stats, "malformed") == malformed);
  FUZZ_CHECK(stat(stats, "phonemes") == phonemes);
  gst_structure_free(stats);
  gst_harness_teardown(h);
  return 0;
}

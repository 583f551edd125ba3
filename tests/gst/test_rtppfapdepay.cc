// SPDX-License-Identifier: LGPL-2.1-or-later
// rtppfapdepay: hand-built PFAP RTP packets in, x-pfap phoneme and state buffers out, read
// back with pfap::testing::read_event; requests for a complete state out upstream.
#include <gst/check/gstharness.h>
#include <gst/rtp/gstrtpbuffer.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "element_harness.h"
#include "pfap/packetizer.h"
#include "pfap/payload.h"
#include "pfap_buffers.h"
#include "pipeline.h"
#include "rtp_packet.h"

namespace pfap {
namespace {

using Bytes = std::vector<uint8_t>;
using testing::Event;
using testing::read_event;

constexpr const char* kCaps =
    "application/x-rtp,media=application,clock-rate=44100,encoding-name=PFAP,payload=96";
constexpr guint32 kSsrc = 0x5eed;

Bytes encode(const Packet& packet) {
  Bytes out(encoded_size(packet));
  EXPECT_EQ(encode_payload(packet, out), EncodeStatus::kOk);
  return out;
}

// An RTP packet whose PTS is `pts` and whose timestamp is `pts` on a `clock_rate` clock.
GstBuffer* rtp_packet(const Bytes& payload, guint16 seqnum, GstClockTime pts, bool marker = false,
                      uint32_t clock_rate = kDefaultClockRate) {
  return testing::rtp_packet(
      payload,
      {.seqnum = seqnum,
       .timestamp = rtp_ticks(static_cast<int64_t>(pts), clock_rate),
       .ssrc = kSsrc,
       .marker = marker},
      pts);
}

// The same packet from another sender.
GstBuffer* with_ssrc(GstBuffer* packet, guint32 ssrc) {
  GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
  EXPECT_TRUE(gst_rtp_buffer_map(packet, GST_MAP_WRITE, &rtp));
  gst_rtp_buffer_set_ssrc(&rtp, ssrc);
  gst_rtp_buffer_unmap(&rtp);
  return packet;
}

Event phoneme_event(const Phoneme& p, std::vector<Fap> faps, uint8_t flags, GstClockTime pts,
                    bool discont = false) {
  return {PFAP_EVENT_PHONEME,
          flags,
          p,
          std::move(faps),
          pts,
          static_cast<GstClockTime>(p.duration_ms) * GST_MSECOND,
          discont};
}

// A recovered or complete event: no phoneme, no duration.
Event state_event(PfapEventKind kind, std::vector<Fap> faps, GstClockTime pts, uint8_t flags = 0,
                  bool discont = false) {
  return {kind, flags, Phoneme{}, std::move(faps), pts, GST_CLOCK_TIME_NONE, discont};
}

// Every buffer the element has output so far.
std::vector<Event> pull_all(GstHarness* h) {
  std::vector<Event> events;
  while (GstBuffer* buffer = gst_harness_try_pull(h)) {
    events.push_back(read_event(buffer));
    gst_buffer_unref(buffer);
  }
  return events;
}

std::vector<Event> push(GstHarness* h, GstBuffer* packet) {
  EXPECT_EQ(gst_harness_push(h, packet), GST_FLOW_OK);
  return pull_all(h);
}

guint64 stat(GstHarness* h, const char* field) {
  GstStructure* stats = nullptr;
  g_object_get(h->element, "stats", &stats, nullptr);
  guint64 value = G_MAXUINT64;
  EXPECT_TRUE(gst_structure_get_uint64(stats, field, &value)) << "no stats field " << field;
  gst_structure_free(stats);
  return value;
}

// How many requests for a complete state the element has sent upstream so far. The check is
// gst_video_event_is_force_key_unit's, spelled out: the tests do not link gstreamer-video.
int pull_requests(GstHarness* h) {
  int requests = 0;
  while (GstEvent* event = gst_harness_try_pull_upstream_event(h)) {
    if (GST_EVENT_TYPE(event) == GST_EVENT_CUSTOM_UPSTREAM &&
        gst_event_has_name(event, "GstForceKeyUnit")) {
      gboolean all_headers = FALSE;
      EXPECT_TRUE(
          gst_structure_get_boolean(gst_event_get_structure(event), "all-headers", &all_headers));
      EXPECT_TRUE(all_headers);  // the whole state
      ++requests;
    }
    gst_event_unref(event);
  }
  return requests;
}

// The warnings on `bus`, as "message | debug".
std::vector<std::string> pop_warnings(GstBus* bus) {
  std::vector<std::string> warnings;
  while (GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_WARNING)) {
    GError* error = nullptr;
    gchar* debug = nullptr;
    gst_message_parse_warning(message, &error, &debug);
    EXPECT_TRUE(g_error_matches(error, GST_STREAM_ERROR, GST_STREAM_ERROR_DECODE));
    warnings.push_back(std::string(error->message) + " | " + (debug ? debug : ""));
    g_error_free(error);
    g_free(debug);
    gst_message_unref(message);
  }
  return warnings;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A one-phoneme packet (80 ms) to follow bad ones with.
const Phoneme kGood{.symbol = 5, .duration_ms = 80, .f0 = 50};
Bytes good_payload() {
  Packet p;
  p.add_phoneme(kGood, {});
  return encode(p);
}

// A complete state: `entries`, every other FAP 0.
Bytes complete_payload(std::vector<Fap> entries = {}) {
  Packet p;
  p.recovery_kind = RecoveryKind::kComplete;
  p.recovery = std::move(entries);
  return encode(p);
}

// Dynamic recovery over `covered` packets, then kGood with `faps` unless `recovery_only`.
Bytes dynamic_payload(uint8_t covered, std::vector<Fap> entries, std::vector<Fap> faps = {},
                      bool recovery_only = false) {
  Packet p;
  p.recovery_kind = RecoveryKind::kDynamic;
  p.covered_packets = covered;
  p.recovery = std::move(entries);
  if (!recovery_only) p.add_phoneme(kGood, faps);
  return encode(p);
}

// The all-zero complete state a sender begins a stream with (rtppfappay does): it makes the
// receiver whole and outputs nothing, so the packets after it are certain and ask nothing.
void start_stream(GstHarness* h, guint16 seqnum, GstClockTime pts = 0) {
  EXPECT_EQ(gst_harness_push(h, rtp_packet(complete_payload(), seqnum, pts)), GST_FLOW_OK);
  EXPECT_EQ(gst_harness_try_pull(h), nullptr);
}

const Fap kJoy{69, 40, 2000, Curve::kSpline};
const Fap kJaw{3, -500, 120, Curve::kLinear};

class RtpPfapDepayTest : public ::testing::Test, public testing::ElementHarness {
 protected:
  RtpPfapDepayTest() : ElementHarness("rtppfapdepay") {}
  void SetUp() override { gst_harness_set_src_caps_str(h_, kCaps); }

  // The element's messages, which the harness alone would drop.
  GstBus* watch_bus() { return bus_; }
  // The tests' stat(h, field), which the fixture's own stat(field) would hide.
  using ElementHarness::stat;
  static guint64 stat(GstHarness* h, const char* field) { return pfap::stat(h, field); }
};

TEST_F(RtpPfapDepayTest, EachPhonemeBecomesABufferWithItsFapsAndTime) {
  const Phoneme a{.symbol = 42, .duration_ms = 100, .f0 = 60, .stress = true, .word_begin = true};
  const Phoneme b{.symbol = 7, .duration_ms = 80, .f0 = 255};
  const Phoneme c{.symbol = 9, .duration_ms = 4095, .f0 = 1, .end_of_text = true};
  const std::vector<Fap> faps_a = {{69, 40, 2000, Curve::kSpline},
                                   {70, -kMaxAmplitude, kMaxTransitionMs, Curve::kTriangle}};
  const std::vector<Fap> faps_c = {{19, -1, 1, Curve::kLinear}};
  Packet packet;
  packet.add_phoneme(a, faps_a);
  packet.add_phoneme(b, {});
  packet.add_phoneme(c, faps_c);

  const GstClockTime t = 3 * GST_SECOND;
  start_stream(h_, 0, t);
  const std::vector<Event> expected = {
      phoneme_event(a, faps_a, PFAP_FLAG_STRESS | PFAP_FLAG_WORD_BEGIN | PFAP_FLAG_SENTENCE_START,
                    t),
      phoneme_event(b, {}, 0, t + 100 * GST_MSECOND),
      phoneme_event(c, faps_c, PFAP_FLAG_END_OF_TEXT, t + 180 * GST_MSECOND),
  };
  EXPECT_EQ(push(h_, rtp_packet(encode(packet), 1, t, /*marker=*/true)), expected);
  EXPECT_EQ(stat(h_, "packets"), 2u);  // with the complete state
  EXPECT_EQ(stat(h_, "phonemes"), 3u);
  EXPECT_EQ(stat(h_, "faps"), 3u);
}

TEST_F(RtpPfapDepayTest, PacketWithOnlyADtsTimesEveryPhonemeFromIt) {
  // pcapparse gives each packet a DTS and no PTS.
  const Phoneme a{.symbol = 42, .duration_ms = 100, .f0 = 60};
  const Phoneme b{.symbol = 7, .duration_ms = 80, .f0 = 255};
  Packet packet;
  packet.add_phoneme(a, {});
  packet.add_phoneme(b, {});
  const GstClockTime t = 2 * GST_SECOND;
  start_stream(h_, 0, t);
  GstBuffer* buffer = rtp_packet(encode(packet), 1, t);
  GST_BUFFER_PTS(buffer) = GST_CLOCK_TIME_NONE;
  GST_BUFFER_DTS(buffer) = t;
  const std::vector<Event> got = push(h_, buffer);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].pts, t);
  EXPECT_EQ(got[1].pts, t + 100 * GST_MSECOND);
}

TEST_F(RtpPfapDepayTest, PayloadSpreadOverMemoriesDecodesAsOne) {
  // The depayloader maps the one memory that holds the payload; a payload spread over two
  // takes the other path.
  const Phoneme a{.symbol = 42, .duration_ms = 100, .f0 = 60};
  const std::vector<Fap> faps = {{19, -1, 1, Curve::kLinear}, {3, 700, 40, Curve::kSpline}};
  Packet packet;
  packet.add_phoneme(a, faps);
  const GstClockTime t = 2 * GST_SECOND;
  start_stream(h_, 0, t);
  GstBuffer* whole = rtp_packet(encode(packet), 1, t);
  const gsize header = 12, size = gst_buffer_get_size(whole), half = (size - header) / 2;
  GstBuffer* split = gst_buffer_copy_region(whole, GST_BUFFER_COPY_ALL, 0, header);
  split = gst_buffer_append(
      split, gst_buffer_copy_region(whole, GST_BUFFER_COPY_MEMORY, header, half));
  split = gst_buffer_append(split, gst_buffer_copy_region(whole, GST_BUFFER_COPY_MEMORY,
                                                          header + half, size - header - half));
  gst_buffer_unref(whole);
  ASSERT_EQ(gst_buffer_n_memory(split), 3u);
  EXPECT_EQ(push(h_, split), std::vector<Event>{phoneme_event(a, faps, 0, t)});
}

TEST_F(RtpPfapDepayTest, SentenceStartComesOnlyFromTheMarkerBitOnTheFirstPhoneme) {
  const Phoneme p{.symbol = 1, .duration_ms = 10};
  Packet packet;
  packet.add_phoneme(p, {});
  packet.add_phoneme(p, {});
  start_stream(h_, 0);
  const std::vector<Event> without_marker = push(h_, rtp_packet(encode(packet), 1, 0));
  ASSERT_EQ(without_marker.size(), 2u);
  EXPECT_EQ(without_marker[0].flags, 0);
  EXPECT_EQ(without_marker[1].flags, 0);

  const std::vector<Event> with_marker =
      push(h_, rtp_packet(encode(packet), 2, GST_SECOND, /*marker=*/true));
  ASSERT_EQ(with_marker.size(), 2u);
  EXPECT_EQ(with_marker[0].flags, PFAP_FLAG_SENTENCE_START);
  EXPECT_EQ(with_marker[1].flags, 0);
}

struct BadPacket {
  const char* name;
  DecodeStatus status;
  const char* field;  // its stats field, spelled out: the names are API
  Bytes payload;
};

// Payloads from tests/lib/test_payload.cc, at least one per class of bad payload.
std::vector<BadPacket> bad_packets() {
  const Bytes end = {0x00, 0x00, 0x00, 0x02};  // phoneme, IB=10 (end of packet)
  const auto cat = [](std::initializer_list<Bytes> parts) {
    Bytes out;
    for (const Bytes& part : parts) out.insert(out.end(), part.begin(), part.end());
    return out;
  };
  // A FAP descriptor (ind 3, a=100, T=0) with `last` as its last byte (C and IB).
  const auto fap = [](uint8_t last) { return Bytes{0x06, 0x00, 0x01, 0x90, 0x00, last}; };
  return {
      {"empty_payload", DecodeStatus::kTruncated, "malformed-truncated", {}},
      {"phoneme_cut_short", DecodeStatus::kTruncated, "malformed-truncated", {0x00, 0x00, 0x00}},
      {"reserved_type_10", DecodeStatus::kReservedRecoveryType, "malformed-reserved-recovery-type",
       cat({{0x40}, end})},
      {"reserved_ib_in_packet_descriptor", DecodeStatus::kReservedInfoBits,
       "malformed-reserved-info-bits", cat({{0x03}, end})},
      {"dynamic_recovery_with_pp_000", DecodeStatus::kMissingCoverage, "malformed-missing-coverage",
       cat({{0x20}, fap(0x07), end})},
      {"fap_index_2", DecodeStatus::kFapIndexOutOfRange, "malformed-fap-index-out-of-range",
       cat({{0x01}, {0x04, 0x00, 0x01, 0x90, 0x00, 0x04}, end})},
      {"amplitude_2529601", DecodeStatus::kAmplitudeOutOfRange, "malformed-amplitude-out-of-range",
       cat({{0x01}, {0x06, 0x9A, 0x65, 0x04, 0x00, 0x04}, end})},
      {"curve_0", DecodeStatus::kCurveZero, "malformed-curve-zero", cat({{0x01}, fap(0x00), end})},
      {"ends_with_fap", DecodeStatus::kMissingFinalPhoneme, "malformed-missing-final-phoneme",
       cat({{0x01}, fap(0x04)})},
      {"bytes_after_end_of_packet", DecodeStatus::kTrailingBytes, "malformed-trailing-bytes",
       cat({{0x00}, end, {0x00}})},
      {"complete_recovery_announcing_phoneme", DecodeStatus::kDataInCompleteRecovery,
       "malformed-data-in-complete-recovery", cat({{0x80}, end})},
      {"recovery_list_never_ends", DecodeStatus::kUnterminatedRecovery,
       "malformed-unterminated-recovery", cat({{0x24}, fap(0x04), fap(0x04)})},
      {"nothing_at_all", DecodeStatus::kEmptyPacket, "malformed-empty-packet", {0x02}},
  };
}

TEST(RtpPfapDepayBadPackets, TableCoversEveryClassWithPayloadsOfThatClass) {
  std::set<DecodeStatus> classes;
  std::set<std::string> fields;
  for (const BadPacket& bad : bad_packets()) {
    SCOPED_TRACE(bad.name);
    Packet packet;
    EXPECT_EQ(decode_payload(bad.payload, packet).status, bad.status);
    classes.insert(bad.status);
    fields.insert(bad.field);
  }
  EXPECT_EQ(classes.size(), static_cast<size_t>(kDecodeStatusCount - 1));
  EXPECT_EQ(classes.count(DecodeStatus::kOk), 0u);
  EXPECT_EQ(fields.size(), classes.size());
}

TEST_F(RtpPfapDepayTest, EachMalformedClassIsDroppedAndCountedWhileTheNextPacketDecodes) {
  const std::vector<BadPacket> bad_list = bad_packets();
  std::map<std::string, guint64> expected_counts;
  for (const BadPacket& bad : bad_list) expected_counts[bad.field] = 0;

  guint16 seqnum = 100;
  GstClockTime t = GST_SECOND;
  start_stream(h_, seqnum++);
  for (size_t i = 0; i < bad_list.size(); ++i) {
    const BadPacket& bad = bad_list[i];
    SCOPED_TRACE(bad.name);
    EXPECT_TRUE(push(h_, rtp_packet(bad.payload, seqnum++, t, true)).empty());
    t += GST_SECOND;
    // The bad packet's FAPs are lost as a lost packet's would be, and nothing recovers them.
    const std::vector<Event> expected = {phoneme_event(kGood, {}, PFAP_FLAG_UNCERTAIN, t)};
    EXPECT_EQ(push(h_, rtp_packet(good_payload(), seqnum++, t)), expected);
    t += GST_SECOND;

    ++expected_counts[bad.field];
    for (const auto& [field, count] : expected_counts)
      EXPECT_EQ(stat(h_, field.c_str()), count) << field;
    EXPECT_EQ(stat(h_, "malformed"), i + 1);
    EXPECT_EQ(stat(h_, "packets"), 2 * (i + 1) + 1);
    EXPECT_EQ(stat(h_, "phonemes"), i + 1);
    EXPECT_EQ(stat(h_, "lost"), i + 1);
  }
}

TEST_F(RtpPfapDepayTest, MalformedPacketIsRecoveredLikeALostOne) {
  start_stream(h_, 0);
  push(h_, rtp_packet(good_payload(), 1, GST_SECOND));
  EXPECT_TRUE(push(h_, rtp_packet({0x02}, 2, 2 * GST_SECOND)).empty());
  const std::vector<Event> expected = {
      state_event(PFAP_EVENT_RECOVERED, {kJaw}, 3 * GST_SECOND),
      phoneme_event(kGood, {}, 0, 3 * GST_SECOND),
  };
  EXPECT_EQ(push(h_, rtp_packet(dynamic_payload(1, {kJaw}), 3, 3 * GST_SECOND)), expected);
  EXPECT_EQ(stat(h_, "lost"), 1u);
  EXPECT_EQ(stat(h_, "recovered"), 1u);
  EXPECT_EQ(pull_requests(h_), 0);
}

TEST_F(RtpPfapDepayTest, MalformedPacketPostsAWarningNamingTheErrorAndItsOffset) {
  GstBus* bus = watch_bus();
  const Bytes trailing = {0x00, 0x00, 0x00, 0x00, 0x02, 0xFF};  // trailing bytes at byte 5
  push(h_, rtp_packet(trailing, 1, 0));
  const std::vector<std::string> warnings = pop_warnings(bus);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(contains(warnings[0], to_string(DecodeStatus::kTrailingBytes))) << warnings[0];
  EXPECT_TRUE(contains(warnings[0], "at byte 5")) << warnings[0];
}

TEST_F(RtpPfapDepayTest, WarningsAreLimitedToPowersOfTwoOfTheMalformedCount) {
  GstBus* bus = watch_bus();
  for (guint16 seqnum = 0; seqnum < 100; ++seqnum) push(h_, rtp_packet({0x02}, seqnum, 0));
  const std::vector<std::string> warnings = pop_warnings(bus);
  ASSERT_EQ(warnings.size(), 7u);  // the 1st, 2nd, 4th, ..., 64th
  EXPECT_TRUE(contains(warnings.back(), "64 malformed packets so far")) << warnings.back();
  EXPECT_EQ(stat(h_, "malformed"), 100u);
  EXPECT_EQ(stat(h_, "malformed-empty-packet"), 100u);
}

// Only a payload over 393 KB can hold this many FAPs; x-pfap counts them in 16 bits.
TEST_F(RtpPfapDepayTest, PhonemeWithMoreFapsThanXPfapHoldsDropsThePacketWithAWarning) {
  GstBus* bus = watch_bus();
  start_stream(h_, 0);
  Packet huge;
  huge.add_phoneme(kGood, std::vector<Fap>(G_MAXUINT16 + 1, Fap{3, 1, 0, Curve::kLinear}));
  EXPECT_TRUE(push(h_, rtp_packet(encode(huge), 1, 0)).empty());
  const std::vector<std::string> warnings = pop_warnings(bus);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(contains(warnings[0], "65536 FAPs")) << warnings[0];

  // Its FAPs are missing downstream, so it counts as lost.
  const std::vector<Event> expected = {phoneme_event(kGood, {}, PFAP_FLAG_UNCERTAIN, GST_SECOND)};
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 2, GST_SECOND)), expected);
  EXPECT_EQ(stat(h_, "lost"), 1u);
}

TEST_F(RtpPfapDepayTest, SequenceGapMarksTheNextOutputDiscontAndCountsTheLostPackets) {
  EXPECT_FALSE(push(h_, rtp_packet(good_payload(), 100, 0)).at(0).discont);
  EXPECT_FALSE(push(h_, rtp_packet(good_payload(), 101, GST_SECOND)).at(0).discont);

  EXPECT_TRUE(push(h_, rtp_packet(good_payload(), 105, 2 * GST_SECOND)).at(0).discont);
  EXPECT_EQ(stat(h_, "lost"), 3u);
  EXPECT_FALSE(push(h_, rtp_packet(good_payload(), 106, 3 * GST_SECOND)).at(0).discont);

  // A gap before a malformed packet: the DISCONT waits for the next buffer out.
  EXPECT_TRUE(push(h_, rtp_packet({0x02}, 110, 4 * GST_SECOND)).empty());
  EXPECT_TRUE(push(h_, rtp_packet(good_payload(), 111, 5 * GST_SECOND)).at(0).discont);
  EXPECT_EQ(stat(h_, "lost"), 7u);  // 107 to 110: the malformed packet counts too
  EXPECT_EQ(stat(h_, "gaps"), 2u);
}

TEST_F(RtpPfapDepayTest, LostPacketsAreCountedAcrossTheSequenceNumberWrap) {
  push(h_, rtp_packet(good_payload(), 65534, 0));
  EXPECT_TRUE(push(h_, rtp_packet(good_payload(), 2, GST_SECOND)).at(0).discont);
  EXPECT_EQ(stat(h_, "lost"), 3u);  // 65535, 0 and 1
}

TEST_F(RtpPfapDepayTest, OnlyForwardJumpsCountAsLoss) {
  push(h_, rtp_packet(good_payload(), 20000, 0));
  EXPECT_TRUE(push(h_, rtp_packet(good_payload(), 40000, GST_SECOND)).at(0).discont);
  EXPECT_EQ(stat(h_, "lost"), 19999u);
  // Further back than max-reorder (100): the base class takes it for a restarted sender.
  EXPECT_TRUE(push(h_, rtp_packet(good_payload(), 30000, 2 * GST_SECOND)).at(0).discont);
  EXPECT_EQ(stat(h_, "lost"), 19999u);
  // Another sender's sequence numbers say nothing about this one's losses.
  EXPECT_TRUE(push(h_, with_ssrc(rtp_packet(good_payload(), 31000, 3 * GST_SECOND), kSsrc + 1))
                  .at(0)
                  .discont);
  EXPECT_EQ(stat(h_, "lost"), 19999u);
}

TEST_F(RtpPfapDepayTest, CoveredGapOutputsTheRecoveryEntriesBeforeThePhonemesStayingCertain) {
  start_stream(h_, 9);
  push(h_, rtp_packet(good_payload(), 10, GST_SECOND));
  // 11 and 12 are lost; 13 covers 4 packets.
  const GstClockTime t = 2 * GST_SECOND;
  const std::vector<Event> expected = {
      state_event(PFAP_EVENT_RECOVERED, {kJaw, kJoy}, t, 0, /*discont=*/true),
      phoneme_event(kGood, {kJoy}, 0, t),
  };
  EXPECT_EQ(push(h_, rtp_packet(dynamic_payload(4, {kJaw, kJoy}, {kJoy}), 13, t)), expected);
  EXPECT_EQ(stat(h_, "lost"), 2u);
  EXPECT_EQ(stat(h_, "gaps"), 1u);
  EXPECT_EQ(stat(h_, "recovered"), 1u);
  EXPECT_EQ(stat(h_, "faps-recovered"), 2u);
  EXPECT_EQ(stat(h_, "phonemes"), 2u);
  EXPECT_EQ(stat(h_, "faps"), 1u);  // phoneme FAPs only
  EXPECT_EQ(pull_requests(h_), 0);
}

TEST_F(RtpPfapDepayTest, RecoveryOnlyPacketAfterACoveredGapOutputsTheRecoveredEvent) {
  start_stream(h_, 0);
  push(h_, rtp_packet(good_payload(), 1, GST_SECOND));
  const std::vector<Event> expected = {
      state_event(PFAP_EVENT_RECOVERED, {kJoy}, 2 * GST_SECOND, 0, /*discont=*/true)};
  EXPECT_EQ(push(h_, rtp_packet(dynamic_payload(2, {kJoy}, {}, /*recovery_only=*/true), 3,
                                2 * GST_SECOND)),
            expected);
  EXPECT_EQ(stat(h_, "recovered"), 1u);
}

// PP without entries: the covered packets left nothing in effect, so the state is whole.
TEST_F(RtpPfapDepayTest, CoveredGapWithNothingToRecoverOutputsARecoveredEventWithoutFaps) {
  start_stream(h_, 0);
  push(h_, rtp_packet(good_payload(), 1, GST_SECOND));
  const std::vector<Event> expected = {
      state_event(PFAP_EVENT_RECOVERED, {}, 2 * GST_SECOND, 0, /*discont=*/true),
      phoneme_event(kGood, {}, 0, 2 * GST_SECOND)};
  EXPECT_EQ(push(h_, rtp_packet(dynamic_payload(1, {}), 3, 2 * GST_SECOND)), expected);
  EXPECT_EQ(stat(h_, "faps-recovered"), 0u);
  EXPECT_EQ(pull_requests(h_), 0);
}

// The phonemes before the entries already set those FAPs: applying them again is no news.
TEST_F(RtpPfapDepayTest, RecoveryEntriesWithoutLossAreNotOutput) {
  start_stream(h_, 0);
  const std::vector<Event> expected = {phoneme_event(kGood, {}, 0, GST_SECOND)};
  EXPECT_EQ(push(h_, rtp_packet(dynamic_payload(4, {kJaw, kJoy}), 1, GST_SECOND)), expected);
  EXPECT_EQ(stat(h_, "gaps"), 0u);
  EXPECT_EQ(stat(h_, "recovered"), 0u);
  EXPECT_EQ(stat(h_, "faps-recovered"), 0u);
}

TEST_F(RtpPfapDepayTest, UncoveredGapIsUncertainAndAsksForACompleteStateUntilOneComes) {
  start_stream(h_, 0);
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 1, 100 * GST_MSECOND)).at(0).flags, 0);
  EXPECT_EQ(pull_requests(h_), 0);

  // 2 to 6 are lost; 7 covers only 2 packets, so its entries are not applied.
  const std::vector<Event> uncovered = {
      phoneme_event(kGood, {}, PFAP_FLAG_UNCERTAIN, GST_SECOND, /*discont=*/true)};
  EXPECT_EQ(push(h_, rtp_packet(dynamic_payload(2, {kJoy}), 7, GST_SECOND)), uncovered);
  EXPECT_EQ(pull_requests(h_), 1);
  // Asked again only after a second of packet time: the request or the answer may be lost.
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 8, 1500 * GST_MSECOND)).at(0).flags,
            PFAP_FLAG_UNCERTAIN);
  EXPECT_EQ(pull_requests(h_), 0);
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 9, 2 * GST_SECOND)).at(0).flags,
            PFAP_FLAG_UNCERTAIN);
  EXPECT_EQ(pull_requests(h_), 1);

  const GstClockTime t = 2200 * GST_MSECOND;
  const std::vector<Event> complete = {state_event(PFAP_EVENT_COMPLETE, {kJaw, kJoy}, t)};
  EXPECT_EQ(push(h_, rtp_packet(complete_payload({kJaw, kJoy}), 10, t)), complete);
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 11, 3500 * GST_MSECOND)).at(0).flags, 0);
  EXPECT_EQ(pull_requests(h_), 0);

  EXPECT_EQ(stat(h_, "lost"), 5u);
  EXPECT_EQ(stat(h_, "gaps"), 1u);
  EXPECT_EQ(stat(h_, "recovered"), 0u);
  EXPECT_EQ(stat(h_, "requests"), 2u);
  EXPECT_EQ(stat(h_, "complete-states"), 2u);
  EXPECT_EQ(stat(h_, "complete-changes"), 1u);
}

TEST_F(RtpPfapDepayTest, WithoutRequestRecoveryAnUncoveredGapAsksForNothing) {
  gboolean request_recovery = FALSE;
  g_object_get(h_->element, "request-recovery", &request_recovery, nullptr);
  EXPECT_TRUE(request_recovery);  // the default
  g_object_set(h_->element, "request-recovery", FALSE, nullptr);

  start_stream(h_, 0);
  push(h_, rtp_packet(good_payload(), 1, 0));
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 7, GST_SECOND)).at(0).flags, PFAP_FLAG_UNCERTAIN);
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 8, 3 * GST_SECOND)).at(0).flags,
            PFAP_FLAG_UNCERTAIN);
  EXPECT_EQ(pull_requests(h_), 0);
  EXPECT_EQ(stat(h_, "requests"), 0u);
}

// A depayloader cannot tell a stream's first packet from one it joined late.
TEST_F(RtpPfapDepayTest, StreamThatStartsWithDataIsUncertainAndAsksForACompleteState) {
  const std::vector<Event> expected = {phoneme_event(kGood, {}, PFAP_FLAG_UNCERTAIN, 0)};
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 1, 0)), expected);
  EXPECT_EQ(pull_requests(h_), 1);
  EXPECT_EQ(stat(h_, "lost"), 0u);
}

TEST_F(RtpPfapDepayTest, StreamThatStartsWithAnAllZeroCompleteStateIsWholeAndOutputsNothing) {
  EXPECT_TRUE(push(h_, rtp_packet(complete_payload(), 1, 0)).empty());
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 2, GST_SECOND)).at(0).flags, 0);
  EXPECT_EQ(pull_requests(h_), 0);
  EXPECT_EQ(stat(h_, "complete-states"), 1u);
  EXPECT_EQ(stat(h_, "complete-changes"), 0u);
}

// An unchanged state says nothing new, and a stream without loss stays what was sent.
TEST_F(RtpPfapDepayTest, CompleteStateEqualToTheCurrentStateOutputsNothing) {
  start_stream(h_, 0);
  const Fap jaw_at_once{3, -500, 0, Curve::kLinear};
  push(h_, rtp_packet(dynamic_payload(1, {}, {kJaw}), 1, 0));
  // kJaw has settled by then; its value with no transition is the same state.
  EXPECT_TRUE(push(h_, rtp_packet(complete_payload({jaw_at_once}), 2, GST_SECOND)).empty());

  const Fap jaw_closed{3, 0, 0, Curve::kLinear};
  const std::vector<Event> changed = {
      state_event(PFAP_EVENT_COMPLETE, {jaw_closed}, 2 * GST_SECOND)};
  EXPECT_EQ(push(h_, rtp_packet(complete_payload({jaw_closed}), 3, 2 * GST_SECOND)), changed);
  EXPECT_EQ(stat(h_, "complete-states"), 3u);
  EXPECT_EQ(stat(h_, "complete-changes"), 1u);
}

TEST_F(RtpPfapDepayTest, NewSsrcStartsANewStream) {
  start_stream(h_, 0);
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 1, 0)).at(0).flags, 0);
  // A restarted sender: no loss counted between the two, and it may be joined mid-stream.
  const std::vector<Event> joined = {
      phoneme_event(kGood, {}, PFAP_FLAG_UNCERTAIN, GST_SECOND, /*discont=*/true)};
  EXPECT_EQ(push(h_, with_ssrc(rtp_packet(good_payload(), 40000, GST_SECOND), kSsrc + 1)), joined);
  EXPECT_EQ(pull_requests(h_), 1);
  EXPECT_EQ(stat(h_, "lost"), 0u);

  // A third sender that begins with a complete state is whole at once.
  EXPECT_TRUE(
      push(h_, with_ssrc(rtp_packet(complete_payload(), 7, 2 * GST_SECOND), kSsrc + 2)).empty());
  EXPECT_EQ(
      push(h_, with_ssrc(rtp_packet(good_payload(), 8, 3 * GST_SECOND), kSsrc + 2)).at(0).flags, 0);
  EXPECT_EQ(pull_requests(h_), 0);
}

// rtpjitterbuffer's packet-lost event says the loss before the next packet does, but not
// whether that packet's recovery covers it: the loss is counted there.
TEST_F(RtpPfapDepayTest, PacketLostEventIsCountedAndBecomesAGap) {
  start_stream(h_, 0);
  push(h_, rtp_packet(good_payload(), 1, 0));
  while (GstEvent* event = gst_harness_try_pull_event(h_)) gst_event_unref(event);
  GstStructure* lost =
      gst_structure_new("GstRTPPacketLost", "seqnum", G_TYPE_UINT, 2u, "timestamp", G_TYPE_UINT64,
                        GST_SECOND, "duration", G_TYPE_UINT64, 100 * GST_MSECOND, nullptr);
  EXPECT_TRUE(gst_harness_push_event(h_, gst_event_new_custom(GST_EVENT_CUSTOM_DOWNSTREAM, lost)));

  GstEvent* gap = gst_harness_try_pull_event(h_);
  ASSERT_NE(gap, nullptr);
  ASSERT_EQ(GST_EVENT_TYPE(gap), GST_EVENT_GAP);
  GstClockTime start = GST_CLOCK_TIME_NONE;
  GstClockTime duration = GST_CLOCK_TIME_NONE;
  gst_event_parse_gap(gap, &start, &duration);
  EXPECT_EQ(start, GST_SECOND);
  EXPECT_EQ(duration, 100 * GST_MSECOND);
  gst_event_unref(gap);
  EXPECT_EQ(stat(h_, "packet-lost-events"), 1u);
  EXPECT_EQ(stat(h_, "lost"), 0u);

  push(h_, rtp_packet(good_payload(), 3, 2 * GST_SECOND));
  EXPECT_EQ(stat(h_, "lost"), 1u);
}

// rtpulpfecdec renumbers what it passes on and reports a packet it could not rebuild with a
// packet-lost event without a sequence number: no gap shows, so the state is uncertain.
TEST_F(RtpPfapDepayTest, PacketLostEventWithoutSeqnumMakesTheStateUncertainAndAsks) {
  start_stream(h_, 0);
  push(h_, rtp_packet(good_payload(), 1, 0));
  while (GstEvent* event = gst_harness_try_pull_event(h_)) gst_event_unref(event);
  GstStructure* lost = gst_structure_new("GstRTPPacketLost", "timestamp", G_TYPE_UINT64, GST_SECOND,
                                         "duration", G_TYPE_UINT64, 100 * GST_MSECOND,
                                         "might-have-been-fec", G_TYPE_BOOLEAN, TRUE, nullptr);
  EXPECT_TRUE(gst_harness_push_event(h_, gst_event_new_custom(GST_EVENT_CUSTOM_DOWNSTREAM, lost)));
  EXPECT_EQ(pull_requests(h_), 0);

  const std::vector<Event> next = push(h_, rtp_packet(good_payload(), 2, 2 * GST_SECOND));
  ASSERT_EQ(next.size(), 1u);
  EXPECT_EQ(next[0].flags, PFAP_FLAG_UNCERTAIN);
  EXPECT_EQ(pull_requests(h_), 1);
}

TEST_F(RtpPfapDepayTest, StreamStartOnTheSourceSideIsSparse) {
  push(h_, rtp_packet(good_payload(), 1, 0));
  GstEvent* upstream = gst_pad_get_sticky_event(h_->srcpad, GST_EVENT_STREAM_START, 0);
  GstEvent* downstream = gst_pad_get_sticky_event(h_->sinkpad, GST_EVENT_STREAM_START, 0);
  ASSERT_NE(downstream, nullptr);
  GstStreamFlags flags = GST_STREAM_FLAG_NONE;
  gst_event_parse_stream_flags(downstream, &flags);
  EXPECT_TRUE(flags & GST_STREAM_FLAG_SPARSE);
  const gchar* upstream_id = nullptr;
  const gchar* downstream_id = nullptr;
  gst_event_parse_stream_start(upstream, &upstream_id);
  gst_event_parse_stream_start(downstream, &downstream_id);
  EXPECT_STREQ(downstream_id, upstream_id);  // the same stream, only marked
  gst_event_unref(upstream);
  gst_event_unref(downstream);
}

TEST_F(RtpPfapDepayTest, AlphabetIsPassedToTheSourceCaps) {
  gst_harness_set_src_caps_str(h_, (std::string(kCaps) + ",alphabet=(string)sampa").c_str());
  push(h_, rtp_packet(good_payload(), 1, 0));
  GstCaps* caps = gst_pad_get_current_caps(h_->sinkpad);
  ASSERT_NE(caps, nullptr);
  const GstStructure* s = gst_caps_get_structure(caps, 0);
  EXPECT_TRUE(gst_structure_has_name(s, "application/x-pfap"));
  EXPECT_STREQ(gst_structure_get_string(s, "alphabet"), "sampa");
  gst_caps_unref(caps);
}

// The error a refused caps event posts: the caps are stored when pushed and refused when the
// next buffer brings them in.
std::string refusal_of(const std::string& caps_string) {
  GstHarness* h = gst_harness_new("rtppfapdepay");
  GstBus* bus = gst_bus_new();
  gst_element_set_bus(h->element, bus);
  GstCaps* caps = gst_caps_from_string(caps_string.c_str());
  gst_harness_push_event(h, gst_event_new_caps(caps));
  gst_caps_unref(caps);
  GstSegment segment;
  gst_segment_init(&segment, GST_FORMAT_TIME);
  gst_harness_push_event(h, gst_event_new_segment(&segment));
  EXPECT_EQ(gst_harness_push(h, rtp_packet(good_payload(), 1, 0)), GST_FLOW_NOT_NEGOTIATED);
  EXPECT_EQ(gst_harness_try_pull(h), nullptr);
  std::string text = "(no error posted)";
  if (GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR)) {
    GError* error = nullptr;
    gst_message_parse_error(message, &error, nullptr);
    text = error->message;
    g_error_free(error);
    gst_message_unref(message);
  }
  gst_bus_set_flushing(bus, TRUE);  // its messages hold the element
  gst_object_unref(bus);
  gst_harness_teardown(h);
  return text;
}

TEST(RtpPfapDepayCaps, AlphabetThatIsNotAStringIsRefusedSayingSo) {
  const std::string error = refusal_of(std::string(kCaps) + ",alphabet=(int)5");
  EXPECT_TRUE(contains(error, "alphabet")) << error;
}

TEST(RtpPfapDepayCaps, CapsWithoutClockRateAreRefused) {
  const std::string error =
      refusal_of("application/x-rtp,media=application,encoding-name=PFAP,payload=96");
  EXPECT_TRUE(contains(error, "clock-rate")) << error;
}

TEST(RtpPfapDepayCaps, ImplausibleClockRatesAreRefusedAsMissingOnes) {
  for (const char* rate : {"1", "999"}) {
    const std::string error = refusal_of(
        std::string("application/x-rtp,media=application,encoding-name=PFAP,payload=96,clock-rate=") +
        rate);
    EXPECT_TRUE(contains(error, "no clock-rate, or one below 1000 Hz")) << rate << ": " << error;
  }
}

// What udpsrc does with caps that lack a clock-rate: it fixates against the template (to
// clock-rate=1), and the depayloader must say so rather than run hours off.
TEST(RtpPfapDepayCaps, UdpsrcWithoutClockRateIsAnErrorNamingIt) {
  pfap::testing::Pipeline p(
      "udpsrc address=127.0.0.1 port=0 caps=\"application/x-rtp,media=application,"
      "encoding-name=PFAP\" name=src ! rtppfapdepay ! fakesink");
  ASSERT_TRUE(p.ok()) << p.error();
  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  const guint port = pfap::testing::bound_port(p.by_name("src"));
  // One packet makes udpsrc negotiate.
  GstElement* sender = gst_parse_launch("appsrc name=in ! udpsink host=127.0.0.1 name=out", nullptr);
  ASSERT_NE(sender, nullptr);
  GstElement* out = gst_bin_get_by_name(GST_BIN(sender), "out");
  g_object_set(out, "port", static_cast<gint>(port), nullptr);
  gst_object_unref(out);
  GstElement* in = gst_bin_get_by_name(GST_BIN(sender), "in");
  gst_element_set_state(sender, GST_STATE_PLAYING);
  pfap::testing::push(in, rtp_packet(good_payload(), 1, 0));
  const std::string error = p.wait_eos(std::chrono::seconds(5));
  gst_element_set_state(sender, GST_STATE_NULL);
  gst_object_unref(in);
  gst_object_unref(sender);
  EXPECT_TRUE(contains(error, "no clock-rate, or one below 1000 Hz")) << error;
}

// The PTS comes from upstream, where rtpjitterbuffer makes it from the RTP timestamp at the
// caps' clock rate; phoneme offsets within a packet are milliseconds whatever the rate.
TEST(RtpPfapDepayClockRate, PtsAt90kHzFollowTheRtpTimestamps) {
  GstHarness* h = gst_harness_new_parse("rtpjitterbuffer mode=none latency=0 ! rtppfapdepay");
  gst_harness_set_src_caps_str(
      h, "application/x-rtp,media=application,clock-rate=90000,encoding-name=PFAP,payload=96");
  const Phoneme p{.symbol = 3, .duration_ms = 40};
  Packet packet;
  packet.add_phoneme(p, {});
  packet.add_phoneme(p, {});
  std::vector<Event> events;
  for (guint16 i = 0; i < 3; ++i) {
    const GstClockTime t = i * 500 * GST_MSECOND;
    GstBuffer* buffer = rtp_packet(encode(packet), i, t, false, 90000);
    GST_BUFFER_DTS(buffer) = t;  // arrival time, which the jitterbuffer reads
    GST_BUFFER_PTS(buffer) = GST_CLOCK_TIME_NONE;
    ASSERT_EQ(gst_harness_push(h, buffer), GST_FLOW_OK);
  }
  for (int i = 0; i < 6; ++i) {
    GstBuffer* buffer = gst_harness_pull(h);
    ASSERT_NE(buffer, nullptr);
    events.push_back(read_event(buffer));
    gst_buffer_unref(buffer);
  }
  for (size_t i = 0; i < events.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(events[i].pts, (i / 2) * 500 * GST_MSECOND + (i % 2) * 40 * GST_MSECOND);
    EXPECT_EQ(events[i].duration, 40 * GST_MSECOND);
  }
  gst_harness_teardown(h);
}

TEST_F(RtpPfapDepayTest, EosPassesThrough) {
  push(h_, rtp_packet(good_payload(), 1, 0));
  EXPECT_TRUE(gst_harness_push_event(h_, gst_event_new_eos()));
  bool saw_eos = false;
  while (GstEvent* event = gst_harness_try_pull_event(h_)) {
    saw_eos |= GST_EVENT_TYPE(event) == GST_EVENT_EOS;
    gst_event_unref(event);
  }
  EXPECT_TRUE(saw_eos);
}

// After a seek the stream goes on somewhere else: a new stream, maybe joined mid-way.
TEST_F(RtpPfapDepayTest, FlushStartsANewStreamButKeepsTheCounters) {
  start_stream(h_, 9);
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 10, 0)).at(0).flags, 0);
  EXPECT_TRUE(gst_harness_push_event(h_, gst_event_new_flush_start()));
  EXPECT_TRUE(gst_harness_push_event(h_, gst_event_new_flush_stop(TRUE)));
  GstSegment segment;
  gst_segment_init(&segment, GST_FORMAT_TIME);
  EXPECT_TRUE(gst_harness_push_event(h_, gst_event_new_segment(&segment)));

  const std::vector<Event> expected = {phoneme_event(kGood, {}, PFAP_FLAG_UNCERTAIN, GST_SECOND)};
  EXPECT_EQ(push(h_, rtp_packet(good_payload(), 5000, GST_SECOND)), expected);
  EXPECT_EQ(pull_requests(h_), 1);
  EXPECT_EQ(stat(h_, "lost"), 0u);
  EXPECT_EQ(stat(h_, "packets"), 3u);
}

TEST_F(RtpPfapDepayTest, GoingFromReadyToPausedClearsTheCounters) {
  push(h_, rtp_packet(good_payload(), 10, 0));
  ASSERT_EQ(gst_element_set_state(h_->element, GST_STATE_READY), GST_STATE_CHANGE_SUCCESS);
  EXPECT_EQ(stat(h_, "packets"), 1u);  // still readable once stopped
  gst_harness_play(h_);
  EXPECT_EQ(stat(h_, "packets"), 0u);
}

}  // namespace
}  // namespace pfap

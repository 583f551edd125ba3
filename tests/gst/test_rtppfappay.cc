// SPDX-License-Identifier: LGPL-2.1-or-later
// rtppfappay: x-pfap phoneme buffers in, PFAP RTP packets out, checked by decoding them.
#include <gst/check/gstharness.h>
#include <gst/rtp/gstrtpbuffer.h>
#include <gst/sdp/gstsdpmessage.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <future>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "element_harness.h"
#include "pfap/markup.h"
#include "pfap/packetizer.h"
#include "pfap/payload.h"
#include "pfap/recovery.h"
#include "glib_log.h"
#include "pfap_buffers.h"

namespace {

using pfap::Curve;
using pfap::Fap;
using pfap::Phoneme;

constexpr GstClockTime kMs = GST_MSECOND;

Phoneme phoneme(uint8_t symbol, uint16_t duration_ms, bool end_of_text = false) {
  return {symbol, duration_ms, 60, false, false, end_of_text};
}

Fap fap(uint8_t index, int32_t amplitude) { return {index, amplitude, 200, Curve::kLinear}; }

struct Input {
  Phoneme phoneme;
  std::vector<Fap> faps;
  GstClockTime pts = 0;
  bool sentence_start = false;
};

// One RTP packet from the payloader, its payload decoded.
struct RtpPacket {
  bool marker = false;
  uint16_t seqnum = 0;
  uint32_t timestamp = 0;
  size_t size = 0;  // the whole RTP packet
  GstClockTime pts = GST_CLOCK_TIME_NONE;
  GstClockTime duration = GST_CLOCK_TIME_NONE;
  pfap::Packet packet;
};

// `count` contiguous phonemes of `duration_ms` each from `start`, without FAPs; the first
// starts a sentence, the last ends the text when `end_of_text`.
std::vector<Input> sentence(GstClockTime start, int count, uint16_t duration_ms, bool end_of_text) {
  std::vector<Input> inputs;
  for (int i = 0; i < count; ++i) {
    inputs.push_back(
        {phoneme(static_cast<uint8_t>(i + 1), duration_ms, end_of_text && i == count - 1),
         {},
         start + static_cast<GstClockTime>(i) * duration_ms * kMs,
         i == 0});
  }
  return inputs;
}

class Payloader : public pfap::testing::ElementHarness {
 public:
  // `downstream` restricts the caps the payloader may send (e.g. a clock-rate), as a
  // capsfilter after it would.
  explicit Payloader(const char* input_caps = PFAP_MARKUP_CAPS, const char* downstream = nullptr)
      : ElementHarness("rtppfappay") {
    if (downstream != nullptr) gst_harness_set_sink_caps_str(h_, downstream);
    gst_harness_set_src_caps_str(h_, input_caps);
  }

  void push(GstBuffer* buffer) { ASSERT_EQ(gst_harness_push(h_, buffer), GST_FLOW_OK); }
  void push(const Input& in) {
    push(pfap::testing::phoneme_buffer(in.phoneme, in.faps, in.pts, in.sentence_start));
  }
  void push(const std::vector<Input>& inputs) {
    for (const Input& in : inputs) push(in);
  }
  void push_event(GstEvent* event) { ASSERT_TRUE(gst_harness_push_event(h_, event)); }

  // Every packet sent so far.
  std::vector<RtpPacket> pull_all() {
    std::vector<RtpPacket> packets;
    while (GstBuffer* buffer = gst_harness_try_pull(h_)) {
      RtpPacket p;
      GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
      EXPECT_TRUE(gst_rtp_buffer_map(buffer, GST_MAP_READ, &rtp));
      p.marker = gst_rtp_buffer_get_marker(&rtp);
      p.seqnum = gst_rtp_buffer_get_seq(&rtp);
      p.timestamp = gst_rtp_buffer_get_timestamp(&rtp);
      const auto* payload = static_cast<const uint8_t*>(gst_rtp_buffer_get_payload(&rtp));
      const pfap::DecodeResult decoded =
          pfap::decode_payload({payload, gst_rtp_buffer_get_payload_len(&rtp)}, p.packet);
      EXPECT_TRUE(decoded.ok()) << pfap::to_string(decoded.status) << " at " << decoded.offset;
      gst_rtp_buffer_unmap(&rtp);
      p.size = gst_buffer_get_size(buffer);
      p.pts = GST_BUFFER_PTS(buffer);
      p.duration = GST_BUFFER_DURATION(buffer);
      gst_buffer_unref(buffer);
      packets.push_back(std::move(p));
    }
    return packets;
  }

  // The data packets sent so far: every packet but the complete recoveries (the one that
  // starts each stream, periodic ones), for tests of packetizing.
  std::vector<RtpPacket> pull_data() {
    std::vector<RtpPacket> packets = pull_all();
    std::erase_if(packets, [](const RtpPacket& p) {
      return p.packet.recovery_kind == pfap::RecoveryKind::kComplete;
    });
    return packets;
  }

  // An event sent upstream into the payloader's src pad, as a downstream element would.
  bool push_upstream(GstEvent* event) { return gst_harness_push_upstream_event(h_, event); }

  // The GError of the next warning posted, or nullptr (the caller frees it).
  GError* pop_warning() {
    GstMessage* message = gst_bus_pop_filtered(bus_, GST_MESSAGE_WARNING);
    if (message == nullptr) return nullptr;
    GError* error = nullptr;
    gst_message_parse_warning(message, &error, nullptr);
    gst_message_unref(message);
    return error;
  }

  std::string output_caps() {
    GstCaps* caps = gst_pad_get_current_caps(h_->sinkpad);
    if (caps == nullptr) return {};
    gchar* text = gst_caps_to_string(caps);
    std::string result = text;
    g_free(text);
    gst_caps_unref(caps);
    return result;
  }
};

// The phonemes of `packets` in order, each with its FAPs.
std::vector<Input> received(const std::vector<RtpPacket>& packets) {
  std::vector<Input> out;
  for (const RtpPacket& p : packets) {
    for (size_t i = 0; i < p.packet.phonemes.size(); ++i) {
      const auto faps = p.packet.faps_of(i);
      out.push_back({p.packet.phonemes[i].phoneme, {faps.begin(), faps.end()}});
    }
  }
  return out;
}

void expect_same_phonemes(const std::vector<Input>& sent, const std::vector<Input>& got) {
  ASSERT_EQ(got.size(), sent.size());
  for (size_t i = 0; i < sent.size(); ++i) {
    EXPECT_EQ(got[i].phoneme, sent[i].phoneme) << "phoneme " << i;
    EXPECT_EQ(got[i].faps, sent[i].faps) << "FAPs of phoneme " << i;
  }
}

size_t phoneme_count(const RtpPacket& p) { return p.packet.phonemes.size(); }

// A state event (recovered or complete FAP state) as an x-pfap buffer.
GstBuffer* state_buffer(PfapEventKind kind, const PfapFap& fap, GstClockTime pts) {
  const PfapEventHeader header{static_cast<uint8_t>(kind), 0, 0, 0, 0, 1};
  const size_t size = pfap_markup_size(1);
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, size, nullptr);
  GstMapInfo map;
  gst_buffer_map(buffer, &map, GST_MAP_WRITE);
  EXPECT_EQ(pfap_markup_write(&header, &fap, map.data, size), 0);
  gst_buffer_unmap(buffer, &map);
  GST_BUFFER_PTS(buffer) = pts;
  return buffer;
}

TEST(RtpPfapPay, FactoryMetadataDescribesAnRtpPayloader) {
  GstElementFactory* factory = gst_element_factory_find("rtppfappay");
  ASSERT_NE(factory, nullptr);
  for (const char* key : {GST_ELEMENT_METADATA_LONGNAME, GST_ELEMENT_METADATA_KLASS,
                          GST_ELEMENT_METADATA_DESCRIPTION, GST_ELEMENT_METADATA_AUTHOR}) {
    const gchar* value = gst_element_factory_get_metadata(factory, key);
    ASSERT_NE(value, nullptr) << key;
    EXPECT_STRNE(value, "") << key;
  }
  EXPECT_STREQ(gst_element_factory_get_metadata(factory, GST_ELEMENT_METADATA_KLASS),
               "Codec/Payloader/Network/RTP");
  gst_object_unref(factory);
}

TEST(RtpPfapPay, MaxDelayPropertyIsDocumentedAndDefaultsTo100Ms) {
  GstElement* element = gst_element_factory_make("rtppfappay", nullptr);
  ASSERT_NE(element, nullptr);
  GParamSpec* pspec = g_object_class_find_property(G_OBJECT_GET_CLASS(element), "max-delay");
  ASSERT_NE(pspec, nullptr);
  ASSERT_EQ(G_PARAM_SPEC_VALUE_TYPE(pspec), G_TYPE_UINT);
  EXPECT_STRNE(g_param_spec_get_blurb(pspec), "");
  const GParamSpecUInt* spec = G_PARAM_SPEC_UINT(pspec);
  EXPECT_EQ(spec->default_value, 100u);
  EXPECT_EQ(spec->minimum, 0u);
  EXPECT_EQ(spec->maximum, 60000u);
  guint max_delay = 0;
  g_object_get(element, "max-delay", &max_delay, nullptr);
  EXPECT_EQ(max_delay, 100u);
  gst_object_unref(element);
}

// gst-launch reads max-delay=-5 as 4294967291: the range refuses it (GObject warns) and the
// value stays.
TEST(RtpPfapPay, NegativeOrHugeMsPropertiesAreRefusedByTheirRange) {
  GstElement* element = gst_element_factory_make("rtppfappay", nullptr);
  ASSERT_NE(element, nullptr);
  for (const char* name : {"max-delay", "complete-recovery-interval"}) {
    guint before = 0;
    g_object_get(element, name, &before, nullptr);
    {
      pfap::testing::GlibLogCounter log;
      gst_util_set_object_arg(G_OBJECT(element), name, "-5");
      EXPECT_EQ(log.count(), 1) << name;
      EXPECT_NE(log.first().find("out of range"), std::string::npos) << log.first();
    }
    guint after = 0;
    g_object_get(element, name, &after, nullptr);
    EXPECT_EQ(after, before) << name;
  }
  gst_object_unref(element);
}

TEST(RtpPfapPay, OutputCapsCarryPfapAt44100AndTheAlphabetAsAString) {
  Payloader pay("application/x-pfap, alphabet=(string)x-sampa");
  GstCaps* caps = gst_pad_get_current_caps(pay.harness()->sinkpad);
  ASSERT_NE(caps, nullptr);
  const GstStructure* s = gst_caps_get_structure(caps, 0);
  EXPECT_TRUE(gst_structure_has_name(s, "application/x-rtp"));
  EXPECT_STREQ(gst_structure_get_string(s, "media"), "application");
  EXPECT_STREQ(gst_structure_get_string(s, "encoding-name"), "PFAP");
  gint clock_rate = 0;
  EXPECT_TRUE(gst_structure_get_int(s, "clock-rate", &clock_rate));
  EXPECT_EQ(clock_rate, 44100);
  EXPECT_STREQ(gst_structure_get_string(s, "alphabet"), "x-sampa");

  // A string field, so it reaches the SDP.
  GstSDPMedia* media = nullptr;
  gst_sdp_media_new(&media);
  ASSERT_EQ(gst_sdp_media_set_media_from_caps(caps, media), GST_SDP_OK);
  const gchar* fmtp = gst_sdp_media_get_attribute_val(media, "fmtp");
  ASSERT_NE(fmtp, nullptr);
  EXPECT_NE(std::string(fmtp).find("alphabet=x-sampa"), std::string::npos) << fmtp;
  gst_sdp_media_free(media);
  gst_caps_unref(caps);
}

TEST(RtpPfapPay, OutputCapsHaveNoAlphabetWhenTheInputHasNone) {
  Payloader pay;
  EXPECT_EQ(pay.output_caps().find("alphabet"), std::string::npos) << pay.output_caps();
  EXPECT_NE(pay.output_caps().find("encoding-name=(string)PFAP"), std::string::npos);
}

TEST(RtpPfapPay, MarkerIsSetExactlyOnPacketsWhoseFirstPhonemeStartsASentence) {
  Payloader pay;  // max-delay 100 ms: 40 ms phonemes go three to a packet
  std::vector<Input> inputs = sentence(0, 5, 40, false);
  std::vector<Input> second = sentence(200 * kMs, 2, 40, true);
  inputs.insert(inputs.end(), second.begin(), second.end());
  pay.push(inputs);

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 3u);
  EXPECT_TRUE(packets[0].marker);  // sentence start
  EXPECT_EQ(phoneme_count(packets[0]), 3u);
  EXPECT_FALSE(packets[1].marker);  // the same sentence, split by max-delay
  EXPECT_EQ(phoneme_count(packets[1]), 2u);
  EXPECT_TRUE(packets[2].marker);  // the next sentence, contiguous, still a new packet
  EXPECT_EQ(phoneme_count(packets[2]), 2u);
  expect_same_phonemes(inputs, received(packets));
}

TEST(RtpPfapPay, EndOfTextSendsThePacketWithoutWaitingForEos) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 10000u, nullptr);
  const std::vector<Input> inputs = sentence(0, 3, 50, true);
  pay.push(inputs[0]);
  pay.push(inputs[1]);
  EXPECT_EQ(gst_harness_buffers_received(pay.harness()), 0u);
  pay.push(inputs[2]);

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 1u);
  expect_same_phonemes(inputs, received(packets));
  EXPECT_TRUE(packets[0].packet.phonemes.back().phoneme.end_of_text);
}

TEST(RtpPfapPay, PacketPtsIsItsFirstStartAndDurationItsPhonemesTotal) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 10000u, nullptr);
  std::vector<Input> inputs = sentence(2 * GST_SECOND, 3, 50, false);
  inputs.push_back({phoneme(9, 70, true), {}, inputs.back().pts + 50 * kMs});
  pay.push(inputs);

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0].pts, 2 * GST_SECOND);
  EXPECT_EQ(packets[0].duration, 220 * kMs);
}

// Starts on whole ticks of the clock: the base class floors running time to ticks where
// rtp_ticks rounds to the nearest, so between ticks the two may differ by one.
void expect_timestamps_follow_starts(Payloader& pay, uint32_t clock_rate,
                                     const std::vector<GstClockTime>& starts) {
  g_object_set(pay.element(), "max-delay", 0u, nullptr);  // a packet per phoneme
  for (GstClockTime start : starts) pay.push({phoneme(1, 7), {}, start});

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), starts.size());
  for (size_t i = 1; i < packets.size(); ++i) {
    const uint32_t expected = pfap::rtp_ticks(static_cast<int64_t>(starts[i]), clock_rate) -
                              pfap::rtp_ticks(static_cast<int64_t>(starts[0]), clock_rate);
    EXPECT_EQ(packets[i].timestamp - packets[0].timestamp, expected) << "packet " << i;
  }
}

TEST(RtpPfapPay, RtpTimestampsAdvanceByStartDifferenceTimes44100ByDefault) {
  Payloader pay;
  expect_timestamps_follow_starts(
      pay, 44100, {GST_SECOND, GST_SECOND + 10 * kMs, GST_SECOND + 370 * kMs, 61 * GST_SECOND});
}

TEST(RtpPfapPay, ClockRateFollowsADownstreamRestrictionTo90000) {
  Payloader pay(PFAP_MARKUP_CAPS, "application/x-rtp, clock-rate=(int)90000");
  EXPECT_NE(pay.output_caps().find("clock-rate=(int)90000"), std::string::npos)
      << pay.output_caps();
  expect_timestamps_follow_starts(
      pay, 90000, {GST_SECOND, GST_SECOND + 7 * kMs, GST_SECOND + 1013 * kMs, 100 * GST_SECOND});
}

class RtpPfapPayMtu : public ::testing::TestWithParam<guint> {};

TEST_P(RtpPfapPayMtu, PacketsFitTheMtuAndKeepPhonemesInOrderWithTheirFaps) {
  const guint mtu = GetParam();
  Payloader pay;
  g_object_set(pay.element(), "mtu", mtu, "max-delay", 60000u, nullptr);
  // Every other phoneme has a FAP: a phoneme and its FAP fit even the smallest MTU.
  std::vector<Input> inputs = sentence(0, 30, 20, true);
  for (size_t i = 0; i < inputs.size(); i += 2) {
    inputs[i].faps = {fap(static_cast<uint8_t>(3 + i), -100 * static_cast<int32_t>(i))};
  }
  pay.push(inputs);

  const std::vector<RtpPacket> packets = pay.pull_data();
  if (mtu < 400) {
    EXPECT_GT(packets.size(), 1u);
  } else {
    EXPECT_EQ(packets.size(), 1u);
  }
  size_t first = 0;
  for (const RtpPacket& p : packets) {
    EXPECT_LE(p.size, mtu);
    ASSERT_LT(first, inputs.size());
    EXPECT_EQ(p.pts, inputs[first].pts) << "a packet's time is its first phoneme's start";
    first += phoneme_count(p);
  }
  expect_same_phonemes(inputs, received(packets));
}

INSTANTIATE_TEST_SUITE_P(Mtus, RtpPfapPayMtu, ::testing::Values(28u, 64u, 200u, 1400u));

TEST(RtpPfapPay, MaxDelayZeroSendsEachPhonemeInAPacketOfItsOwn) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 0u, nullptr);
  const std::vector<Input> inputs = sentence(0, 4, 30, false);
  pay.push(inputs);

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 4u);
  for (const RtpPacket& p : packets) EXPECT_EQ(phoneme_count(p), 1u);
  expect_same_phonemes(inputs, received(packets));
}

TEST(RtpPfapPay, LargeMaxDelayPacksContiguousPhonemesTogether) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 5000u, nullptr);
  const std::vector<Input> inputs = sentence(0, 20, 100, true);
  pay.push(inputs);

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 1u);
  expect_same_phonemes(inputs, received(packets));
}

TEST(RtpPfapPay, MaxDelayChangeTakesEffectFromTheNextPacket) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 5000u, nullptr);
  const std::vector<Input> inputs = sentence(0, 5, 30, false);
  pay.push(inputs[0]);
  pay.push(inputs[1]);
  g_object_set(pay.element(), "max-delay", 0u, nullptr);
  pay.push(inputs[2]);  // joins the pending packet, which keeps its 5000 ms
  EXPECT_EQ(gst_harness_buffers_received(pay.harness()), 0u);
  pay.push_event(gst_event_new_gap(90 * kMs, 0));
  pay.push(inputs[3]);
  pay.push(inputs[4]);

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 3u);
  EXPECT_EQ(phoneme_count(packets[0]), 3u);
  EXPECT_EQ(phoneme_count(packets[1]), 1u);
  EXPECT_EQ(phoneme_count(packets[2]), 1u);
  expect_same_phonemes(inputs, received(packets));
}

TEST(RtpPfapPay, MtuChangeTakesEffectFromTheNextPacket) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 0u, nullptr);
  pay.push({phoneme(1, 30), {fap(3, 1), fap(4, 2), fap(5, 3)}, 0, true});
  g_object_set(pay.element(), "mtu", 28u, nullptr);
  pay.push({phoneme(2, 30), {fap(3, 1), fap(4, 2), fap(5, 3)}, 30 * kMs});

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 2u);
  EXPECT_GT(packets[1].size, 28u);
  GError* warning = pay.pop_warning();  // only the second is oversized
  ASSERT_NE(warning, nullptr);
  g_error_free(warning);
  EXPECT_EQ(pay.pop_warning(), nullptr);
}

TEST(RtpPfapPay, LatencyIsUpstreamLatencyPlusMaxDelay) {
  Payloader pay;
  gst_harness_set_upstream_latency(pay.harness(), 10 * kMs);
  EXPECT_EQ(gst_harness_query_latency(pay.harness()), 110 * kMs);
  g_object_set(pay.element(), "max-delay", 0u, nullptr);
  EXPECT_EQ(gst_harness_query_latency(pay.harness()), 10 * kMs);
}

TEST(RtpPfapPay, MaxDelayChangeAsksThePipelineToRecomputeLatency) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 40u, nullptr);
  GstMessage* message = gst_bus_pop_filtered(pay.bus(), GST_MESSAGE_LATENCY);
  ASSERT_NE(message, nullptr);
  gst_message_unref(message);
}

// Each event after which no later phoneme may join the pending packet.
struct DrainingEvent {
  const char* name;
  GstEvent* (*make)();
};

class RtpPfapPayDrain : public ::testing::TestWithParam<DrainingEvent> {};

TEST_P(RtpPfapPayDrain, EventSendsThePendingPacket) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 5000u, nullptr);
  const std::vector<Input> inputs = sentence(0, 3, 40, false);
  pay.push(inputs);
  EXPECT_EQ(gst_harness_buffers_received(pay.harness()), 0u);
  pay.push_event(GetParam().make());

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 1u);
  expect_same_phonemes(inputs, received(packets));
}

INSTANTIATE_TEST_SUITE_P(
    RtpPfapPay, RtpPfapPayDrain,
    ::testing::Values(DrainingEvent{"Eos", [] { return gst_event_new_eos(); }},
                      DrainingEvent{"Gap", [] { return gst_event_new_gap(120 * kMs, GST_SECOND); }},
                      DrainingEvent{"NewSegment",
                                    [] {
                                      GstSegment segment;
                                      gst_segment_init(&segment, GST_FORMAT_TIME);
                                      segment.base = 10 * GST_SECOND;
                                      return gst_event_new_segment(&segment);
                                    }}),
    [](const ::testing::TestParamInfo<DrainingEvent>& info) { return info.param.name; });

TEST(RtpPfapPay, FlushDropsThePendingPacket) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 5000u, nullptr);
  pay.push(sentence(0, 3, 40, false));
  pay.push_event(gst_event_new_flush_start());
  pay.push_event(gst_event_new_flush_stop(TRUE));
  GstSegment segment;
  gst_segment_init(&segment, GST_FORMAT_TIME);
  pay.push_event(gst_event_new_segment(&segment));
  const std::vector<Input> after = sentence(GST_SECOND, 1, 40, true);
  pay.push(after);

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 1u);
  expect_same_phonemes(after, received(packets));
}

static GstPadProbeReturn record_alphabet(GstPad* pad, GstPadProbeInfo*, gpointer alphabets) {
  GstCaps* caps = gst_pad_get_current_caps(pad);
  const gchar* alphabet = gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet");
  static_cast<std::vector<std::string>*>(alphabets)->push_back(alphabet ? alphabet : "");
  gst_caps_unref(caps);
  return GST_PAD_PROBE_OK;
}

TEST(RtpPfapPay, NewCapsSendThePendingPacketUnderTheOldCaps) {
  Payloader pay("application/x-pfap, alphabet=(string)x-sampa");
  std::vector<std::string> alphabets;  // the output caps' alphabet when each packet arrived
  gst_pad_add_probe(pay.harness()->sinkpad, GST_PAD_PROBE_TYPE_BUFFER, record_alphabet, &alphabets,
                    nullptr);
  g_object_set(pay.element(), "max-delay", 5000u, "complete-recovery-interval", 0u, nullptr);
  pay.push(sentence(0, 2, 40, false));
  gst_harness_set_src_caps_str(pay.harness(), "application/x-pfap, alphabet=(string)ipa");
  pay.push(sentence(GST_SECOND, 1, 40, true));

  // The stream's complete recovery, then the two data packets.
  EXPECT_EQ(alphabets, (std::vector<std::string>{"x-sampa", "x-sampa", "ipa"}));
  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 2u);
  EXPECT_EQ(phoneme_count(packets[0]), 2u);
}

TEST(RtpPfapPay, MalformedBufferIsDroppedWithAWarningAndTheStreamGoesOn) {
  Payloader pay;
  const guint8 garbage[] = {PFAP_EVENT_PHONEME, 0, 1, 60, 0, 40, 0, 3};  // 3 FAPs missing
  pay.push(gst_buffer_new_memdup(garbage, sizeof garbage));
  GError* warning = pay.pop_warning();
  ASSERT_NE(warning, nullptr);
  EXPECT_TRUE(g_error_matches(warning, GST_STREAM_ERROR, GST_STREAM_ERROR_DECODE))
      << warning->message;
  g_error_free(warning);
  EXPECT_EQ(gst_harness_buffers_received(pay.harness()), 0u);

  const std::vector<Input> good = sentence(0, 1, 40, true);
  pay.push(good);
  expect_same_phonemes(good, received(pay.pull_data()));
}

TEST(RtpPfapPay, OversizedPhonemeStillGoesOutWithAWarning) {
  Payloader pay;
  g_object_set(pay.element(), "mtu", 28u, "max-delay", 5000u, nullptr);  // 16-byte payloads
  std::vector<Input> inputs = sentence(0, 3, 40, true);
  inputs[1].faps = {fap(3, 10), fap(4, -20), fap(5, 30), fap(6, -40), fap(7, 50)};
  pay.push(inputs);

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 3u);
  EXPECT_GT(packets[1].size, 28u);
  EXPECT_EQ(phoneme_count(packets[1]), 1u);
  expect_same_phonemes(inputs, received(packets));
  GError* warning = pay.pop_warning();
  ASSERT_NE(warning, nullptr);
  EXPECT_TRUE(g_error_matches(warning, GST_STREAM_ERROR, GST_STREAM_ERROR_ENCODE));
  g_error_free(warning);
  EXPECT_EQ(pay.pop_warning(), nullptr) << "one warning per oversized packet";
}

// Posted warnings, counted and taken off the bus.
size_t count_warnings(Payloader& pay) {
  size_t n = 0;
  while (GError* warning = pay.pop_warning()) {
    g_error_free(warning);
    ++n;
  }
  return n;
}

TEST(RtpPfapPay, OversizedPhonemesAreWarnedAboutAtThe1st2nd4th8thAndAllCounted) {
  Payloader pay;
  g_object_set(pay.element(), "mtu", 28u, "max-delay", 0u, nullptr);  // 16-byte payloads
  std::vector<Input> inputs = sentence(0, 100, 40, true);
  // 23 bytes each; at 0 they leave the complete state empty, so only the data is too large.
  for (Input& in : inputs) in.faps = {fap(3, 0), fap(4, 0), fap(5, 0)};
  pay.push(inputs);
  expect_same_phonemes(inputs, received(pay.pull_data()));
  EXPECT_EQ(pay.stat("oversized"), 100u);
  EXPECT_EQ(count_warnings(pay), 7u) << "the 1st, 2nd, 4th, ..., 64th";
}

TEST(RtpPfapPay, MalformedBuffersAreWarnedAboutAtThe1st2nd4th8thAndAllCounted) {
  Payloader pay;
  const guint8 garbage[] = {PFAP_EVENT_PHONEME, 0, 1, 60, 0, 40, 0, 3};  // 3 FAPs missing
  for (int i = 0; i < 20; ++i) pay.push(gst_buffer_new_memdup(garbage, sizeof garbage));
  EXPECT_EQ(pay.stat("malformed"), 20u);
  EXPECT_EQ(count_warnings(pay), 5u) << "the 1st, 2nd, 4th, 8th and 16th";
  EXPECT_EQ(gst_harness_buffers_received(pay.harness()), 0u);
}

TEST(RtpPfapPay, BackwardTimestampsSendNoMoreCompleteStatesThanForwardOnes) {
  // 300 phonemes of 100 ms, one packet each, forward and in reverse time order: one complete
  // state per second of speech either way (30), not one per packet.
  for (const bool reversed : {false, true}) {
    SCOPED_TRACE(reversed ? "reversed" : "forward");
    Payloader pay;
    g_object_set(pay.element(), "max-delay", 0u, nullptr);
    std::vector<Input> inputs = sentence(0, 300, 100, false);
    if (reversed) std::reverse(inputs.begin(), inputs.end());
    pay.push(inputs);
    EXPECT_EQ(pay.stat("packets"), 300u);
    EXPECT_EQ(pay.stat("complete-recoveries"), 30u);
  }
}

TEST(RtpPfapPay, StateEventsAreDroppedWithoutAWarning) {
  Payloader pay;
  const PfapFap fap{3, 1, 0, 100};
  pay.push(state_buffer(PFAP_EVENT_COMPLETE, fap, 0));
  pay.push(state_buffer(PFAP_EVENT_RECOVERED, fap, 0));
  EXPECT_EQ(gst_harness_buffers_received(pay.harness()), 0u);
  EXPECT_EQ(pay.pop_warning(), nullptr);

  const std::vector<Input> good = sentence(0, 1, 40, true);
  pay.push(good);
  expect_same_phonemes(good, received(pay.pull_data()));
}

TEST(RtpPfapPay, PhonemeWithoutPtsStartsWhereThePreviousOneEnded) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 0u, nullptr);
  pay.push({phoneme(1, 50), {}, GST_SECOND, true});
  pay.push({phoneme(2, 30), {}, GST_CLOCK_TIME_NONE});
  pay.push({phoneme(3, 20), {}, GST_CLOCK_TIME_NONE});

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 3u);
  EXPECT_EQ(packets[1].pts, GST_SECOND + 50 * kMs);
  EXPECT_EQ(packets[2].pts, GST_SECOND + 80 * kMs);
}

TEST(RtpPfapPay, FirstPhonemeWithoutPtsStartsAtTheSegmentStart) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 0u, nullptr);
  pay.push({phoneme(1, 50), {}, GST_CLOCK_TIME_NONE, true});

  const std::vector<RtpPacket> packets = pay.pull_data();
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0].pts, 0u);
}

// --- Recovery -------------------------------------------------------------------------------

bool is_complete(const RtpPacket& p) {
  return p.packet.recovery_kind == pfap::RecoveryKind::kComplete;
}

Fap entry(uint8_t index, int32_t amplitude, uint16_t transition_ms = 0,
          Curve curve = Curve::kLinear) {
  return {index, amplitude, transition_ms, curve};
}

// What rtpbin's session sends upstream when a receiver sends RTCP PLI or FIR for our SSRC
// (gst_rtp_session_request_key_unit in gstrtpsession.c).
GstEvent* rtcp_key_unit_request() {
  return gst_event_new_custom(GST_EVENT_CUSTOM_UPSTREAM,
                              gst_structure_new("GstForceKeyUnit", "ssrc", G_TYPE_UINT, 1234u,
                                                "all-headers", G_TYPE_BOOLEAN, TRUE, nullptr));
}

// gst_video_event_new_upstream_force_key_unit(GST_CLOCK_TIME_NONE, TRUE, 1), as an
// application sends it, spelled out: the element tests do not link gstreamer-video.
GstEvent* application_key_unit_request() {
  return gst_event_new_custom(
      GST_EVENT_CUSTOM_UPSTREAM,
      gst_structure_new("GstForceKeyUnit", "running-time", G_TYPE_UINT64, GST_CLOCK_TIME_NONE,
                        "all-headers", G_TYPE_BOOLEAN, TRUE, "count", G_TYPE_UINT, 1u, nullptr));
}

// Holds the payloader's stream lock from another thread while it lives, as a streaming
// thread in the middle of a buffer does.
class StreamBusy {
 public:
  explicit StreamBusy(GstElement* element) : pad_(gst_element_get_static_pad(element, "sink")) {
    std::promise<void> locked;
    std::future<void> is_locked = locked.get_future();
    thread_ = std::thread([this, &locked, released = release_.get_future()] {
      GST_PAD_STREAM_LOCK(pad_);
      locked.set_value();
      released.wait();
      GST_PAD_STREAM_UNLOCK(pad_);
    });
    is_locked.wait();
  }
  StreamBusy(const StreamBusy&) = delete;
  StreamBusy& operator=(const StreamBusy&) = delete;
  ~StreamBusy() {
    release_.set_value();
    thread_.join();
    gst_object_unref(pad_);
  }

 private:
  GstPad* pad_;
  std::promise<void> release_;
  std::thread thread_;
};

// One packet per phoneme, and no complete packets but the stream's first and requested ones.
void one_packet_per_phoneme(Payloader& pay) {
  g_object_set(pay.element(), "max-delay", 0u, "complete-recovery-interval", 0u, nullptr);
}

TEST(RtpPfapPay, RecoveryPropertiesAreDocumentedWithTheirDefaults) {
  GstElement* element = gst_element_factory_make("rtppfappay", nullptr);
  GObjectClass* klass = G_OBJECT_GET_CLASS(element);
  GParamSpec* depth = g_object_class_find_property(klass, "recovery-depth");
  ASSERT_NE(depth, nullptr);
  ASSERT_TRUE(G_IS_PARAM_SPEC_ENUM(depth));
  EXPECT_STRNE(g_param_spec_get_blurb(depth), "");
  EXPECT_EQ(G_PARAM_SPEC_ENUM(depth)->default_value, 4);
  GParamSpec* interval = g_object_class_find_property(klass, "complete-recovery-interval");
  ASSERT_NE(interval, nullptr);
  ASSERT_EQ(G_PARAM_SPEC_VALUE_TYPE(interval), G_TYPE_UINT);
  EXPECT_STRNE(g_param_spec_get_blurb(interval), "");
  EXPECT_EQ(G_PARAM_SPEC_UINT(interval)->default_value, 1000u);
  EXPECT_EQ(G_PARAM_SPEC_UINT(interval)->minimum, 0u);
  GParamSpec* stats = g_object_class_find_property(klass, "stats");
  ASSERT_NE(stats, nullptr);
  EXPECT_EQ(G_PARAM_SPEC_VALUE_TYPE(stats), GST_TYPE_STRUCTURE);
  gst_object_unref(element);
}

TEST(RtpPfapPay, RecoveryDepthValuesAreZeroAndTheCoveragesPpCanSignalWithWordNicks) {
  GstElement* element = gst_element_factory_make("rtppfappay", nullptr);
  GParamSpec* pspec = g_object_class_find_property(G_OBJECT_GET_CLASS(element), "recovery-depth");
  GEnumClass* enum_class = G_PARAM_SPEC_ENUM(pspec)->enum_class;
  std::vector<int> values;
  for (guint i = 0; i < enum_class->n_values; ++i) {
    const GEnumValue& v = enum_class->values[i];
    values.push_back(v.value);
    EXPECT_EQ(std::string(v.value_nick),
              v.value == 0   ? std::string("none")
              : v.value == 1 ? std::string("1-packet")
                             : std::to_string(v.value) + "-packets");
    EXPECT_STRNE(v.value_name, v.value_nick) << "a descriptive name";
  }
  std::vector<int> expected{0};
  expected.insert(expected.end(), std::begin(pfap::kCoverageSteps), std::end(pfap::kCoverageSteps));
  EXPECT_EQ(values, expected);
  gst_object_unref(element);
}

TEST(RtpPfapPay, RecoveryDepthIsSetFromItsNumberAsAStringAndRefusesOtherNumbers) {
  GstElement* element = gst_element_factory_make("rtppfappay", nullptr);
  gint depth = -1;
  gst_util_set_object_arg(G_OBJECT(element), "recovery-depth", "40");
  g_object_get(element, "recovery-depth", &depth, nullptr);
  EXPECT_EQ(depth, 40);
  gst_util_set_object_arg(G_OBJECT(element), "recovery-depth", "4");
  g_object_get(element, "recovery-depth", &depth, nullptr);
  EXPECT_EQ(depth, 4);
  gst_util_set_object_arg(G_OBJECT(element), "recovery-depth", "3");  // PP cannot say 3
  g_object_get(element, "recovery-depth", &depth, nullptr);
  EXPECT_EQ(depth, 4);
  gst_util_set_object_arg(G_OBJECT(element), "recovery-depth", "7-packets");
  g_object_get(element, "recovery-depth", &depth, nullptr);
  EXPECT_EQ(depth, 7);
  gst_util_set_object_arg(G_OBJECT(element), "recovery-depth", "none");
  g_object_get(element, "recovery-depth", &depth, nullptr);
  EXPECT_EQ(depth, 0);
  gst_object_unref(element);
}

TEST(RtpPfapPay, FirstPacketOfAStreamIsACompleteRecoveryThenDataAndAgainAfterAFlush) {
  Payloader pay;
  // Whatever the properties: no dynamic recovery, no periodic complete packets.
  g_object_set(pay.element(), "max-delay", 0u, "recovery-depth", 0, "complete-recovery-interval",
               0u, nullptr);
  pay.push({phoneme(1, 40), {fap(3, 100)}, GST_SECOND, true});
  pay.push({phoneme(2, 40), {}, GST_SECOND + 40 * kMs});

  std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 3u);
  EXPECT_TRUE(is_complete(packets[0]));
  // The state at the first data packet's start, before its bookmarks: every FAP at 0.
  EXPECT_TRUE(packets[0].packet.recovery.empty());
  EXPECT_EQ(packets[0].pts, GST_SECOND);
  EXPECT_EQ(packets[0].timestamp, packets[1].timestamp);
  EXPECT_FALSE(packets[0].marker);
  EXPECT_EQ(packets[0].duration, 0u);
  EXPECT_EQ(packets[1].seqnum, static_cast<uint16_t>(packets[0].seqnum + 1));
  EXPECT_FALSE(is_complete(packets[1]));
  EXPECT_TRUE(packets[1].marker);
  EXPECT_FALSE(is_complete(packets[2]));

  pay.push_event(gst_event_new_flush_start());
  pay.push_event(gst_event_new_flush_stop(TRUE));
  GstSegment segment;
  gst_segment_init(&segment, GST_FORMAT_TIME);
  pay.push_event(gst_event_new_segment(&segment));
  pay.push({phoneme(3, 40), {}, 5 * GST_SECOND, true});

  packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 2u);
  EXPECT_TRUE(is_complete(packets[0]));
  EXPECT_TRUE(packets[0].packet.recovery.empty()) << "a new stream starts from nothing";
  EXPECT_EQ(packets[0].pts, 5 * GST_SECOND);
  EXPECT_FALSE(is_complete(packets[1]));
}

TEST(RtpPfapPay, DataPacketsCarryCoverageAndEntriesOfFapsStillInEffectAtTheirTime) {
  Payloader pay;
  one_packet_per_phoneme(pay);
  g_object_set(pay.element(), "recovery-depth", 2, nullptr);
  pay.push({phoneme(1, 100), {entry(3, 100, 200)}, 0, true});
  pay.push({phoneme(2, 100), {entry(4, -50), entry(5, 80, 150, Curve::kTriangle)}, 100 * kMs});
  pay.push({phoneme(3, 100), {}, 200 * kMs});
  pay.push({phoneme(4, 100), {}, 300 * kMs});
  pay.push({phoneme(5, 100), {}, 400 * kMs});

  const std::vector<RtpPacket> data = pay.pull_data();
  ASSERT_EQ(data.size(), 5u);
  // Worked by hand, from the draft's rules (6.4). Every packet counts, the complete packet
  // that starts the stream too, and each covers the two before it.
  const std::vector<std::vector<Fap>> expected{
      // at 0 ms: only the (empty) complete packet before it
      {},
      // at 100 ms: FAP 3's linear transition runs until 200 ms
      {entry(3, 100, 100)},
      // at 200 ms: FAP 3 has arrived; FAP 4 jumped; FAP 5's triangle still runs (until
      // 250 ms) and is sent as the value it returns to
      {entry(3, 100), entry(4, -50), entry(5, 0)},
      // at 300 ms: only the packet of 100 ms and the empty one of 200 ms are covered, and
      // FAP 5's triangle is over: it changed nothing
      {entry(4, -50)},
      // at 400 ms: the covered packets bookmarked nothing
      {},
  };
  for (size_t i = 0; i < data.size(); ++i) {
    EXPECT_EQ(data[i].packet.recovery_kind, pfap::RecoveryKind::kDynamic) << "packet " << i;
    EXPECT_EQ(data[i].packet.covered_packets, 2u) << "packet " << i;
    EXPECT_EQ(data[i].packet.recovery, expected[i]) << "packet " << i;
  }
}

TEST(RtpPfapPay, DefaultRecoveryDepthCoversFourPackets) {
  Payloader pay;
  one_packet_per_phoneme(pay);
  pay.push(sentence(0, 3, 40, true));
  const std::vector<RtpPacket> data = pay.pull_data();
  ASSERT_EQ(data.size(), 3u);
  for (const RtpPacket& p : data) {
    EXPECT_EQ(p.packet.recovery_kind, pfap::RecoveryKind::kDynamic);
    EXPECT_EQ(p.packet.covered_packets, 4u);
  }
}

TEST(RtpPfapPay, RecoveryDepthZeroSendsNoDynamicRecovery) {
  Payloader pay;
  one_packet_per_phoneme(pay);
  g_object_set(pay.element(), "recovery-depth", 0, nullptr);
  pay.push({phoneme(1, 40), {fap(3, 100)}, 0, true});
  pay.push({phoneme(2, 40), {fap(4, 100)}, 40 * kMs});
  pay.push({phoneme(3, 40), {}, 80 * kMs});

  const std::vector<RtpPacket> data = pay.pull_data();
  ASSERT_EQ(data.size(), 3u);
  for (const RtpPacket& p : data) {
    EXPECT_EQ(p.packet.recovery_kind, pfap::RecoveryKind::kNone);
    EXPECT_EQ(p.packet.covered_packets, 0u);
    EXPECT_TRUE(p.packet.recovery.empty());
  }
}

TEST(RtpPfapPay, RecoveryDepthChangeKeepsTheFapStateAndThePacketsItHolds) {
  Payloader pay;
  one_packet_per_phoneme(pay);
  pay.push({phoneme(1, 40), {entry(3, 100)}, 0, true});
  g_object_set(pay.element(), "recovery-depth", 2, nullptr);
  pay.push({phoneme(2, 40), {}, 40 * kMs});
  pay.push({phoneme(3, 40), {}, 80 * kMs});
  pay.push({phoneme(4, 40), {}, 120 * kMs});
  ASSERT_TRUE(pay.push_upstream(rtcp_key_unit_request()));

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 6u);
  // Packets 2 and 3 still cover packet 1, which set FAP 3; packet 4 no longer does.
  for (size_t i : {2u, 3u}) {
    EXPECT_EQ(packets[i].packet.covered_packets, 2u) << "packet " << i;
    EXPECT_EQ(packets[i].packet.recovery, std::vector<Fap>{entry(3, 100)}) << "packet " << i;
  }
  EXPECT_EQ(packets[4].packet.covered_packets, 2u);
  EXPECT_TRUE(packets[4].packet.recovery.empty());
  // The complete state still knows FAP 3, set before the change.
  ASSERT_TRUE(is_complete(packets[5]));
  EXPECT_EQ(packets[5].packet.recovery, std::vector<Fap>{entry(3, 100)});
}

TEST(RtpPfapPay, CompleteRecoveryGoesBeforeTheFirstDataPacketEachIntervalOfStreamTime) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 0u, "complete-recovery-interval", 500u, nullptr);
  // A 3 s session of 70 ms phonemes, one packet each: FAP 3 set by the first phoneme, FAP 4
  // by the one at 560 ms.
  std::vector<Input> inputs = sentence(0, 43, 70, true);
  inputs[0].faps = {entry(3, 100)};
  inputs[8].faps = {entry(4, 70)};
  pay.push(inputs);

  const std::vector<RtpPacket> packets = pay.pull_all();
  std::vector<GstClockTime> times;
  for (size_t i = 0; i < packets.size(); ++i) {
    if (!is_complete(packets[i])) continue;
    times.push_back(packets[i].pts);
    EXPECT_FALSE(packets[i].marker);
    EXPECT_EQ(packets[i].duration, 0u);
    // Between data packets, with the time of the one after it.
    ASSERT_LT(i + 1, packets.size());
    EXPECT_FALSE(is_complete(packets[i + 1]));
    EXPECT_EQ(packets[i + 1].pts, packets[i].pts);
    EXPECT_EQ(packets[i + 1].timestamp, packets[i].timestamp);
  }
  // The first data packet at least 500 ms after the last complete one.
  const std::vector<GstClockTime> expected{0,          560 * kMs,  1120 * kMs,
                                           1680 * kMs, 2240 * kMs, 2800 * kMs};
  EXPECT_EQ(times, expected);
  // The state at each time, before that packet's bookmarks.
  EXPECT_TRUE(packets[0].packet.recovery.empty());
  ASSERT_TRUE(is_complete(packets[9]));
  EXPECT_EQ(packets[9].packet.recovery, std::vector<Fap>{entry(3, 100)});
  ASSERT_TRUE(is_complete(packets[18]));
  EXPECT_EQ(packets[18].packet.recovery, (std::vector<Fap>{entry(3, 100), entry(4, 70)}));
  expect_same_phonemes(inputs, received(packets));
}

TEST(RtpPfapPay, CompleteRecoveryIntervalZeroSendsOnlyTheFirst) {
  Payloader pay;
  one_packet_per_phoneme(pay);
  pay.push(sentence(0, 43, 70, true));
  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 44u);
  EXPECT_EQ(std::count_if(packets.begin(), packets.end(), is_complete), 1);
  EXPECT_TRUE(is_complete(packets[0]));
}

TEST(RtpPfapPay, KeyUnitRequestWhenIdleSendsTheCompleteStateAtOnceAndGoesNoFurther) {
  Payloader pay;
  one_packet_per_phoneme(pay);
  pay.push({phoneme(1, 40), {entry(3, 100)}, 0, true});
  pay.push({phoneme(2, 40), {entry(4, -20, 100)}, 40 * kMs});
  ASSERT_EQ(pay.pull_all().size(), 3u);

  EXPECT_TRUE(pay.push_upstream(rtcp_key_unit_request()));
  std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_TRUE(is_complete(packets[0]));
  // Where the stream is: the end of the last data packet, FAP 4 still on its way.
  EXPECT_EQ(packets[0].pts, 80 * kMs);
  EXPECT_EQ(packets[0].packet.recovery, (std::vector<Fap>{entry(3, 100), entry(4, -20, 60)}));

  EXPECT_TRUE(pay.push_upstream(application_key_unit_request()));
  packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_TRUE(is_complete(packets[0]));

  // Answered here, not passed on to the source.
  while (GstEvent* event = gst_harness_try_pull_upstream_event(pay.harness())) {
    EXPECT_FALSE(gst_event_has_name(event, "GstForceKeyUnit"));
    gst_event_unref(event);
  }
  EXPECT_EQ(pay.stat("requests"), 2u);
  EXPECT_EQ(pay.stat("requests-served"), 2u);
  EXPECT_EQ(pay.stat("complete-recoveries"), 3u);
  EXPECT_EQ(pay.stat("packets"), 2u);
}

TEST(RtpPfapPay, KeyUnitRequestWhileStreamingGoesBeforeTheNextDataPacket) {
  Payloader pay;
  one_packet_per_phoneme(pay);
  pay.push({phoneme(1, 40), {entry(3, 100)}, 0, true});
  pay.pull_all();
  {
    StreamBusy busy(pay.element());
    EXPECT_TRUE(pay.push_upstream(rtcp_key_unit_request()));
    EXPECT_TRUE(pay.push_upstream(rtcp_key_unit_request()));
  }
  EXPECT_TRUE(pay.pull_all().empty()) << "not sent from the request's thread";
  pay.push({phoneme(2, 40), {entry(4, 7)}, 40 * kMs});

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 2u);
  ASSERT_TRUE(is_complete(packets[0]));
  EXPECT_EQ(packets[0].pts, 40 * kMs);
  EXPECT_EQ(packets[0].packet.recovery, std::vector<Fap>{entry(3, 100)});
  EXPECT_FALSE(is_complete(packets[1]));
  EXPECT_EQ(pay.stat("requests"), 2u);
  EXPECT_EQ(pay.stat("requests-served"), 1u) << "both answered by one packet";
}

TEST(RtpPfapPay, KeyUnitRequestWhileStreamingGoesOutAtGap) {
  Payloader pay;
  one_packet_per_phoneme(pay);
  pay.push({phoneme(1, 40), {entry(3, 100)}, 0, true});
  pay.pull_all();
  {
    StreamBusy busy(pay.element());
    EXPECT_TRUE(pay.push_upstream(rtcp_key_unit_request()));
  }
  pay.push_event(gst_event_new_gap(40 * kMs, GST_SECOND));

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 1u);
  ASSERT_TRUE(is_complete(packets[0]));
  EXPECT_EQ(packets[0].pts, 40 * kMs);
  EXPECT_EQ(packets[0].packet.recovery, std::vector<Fap>{entry(3, 100)});
}

// Sends a key unit request upstream from inside the payloader's push of its second data
// packet, as a downstream element reacting to a packet could.
static GstPadProbeReturn request_on_second_data(GstPad* pad, GstPadProbeInfo* info,
                                                gpointer data_seen) {
  GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
  gst_rtp_buffer_map(GST_PAD_PROBE_INFO_BUFFER(info), GST_MAP_READ, &rtp);
  const bool complete = static_cast<const uint8_t*>(gst_rtp_buffer_get_payload(&rtp))[0] & 0x80;
  gst_rtp_buffer_unmap(&rtp);
  if (complete || ++*static_cast<int*>(data_seen) < 2) return GST_PAD_PROBE_OK;
  gst_pad_push_event(pad, rtcp_key_unit_request());
  return GST_PAD_PROBE_REMOVE;
}

TEST(RtpPfapPay, KeyUnitRequestFromInsideAPushWaitsForTheNextDataPacket) {
  Payloader pay;
  one_packet_per_phoneme(pay);
  int data_seen = 0;
  gst_pad_add_probe(pay.harness()->sinkpad, GST_PAD_PROBE_TYPE_BUFFER, request_on_second_data,
                    &data_seen, nullptr);
  pay.push({phoneme(1, 40), {entry(3, 100)}, 0, true});
  pay.push({phoneme(2, 40), {entry(4, 50)}, 40 * kMs});
  EXPECT_EQ(pay.pull_all().size(), 3u) << "no complete packet in the middle of a push";
  EXPECT_EQ(pay.stat("requests"), 1u);
  pay.push({phoneme(3, 40), {}, 80 * kMs});

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 2u);
  ASSERT_TRUE(is_complete(packets[0]));
  // It holds the FAP of the packet whose push the request came in, which went out before.
  EXPECT_EQ(packets[0].packet.recovery, (std::vector<Fap>{entry(3, 100), entry(4, 50)}));
}

TEST(RtpPfapPay, KeyUnitRequestBeforeTheStreamIsAnsweredByItsFirstPacket) {
  Payloader pay;
  one_packet_per_phoneme(pay);
  EXPECT_TRUE(pay.push_upstream(rtcp_key_unit_request()));
  EXPECT_TRUE(pay.pull_all().empty());
  pay.push(sentence(0, 1, 40, true));

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 2u);
  EXPECT_TRUE(is_complete(packets[0]));
  EXPECT_EQ(pay.stat("complete-recoveries"), 1u);
  EXPECT_EQ(pay.stat("requests-served"), 1u);
}

TEST(RtpPfapPay, DynamicRecoveryShrinksItsCoverageToFitTheMtu) {
  Payloader pay;
  const guint mtu = 64;  // 52-byte payloads: a phoneme with 2 FAPs and 5 recovery entries
  g_object_set(pay.element(), "mtu", mtu, "max-delay", 0u, "recovery-depth", 40, nullptr);
  // 60 phonemes, each setting 2 FAPs, every FAP in turn.
  std::vector<Input> inputs = sentence(0, 60, 50, true);
  for (size_t i = 0; i < inputs.size(); ++i) {
    for (size_t k = 0; k < 2; ++k) {
      inputs[i].faps.push_back(entry(static_cast<uint8_t>(3 + (2 * i + k) % 72), 10));
    }
  }
  pay.push(inputs);

  const std::vector<RtpPacket> data = pay.pull_data();
  ASSERT_EQ(data.size(), inputs.size());
  std::vector<unsigned> coverage;
  for (const RtpPacket& p : data) {
    EXPECT_LE(p.size, mtu);
    ASSERT_EQ(p.packet.recovery_kind, pfap::RecoveryKind::kDynamic);
    coverage.push_back(p.packet.covered_packets);
  }
  // 40 while the stream is young (the complete packet, then up to 2 data packets: 4
  // entries); then 2, the deepest whose entries (2 packets of 2 FAPs) fit.
  EXPECT_EQ(std::vector<unsigned>(coverage.begin(), coverage.begin() + 3),
            (std::vector<unsigned>{40, 40, 40}));
  EXPECT_EQ(std::count(coverage.begin() + 3, coverage.end(), 2u),
            static_cast<std::ptrdiff_t>(data.size() - 3));
  expect_same_phonemes(inputs, received(data));
}

TEST(RtpPfapPay, CompleteStateIsNeverCutButLeftOutWithAWarningWhenOverTheMtu) {
  Payloader pay;
  const guint mtu = 64;  // room for a complete state of 8 FAPs
  g_object_set(pay.element(), "mtu", mtu, "max-delay", 0u, "complete-recovery-interval", 200u,
               nullptr);
  // Each 50 ms phoneme sets 2 more FAPs, until all 72 are set: 8 at 200 ms, 16 at 400 ms, ...
  std::vector<Input> inputs = sentence(0, 36, 50, true);
  for (size_t i = 0; i < inputs.size(); ++i) {
    for (size_t k = 0; k < 2; ++k) {
      inputs[i].faps.push_back(
          entry(static_cast<uint8_t>(3 + 2 * i + k), static_cast<int32_t>(10 * (2 * i + k + 1))));
    }
  }
  pay.push(inputs);

  std::vector<Fap> state;  // what a lossless receiver holds, from the data packets
  std::vector<GstClockTime> complete_times;
  for (const RtpPacket& p : pay.pull_all()) {
    EXPECT_LE(p.size, mtu);
    if (is_complete(p)) {
      EXPECT_EQ(p.packet.recovery, state) << "at " << p.pts;
      complete_times.push_back(p.pts);
    }
    for (const Fap& f : p.packet.faps) state.push_back(entry(f.index, f.amplitude));
  }
  EXPECT_EQ(complete_times, (std::vector<GstClockTime>{0, 200 * kMs}));
  // Due at 400, 600, ..., 1600 ms: 7 left out, with warnings at the 1st, 2nd and 4th.
  EXPECT_EQ(pay.stat("complete-too-large"), 7u);
  EXPECT_EQ(pay.stat("complete-recoveries"), 2u);
  int warnings = 0;
  while (GError* warning = pay.pop_warning()) {
    EXPECT_TRUE(g_error_matches(warning, GST_STREAM_ERROR, GST_STREAM_ERROR_ENCODE));
    g_error_free(warning);
    ++warnings;
  }
  EXPECT_EQ(warnings, 3);
}

// A small deterministic generator, so that a failure can be reproduced.
class Lcg {
 public:
  uint32_t next(uint32_t bound) {
    state_ = state_ * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<uint32_t>(state_ >> 33) % bound;
  }

 private:
  uint64_t state_ = 42;
};

// A session with random bookmarks of every curve, one packet per phoneme.
std::vector<Input> random_session(int count) {
  Lcg random;
  std::vector<Input> inputs = sentence(0, count, 40, true);
  for (Input& in : inputs) {
    const uint32_t faps = random.next(4) == 0 ? 1 + random.next(3) : 0;
    for (uint32_t k = 0; k < faps; ++k) {
      in.faps.push_back(entry(
          static_cast<uint8_t>(3 + random.next(72)), static_cast<int32_t>(random.next(2001)) - 1000,
          static_cast<uint16_t>(random.next(300)), static_cast<Curve>(1 + random.next(3))));
    }
  }
  return inputs;
}

// Feeds `packets` to a lossless receiver and to one that loses those `lost` says, and checks
// after each packet the lossy one gets that it knows whether its state is whole and, when
// it is, that its settled values are the lossless one's. Returns the requests the lossy
// receiver made.
int expect_recovers(const std::vector<RtpPacket>& packets, const std::vector<bool>& lost,
                    pfap::RecoveryReceiver& lossy) {
  pfap::RecoveryReceiver lossless;
  int requests = 0;
  for (size_t i = 0; i < packets.size(); ++i) {
    const RtpPacket& p = packets[i];
    const auto time_ns = static_cast<int64_t>(p.pts);
    lossless.receive(p.packet, p.seqnum, time_ns);
    if (lost[i]) continue;
    const pfap::ReceiveResult result = lossy.receive(p.packet, p.seqnum, time_ns);
    requests += result.request_complete;
    if (!result.state_whole) continue;
    for (int f = pfap::kMinFapIndex; f <= pfap::kMaxFapIndex; ++f) {
      EXPECT_EQ(lossy.state().settled(f), lossless.state().settled(f))
          << "FAP " << f << " after packet " << i;
    }
  }
  return requests;
}

TEST(RtpPfapPay, LossesWithinTheCoverageLeaveAReceiverWithALosslessReceiversState) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 0u, nullptr);
  const std::vector<Input> inputs = random_session(400);
  pay.push(std::vector<Input>(inputs.begin(), inputs.begin() + 200));
  g_object_set(pay.element(), "recovery-depth", 2, nullptr);  // a change mid-way
  pay.push(std::vector<Input>(inputs.begin() + 200, inputs.end()));
  const std::vector<RtpPacket> packets = pay.pull_all();
  // The first packet of the new setting.
  const auto change = static_cast<size_t>(
      std::find_if(packets.begin(), packets.end(),
                   [](const RtpPacket& p) { return p.packet.covered_packets == 2; }) -
      packets.begin());
  ASSERT_LT(change, packets.size());

  // Runs of 2 lost packets every 7, one of them the last packet before the change and the
  // first after it.
  std::vector<bool> lost(packets.size());
  for (size_t i = 3; i < packets.size(); ++i) lost[i] = (i + 7 - (change - 1) % 7) % 7 < 2;
  ASSERT_TRUE(lost[change - 1] && lost[change] && !lost[change + 1]);
  pfap::RecoveryReceiver lossy;
  EXPECT_EQ(expect_recovers(packets, lost, lossy), 0);
  EXPECT_TRUE(lossy.state_whole());
}

TEST(RtpPfapPay, ALossBeyondTheCoverageIsRepairedByTheRequestedCompleteState) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 0u, "recovery-depth", 1, "complete-recovery-interval",
               0u, nullptr);
  const std::vector<Input> inputs = random_session(100);
  pay.push(inputs);
  std::vector<RtpPacket> packets = pay.pull_all();
  // Three in a row lost near the end (less than the receiver's 1 s retry before it): the
  // receiver is not whole and asks for the complete state once.
  std::vector<bool> lost(packets.size());
  const size_t first_lost = packets.size() - 6;
  lost[first_lost] = lost[first_lost + 1] = lost[first_lost + 2] = true;
  pfap::RecoveryReceiver lossy;
  EXPECT_EQ(expect_recovers(packets, lost, lossy), 1);
  EXPECT_FALSE(lossy.state_whole());

  // The request reaches the payloader, whose answer comes after the last packet.
  ASSERT_TRUE(pay.push_upstream(rtcp_key_unit_request()));
  const std::vector<RtpPacket> answer = pay.pull_all();
  ASSERT_EQ(answer.size(), 1u);
  ASSERT_TRUE(is_complete(answer[0]));
  packets.push_back(answer[0]);
  lost.push_back(false);
  pfap::RecoveryReceiver replay;
  EXPECT_EQ(expect_recovers(packets, lost, replay), 1);
  EXPECT_TRUE(replay.state_whole());
}

}  // namespace

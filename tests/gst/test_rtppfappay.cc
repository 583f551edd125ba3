// rtppfappay: x-pfap phoneme buffers in, PFAP RTP packets out, checked by decoding them.
#include <gst/check/gstharness.h>
#include <gst/rtp/gstrtpbuffer.h>
#include <gst/sdp/gstsdpmessage.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "pfap/markup.h"
#include "pfap/packetizer.h"
#include "pfap/payload.h"
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

class Payloader {
 public:
  // `downstream` restricts the caps the payloader may send (e.g. a clock-rate), as a
  // capsfilter after it would.
  explicit Payloader(const char* input_caps = PFAP_MARKUP_CAPS, const char* downstream = nullptr)
      : h_(gst_harness_new("rtppfappay")), bus_(gst_bus_new()) {
    gst_element_set_bus(h_->element, bus_);
    if (downstream != nullptr) gst_harness_set_sink_caps_str(h_, downstream);
    gst_harness_set_src_caps_str(h_, input_caps);
  }
  ~Payloader() {
    gst_harness_teardown(h_);
    gst_bus_set_flushing(bus_, TRUE);  // its messages hold the element
    gst_object_unref(bus_);
  }
  Payloader(const Payloader&) = delete;
  Payloader& operator=(const Payloader&) = delete;

  GstHarness* harness() { return h_; }
  GstElement* element() { return h_->element; }
  GstBus* bus() { return bus_; }

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

 private:
  GstHarness* h_;
  GstBus* bus_;
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
  EXPECT_EQ(spec->maximum, G_MAXUINT);
  guint max_delay = 0;
  g_object_get(element, "max-delay", &max_delay, nullptr);
  EXPECT_EQ(max_delay, 100u);
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

  const std::vector<RtpPacket> packets = pay.pull_all();
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

  const std::vector<RtpPacket> packets = pay.pull_all();
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

  const std::vector<RtpPacket> packets = pay.pull_all();
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

  const std::vector<RtpPacket> packets = pay.pull_all();
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
  g_object_set(pay.element(), "mtu", mtu, "max-delay", G_MAXUINT, nullptr);
  // Every other phoneme has a FAP: a phoneme and its FAP fit even the smallest MTU.
  std::vector<Input> inputs = sentence(0, 30, 20, true);
  for (size_t i = 0; i < inputs.size(); i += 2) {
    inputs[i].faps = {fap(static_cast<uint8_t>(3 + i), -100 * static_cast<int32_t>(i))};
  }
  pay.push(inputs);

  const std::vector<RtpPacket> packets = pay.pull_all();
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

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 4u);
  for (const RtpPacket& p : packets) EXPECT_EQ(phoneme_count(p), 1u);
  expect_same_phonemes(inputs, received(packets));
}

TEST(RtpPfapPay, LargeMaxDelayPacksContiguousPhonemesTogether) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 5000u, nullptr);
  const std::vector<Input> inputs = sentence(0, 20, 100, true);
  pay.push(inputs);

  const std::vector<RtpPacket> packets = pay.pull_all();
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

  const std::vector<RtpPacket> packets = pay.pull_all();
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

  const std::vector<RtpPacket> packets = pay.pull_all();
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

TEST(RtpPfapPay, EosSendsThePendingPacket) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 5000u, nullptr);
  const std::vector<Input> inputs = sentence(0, 3, 40, false);
  pay.push(inputs);
  EXPECT_EQ(gst_harness_buffers_received(pay.harness()), 0u);
  pay.push_event(gst_event_new_eos());

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 1u);
  expect_same_phonemes(inputs, received(packets));
}

TEST(RtpPfapPay, GapSendsThePendingPacket) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 5000u, nullptr);
  const std::vector<Input> inputs = sentence(0, 3, 40, false);
  pay.push(inputs);
  pay.push_event(gst_event_new_gap(120 * kMs, GST_SECOND));

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 1u);
  expect_same_phonemes(inputs, received(packets));
}

TEST(RtpPfapPay, NewSegmentSendsThePendingPacket) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 5000u, nullptr);
  const std::vector<Input> inputs = sentence(0, 3, 40, false);
  pay.push(inputs);
  GstSegment segment;
  gst_segment_init(&segment, GST_FORMAT_TIME);
  segment.base = 10 * GST_SECOND;
  pay.push_event(gst_event_new_segment(&segment));

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 1u);
  expect_same_phonemes(inputs, received(packets));
}

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

  const std::vector<RtpPacket> packets = pay.pull_all();
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
  g_object_set(pay.element(), "max-delay", 5000u, nullptr);
  pay.push(sentence(0, 2, 40, false));
  gst_harness_set_src_caps_str(pay.harness(), "application/x-pfap, alphabet=(string)ipa");
  pay.push(sentence(GST_SECOND, 1, 40, true));

  EXPECT_EQ(alphabets, (std::vector<std::string>{"x-sampa", "ipa"}));
  const std::vector<RtpPacket> packets = pay.pull_all();
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
  expect_same_phonemes(good, received(pay.pull_all()));
}

TEST(RtpPfapPay, OversizedPhonemeStillGoesOutWithAWarning) {
  Payloader pay;
  g_object_set(pay.element(), "mtu", 28u, "max-delay", 5000u, nullptr);  // 16-byte payloads
  std::vector<Input> inputs = sentence(0, 3, 40, true);
  inputs[1].faps = {fap(3, 10), fap(4, -20), fap(5, 30), fap(6, -40), fap(7, 50)};
  pay.push(inputs);

  const std::vector<RtpPacket> packets = pay.pull_all();
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

TEST(RtpPfapPay, StateEventsAreDroppedWithoutAWarning) {
  Payloader pay;
  const PfapFap fap{3, 1, 0, 100};
  pay.push(state_buffer(PFAP_EVENT_COMPLETE, fap, 0));
  pay.push(state_buffer(PFAP_EVENT_RECOVERED, fap, 0));
  EXPECT_EQ(gst_harness_buffers_received(pay.harness()), 0u);
  EXPECT_EQ(pay.pop_warning(), nullptr);

  const std::vector<Input> good = sentence(0, 1, 40, true);
  pay.push(good);
  expect_same_phonemes(good, received(pay.pull_all()));
}

TEST(RtpPfapPay, PhonemeWithoutPtsStartsWhereThePreviousOneEnded) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 0u, nullptr);
  pay.push({phoneme(1, 50), {}, GST_SECOND, true});
  pay.push({phoneme(2, 30), {}, GST_CLOCK_TIME_NONE});
  pay.push({phoneme(3, 20), {}, GST_CLOCK_TIME_NONE});

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 3u);
  EXPECT_EQ(packets[1].pts, GST_SECOND + 50 * kMs);
  EXPECT_EQ(packets[2].pts, GST_SECOND + 80 * kMs);
}

TEST(RtpPfapPay, FirstPhonemeWithoutPtsStartsAtTheSegmentStart) {
  Payloader pay;
  g_object_set(pay.element(), "max-delay", 0u, nullptr);
  pay.push({phoneme(1, 50), {}, GST_CLOCK_TIME_NONE, true});

  const std::vector<RtpPacket> packets = pay.pull_all();
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0].pts, 0u);
}

}  // namespace

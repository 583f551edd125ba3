// The example pipeline stays on one line, to be copied.
// clang-format off
/**
 * SECTION:element-rtppfapdepay
 * @title: rtppfapdepay
 * @see_also: rtppfappay
 *
 * Extracts phonemes and facial animation parameters (FAPs) from RTP packets of the PFAP
 * payload format (draft-ietf-avt-rtp-pfap-00) as application/x-pfap buffers, laid out as
 * pfap/markup.h describes: one buffer per phoneme, holding the FAPs that start with it. A
 * buffer's PTS is the packet's PTS plus the durations of the phonemes before it in the
 * packet, its duration the phoneme's. The first phoneme of a packet with the RTP marker bit
 * set starts a sentence. The output stream is sparse: phonemes come only while someone speaks.
 *
 * A malformed packet is dropped whole and counted in #GstRtpPfapDepay:stats; warnings are
 * posted for the 1st, 2nd, 4th, 8th, ... malformed packet. Recovery information is counted
 * but not applied yet.
 *
 * ## Example pipeline
 * |[
 * gst-launch-1.0 udpsrc port=5004 caps="application/x-rtp,media=application,clock-rate=44100,encoding-name=PFAP" ! rtpjitterbuffer ! rtppfapdepay ! fakesink dump=true
 * ]| Receives a PFAP stream on UDP port 5004 and dumps each phoneme buffer. The jitterbuffer
 * turns RTP timestamps into the PTS this element starts from.
 */
// clang-format on
#include "gstrtppfapdepay.h"

#include <gst/rtp/gstrtpbuffer.h>

#include <array>
#include <cstdint>
#include <iterator>
#include <memory>
#include <new>
#include <span>
#include <vector>

#include "pfap/payload.h"
#include "pfapbuffer.h"

GST_DEBUG_CATEGORY_STATIC(rtp_pfap_depay_debug);
#define GST_CAT_DEFAULT rtp_pfap_depay_debug

namespace {

// The stats field of each class of malformed payload. The names are API: keep them stable.
struct MalformedField {
  pfap::DecodeStatus status;
  const char* name;
};

constexpr MalformedField kMalformedFields[] = {
    {pfap::DecodeStatus::kTruncated, "malformed-truncated"},
    {pfap::DecodeStatus::kReservedRecoveryType, "malformed-reserved-recovery-type"},
    {pfap::DecodeStatus::kReservedInfoBits, "malformed-reserved-info-bits"},
    {pfap::DecodeStatus::kMissingCoverage, "malformed-missing-coverage"},
    {pfap::DecodeStatus::kFapIndexOutOfRange, "malformed-fap-index-out-of-range"},
    {pfap::DecodeStatus::kAmplitudeOutOfRange, "malformed-amplitude-out-of-range"},
    {pfap::DecodeStatus::kCurveZero, "malformed-curve-zero"},
    {pfap::DecodeStatus::kMissingFinalPhoneme, "malformed-missing-final-phoneme"},
    {pfap::DecodeStatus::kTrailingBytes, "malformed-trailing-bytes"},
    {pfap::DecodeStatus::kDataInCompleteRecovery, "malformed-data-in-complete-recovery"},
    {pfap::DecodeStatus::kUnterminatedRecovery, "malformed-unterminated-recovery"},
    {pfap::DecodeStatus::kEmptyPacket, "malformed-empty-packet"},
};

// Entry i is status i + 1, so a status added to the library without a field fails to build.
constexpr bool malformed_fields_follow_the_statuses() {
  if (std::size(kMalformedFields) != pfap::kDecodeStatusCount - 1) return false;
  for (size_t i = 0; i < std::size(kMalformedFields); ++i) {
    if (static_cast<size_t>(kMalformedFields[i].status) != i + 1) return false;
  }
  return true;
}
static_assert(malformed_fields_follow_the_statuses(),
              "kMalformedFields lists every DecodeStatus but kOk, in enum order");

struct Stats {
  guint64 packets = 0;
  guint64 phonemes = 0;
  guint64 faps = 0;
  guint64 malformed = 0;
  std::array<guint64, pfap::kDecodeStatusCount> malformed_by_status{};
  guint64 lost = 0;
  guint64 complete_recoveries = 0;
  guint64 recovery_entries = 0;
};

// The last packet seen, for counting losses.
struct SeqnumTracker {
  bool started = false;
  guint32 ssrc = 0;
  guint16 last = 0;

  // The packets missing before `seqnum`: a forward jump of under 2^15. A backward jump (the
  // base class has already dropped duplicates and late packets, so the sender restarted) or
  // a new SSRC says nothing about loss.
  guint64 advance(guint32 packet_ssrc, guint16 seqnum) {
    const guint16 gap = static_cast<guint16>(seqnum - last - 1);
    const guint64 lost = started && packet_ssrc == ssrc && gap < 0x8000 ? gap : 0;
    *this = {true, packet_ssrc, seqnum};
    return lost;
  }
};

// Every warning cannot go to the bus (a broken sender could flood it), so warn at the 1st,
// 2nd, 4th, 8th, ... malformed packet: a fault shows at once, a lasting one costs log2(n)
// messages, and the stats property has every count. It needs no running time, which a
// stream of bad packets may not give.
bool warn_at(guint64 malformed) { return (malformed & (malformed - 1)) == 0; }

}  // namespace

struct _GstRtpPfapDepay {
  GstRTPBaseDepayload parent;

  // C++ members: constructed in init, destroyed in finalize.
  pfap::Packet packet;      // reused, so decoding stops allocating
  pfap::MarkupEvent event;  // one phoneme's event, reused
  SeqnumTracker seqnums;
  Stats stats;  // under the object lock: the stats property is read from any thread
};

enum { PROP_0, PROP_STATS };

static GstStaticPadTemplate sink_template = GST_STATIC_PAD_TEMPLATE(
    "sink", GST_PAD_SINK, GST_PAD_ALWAYS,
    GST_STATIC_CAPS("application/x-rtp, media = (string) application, "
                    "clock-rate = (int) [ 1, 2147483647 ], encoding-name = (string) PFAP"));

static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

G_DEFINE_TYPE(GstRtpPfapDepay, gst_rtp_pfap_depay, GST_TYPE_RTP_BASE_DEPAYLOAD)
GST_ELEMENT_REGISTER_DEFINE(rtppfapdepay, "rtppfapdepay", GST_RANK_SECONDARY,
                            GST_TYPE_RTP_PFAP_DEPAY)

template <typename Update>
static void update_stats(GstRtpPfapDepay* self, Update&& update) {
  GST_OBJECT_LOCK(self);
  update(self->stats);
  GST_OBJECT_UNLOCK(self);
}

// Forgets the stream position (FLUSH_STOP, READY to PAUSED). The stats are counters and
// outlive a flush.
static void reset(GstRtpPfapDepay* self) { self->seqnums = {}; }

static gboolean gst_rtp_pfap_depay_set_caps(GstRTPBaseDepayload* depay, GstCaps* caps) {
  const GstStructure* s = gst_caps_get_structure(caps, 0);
  gint clock_rate = 0;  // the template's range refuses any other value
  if (!gst_structure_get_int(s, "clock-rate", &clock_rate)) {
    GST_ELEMENT_ERROR(depay, CORE, NEGOTIATION,
                      ("The RTP caps have no clock-rate (add clock-rate=44100, or the rate the "
                       "sender signals)"),
                      ("caps: %" GST_PTR_FORMAT, static_cast<gpointer>(caps)));
    return FALSE;
  }
  depay->clock_rate = static_cast<guint>(clock_rate);

  GstCaps* src_caps = gst_caps_new_empty_simple(PFAP_MARKUP_CAPS);
  // The phoneme alphabet, an fmtp parameter. SDP gives every fmtp parameter as a string; any
  // other type means hand-made caps, refused rather than guessed at.
  if (const GValue* alphabet = gst_structure_get_value(s, "alphabet")) {
    if (!G_VALUE_HOLDS_STRING(alphabet)) {
      GST_ELEMENT_ERROR(
          depay, CORE, NEGOTIATION,
          ("The alphabet caps field must be a string, not %s (write alphabet=(string)...)",
           G_VALUE_TYPE_NAME(alphabet)),
          ("caps: %" GST_PTR_FORMAT, static_cast<gpointer>(caps)));
      gst_caps_unref(src_caps);
      return FALSE;
    }
    gst_caps_set_value(src_caps, "alphabet", alphabet);
  }
  const gboolean ok = gst_pad_set_caps(GST_RTP_BASE_DEPAYLOAD_SRCPAD(depay), src_caps);
  gst_caps_unref(src_caps);
  return ok;
}

static gboolean gst_rtp_pfap_depay_handle_event(GstRTPBaseDepayload* depay, GstEvent* event) {
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_STREAM_START: {
      // Phonemes come only while someone speaks; sparse tells queues, muxers and
      // aggregators downstream not to wait for our data.
      event = gst_event_make_writable(event);
      GstStreamFlags flags;
      gst_event_parse_stream_flags(event, &flags);
      gst_event_set_stream_flags(event,
                                 static_cast<GstStreamFlags>(flags | GST_STREAM_FLAG_SPARSE));
      break;
    }
    case GST_EVENT_FLUSH_STOP:
      reset(GST_RTP_PFAP_DEPAY(depay));
      break;
    default:
      break;
  }
  return GST_RTP_BASE_DEPAYLOAD_CLASS(gst_rtp_pfap_depay_parent_class)->handle_event(depay, event);
}

static void drop_malformed(GstRtpPfapDepay* self, pfap::DecodeResult result, guint16 seqnum) {
  guint64 malformed = 0;
  update_stats(self, [&](Stats& s) {
    ++s.malformed_by_status[static_cast<size_t>(result.status)];
    malformed = ++s.malformed;
  });
  GST_DEBUG_OBJECT(self, "dropped packet %u: %s at byte %u", seqnum, pfap::to_string(result.status),
                   result.offset);
  if (warn_at(malformed)) {
    GST_ELEMENT_WARNING(self, STREAM, DECODE,
                        ("Dropped a malformed PFAP packet: %s at byte %u",
                         pfap::to_string(result.status), result.offset),
                        ("RTP seqnum %u; %" G_GUINT64_FORMAT
                         " malformed packets so far (warned at the 1st, 2nd, 4th, 8th, ...; "
                         "the stats property counts each class)",
                         seqnum, malformed));
  }
}

// Phoneme i of the decoded packet as an x-pfap buffer, or NULL when it does not fit one
// (more FAPs than its 16-bit count holds).
static GstBuffer* phoneme_buffer(GstRtpPfapDepay* self, size_t i, bool sentence_start) {
  const std::span<const pfap::Fap> faps = self->packet.faps_of(i);
  pfap::MarkupEvent& event = self->event;
  event.phoneme = self->packet.phonemes[i].phoneme;
  event.sentence_start = sentence_start;
  event.faps.assign(faps.begin(), faps.end());
  return pfap_buffer_new(event);
}

static GstBuffer* gst_rtp_pfap_depay_process_rtp_packet(GstRTPBaseDepayload* depay,
                                                        GstRTPBuffer* rtp) {
  GstRtpPfapDepay* self = GST_RTP_PFAP_DEPAY(depay);
  const guint16 seqnum = gst_rtp_buffer_get_seq(rtp);
  const guint64 lost = self->seqnums.advance(gst_rtp_buffer_get_ssrc(rtp), seqnum);
  const std::span<const uint8_t> payload(
      static_cast<const uint8_t*>(gst_rtp_buffer_get_payload(rtp)),
      gst_rtp_buffer_get_payload_len(rtp));
  const pfap::DecodeResult result = pfap::decode_payload(payload, self->packet);
  update_stats(self, [&](Stats& s) {
    ++s.packets;
    s.lost += lost;
  });
  if (!result.ok()) {
    drop_malformed(self, result, seqnum);
    return nullptr;
  }

  const pfap::Packet& packet = self->packet;
  // The base class derives no time from the RTP timestamp: the PTS comes from upstream
  // (rtpjitterbuffer), and DISCONT after a gap is set on our first buffer by the base class.
  const GstClockTime packet_pts = GST_BUFFER_PTS(rtp->buffer);
  GstBufferList* list = gst_buffer_list_new_sized(static_cast<guint>(packet.phonemes.size()));
  GstClockTime offset = 0;
  for (size_t i = 0; i < packet.phonemes.size(); ++i) {
    GstBuffer* buffer = phoneme_buffer(self, i, i == 0 && gst_rtp_buffer_get_marker(rtp));
    if (!buffer) {
      GST_ELEMENT_WARNING(self, STREAM, DECODE,
                          ("Dropped a PFAP packet whose phoneme %zu does not fit an x-pfap "
                           "buffer (%zu FAPs)",
                           i, packet.faps_of(i).size()),
                          ("RTP seqnum %u", seqnum));
      gst_buffer_list_unref(list);
      return nullptr;
    }
    const GstClockTime duration = packet.phonemes[i].phoneme.duration_ms * GST_MSECOND;
    GST_BUFFER_PTS(buffer) =
        GST_CLOCK_TIME_IS_VALID(packet_pts) ? packet_pts + offset : GST_CLOCK_TIME_NONE;
    GST_BUFFER_DURATION(buffer) = duration;
    offset += duration;
    gst_buffer_list_add(list, buffer);
  }
  update_stats(self, [&](Stats& s) {
    s.phonemes += packet.phonemes.size();
    s.faps += packet.faps.size();
    s.recovery_entries += packet.recovery.size();
    s.complete_recoveries += packet.recovery_kind == pfap::RecoveryKind::kComplete;
  });

  if (gst_buffer_list_length(list) == 0) {
    gst_buffer_list_unref(list);  // recovery only: nothing to output until recovery is applied
    return nullptr;
  }
  gst_rtp_base_depayload_push_list(depay, list);
  return nullptr;
}

static GstStructure* stats_structure(GstRtpPfapDepay* self) {
  GST_OBJECT_LOCK(self);
  const Stats s = self->stats;
  GST_OBJECT_UNLOCK(self);
  GstStructure* out =
      gst_structure_new("application/x-rtp-pfap-depay-stats", "packets", G_TYPE_UINT64, s.packets,
                        "phonemes", G_TYPE_UINT64, s.phonemes, "faps", G_TYPE_UINT64, s.faps,
                        "malformed", G_TYPE_UINT64, s.malformed, nullptr);
  for (const MalformedField& field : kMalformedFields) {
    gst_structure_set(out, field.name, G_TYPE_UINT64,
                      s.malformed_by_status[static_cast<size_t>(field.status)], nullptr);
  }
  gst_structure_set(out, "lost", G_TYPE_UINT64, s.lost, "complete-recoveries", G_TYPE_UINT64,
                    s.complete_recoveries, "recovery-entries", G_TYPE_UINT64, s.recovery_entries,
                    "recovered", G_TYPE_UINT64, guint64{0},  // recovery is not applied yet
                    nullptr);
  return out;
}

static void gst_rtp_pfap_depay_get_property(GObject* object, guint prop_id, GValue* value,
                                            GParamSpec* pspec) {
  switch (prop_id) {
    case PROP_STATS:
      g_value_take_boxed(value, stats_structure(GST_RTP_PFAP_DEPAY(object)));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
}

static GstStateChangeReturn gst_rtp_pfap_depay_change_state(GstElement* element,
                                                            GstStateChange transition) {
  GstRtpPfapDepay* self = GST_RTP_PFAP_DEPAY(element);
  if (transition == GST_STATE_CHANGE_READY_TO_PAUSED) {
    reset(self);
    update_stats(self, [](Stats& s) { s = {}; });
  }
  return GST_ELEMENT_CLASS(gst_rtp_pfap_depay_parent_class)->change_state(element, transition);
}

static void gst_rtp_pfap_depay_init(GstRtpPfapDepay* self) {
  // Accept caps that leave out template fields, so that pushed caps without a clock-rate
  // (appsrc, an application) reach set_caps and are refused with a message naming it, not
  // with a bare not-negotiated. A source that fixates against the template, like udpsrc,
  // gets clock-rate=1 instead, before we can say anything.
  GST_PAD_SET_ACCEPT_INTERSECT(GST_RTP_BASE_DEPAYLOAD_SINKPAD(self));
  new (&self->packet) pfap::Packet();
  new (&self->event) pfap::MarkupEvent();
  new (&self->seqnums) SeqnumTracker();
  new (&self->stats) Stats();
}

static void gst_rtp_pfap_depay_finalize(GObject* object) {
  GstRtpPfapDepay* self = GST_RTP_PFAP_DEPAY(object);
  std::destroy_at(&self->packet);
  std::destroy_at(&self->event);
  G_OBJECT_CLASS(gst_rtp_pfap_depay_parent_class)->finalize(object);
}

static void gst_rtp_pfap_depay_class_init(GstRtpPfapDepayClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstRTPBaseDepayloadClass* depay_class = GST_RTP_BASE_DEPAYLOAD_CLASS(klass);

  gobject_class->get_property = gst_rtp_pfap_depay_get_property;
  gobject_class->finalize = gst_rtp_pfap_depay_finalize;

  /**
   * GstRtpPfapDepay:stats:
   *
   * Counters since the element last went from READY to PAUSED (a flush keeps them), all
   * guint64, in an application/x-rtp-pfap-depay-stats structure:
   *
   * - packets: RTP packets received, good or malformed
   * - phonemes: phoneme buffers made
   * - faps: FAPs in those buffers
   * - malformed: packets dropped as malformed, the sum of the malformed-* fields
   * - malformed-truncated: the payload ends inside a descriptor, or is empty
   * - malformed-reserved-recovery-type: recovery type T = 10 or 11
   * - malformed-reserved-info-bits: an InfoBits value reserved where it is
   * - malformed-missing-coverage: dynamic recovery entries with PP = 000
   * - malformed-fap-index-out-of-range: a FAP index outside 3..74
   * - malformed-amplitude-out-of-range: an amplitude over 2529600
   * - malformed-curve-zero: a FAP or recovery entry with curve 0
   * - malformed-missing-final-phoneme: the payload ends before a phoneme that ends it
   * - malformed-trailing-bytes: bytes after the end of the packet
   * - malformed-data-in-complete-recovery: a complete recovery announcing phonemes or FAPs
   * - malformed-unterminated-recovery: a recovery list without its last entry
   * - malformed-empty-packet: no recovery entries and no phoneme
   * - lost: packets missing, from forward jumps of the RTP sequence number
   * - complete-recoveries: complete-recovery packets received (not applied yet)
   * - recovery-entries: recovery entries received in good packets (not applied yet)
   * - recovered: FAP states restored from recovery information (0: not applied yet)
   */
  g_object_class_install_property(
      gobject_class, PROP_STATS,
      g_param_spec_boxed(
          "stats", "Statistics",
          "Counters since READY to PAUSED (guint64): packets received; phonemes and faps "
          "output; malformed packets dropped, in total and per class (malformed-truncated, "
          "-reserved-recovery-type, -reserved-info-bits, -missing-coverage, "
          "-fap-index-out-of-range, -amplitude-out-of-range, -curve-zero, "
          "-missing-final-phoneme, -trailing-bytes, -data-in-complete-recovery, "
          "-unterminated-recovery, -empty-packet); lost packets (sequence-number gaps); "
          "complete-recoveries and recovery-entries received; recovered (0: recovery is not "
          "applied yet)",
          GST_TYPE_STRUCTURE, static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS)));

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_set_static_metadata(
      element_class, "RTP PFAP depayloader", "Codec/Depayloader/Network/RTP",
      "Extracts phonemes and facial animation parameters from RTP packets "
      "(draft-ietf-avt-rtp-pfap-00)",
      "gst-pfap developers");
  element_class->change_state = gst_rtp_pfap_depay_change_state;

  depay_class->set_caps = gst_rtp_pfap_depay_set_caps;
  depay_class->handle_event = gst_rtp_pfap_depay_handle_event;
  depay_class->process_rtp_packet = gst_rtp_pfap_depay_process_rtp_packet;

  GST_DEBUG_CATEGORY_INIT(rtp_pfap_depay_debug, "rtppfapdepay", 0, "PFAP RTP depayloader");
}

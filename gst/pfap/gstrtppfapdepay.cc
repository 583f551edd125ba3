// SPDX-License-Identifier: LGPL-2.1-or-later
// The example pipeline stays on one line, to be copied.
// clang-format off
/**
 * SECTION:element-rtppfapdepay
 * @title: rtppfapdepay
 * @see_also: rtppfappay
 *
 * Extracts phonemes and facial animation parameters (FAPs) from RTP packets of the PFAP
 * payload format (draft-ietf-avt-rtp-pfap-00) as application/x-pfap buffers, laid out as
 * pfap/markup.h describes: one buffer per phoneme, holding the FAPs that start with it, and
 * state events from recovery information (below). A phoneme buffer's PTS is the packet's PTS
 * plus the durations of the phonemes before it in the packet, its duration the phoneme's.
 * The first phoneme of a packet with the RTP marker bit set starts a sentence. The output
 * stream is sparse: phonemes come only while someone speaks.
 *
 * A malformed packet is dropped whole and counted in #GstRtpPfapDepay:stats; warnings are
 * posted for the 1st, 2nd, 4th, 8th, ... malformed packet.
 *
 * ## Loss recovery
 *
 * The element keeps the FAP state the stream has built (pfap::RecoveryReceiver) and uses the
 * recovery information of draft sections 6.1, 6.4 and 8 to repair it after a loss:
 *
 * - After lost packets that the next packet's dynamic recovery covers: a recovered event
 *   (PFAP_EVENT_RECOVERED) with that packet's recovery entries, at its PTS, before its
 *   phonemes; without FAPs when nothing in the covered packets still had an effect.
 *   Recovery entries when nothing was lost are not output: the phonemes before them
 *   already set those FAPs.
 * - A complete-recovery packet: a complete event (PFAP_EVENT_COMPLETE) with the whole state
 *   at the packet's PTS, only if it changes the state. An unchanged complete state tells
 *   downstream nothing, and leaving it out keeps the output of a stream without loss what
 *   the sender was given.
 * - After a loss the coverage does not span, the state may be wrong: every event is flagged
 *   PFAP_FLAG_UNCERTAIN until a complete state comes, and the element asks the sender for
 *   one (#GstRtpPfapDepay:request-recovery).
 *
 * A depayloader cannot know whether it joined a stream at its start, so after READY to
 * PAUSED, a flush or a new SSRC it takes itself for joined mid-stream: uncertain, and asking
 * for a complete state, unless the first packet is one. Senders begin every stream with a
 * complete state (rtppfappay does), so a receiver there from the start is whole at once; the
 * all-zero state a stream starts with outputs nothing.
 *
 * A packet dropped as malformed counts as lost: its FAPs are missing just the same, and
 * recovery repairs both alike. Losses are accounted at the next good packet, from sequence
 * numbers, because only that packet's coverage tells whether they are repaired;
 * rtpjitterbuffer's packet-lost events are counted and, as in every depayloader, become GAP
 * events.
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
#include <gst/video/video.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <iterator>
#include <optional>
#include <span>

#include "markupbuffer.h"
#include "pfap/payload.h"
#include "pfap/recovery.h"
#include "ratelimit.h"
#include "sparse.h"
#include "stats.h"

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
  guint64 gaps = 0;
  guint64 recovered = 0;
  guint64 faps_recovered = 0;
  guint64 complete_states = 0;
  guint64 complete_changes = 0;
  guint64 requests = 0;
  guint64 packet_lost_events = 0;
};

// What the streaming thread keeps between packets. GObject runs no C++ constructors, so it
// lives behind a pointer made in init and deleted in finalize.
struct Stream {
  pfap::Packet packet;      // reused, so decoding stops allocating
  pfap::MarkupEvent event;  // one output event, reused
  pfap::RecoveryReceiver receiver{};
  std::optional<guint32> ssrc;  // the stream's; none until a good packet starts one
};

}  // namespace

struct _GstRtpPfapDepay {
  GstRTPBaseDepayload parent;
  Stream* stream;
  // Under the object lock: the stats property is read from any thread.
  Stats stats;
  // A gboolean, atomic: the property may be set from any thread.
  gint request_recovery;
};

enum { PROP_0, PROP_STATS, PROP_REQUEST_RECOVERY };

constexpr gboolean kDefaultRequestRecovery = TRUE;
// The lowest RTP clock rate taken: PFAP times are in ms, and real rates are 8000 Hz and up.
constexpr gint kMinClockRate = 1000;

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

// Forgets the stream (FLUSH_STOP, READY to PAUSED): the next good packet starts a new one,
// as a new SSRC does. The stats are counters and outlive a flush.
static void reset(GstRtpPfapDepay* self) { self->stream->ssrc.reset(); }

static gboolean gst_rtp_pfap_depay_set_caps(GstRTPBaseDepayload* depay, GstCaps* caps) {
  const GstStructure* s = gst_caps_get_structure(caps, 0);
  gint clock_rate = 0;
  // Below kMinClockRate is no sender's rate but a source's guess: udpsrc given caps without
  // a clock-rate fixates the template's range to 1, and times would come out hours off. The
  // template keeps the whole range so that such caps reach this message.
  if (!gst_structure_get_int(s, "clock-rate", &clock_rate) || clock_rate < kMinClockRate) {
    GST_ELEMENT_ERROR(depay, CORE, NEGOTIATION,
                      ("The RTP caps have no clock-rate, or one below %d Hz (add "
                       "clock-rate=44100, or the rate the sender signals)",
                       kMinClockRate),
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
    case GST_EVENT_STREAM_START:
      event = pfap_make_sparse(event);
      break;
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
    ++s.packets;
    ++s.malformed_by_status[static_cast<size_t>(result.status)];
    malformed = ++s.malformed;
  });
  GST_DEBUG_OBJECT(self, "dropped packet %u: %s at byte %u", seqnum, pfap::to_string(result.status),
                   result.offset);
  // A broken sender could flood the bus; the stats property has every count. Counting needs
  // no running time, which a stream of bad packets may not give.
  if (pfap_warn_at(malformed)) {
    GST_ELEMENT_WARNING(self, STREAM, DECODE,
                        ("Dropped a malformed PFAP packet: %s at byte %u",
                         pfap::to_string(result.status), result.offset),
                        ("RTP seqnum %u; %" G_GUINT64_FORMAT
                         " malformed packets so far (warned at the 1st, 2nd, 4th, 8th, ...; "
                         "the stats property counts each class)",
                         seqnum, malformed));
  }
}

// x-pfap counts an event's FAPs in 16 bits, and only a payload over 393 KB holds more in one
// phoneme or recovery list. Such a packet is dropped before the receiver sees it, so that
// it counts as lost, like a malformed one.
static bool fits_x_pfap(GstRtpPfapDepay* self, guint16 seqnum, size_t payload_size) {
  // Every FAP takes a descriptor on the wire: a smaller payload cannot hold too many.
  if (payload_size < (G_MAXUINT16 + 1) * pfap::kFapDescriptorBytes) return true;
  const pfap::Packet& packet = self->stream->packet;
  size_t most = packet.recovery.size();
  for (size_t i = 0; i < packet.phonemes.size(); ++i) {
    most = std::max(most, packet.faps_of(i).size());
  }
  if (most <= G_MAXUINT16) return true;
  GST_ELEMENT_WARNING(self, STREAM, DECODE,
                      ("Dropped a PFAP packet with %zu FAPs in one event; an x-pfap buffer "
                       "holds at most %u",
                       most, G_MAXUINT16),
                      ("RTP seqnum %u", seqnum));
  return false;
}

// The output event as a buffer. It always fits: fits_x_pfap checked the counts and the decoder
// every value.
static GstBuffer* event_buffer(GstRtpPfapDepay* self, GstClockTime pts, GstClockTime duration) {
  GstBuffer* buffer = pfap_buffer_new(self->stream->event);
  g_assert(buffer);
  GST_BUFFER_PTS(buffer) = pts;
  GST_BUFFER_DURATION(buffer) = duration;
  return buffer;
}

// The decoded packet's recovery entries as a recovered or complete event at `pts`.
static GstBuffer* state_buffer(GstRtpPfapDepay* self, PfapEventKind kind, bool uncertain,
                               GstClockTime pts) {
  pfap::MarkupEvent& event = self->stream->event;
  event.kind = kind;
  event.phoneme = {};
  event.sentence_start = false;
  event.uncertain = uncertain;
  event.faps = self->stream->packet.recovery;
  return event_buffer(self, pts, GST_CLOCK_TIME_NONE);
}

// Phoneme i of the decoded packet, starting at `pts`.
static GstBuffer* phoneme_buffer(GstRtpPfapDepay* self, size_t i, bool sentence_start,
                                 bool uncertain, GstClockTime pts) {
  const std::span<const pfap::Fap> faps = self->stream->packet.faps_of(i);
  pfap::MarkupEvent& event = self->stream->event;
  event.kind = PFAP_EVENT_PHONEME;
  event.phoneme = self->stream->packet.phonemes[i].phoneme;
  event.sentence_start = sentence_start;
  event.uncertain = uncertain;
  event.faps.assign(faps.begin(), faps.end());
  return event_buffer(self, pts, event.phoneme.duration_ms * GST_MSECOND);
}

// Asks the sender for a complete state with the event video depayloaders send for a key
// frame (all headers: the whole state); rtpbin sends it on as RTCP feedback.
static void request_complete_state(GstRtpPfapDepay* self, guint16 seqnum) {
  GST_DEBUG_OBJECT(self, "asking for a complete state at packet %u", seqnum);
  gst_pad_push_event(GST_RTP_BASE_DEPAYLOAD_SINKPAD(self),
                     gst_video_event_new_upstream_force_key_unit(GST_CLOCK_TIME_NONE, TRUE, 0));
  update_stats(self, [](Stats& s) { ++s.requests; });
}

// Decodes the payload of `rtp` into the stream's packet. The base class maps only the RTP
// header; gst_rtp_buffer_get_payload maps the payload as a range of the buffer, which costs
// about twice as much as mapping the one memory that holds it (as in every packet from a
// socket or from rtppfappay). A payload spread over memories takes the range path.
static pfap::DecodeResult decode(GstRtpPfapDepay* self, GstRTPBuffer* rtp, size_t& size) {
  size = gst_rtp_buffer_get_payload_len(rtp);
  const guint offset = gst_rtp_buffer_get_header_len(rtp);
  guint index = 0, count = 0;
  gsize skip = 0;
  GstMapInfo map;
  if (size > 0 && gst_buffer_find_memory(rtp->buffer, offset, size, &index, &count, &skip) &&
      count == 1) {
    GstMemory* memory = gst_buffer_peek_memory(rtp->buffer, index);
    if (gst_memory_map(memory, &map, GST_MAP_READ)) {
      const pfap::DecodeResult result =
          pfap::decode_payload({map.data + skip, size}, self->stream->packet);
      gst_memory_unmap(memory, &map);
      return result;
    }
  }
  const auto* payload = static_cast<const uint8_t*>(gst_rtp_buffer_get_payload(rtp));
  return pfap::decode_payload({payload, size}, self->stream->packet);
}

// The packet through the stream's receiver. A new SSRC is a new sender, or one restarted:
// its sequence numbers and FAP state owe nothing to the last one's.
static pfap::ReceiveResult receive(GstRtpPfapDepay* self, guint32 ssrc, guint16 seqnum,
                                   GstClockTime packet_pts) {
  Stream& stream = *self->stream;
  if (stream.ssrc != ssrc) {
    GST_DEBUG_OBJECT(self, "new stream, SSRC %08x", ssrc);
    stream.receiver.reset(/*joined_mid_stream=*/true);
    stream.ssrc = ssrc;
  }
  return stream.receiver.receive(
      stream.packet, seqnum,
      GST_CLOCK_TIME_IS_VALID(packet_pts) ? static_cast<int64_t>(packet_pts) : 0);
}

// Counts a received packet, in one update of the stats.
static void count_received(GstRtpPfapDepay* self, const pfap::ReceiveResult& r, bool recovered,
                           bool complete_changed) {
  const pfap::Packet& packet = self->stream->packet;
  update_stats(self, [&](Stats& s) {
    ++s.packets;
    s.phonemes += packet.phonemes.size();
    s.faps += packet.faps.size();
    s.lost += r.lost;
    s.gaps += r.lost > 0;
    s.recovered += recovered;
    s.faps_recovered += recovered ? packet.recovery.size() : 0;
    s.complete_states += r.recovery == pfap::ReceiveResult::Recovery::kComplete;
    s.complete_changes += complete_changed;
  });
}

// Pushes the decoded packet's events: the state event of `state_kind` (if any) first, before
// the phonemes and the one that carries the DISCONT after a gap, then each phoneme, the first
// a sentence start if the RTP marker is set. A lone buffer (every packet at max-delay=0) is
// pushed without a list, which would cost an allocation and the base class's walk over it;
// nothing at all when there is no loss to repair, no change and no phoneme.
static void push_events(GstRtpPfapDepay* self, std::optional<PfapEventKind> state_kind,
                        bool uncertain, bool marker, GstClockTime packet_pts) {
  const pfap::Packet& packet = self->stream->packet;
  const size_t n_out = packet.phonemes.size() + (state_kind ? 1 : 0);
  GstBufferList* list = n_out > 1 ? gst_buffer_list_new_sized(static_cast<guint>(n_out)) : nullptr;
  GstBuffer* lone = nullptr;
  auto output = [&](GstBuffer* buffer) {
    if (list != nullptr) {
      gst_buffer_list_add(list, buffer);
    } else {
      lone = buffer;
    }
  };
  if (state_kind) output(state_buffer(self, *state_kind, uncertain, packet_pts));
  packet.for_each_phoneme(0, [&](size_t i, int64_t offset_ns) {
    const GstClockTime pts =
        GST_CLOCK_TIME_IS_VALID(packet_pts) ? packet_pts + offset_ns : GST_CLOCK_TIME_NONE;
    output(phoneme_buffer(self, i, i == 0 && marker, uncertain, pts));
  });
  GstRTPBaseDepayload* depay = GST_RTP_BASE_DEPAYLOAD(self);
  if (list != nullptr) {
    gst_rtp_base_depayload_push_list(depay, list);
  } else if (lone != nullptr) {
    gst_rtp_base_depayload_push(depay, lone);
  }
}

static GstBuffer* gst_rtp_pfap_depay_process_rtp_packet(GstRTPBaseDepayload* depay,
                                                        GstRTPBuffer* rtp) {
  GstRtpPfapDepay* self = GST_RTP_PFAP_DEPAY(depay);
  const guint16 seqnum = gst_rtp_buffer_get_seq(rtp);
  size_t payload_size = 0;
  const pfap::DecodeResult result = decode(self, rtp, payload_size);
  // Each path counts the packet in its one update of the stats.
  if (!result.ok()) {
    drop_malformed(self, result, seqnum);
    return nullptr;
  }
  if (!fits_x_pfap(self, seqnum, payload_size)) {
    update_stats(self, [](Stats& s) { ++s.packets; });
    return nullptr;
  }

  // The base class derives no time from the RTP timestamp: the PTS comes from upstream
  // (rtpjitterbuffer), and DISCONT after a gap is set on our first buffer by the base class.
  // A source that gives only a DTS (pcapparse) means the packet's time by it.
  const GstClockTime packet_pts = GST_BUFFER_PTS_IS_VALID(rtp->buffer)
                                      ? GST_BUFFER_PTS(rtp->buffer)
                                      : GST_BUFFER_DTS(rtp->buffer);
  const pfap::ReceiveResult r = receive(self, gst_rtp_buffer_get_ssrc(rtp), seqnum, packet_pts);

  using Recovery = pfap::ReceiveResult::Recovery;
  const bool recovered = r.recovery == Recovery::kRecovered;
  // An unchanged complete state changes nothing downstream; left out, a stream without loss
  // comes out as it was sent.
  const bool complete_changed = r.recovery == Recovery::kComplete && r.changed;
  std::optional<PfapEventKind> state_kind;
  if (recovered) state_kind = PFAP_EVENT_RECOVERED;
  if (complete_changed) state_kind = PFAP_EVENT_COMPLETE;
  count_received(self, r, recovered, complete_changed);
  push_events(self, state_kind, /*uncertain=*/!r.state_whole, gst_rtp_buffer_get_marker(rtp),
              packet_pts);
  if (r.request_complete && g_atomic_int_get(&self->request_recovery)) {
    request_complete_state(self, seqnum);
  }
  return nullptr;
}

// A loss with a sequence number is accounted at the next packet, whose sequence number tells
// how many were lost and whose coverage whether recovery repairs them. One without (what
// rtpulpfecdec sends for a packet it could not rebuild, after renumbering the rest) leaves no
// gap in the sequence numbers to see: the state is uncertain from here. The parent pushes a
// GAP, so that downstream does not wait for the lost time.
static gboolean gst_rtp_pfap_depay_packet_lost(GstRTPBaseDepayload* depay, GstEvent* event) {
  GstRtpPfapDepay* self = GST_RTP_PFAP_DEPAY(depay);
  update_stats(self, [](Stats& s) { ++s.packet_lost_events; });
  if (!gst_structure_has_field(gst_event_get_structure(event), "seqnum")) {
    GST_DEBUG_OBJECT(self, "packet lost without a sequence number: state uncertain");
    self->stream->receiver.lost_unknown();
  }
  return GST_RTP_BASE_DEPAYLOAD_CLASS(gst_rtp_pfap_depay_parent_class)->packet_lost(depay, event);
}

static GstStructure* stats_structure(GstRtpPfapDepay* self) {
  GST_OBJECT_LOCK(self);
  const Stats s = self->stats;
  GST_OBJECT_UNLOCK(self);
  // GstRTPBaseDepayload's (seqnum, timestamp, npt-start, running-time-pts, ...) and ours.
  GstStructure* out = pfap_owner_stats(G_OBJECT(self), GST_TYPE_RTP_BASE_DEPAYLOAD);
  gst_structure_set(out, "packets", G_TYPE_UINT64, s.packets, "phonemes", G_TYPE_UINT64, s.phonemes,
                    "faps", G_TYPE_UINT64, s.faps, "malformed", G_TYPE_UINT64, s.malformed,
                    nullptr);
  for (const MalformedField& field : kMalformedFields) {
    gst_structure_set(out, field.name, G_TYPE_UINT64,
                      s.malformed_by_status[static_cast<size_t>(field.status)], nullptr);
  }
  gst_structure_set(out, "lost", G_TYPE_UINT64, s.lost, "gaps", G_TYPE_UINT64, s.gaps, "recovered",
                    G_TYPE_UINT64, s.recovered, "faps-recovered", G_TYPE_UINT64, s.faps_recovered,
                    "complete-states", G_TYPE_UINT64, s.complete_states, "complete-changes",
                    G_TYPE_UINT64, s.complete_changes, "requests", G_TYPE_UINT64, s.requests,
                    "packet-lost-events", G_TYPE_UINT64, s.packet_lost_events, nullptr);
  return out;
}

static void gst_rtp_pfap_depay_set_property(GObject* object, guint prop_id, const GValue* value,
                                            GParamSpec* pspec) {
  switch (prop_id) {
    case PROP_REQUEST_RECOVERY:
      g_atomic_int_set(&GST_RTP_PFAP_DEPAY(object)->request_recovery, g_value_get_boolean(value));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
}

static void gst_rtp_pfap_depay_get_property(GObject* object, guint prop_id, GValue* value,
                                            GParamSpec* pspec) {
  switch (prop_id) {
    case PROP_STATS:
      g_value_take_boxed(value, stats_structure(GST_RTP_PFAP_DEPAY(object)));
      break;
    case PROP_REQUEST_RECOVERY:
      g_value_set_boolean(value, g_atomic_int_get(&GST_RTP_PFAP_DEPAY(object)->request_recovery));
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
  self->stream = new Stream{};
  self->stats = {};
  self->request_recovery = kDefaultRequestRecovery;
}

static void gst_rtp_pfap_depay_finalize(GObject* object) {
  delete GST_RTP_PFAP_DEPAY(object)->stream;
  G_OBJECT_CLASS(gst_rtp_pfap_depay_parent_class)->finalize(object);
}

static void gst_rtp_pfap_depay_class_init(GstRtpPfapDepayClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstRTPBaseDepayloadClass* depay_class = GST_RTP_BASE_DEPAYLOAD_CLASS(klass);

  gobject_class->set_property = gst_rtp_pfap_depay_set_property;
  gobject_class->get_property = gst_rtp_pfap_depay_get_property;
  gobject_class->finalize = gst_rtp_pfap_depay_finalize;

  /**
   * GstRtpPfapDepay:stats:
   *
   * GstRTPBaseDepayload's statistics (seqnum, timestamp, npt-start, npt-stop, play-speed,
   * play-scale, running-time-dts, running-time-pts), with the depayloader's counters added,
   * each guint64, since the element last went from READY to PAUSED (a flush keeps them):
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
   * - lost: packets missing before good packets, from forward jumps of the RTP sequence
   *   number; packets dropped here (malformed, or too large for x-pfap) count too
   * - gaps: good packets that came after lost ones
   * - recovered: gaps that dynamic recovery covered: the recovered events output
   * - faps-recovered: the recovery entries in those events
   * - complete-states: complete-recovery packets received
   * - complete-changes: those that changed the state: the complete events output
   * - requests: requests for a complete state sent upstream (GstForceKeyUnit events)
   * - packet-lost-events: rtpjitterbuffer's packet-lost events received
   */
  g_object_class_override_property(gobject_class, PROP_STATS, "stats");

  /**
   * GstRtpPfapDepay:request-recovery:
   *
   * Whether to ask the sender for a complete FAP state while the state may be wrong: after
   * a loss that dynamic recovery does not cover, on joining a stream mid-way, and again each
   * second of stream time until one comes (the request or its answer may be lost). The
   * request is the upstream GstForceKeyUnit event that rtpvp8depay and rtph264depay send
   * for request-keyframe; rtpbin turns it into RTCP PLI feedback when the receiving caps
   * have rtcp-fb-nack-pli=(boolean)true (SDP `a=rtcp-fb:<pt> nack pli`).
   */
  g_object_class_install_property(
      gobject_class, PROP_REQUEST_RECOVERY,
      g_param_spec_boolean(
          "request-recovery", "Request recovery",
          "Ask the sender for a complete FAP state (upstream GstForceKeyUnit, RTCP PLI in "
          "rtpbin) when the state may be wrong after a loss or on joining mid-stream",
          kDefaultRequestRecovery,
          static_cast<GParamFlags>(G_PARAM_READWRITE | GST_PARAM_MUTABLE_PLAYING |
                                   G_PARAM_STATIC_STRINGS)));

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
  depay_class->packet_lost = gst_rtp_pfap_depay_packet_lost;

  GST_DEBUG_CATEGORY_INIT(rtp_pfap_depay_debug, "rtppfapdepay", 0, "PFAP RTP depayloader");
}

// SPDX-License-Identifier: LGPL-2.1-or-later
/**
 * SECTION:element-rtppfappay
 * @title: rtppfappay
 * @see_also: rtppfapdepay
 *
 * Payloads a phoneme / MPEG-4 facial animation parameter (PFAP) stream into RTP packets as
 * draft-ietf-avt-rtp-pfap-00 defines them. Each application/x-pfap input buffer is one
 * phoneme and the FAPs (bookmarks) that start with it; its PTS is the phoneme's start.
 *
 * The element is glue around the library's pfap::Sender, which turns phonemes into packets
 * and decides when a complete state is due; its rules are these.
 *
 * How phonemes are grouped is the library's pfap::Packetizer: a packet starts at each
 * sentence start (the RTP M bit marks it), ends at end of text (sent at once, without
 * waiting for more input), holds only phonemes contiguous in time, stays within the
 * #GstRTPBasePayload:mtu unless one phoneme's FAPs alone do not fit (then that phoneme goes
 * alone in a larger packet, with a warning), and no phoneme waits longer than
 * #GstRtpPfapPay:max-delay of stream time for its packet. A pending packet goes out when a
 * later phoneme shows it is finished, or at EOS, GAP, new caps or a new segment; FLUSH
 * drops it. A live source that goes quiet should therefore send GAP events. The element
 * reports max-delay as its latency, so that sinks which sync send every packet on time.
 *
 * A buffer without a PTS starts where the previous phoneme ended (the first one at the
 * segment start): phonemes follow one another, so this is what a TTS source that left
 * the PTS out means. Malformed buffers are dropped with a warning and the stream goes on.
 * State events (recovered or complete FAP state) are dropped: the payloader makes its own
 * recovery information.
 *
 * Loss recovery (draft sections 6.1, 6.4 and 8) is the library's pfap::RecoverySender:
 *
 * - Every data packet carries dynamic recovery (C=0) covering the
 *   #GstRtpPfapPay:recovery-depth packets before it: one entry per FAP those packets
 *   bookmarked whose effect is not over, with its transition adjusted to the packet's time,
 *   so a receiver that lost up to that many packets gets its FAP state back.
 * - Complete-recovery packets (C=1, every FAP whose value is not 0) make a receiver whole
 *   whatever it lost or when it joined. Every stream (after READY to PAUSED and after a
 *   FLUSH) starts with one, so that a receiver knows from the start that its state is whole,
 *   even without RTCP; one goes before a data packet each
 *   #GstRtpPfapPay:complete-recovery-interval of stream time; and one answers a request.
 *   The interval counts stream time that moves forward: input whose timestamps go back
 *   (a new segment, a confused source) gets no extra complete packet for it, so there is
 *   never more than one per interval of speech sent plus one per request.
 * - A request is an upstream GstForceKeyUnit event on the src pad: what rtpbin's session
 *   sends when a receiver sends RTCP PLI or FIR for our SSRC, and what an application can
 *   send. If the stream is idle the packet goes out at once, with the state at the end of
 *   the last data packet; otherwise the streaming thread sends it before its next packet,
 *   or at GAP or EOS. The event is not forwarded upstream: the complete state is made here,
 *   and a PFAP source has no key units to force.
 * - Recovery never makes a packet exceed the MTU. Dynamic recovery shrinks its coverage to
 *   the deepest step whose entries fit the room the data leaves (PP says which), and goes
 *   without entries if none fits. A complete state is never cut, since a receiver takes
 *   every FAP it leaves out for 0: one that does not fit (all 72 FAPs non-zero take 433
 *   bytes) is not sent, with a warning, and the next one is due an interval or a request
 *   later.
 *
 * A complete-recovery packet has PTS = the time whose state it holds, M = 0 and no
 * duration. #GstRtpPfapPay:stats counts packets, requests and faults. A fault that repeats
 * (an oversized phoneme, a malformed buffer, a complete state over the MTU) is warned about
 * at its 1st, 2nd, 4th, 8th, ... occurrence.
 *
 * The RTP clock rate is the one downstream asks for (e.g. a capsfilter with
 * `application/x-rtp,clock-rate=90000`), else the draft's 44100 Hz. The sink caps' `alphabet`
 * string, the phoneme alphabet's identity, is copied to the output caps, so it reaches the
 * SDP as an a=fmtp parameter.
 *
 * ## Example pipeline
 * |[
 * gst-launch-1.0 filesrc location=hello.pfap ! pfaptextparse ! rtppfappay ! udpsink host=127.0.0.1
 * port=5004
 * ]| Sends the phonemes and FAPs of hello.pfap as PFAP RTP packets to port 5004.
 */
#include "gstrtppfappay.h"

#include <gst/rtp/gstrtpbuffer.h>
#include <gst/video/video-event.h>

#include <cstdint>
#include <iterator>
#include <optional>

#include "markupbuffer.h"
#include "pfap/payload.h"
#include "pfap/sender.h"
#include "pfap/timeline.h"
#include "stats.h"
#include "warning.h"

GST_DEBUG_CATEGORY_STATIC(rtppfappay_debug);
#define GST_CAT_DEFAULT rtppfappay_debug

namespace {

// The library's defaults (pfap/sender.h says why each).
constexpr pfap::SenderConfig kDefaults{};
constexpr guint kDefaultMaxDelayMs = kDefaults.max_delay_ns / pfap::kNsPerMs;
constexpr guint kDefaultRecoveryDepth = kDefaults.recovery_depth;
constexpr guint kDefaultCompleteIntervalMs = kDefaults.complete_interval_ns / pfap::kNsPerMs;
// The property ranges: a minute's wait is far past any use (the element adds it to its
// latency), an hour between complete states far past any recovery; a negative number given
// to gst-launch reads as a huge one and is refused, not taken.
constexpr guint kMaxMaxDelayMs = 60'000;
constexpr guint kMaxCompleteIntervalMs = 3'600'000;

enum { PROP_0, PROP_MAX_DELAY, PROP_RECOVERY_DEPTH, PROP_COMPLETE_RECOVERY_INTERVAL, PROP_STATS };

struct Stats {
  guint64 packets = 0;           // data packets
  guint64 recovery_entries = 0;  // dynamic recovery entries in them
  guint64 complete_recoveries = 0;
  guint64 requests = 0;
  guint64 requests_served = 0;     // complete packets that answered at least one request
  guint64 complete_too_large = 0;  // complete states not sent: larger than the MTU allows
  guint64 oversized = 0;           // data packets over the MTU: one phoneme's FAPs alone
  guint64 malformed = 0;           // input buffers dropped: not valid x-pfap events
};

// What the streaming thread keeps between buffers, under the sink pad's stream lock (the
// src event handler sends requested packets under it too). GObject runs no C++
// constructors, so it lives behind a pointer made in init and deleted in finalize.
struct Stream {
  pfap::Sender sender{};
  pfap::EventTimeline timeline;  // where a phoneme without PTS starts
  bool pushing = false;          // inside a push: a request from this thread must wait
  pfap::MarkupEvent event;       // reused for every buffer so that streaming does not allocate
};

}  // namespace

struct _GstRtpPfapPay {
  GstRTPBasePayload parent;
  // Under the object lock: properties and the counters.
  guint max_delay_ms;
  guint recovery_depth;
  guint complete_interval_ms;
  Stats stats;
  // Atomic: whether a request for a complete state waits. The streaming thread reads it before
  // every packet, and takes the object lock only to count.
  gint complete_requested;
  Stream* stream;
};

GType gst_rtp_pfap_recovery_depth_get_type() {
  static gsize type = 0;
  static constexpr GEnumValue values[] = {
      // Nicks are words; gst-launch also takes the number (recovery-depth=4), as GStreamer
      // reads an enum from its name, its nick or its value.
      {0, "No dynamic recovery", "none"},
      {1, "Recover a loss of the previous packet", "1-packet"},
      {2, "Recover losses within the previous 2 packets", "2-packets"},
      {4, "Recover losses within the previous 4 packets", "4-packets"},
      {7, "Recover losses within the previous 7 packets", "7-packets"},
      {15, "Recover losses within the previous 15 packets", "15-packets"},
      {25, "Recover losses within the previous 25 packets", "25-packets"},
      {40, "Recover losses within the previous 40 packets", "40-packets"},
      {0, nullptr, nullptr},
  };
  // A coverage added to the library without a value here, or a typo, fails to build.
  static_assert(
      [] {
        if (std::size(values) != std::size(pfap::kCoverageSteps) + 2) return false;
        for (size_t i = 0; i < std::size(pfap::kCoverageSteps); ++i) {
          if (values[i + 1].value != pfap::kCoverageSteps[i]) return false;
        }
        return true;
      }(),
      "the recovery depths are 0 and pfap::kCoverageSteps, in order");
  if (g_once_init_enter(&type)) {
    g_once_init_leave(&type, g_enum_register_static("GstRtpPfapRecoveryDepth", values));
  }
  return type;
}

static GstStaticPadTemplate sink_template = GST_STATIC_PAD_TEMPLATE(
    "sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

// The second structure shows the optional alphabet field (SDP fmtp) with the alphabet
// pfaptts and the examples use; the first, which fixation picks, any other alphabet or none.
#define PFAP_RTP_CAPS                                                              \
  "application/x-rtp, media = (string) application, payload = (int) [ 96, 127 ], " \
  "clock-rate = (int) [ 1, 2147483647 ], encoding-name = (string) PFAP"
static GstStaticPadTemplate src_template = GST_STATIC_PAD_TEMPLATE(
    "src", GST_PAD_SRC, GST_PAD_ALWAYS,
    GST_STATIC_CAPS(PFAP_RTP_CAPS "; " PFAP_RTP_CAPS ", alphabet = (string) x-pfap-arpabet"));

G_DEFINE_TYPE(GstRtpPfapPay, gst_rtp_pfap_pay, GST_TYPE_RTP_BASE_PAYLOAD)
// SECONDARY, as gst-plugins-good's payloaders: what picks a payloader by caps finds it.
GST_ELEMENT_REGISTER_DEFINE(rtppfappay, "rtppfappay", GST_RANK_SECONDARY, GST_TYPE_RTP_PFAP_PAY)

template <typename Update>
static void update_stats(GstRtpPfapPay* self, Update&& update) {
  GST_OBJECT_LOCK(self);
  update(self->stats);
  GST_OBJECT_UNLOCK(self);
}

// Forgets the stream: the next data packet starts a new one, after a complete packet (state
// changes, FLUSH). Under the stream lock, which the streaming thread already holds at
// FLUSH_STOP, because a request may send from another thread.
static void reset(GstRtpPfapPay* self) {
  GstPad* sinkpad = GST_RTP_BASE_PAYLOAD_SINKPAD(self);
  GST_PAD_STREAM_LOCK(sinkpad);
  self->stream->sender.reset();
  self->stream->timeline.reset();
  GST_PAD_STREAM_UNLOCK(sinkpad);
}

// The properties and the MTU as the sender's settings; it puts each into effect when it may.
static pfap::SenderConfig current_config(GstRtpPfapPay* self) {
  pfap::SenderConfig config;
  config.max_payload_size =
      gst_rtp_buffer_calc_payload_len(GST_RTP_BASE_PAYLOAD_MTU(GST_RTP_BASE_PAYLOAD(self)), 0, 0);
  GST_OBJECT_LOCK(self);
  config.max_delay_ns = int64_t{self->max_delay_ms} * pfap::kNsPerMs;
  config.recovery_depth = self->recovery_depth;
  config.complete_interval_ns = int64_t{self->complete_interval_ms} * pfap::kNsPerMs;
  GST_OBJECT_UNLOCK(self);
  return config;
}

// An RTP buffer with `packet` as its payload, or nullptr (with an error posted) if it cannot
// be encoded. The header and the payload are memories of their own, as rtpklvpay makes them:
// the payload is encoded into its memory before it joins the buffer, which costs less than
// mapping the RTP buffer and finding its payload, and the header is mapped only for M=1.
static GstBuffer* make_buffer(GstRtpPfapPay* self, const pfap::Packet& packet, bool marker) {
  const size_t size = pfap::encoded_size(packet);
  GstMemory* memory = gst_allocator_alloc(nullptr, size, nullptr);
  GstMapInfo map;
  gst_memory_map(memory, &map, GST_MAP_WRITE);
  const pfap::EncodeStatus status = pfap::encode_payload(packet, {map.data, size});
  gst_memory_unmap(memory, &map);
  if (status != pfap::EncodeStatus::kOk) {
    // Packets come from validated input and the library: this is a bug, not bad data.
    gst_memory_unref(memory);
    GST_ELEMENT_ERROR(self, STREAM, ENCODE, (nullptr),
                      ("cannot encode a packet: %s", pfap::to_string(status)));
    return nullptr;
  }
  GstBuffer* buffer =
      gst_rtp_base_payload_allocate_output_buffer(GST_RTP_BASE_PAYLOAD(self), 0, 0, 0);
  if (marker) {
    GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
    gst_rtp_buffer_map(buffer, GST_MAP_WRITE, &rtp);
    gst_rtp_buffer_set_marker(&rtp, TRUE);
    gst_rtp_buffer_unmap(&rtp);
  }
  gst_buffer_append_memory(buffer, memory);
  return buffer;
}

// Counts `out` and warns about what is wrong with it (rate-limited: the same fault may come
// with every phoneme or every interval).
static void account(GstRtpPfapPay* self, const pfap::OutgoingPacket& out, bool requested) {
  using Kind = pfap::OutgoingPacket::Kind;
  guint64 faults = 0;
  update_stats(self, [&](Stats& s) {
    switch (out.kind) {
      case Kind::kData:
        s.packets++;
        s.recovery_entries += out.packet->recovery.size();
        if (out.oversized) faults = ++s.oversized;
        break;
      case Kind::kComplete:
        s.complete_recoveries++;
        s.requests_served += requested;
        break;
      case Kind::kCompleteTooLarge:
        faults = ++s.complete_too_large;
        break;
    }
  });
  if (!pfap_warn_at(faults)) return;
  const guint mtu = GST_RTP_BASE_PAYLOAD_MTU(GST_RTP_BASE_PAYLOAD(self));
  if (out.kind == Kind::kData) {
    GST_ELEMENT_WARNING(self, STREAM, ENCODE, ("A phoneme and its FAPs do not fit in the MTU."),
                        ("sending a %" G_GSIZE_FORMAT "-byte payload at %" GST_TIME_FORMAT
                         "; mtu %u leaves room for %" G_GSIZE_FORMAT " bytes (%" G_GUINT64_FORMAT
                         " times so far, warned at the 1st, 2nd, 4th, 8th, ...)",
                         pfap::encoded_size(*out.packet), GST_TIME_ARGS(out.pts_ns), mtu,
                         out.max_payload_size, faults));
  } else {
    GST_ELEMENT_WARNING(
        self, STREAM, ENCODE, ("The complete FAP state does not fit in the MTU."),
        ("%" G_GSIZE_FORMAT " non-zero FAPs at %" GST_TIME_FORMAT " need %" G_GSIZE_FORMAT
         " bytes, mtu %u leaves %" G_GSIZE_FORMAT "; not sent (%" G_GUINT64_FORMAT
         " times so far, warned at the 1st, 2nd, 4th, 8th, ...)",
         out.packet->recovery.size(), GST_TIME_ARGS(out.pts_ns), pfap::encoded_size(*out.packet),
         mtu, out.max_payload_size, faults));
  }
}

// Sends `out` (a complete state too large for the MTU is only counted). A complete packet
// answers every request made before it.
static GstFlowReturn push_packet(GstRtpPfapPay* self, const pfap::OutgoingPacket& out) {
  using Kind = pfap::OutgoingPacket::Kind;
  bool requested = false;
  if (out.kind != Kind::kData) requested = g_atomic_int_exchange(&self->complete_requested, FALSE);
  account(self, out, requested);
  if (out.kind == Kind::kCompleteTooLarge) return GST_FLOW_OK;
  GstBuffer* buffer = make_buffer(self, *out.packet, out.marker);
  if (buffer == nullptr) return GST_FLOW_ERROR;
  // The base class makes the RTP timestamp from the PTS.
  GST_BUFFER_PTS(buffer) = out.pts_ns;
  GST_BUFFER_DURATION(buffer) = out.duration_ns;
  GST_LOG_OBJECT(self,
                 "%s packet at %" GST_TIME_FORMAT ": %" G_GSIZE_FORMAT " phonemes, %" G_GSIZE_FORMAT
                 " bytes, M=%d, %" G_GSIZE_FORMAT " recovery entries",
                 out.kind == Kind::kData ? "data" : "complete-recovery", GST_TIME_ARGS(out.pts_ns),
                 out.packet->phonemes.size(), gst_buffer_get_size(buffer), out.marker,
                 out.packet->recovery.size());
  Stream& stream = *self->stream;
  stream.pushing = true;
  const GstFlowReturn ret = gst_rtp_base_payload_push(GST_RTP_BASE_PAYLOAD(self), buffer);
  stream.pushing = false;
  return ret;
}

// Sends every packet the sender has ready, one push each: the base class gives all the
// packets of a buffer list the RTP timestamp of the first. A request made while pushing is
// answered before the next data packet.
static GstFlowReturn push_ready(GstRtpPfapPay* self) {
  pfap::Sender& sender = self->stream->sender;
  GstFlowReturn ret = GST_FLOW_OK;
  while (true) {
    const pfap::OutgoingPacket* out = sender.next(g_atomic_int_get(&self->complete_requested));
    if (out == nullptr) break;
    // After an error the rest is not pushed, but taken, so that the next buffer starts clean.
    if (ret == GST_FLOW_OK) ret = push_packet(self, *out);
  }
  return ret;
}

// Answers a pending request at once, with the state where the stream is now. Before the
// stream's first data packet there is nothing to send yet: the complete packet that goes
// before it answers. Under the stream lock.
static GstFlowReturn serve_request(GstRtpPfapPay* self) {
  Stream& stream = *self->stream;
  if (stream.pushing) return GST_FLOW_OK;
  if (!g_atomic_int_get(&self->complete_requested)) return GST_FLOW_OK;
  const pfap::OutgoingPacket* out = stream.sender.complete_now();
  return out != nullptr ? push_packet(self, *out) : GST_FLOW_OK;
}

// Sends the pending packet now: no later phoneme may join it.
static GstFlowReturn drain(GstRtpPfapPay* self) {
  self->stream->sender.drain();
  return push_ready(self);
}

static GstFlowReturn gst_rtp_pfap_pay_handle_buffer(GstRTPBasePayload* payload, GstBuffer* buffer) {
  GstRtpPfapPay* self = GST_RTP_PFAP_PAY(payload);
  Stream& stream = *self->stream;
  const GstClockTime pts = GST_BUFFER_PTS(buffer);
  pfap::MarkupEvent& event = stream.event;
  if (!pfap_buffer_read(buffer, event)) {
    guint64 malformed = 0;
    update_stats(self, [&](Stats& s) { malformed = ++s.malformed; });
    PFAP_WARN_MALFORMED_EVENT(self, buffer, malformed);
    gst_buffer_unref(buffer);
    return GST_FLOW_OK;
  }
  gst_buffer_unref(buffer);
  if (event.kind != PFAP_EVENT_PHONEME) {
    GST_DEBUG_OBJECT(self, "dropping state event (kind %d) at %" GST_TIME_FORMAT, event.kind,
                     GST_TIME_ARGS(pts));
    return GST_FLOW_OK;
  }

  const int64_t start = stream.timeline.start(
      GST_CLOCK_TIME_IS_VALID(pts) ? std::optional<int64_t>(pts) : std::nullopt,
      static_cast<int64_t>(payload->segment.start));
  stream.timeline.add(start, int64_t{event.phoneme.duration_ms} * pfap::kNsPerMs);
  if (const pfap::SenderConfig config = current_config(self); config != stream.sender.config()) {
    stream.sender.configure(config);
  }
  stream.sender.push({start, event.phoneme, event.sentence_start}, event.faps);
  return push_ready(self);
}

// The clock rate downstream insists on (a fixed clock-rate in its caps), else 44100 Hz.
static uint32_t downstream_clock_rate(GstRTPBasePayload* payload) {
  GstPad* srcpad = GST_RTP_BASE_PAYLOAD_SRCPAD(payload);
  GstCaps* template_caps = gst_pad_get_pad_template_caps(srcpad);
  GstCaps* peer_caps = gst_pad_peer_query_caps(srcpad, template_caps);
  gst_caps_unref(template_caps);
  gint rate = 0;
  if (!gst_caps_is_empty(peer_caps)) {
    gst_structure_get_int(gst_caps_get_structure(peer_caps, 0), "clock-rate", &rate);
  }
  gst_caps_unref(peer_caps);
  return rate > 0 ? static_cast<uint32_t>(rate) : pfap::kDefaultClockRate;
}

static gboolean gst_rtp_pfap_pay_set_caps(GstRTPBasePayload* payload, GstCaps* caps) {
  gst_rtp_base_payload_set_options(payload, "application", TRUE, "PFAP",
                                   downstream_clock_rate(payload));
  // Copied as a string: only string fields become SDP a=fmtp parameters.
  const gchar* alphabet = gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet");
  if (alphabet != nullptr) {
    return gst_rtp_base_payload_set_outcaps(payload, "alphabet", G_TYPE_STRING, alphabet, nullptr);
  }
  return gst_rtp_base_payload_set_outcaps(payload, nullptr);
}

static gboolean gst_rtp_pfap_pay_sink_event(GstRTPBasePayload* payload, GstEvent* event) {
  GstRtpPfapPay* self = GST_RTP_PFAP_PAY(payload);
  switch (GST_EVENT_TYPE(event)) {
    // No later phoneme joins the pending packet: the stream ends or has a gap, or what
    // follows is read under new caps (another alphabet) or a new segment.
    case GST_EVENT_EOS:
    case GST_EVENT_GAP:
      drain(self);
      // No packet may come for a while, or ever: a request waiting for one goes now.
      serve_request(self);
      break;
    case GST_EVENT_CAPS:
    case GST_EVENT_SEGMENT:
      drain(self);
      break;
    case GST_EVENT_FLUSH_STOP:
      reset(self);
      break;
    default:
      break;
  }
  return GST_RTP_BASE_PAYLOAD_CLASS(gst_rtp_pfap_pay_parent_class)->sink_event(payload, event);
}

// A request for the complete state (GstForceKeyUnit). It comes from another thread (rtpbin's
// RTCP, an application) while the streaming thread may be pushing: it is sent from here only
// if the stream lock is free, else the streaming thread sends it before its next packet.
static gboolean gst_rtp_pfap_pay_src_event(GstRTPBasePayload* payload, GstEvent* event) {
  if (!gst_video_event_parse_upstream_force_key_unit(event, nullptr, nullptr, nullptr)) {
    return GST_RTP_BASE_PAYLOAD_CLASS(gst_rtp_pfap_pay_parent_class)->src_event(payload, event);
  }
  GstRtpPfapPay* self = GST_RTP_PFAP_PAY(payload);
  GST_DEBUG_OBJECT(self, "complete recovery requested");
  GST_OBJECT_LOCK(self);
  self->stats.requests++;
  GST_OBJECT_UNLOCK(self);
  g_atomic_int_set(&self->complete_requested, TRUE);
  GstPad* sinkpad = GST_RTP_BASE_PAYLOAD_SINKPAD(payload);
  if (GST_PAD_STREAM_TRYLOCK(sinkpad)) {
    serve_request(self);
    GST_PAD_STREAM_UNLOCK(sinkpad);
  }
  // Answered here: upstream has no key units, and the complete state is made here.
  gst_event_unref(event);
  return TRUE;
}

static GstStructure* stats_structure(GstRtpPfapPay* self) {
  GST_OBJECT_LOCK(self);
  const Stats s = self->stats;
  GST_OBJECT_UNLOCK(self);
  // GstRTPBasePayload's (clock-rate, running-time, seqnum, timestamp, ssrc, pt, ...) and ours.
  GstStructure* stats = pfap_owner_stats(G_OBJECT(self), GST_TYPE_RTP_BASE_PAYLOAD);
  gst_structure_set(stats, "packets", G_TYPE_UINT64, s.packets, "recovery-entries", G_TYPE_UINT64,
                    s.recovery_entries, "complete-recoveries", G_TYPE_UINT64, s.complete_recoveries,
                    "requests", G_TYPE_UINT64, s.requests, "requests-served", G_TYPE_UINT64,
                    s.requests_served, "complete-too-large", G_TYPE_UINT64, s.complete_too_large,
                    "oversized", G_TYPE_UINT64, s.oversized, "malformed", G_TYPE_UINT64,
                    s.malformed, nullptr);
  return stats;
}

static GstStateChangeReturn gst_rtp_pfap_pay_change_state(GstElement* element,
                                                          GstStateChange transition) {
  GstRtpPfapPay* self = GST_RTP_PFAP_PAY(element);
  if (transition == GST_STATE_CHANGE_READY_TO_PAUSED) {
    reset(self);
    GST_OBJECT_LOCK(self);
    self->stats = {};
    GST_OBJECT_UNLOCK(self);
    // A new stream starts with a complete packet anyway.
    g_atomic_int_set(&self->complete_requested, FALSE);
  }
  const GstStateChangeReturn ret =
      GST_ELEMENT_CLASS(gst_rtp_pfap_pay_parent_class)->change_state(element, transition);
  if (transition == GST_STATE_CHANGE_PAUSED_TO_READY) reset(self);
  return ret;
}

// LATENCY: upstream's plus max-delay, the longest a phoneme waits here. Without it, sinks
// that sync (udpsink) send late packets, and a receiver's jitterbuffer takes the varying
// lateness for clock skew, which moves the phonemes against the audio.
// Set on the src pad itself: on 1.22 LATENCY queries on the src pad never reach the base
// class's query vfunc (LatencyIsUpstreamLatencyPlusMaxDelay fails with it).
static gboolean gst_rtp_pfap_pay_src_query(GstPad* pad, GstObject* parent, GstQuery* query) {
  if (GST_QUERY_TYPE(query) != GST_QUERY_LATENCY) return gst_pad_query_default(pad, parent, query);
  if (!gst_pad_peer_query(GST_RTP_BASE_PAYLOAD_SINKPAD(parent), query)) return FALSE;
  gboolean live = FALSE;
  GstClockTime min = 0;
  GstClockTime max = GST_CLOCK_TIME_NONE;
  gst_query_parse_latency(query, &live, &min, &max);
  GST_OBJECT_LOCK(parent);
  const GstClockTime delay = GST_RTP_PFAP_PAY(parent)->max_delay_ms * GST_MSECOND;
  GST_OBJECT_UNLOCK(parent);
  gst_query_set_latency(query, live, min + delay, GST_CLOCK_TIME_IS_VALID(max) ? max + delay : max);
  return TRUE;
}

static void gst_rtp_pfap_pay_set_property(GObject* object, guint prop_id, const GValue* value,
                                          GParamSpec* pspec) {
  GstRtpPfapPay* self = GST_RTP_PFAP_PAY(object);
  switch (prop_id) {
    case PROP_MAX_DELAY:
      GST_OBJECT_LOCK(self);
      self->max_delay_ms = g_value_get_uint(value);
      GST_OBJECT_UNLOCK(self);
      // The pipeline asks for the latency again.
      gst_element_post_message(GST_ELEMENT(self), gst_message_new_latency(GST_OBJECT(self)));
      break;
    case PROP_RECOVERY_DEPTH:
      GST_OBJECT_LOCK(self);
      self->recovery_depth = static_cast<guint>(g_value_get_enum(value));
      GST_OBJECT_UNLOCK(self);
      break;
    case PROP_COMPLETE_RECOVERY_INTERVAL:
      GST_OBJECT_LOCK(self);
      self->complete_interval_ms = g_value_get_uint(value);
      GST_OBJECT_UNLOCK(self);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
}

static void gst_rtp_pfap_pay_get_property(GObject* object, guint prop_id, GValue* value,
                                          GParamSpec* pspec) {
  GstRtpPfapPay* self = GST_RTP_PFAP_PAY(object);
  switch (prop_id) {
    case PROP_MAX_DELAY:
      GST_OBJECT_LOCK(self);
      g_value_set_uint(value, self->max_delay_ms);
      GST_OBJECT_UNLOCK(self);
      break;
    case PROP_RECOVERY_DEPTH:
      GST_OBJECT_LOCK(self);
      g_value_set_enum(value, static_cast<gint>(self->recovery_depth));
      GST_OBJECT_UNLOCK(self);
      break;
    case PROP_COMPLETE_RECOVERY_INTERVAL:
      GST_OBJECT_LOCK(self);
      g_value_set_uint(value, self->complete_interval_ms);
      GST_OBJECT_UNLOCK(self);
      break;
    case PROP_STATS:
      g_value_take_boxed(value, stats_structure(self));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
}

static void gst_rtp_pfap_pay_finalize(GObject* object) {
  delete GST_RTP_PFAP_PAY(object)->stream;
  G_OBJECT_CLASS(gst_rtp_pfap_pay_parent_class)->finalize(object);
}

static void gst_rtp_pfap_pay_class_init(GstRtpPfapPayClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstRTPBasePayloadClass* payload_class = GST_RTP_BASE_PAYLOAD_CLASS(klass);

  GST_DEBUG_CATEGORY_INIT(rtppfappay_debug, "rtppfappay", 0, "PFAP RTP payloader");

  gobject_class->set_property = gst_rtp_pfap_pay_set_property;
  gobject_class->get_property = gst_rtp_pfap_pay_get_property;
  gobject_class->finalize = gst_rtp_pfap_pay_finalize;

  /**
   * GstRtpPfapPay:max-delay:
   *
   * The longest a phoneme waits for its packet, in milliseconds of stream time; 0 sends
   * every phoneme in a packet of its own. Larger values make fewer, larger packets. The
   * default of 100 ms stays below rtpbin's default jitterbuffer latency of 200 ms, so a
   * live receiver still shows each phoneme in lip sync with the audio. The element adds
   * max-delay to the pipeline latency.
   */
  g_object_class_install_property(
      gobject_class, PROP_MAX_DELAY,
      g_param_spec_uint("max-delay", "Maximum delay",
                        "Longest a phoneme waits for its packet, in ms of stream time "
                        "(0 = one packet per phoneme)",
                        0, kMaxMaxDelayMs, kDefaultMaxDelayMs,
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_PLAYING)));

  /**
   * GstRtpPfapPay:recovery-depth:
   *
   * How many packets before it each data packet's dynamic recovery covers: 0 (none) or a
   * coverage the PP field can signal, 1, 2, 4, 7, 15, 25 or 40. A receiver that lost at
   * most that many packets in a row gets its FAP state back from the next packet, without
   * waiting for a complete state. It costs 6 bytes in every data packet per FAP bookmarked
   * in the covered packets whose effect is not over, and nothing when there is none. Where
   * the MTU leaves too little room, a packet covers fewer packets (PP says how many). The
   * default of 4 covers most loss bursts.
   *
   * A change takes effect from the next data packet. A deeper setting covers only the
   * packets the payloader still holds, and grows to the new depth one packet at a time: a
   * packet never claims to cover packets whose bookmarks it does not know.
   */
  g_object_class_install_property(
      gobject_class, PROP_RECOVERY_DEPTH,
      g_param_spec_enum("recovery-depth", "Recovery depth",
                        "Packets each data packet's dynamic recovery covers (0 = none; 6 bytes "
                        "per FAP still in effect in them, less coverage where the MTU lacks room)",
                        GST_TYPE_RTP_PFAP_RECOVERY_DEPTH, kDefaultRecoveryDepth,
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_PLAYING)));

  /**
   * GstRtpPfapPay:complete-recovery-interval:
   *
   * The stream time in milliseconds after which a complete-recovery packet goes before the
   * next data packet; 0 sends one only at the start of a stream and on request. The default
   * of 1000 ms is for receivers that cannot ask: late joiners of shared RTSP media on
   * GStreamer 1.22 get no request path (rtsp-server does not necessarily pass on a new
   * joiner's PLI) and depend on the periodic packet. 1 s bounds their wait for 13 bytes
   * (RTP header and packet descriptor) plus 6 per FAP not at 0, each second. The packet goes
   * before a data packet, so a stream that only sends GAP sends none until it speaks again.
   */
  g_object_class_install_property(
      gobject_class, PROP_COMPLETE_RECOVERY_INTERVAL,
      g_param_spec_uint("complete-recovery-interval", "Complete recovery interval",
                        "Stream time between complete-recovery packets, in ms (0 = only at the "
                        "start of a stream and on request)",
                        0, kMaxCompleteIntervalMs, kDefaultCompleteIntervalMs,
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_PLAYING)));

  /**
   * GstRtpPfapPay:stats:
   *
   * GstRTPBasePayload's statistics (clock-rate, running-time, seqnum, timestamp, ssrc, pt,
   * seqnum-offset, timestamp-offset), with the payloader's counters added, each guint64,
   * since the element last went from READY to PAUSED (a flush keeps them):
   *
   * - packets: data packets sent
   * - recovery-entries: dynamic recovery entries in them
   * - complete-recoveries: complete-recovery packets sent, for any reason
   * - requests: requests for the complete state received (GstForceKeyUnit events)
   * - requests-served: complete-recovery packets that answered requests (requests that
   *   arrive before one is sent share it)
   * - complete-too-large: complete states not sent because they do not fit in the MTU
   * - oversized: data packets larger than the MTU: one phoneme whose FAPs alone do not fit
   * - malformed: input buffers dropped because they are not valid x-pfap events
   *
   * The faults counted in the last three are each warned about at their 1st, 2nd, 4th, 8th,
   * ... occurrence only, so that a lasting fault does not flood the bus.
   */
  g_object_class_override_property(gobject_class, PROP_STATS, "stats");

  gst_type_mark_as_plugin_api(GST_TYPE_RTP_PFAP_RECOVERY_DEPTH, static_cast<GstPluginAPIFlags>(0));
  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_set_static_metadata(
      element_class, "RTP PFAP payloader", "Codec/Payloader/Network/RTP",
      "Payloads phoneme and MPEG-4 facial animation parameter (PFAP) streams as RTP packets "
      "(draft-ietf-avt-rtp-pfap-00)",
      "gst-pfap developers");

  element_class->change_state = gst_rtp_pfap_pay_change_state;

  payload_class->set_caps = gst_rtp_pfap_pay_set_caps;
  payload_class->handle_buffer = gst_rtp_pfap_pay_handle_buffer;
  payload_class->sink_event = gst_rtp_pfap_pay_sink_event;
  payload_class->src_event = gst_rtp_pfap_pay_src_event;
}

static void gst_rtp_pfap_pay_init(GstRtpPfapPay* self) {
  self->max_delay_ms = kDefaultMaxDelayMs;
  self->recovery_depth = kDefaultRecoveryDepth;
  self->complete_interval_ms = kDefaultCompleteIntervalMs;
  self->complete_requested = FALSE;
  self->stats = {};
  self->stream = new Stream{};
  gst_pad_set_query_function(GST_RTP_BASE_PAYLOAD_SRCPAD(self), gst_rtp_pfap_pay_src_query);
}

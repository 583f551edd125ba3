/**
 * SECTION:element-rtppfappay
 * @title: rtppfappay
 * @see_also: rtppfapdepay
 *
 * Payloads a phoneme / MPEG-4 facial animation parameter (PFAP) stream into RTP packets as
 * draft-ietf-avt-rtp-pfap-00 defines them. Each application/x-pfap input buffer is one
 * phoneme and the FAPs (bookmarks) that start with it; its PTS is the phoneme's start.
 *
 * How phonemes are grouped is the library's pfap::Packetizer: a packet starts at each
 * sentence start (the RTP M bit marks it), ends at end of text (sent at once, without
 * waiting for more input), holds only phonemes contiguous in time, stays within the
 * #GstRTPBasePayload:mtu unless one phoneme's FAPs alone do not fit (then that phoneme goes
 * alone in a larger packet, with a warning), and no phoneme waits longer than
 * #GstRtpPfapPay:max-delay of stream time for its packet. A pending packet goes out when a
 * later phoneme shows it is complete, or at EOS, GAP, new caps or a new segment; FLUSH
 * drops it. A live source that goes quiet should therefore send GAP events. The element
 * reports max-delay as its latency, so that sinks which sync send every packet on time.
 *
 * A buffer without a PTS starts where the previous phoneme ended (the first one at the
 * segment start): phonemes follow one another, so this is what a TTS source that left
 * the PTS out means. Malformed buffers are dropped with a warning and the stream goes on.
 * State events (recovered or complete FAP state) are dropped: the payloader will make its
 * own recovery information.
 *
 * The RTP clock rate is the one downstream asks for (e.g. a capsfilter with
 * `application/x-rtp,clock-rate=90000`), else the draft's 44100 Hz. The sink caps' `alphabet`
 * string, the phoneme alphabet's identity, is copied to the output caps, so it reaches the
 * SDP as an a=fmtp parameter.
 *
 * ## Example pipeline
 * |[
 * gst-launch-1.0 filesrc location=hello.pfap ! pfapparse ! rtppfappay ! udpsink host=127.0.0.1 port=5004
 * ]| Sends the phonemes and FAPs of hello.pfap as PFAP RTP packets to port 5004.
 */
#include "gstrtppfappay.h"

#include <gst/rtp/gstrtpbuffer.h>

#include <cstdint>
#include <vector>

#include "pfap/packetizer.h"
#include "pfap/payload.h"
#include "pfapbuffer.h"

GST_DEBUG_CATEGORY_STATIC(rtppfappay_debug);
#define GST_CAT_DEFAULT rtppfappay_debug

namespace {

// Below rtpbin's default jitterbuffer latency of 200 ms, so a live receiver still gets each
// phoneme in time to show it in lip sync with the audio.
constexpr guint kDefaultMaxDelayMs = 100;

enum { PROP_0, PROP_MAX_DELAY };

// What the streaming thread keeps between buffers. GObject runs no C++ constructors, so it
// lives behind a pointer made in init and deleted in finalize.
struct Stream {
  pfap::Packetizer packetizer{pfap::PacketizerConfig{}};
  uint32_t clock_rate = pfap::kDefaultClockRate;
  GstClockTime next_start = GST_CLOCK_TIME_NONE;  // where a phoneme without PTS starts
  // Reused for every buffer so that steady streaming does not allocate.
  pfap::MarkupEvent event;
  std::vector<pfap::PlannedPacket> planned;
};

}  // namespace

struct _GstRtpPfapPay {
  GstRTPBasePayload parent;
  guint max_delay_ms;  // under the object lock
  Stream* stream;
};

static GstStaticPadTemplate sink_template = GST_STATIC_PAD_TEMPLATE(
    "sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

static GstStaticPadTemplate src_template = GST_STATIC_PAD_TEMPLATE(
    "src", GST_PAD_SRC, GST_PAD_ALWAYS,
    GST_STATIC_CAPS("application/x-rtp, media = (string) application, "
                    "payload = (int) [ 96, 127 ], clock-rate = (int) [ 1, 2147483647 ], "
                    "encoding-name = (string) PFAP"));

G_DEFINE_TYPE(GstRtpPfapPay, gst_rtp_pfap_pay, GST_TYPE_RTP_BASE_PAYLOAD)
GST_ELEMENT_REGISTER_DEFINE(rtppfappay, "rtppfappay", GST_RANK_NONE, GST_TYPE_RTP_PFAP_PAY)

// Forgets the pending packet and the stream position (state changes, FLUSH).
static void reset(GstRtpPfapPay* self) {
  self->stream->packetizer.reset();
  self->stream->next_start = GST_CLOCK_TIME_NONE;
}

static pfap::PacketizerConfig current_config(GstRtpPfapPay* self) {
  pfap::PacketizerConfig config;
  config.max_payload_size =
      gst_rtp_buffer_calc_payload_len(GST_RTP_BASE_PAYLOAD_MTU(GST_RTP_BASE_PAYLOAD(self)), 0, 0);
  GST_OBJECT_LOCK(self);
  config.max_delay_ns = int64_t{self->max_delay_ms} * pfap::kNsPerMs;
  GST_OBJECT_UNLOCK(self);
  config.clock_rate = self->stream->clock_rate;
  return config;
}

// Puts mtu, max-delay and clock rate changes into effect. Only between packets: a packet
// keeps the limits it was started with.
static void update_config(GstRtpPfapPay* self) {
  pfap::Packetizer& packetizer = self->stream->packetizer;
  if (packetizer.has_pending()) return;
  const pfap::PacketizerConfig config = current_config(self);
  const pfap::PacketizerConfig& old = packetizer.config();
  if (config.max_payload_size != old.max_payload_size || config.max_delay_ns != old.max_delay_ns ||
      config.clock_rate != old.clock_rate) {
    GST_DEBUG_OBJECT(
        self,
        "max payload %" G_GSIZE_FORMAT " bytes, max delay %" GST_TIME_FORMAT ", clock rate %u",
        config.max_payload_size, GST_TIME_ARGS(config.max_delay_ns), config.clock_rate);
    packetizer = pfap::Packetizer(config);
  }
}

static GstFlowReturn push_packet(GstRtpPfapPay* self, const pfap::PlannedPacket& planned) {
  GstRTPBasePayload* payload = GST_RTP_BASE_PAYLOAD(self);
  const size_t size = pfap::encoded_size(planned.packet);
  if (planned.oversized) {
    GST_ELEMENT_WARNING(self, STREAM, ENCODE, ("A phoneme and its FAPs do not fit in the MTU."),
                        ("sending a %" G_GSIZE_FORMAT "-byte payload at %" GST_TIME_FORMAT
                         "; mtu %u leaves room for %" G_GSIZE_FORMAT " bytes",
                         size, GST_TIME_ARGS(planned.start_ns), GST_RTP_BASE_PAYLOAD_MTU(payload),
                         self->stream->packetizer.config().max_payload_size));
  }

  GstBuffer* buffer = gst_rtp_base_payload_allocate_output_buffer(payload, size, 0, 0);
  GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
  gst_rtp_buffer_map(buffer, GST_MAP_WRITE, &rtp);
  const pfap::EncodeStatus status = pfap::encode_payload(
      planned.packet, {static_cast<uint8_t*>(gst_rtp_buffer_get_payload(&rtp)), size});
  gst_rtp_buffer_set_marker(&rtp, planned.marker);
  gst_rtp_buffer_unmap(&rtp);
  if (status != pfap::EncodeStatus::kOk) {
    // The packetizer only plans packets of validated input: this is a bug, not bad data.
    gst_buffer_unref(buffer);
    GST_ELEMENT_ERROR(self, STREAM, ENCODE, (nullptr),
                      ("cannot encode a packet: %s", pfap::to_string(status)));
    return GST_FLOW_ERROR;
  }

  uint32_t duration_ms = 0;
  for (const pfap::PacketPhoneme& p : planned.packet.phonemes) duration_ms += p.phoneme.duration_ms;
  // The base class makes the RTP timestamp from the PTS.
  GST_BUFFER_PTS(buffer) = planned.start_ns;
  GST_BUFFER_DURATION(buffer) = duration_ms * GST_MSECOND;
  GST_LOG_OBJECT(self, "packet of %" G_GSIZE_FORMAT " phonemes, %" G_GSIZE_FORMAT " bytes, M=%d",
                 planned.packet.phonemes.size(), size, planned.marker);
  return gst_rtp_base_payload_push(payload, buffer);
}

// Sends the packets the packetizer completed, one push each: the base class gives all the
// packets of a buffer list the RTP timestamp of the first.
static GstFlowReturn push_planned(GstRtpPfapPay* self) {
  GstFlowReturn ret = GST_FLOW_OK;
  for (const pfap::PlannedPacket& planned : self->stream->planned) {
    ret = push_packet(self, planned);
    if (ret != GST_FLOW_OK) break;
  }
  self->stream->planned.clear();
  return ret;
}

// Sends the pending packet now: no later phoneme may join it.
static GstFlowReturn drain(GstRtpPfapPay* self) {
  self->stream->packetizer.flush(self->stream->planned);
  return push_planned(self);
}

static GstFlowReturn gst_rtp_pfap_pay_handle_buffer(GstRTPBasePayload* payload, GstBuffer* buffer) {
  GstRtpPfapPay* self = GST_RTP_PFAP_PAY(payload);
  Stream& stream = *self->stream;
  GstClockTime start = GST_BUFFER_PTS(buffer);
  pfap::MarkupEvent& event = stream.event;
  const bool ok = pfap_buffer_read(buffer, event);
  if (!ok) {
    GST_ELEMENT_WARNING(self, STREAM, DECODE, ("Dropped a malformed PFAP event."),
                        ("%" G_GSIZE_FORMAT " bytes at %" GST_TIME_FORMAT
                         " are not a valid application/x-pfap event",
                         gst_buffer_get_size(buffer), GST_TIME_ARGS(start)));
  }
  gst_buffer_unref(buffer);
  if (!ok) return GST_FLOW_OK;
  if (event.kind != PFAP_EVENT_PHONEME) {
    GST_DEBUG_OBJECT(self, "dropping state event (kind %d) at %" GST_TIME_FORMAT, event.kind,
                     GST_TIME_ARGS(start));
    return GST_FLOW_OK;
  }

  if (!GST_CLOCK_TIME_IS_VALID(start)) {
    start = GST_CLOCK_TIME_IS_VALID(stream.next_start) ? stream.next_start : payload->segment.start;
  }
  stream.next_start = start + event.phoneme.duration_ms * GST_MSECOND;

  const pfap::TimedPhoneme phoneme{static_cast<int64_t>(start), event.phoneme,
                                   event.sentence_start};
  update_config(self);
  stream.packetizer.push(phoneme, event.faps, stream.planned);
  return push_planned(self);
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
  GstRtpPfapPay* self = GST_RTP_PFAP_PAY(payload);
  self->stream->clock_rate = downstream_clock_rate(payload);
  gst_rtp_base_payload_set_options(payload, "application", TRUE, "PFAP", self->stream->clock_rate);
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

static GstStateChangeReturn gst_rtp_pfap_pay_change_state(GstElement* element,
                                                          GstStateChange transition) {
  GstRtpPfapPay* self = GST_RTP_PFAP_PAY(element);
  if (transition == GST_STATE_CHANGE_READY_TO_PAUSED) reset(self);
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
                        0, G_MAXUINT, kDefaultMaxDelayMs,
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_PLAYING)));

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
}

static void gst_rtp_pfap_pay_init(GstRtpPfapPay* self) {
  self->max_delay_ms = kDefaultMaxDelayMs;
  self->stream = new Stream{};
  gst_pad_set_query_function(GST_RTP_BASE_PAYLOAD_SRCPAD(self), gst_rtp_pfap_pay_src_query);
}

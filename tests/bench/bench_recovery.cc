// SPDX-License-Identifier: LGPL-2.1-or-later
// Loss recovery measured: what each protection of a PFAP stream costs in bytes, and how many
// received phonemes still see a wrong FAP state, on one seeded session and the same seeded
// loss patterns, side by side.
//
// The session: 3000 phonemes of speech (sentences of 6..14 phonemes of 40..100 ms, pauses of
// 100..300 ms; about 11 phonemes per second of stream time), a FAP before 45 % of the
// phonemes (1..3 each: linear, triangle and spline curves on the indexes 3..12 and the
// expressions 69..74, reused, so FAPs interact).
//
// Each protection is a sender chain after `appsrc ! rtppfappay` and the receiver chain that
// undoes it before `rtppfapdepay request-recovery=false ! (the application)`:
//
//   none                  rtppfappay recovery-depth=0
//   depth N               rtppfappay recovery-depth=N               (the payload format's own)
//   RED distance=N        rtppfappay ! rtpredenc pt=122 distance=N  | rtpreddec pt=122
//   RED ... by seqnum     rtppfappay ! rtpredenc pt=122 distance=1  | unred() below: what
//                         RFC 2198 could give with a decoder that does not need evenly
//                         spaced timestamps, which rtpreddec does
//   ULPFEC P %            rtppfappay ! rtpulpfecenc pt=122 percentage=P [multipacket=false]
//                         | rtpstorage ! rtpjitterbuffer do-lost=true latency=L
//                           ! rtpulpfecdec pt=122 (storage: rtpstorage's internal-storage;
//                           the FEC packets kept out of it, as rtpbin's rtpptdemux does)
//
// complete-recovery-interval=0 everywhere (one complete state at the start of the stream)
// and request-recovery=false, so that only the protection under test repairs anything;
// the row "depth 4 + complete 1 s" is the element defaults without the request path, and
// "depth 4 + ULPFEC 50 %" shows what rtpulpfecdec does to the payload format's recovery.
//
// Each sender runs once; its RTP packets are then fed to a fresh receiver per loss pattern,
// in the order sent, leaving out those the pattern drops. Loss patterns drop by the packet's
// position on the wire (so a FEC stream, which has more packets, loses as often per packet);
// the first packet (the complete state a stream starts with) always arrives.
//
// Measured per protection: overhead = RTP payload bytes sent (recovery entries, RED blocks
// and headers, FEC packets included) / those of "none" - 1; per pattern, the share of
// received phonemes after which the receiver's settled FAP values (FapState::settled, built
// from the depayloader's events as an application would) differ from a lossless receiver's,
// and the share of the session's phonemes received at all. Also printed: the payload bit
// rate, the overhead with 40 bytes of IPv4/UDP/RTP headers per packet, the packets RED or
// FEC rebuilt, the share of phonemes with a wrong state the depayloader did not flag
// uncertain (it promises none), the share it flagged, and the losses it counted.
//
// The ULPFEC receiver runs against a GstTestClock: packets arrive at their PTS (the time of
// their first phoneme), and rtpjitterbuffer's lost timers fire at their own times, so
// rtpulpfecdec finds in rtpstorage exactly what had arrived by then (FecReceiver).
//
// Run: meson test -C build --benchmark --suite gst --verbose recovery
//  or: GST_PLUGIN_PATH=build/gst:build/ext build/tests/bench/bench_recovery [phonemes [only]]
// (`only`: run just the protections whose name contains it, beside "none").
#include <gst/check/gstharness.h>
#include <gst/check/gsttestclock.h>
#include <gst/gst.h>
#include <gst/rtp/gstrtpbuffer.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "element_stats.h"
#include "pfap/fap_state.h"
#include "pfap/markup.h"
#include "pfap/model.h"
#include "rtp_packet.h"
#include "speech_session.h"

namespace {

using pfap::testing::Settled;

constexpr int kRedPt = 122;
constexpr int kFecPt = 122;

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "bench_recovery: %s\n", what.c_str());
  std::exit(1);
}

// ---------------------------------------------------------------------------------------------
// The session and the lossless receiver

using Phoneme = pfap::testing::SpeechPhoneme;
using pfap::testing::lossless_states;
using pfap::testing::settled_of;
using pfap::testing::speech_session;
using pfap::testing::stat;

GstBuffer* phoneme_buffer(const Phoneme& p) {
  const pfap::Phoneme& ph = p.phoneme;
  const PfapEventHeader header{
      PFAP_EVENT_PHONEME,
      static_cast<uint8_t>((ph.stress ? PFAP_FLAG_STRESS : 0) |
                           (ph.word_begin ? PFAP_FLAG_WORD_BEGIN : 0) |
                           (ph.end_of_text ? PFAP_FLAG_END_OF_TEXT : 0) |
                           (p.sentence_start ? PFAP_FLAG_SENTENCE_START : 0)),
      ph.symbol,
      ph.f0,
      ph.duration_ms,
      static_cast<uint16_t>(p.faps.size())};
  std::vector<PfapFap> records;
  for (const pfap::Fap& f : p.faps) {
    records.push_back({f.index, static_cast<uint8_t>(f.curve), f.transition_ms, f.amplitude});
  }
  const size_t size = pfap_markup_size(header.n_faps);
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, size, nullptr);
  GstMapInfo map;
  gst_buffer_map(buffer, &map, GST_MAP_WRITE);
  if (pfap_markup_write(&header, records.data(), map.data, size) != 0) fail("bad phoneme");
  gst_buffer_unmap(buffer, &map);
  GST_BUFFER_PTS(buffer) = p.start_ns;
  GST_BUFFER_DURATION(buffer) = ph.duration_ms * GST_MSECOND;
  return buffer;
}

// ---------------------------------------------------------------------------------------------
// Loss patterns

struct LossPattern {
  std::string name;
  std::vector<bool> drop;  // by position on the wire
};

LossPattern random_loss(double loss, uint32_t seed, size_t n) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution d(loss);
  LossPattern p{std::to_string(static_cast<int>(loss * 100 + 0.5)) + " %", std::vector<bool>(n)};
  for (size_t i = 1; i < n; ++i) p.drop[i] = d(rng);
  return p;
}

// A two-state (Gilbert) channel: from "good" into a burst with probability `enter`, out of
// it with probability `leave`; every packet in a burst is lost. Mean burst 1 / leave.
LossPattern bursty_loss(double enter, double leave, uint32_t seed, size_t n) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution in(enter), out(leave);
  LossPattern p{"bursty", std::vector<bool>(n)};
  bool bad = false;
  for (size_t i = 1; i < n; ++i) {
    bad = bad ? !out(rng) : in(rng);
    p.drop[i] = bad;
  }
  return p;
}

// ---------------------------------------------------------------------------------------------
// Senders

struct Protection {
  std::string name;
  std::string sender;  // after appsrc
  // kRedBySeqnum: RED decoded here, not by rtpreddec (see unred()).
  enum class Receiver { kPlain, kRed, kRedBySeqnum, kFec } receiver = Receiver::kPlain;
  unsigned fec_latency_ms = 0;
};

struct Sent {
  std::vector<GstBuffer*> packets;
  GstCaps* caps = nullptr;
  uint64_t payload_bytes = 0;
  size_t protection_packets = 0;  // FEC packets
};

Sent send(const std::vector<Phoneme>& session, const std::string& chain) {
  const std::string description =
      "appsrc name=src format=time max-bytes=0 caps=application/x-pfap ! " + chain +
      " ! appsink name=sink sync=false emit-signals=false wait-on-eos=false";
  GError* error = nullptr;
  GstElement* pipeline = gst_parse_launch(description.c_str(), &error);
  if (error != nullptr) fail(std::string(error->message) + " in: " + description);
  GstElement* src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  GstBus* bus = gst_element_get_bus(pipeline);
  if (gst_element_set_state(pipeline, GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
    fail("cannot play " + description);
  }
  for (const Phoneme& p : session) {
    GstBuffer* b = phoneme_buffer(p);
    GstFlowReturn ret = GST_FLOW_ERROR;
    g_signal_emit_by_name(src, "push-buffer", b, &ret);
    gst_buffer_unref(b);
    if (ret != GST_FLOW_OK) fail("push-buffer failed in " + description);
  }
  GstFlowReturn ret = GST_FLOW_ERROR;
  g_signal_emit_by_name(src, "end-of-stream", &ret);
  GstMessage* m = gst_bus_timed_pop_filtered(
      bus, 60 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
  if (m == nullptr || GST_MESSAGE_TYPE(m) == GST_MESSAGE_ERROR) fail("no EOS from " + description);
  gst_message_unref(m);

  Sent sent;
  for (;;) {
    GstSample* sample = nullptr;
    g_signal_emit_by_name(sink, "try-pull-sample", GstClockTime{0}, &sample);
    if (sample == nullptr) break;
    GstBuffer* b = gst_sample_get_buffer(sample);
    GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
    if (!gst_rtp_buffer_map(b, GST_MAP_READ, &rtp)) fail("not RTP from " + description);
    sent.payload_bytes += gst_rtp_buffer_get_payload_len(&rtp);
    const bool fec = chain.find("rtpulpfecenc") != std::string::npos &&
                     gst_rtp_buffer_get_payload_type(&rtp) == kFecPt;
    sent.protection_packets += fec;
    gst_rtp_buffer_unmap(&rtp);
    sent.packets.push_back(gst_buffer_ref(b));
    // The caps of the media packets (rtpulpfecenc sends its FEC packets with them too).
    gst_caps_replace(&sent.caps, gst_sample_get_caps(sample));
    gst_sample_unref(sample);
  }
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(bus);
  gst_object_unref(src);
  gst_object_unref(sink);
  gst_object_unref(pipeline);
  if (sent.packets.empty() || sent.caps == nullptr) fail("nothing sent by " + description);
  return sent;
}

// ---------------------------------------------------------------------------------------------
// Receivers

struct Outcome {
  size_t dropped = 0;
  size_t wire_packets = 0;
  int received = 0;               // phonemes
  int differing = 0;              // of those, with a settled state not the lossless receiver's
  int uncertain = 0;              // of those, flagged uncertain
  int wrong_unflagged = 0;        // with a wrong state but not flagged uncertain
  guint recovered_packets = 0;    // RED or FEC: packets rebuilt
  guint64 depay_lost = 0;         // packets rtppfapdepay counted as lost
  guint64 depay_lost_events = 0;  // packet-lost events rtppfapdepay received
};

// Reads the depayloader's output as an application would and compares it phoneme by phoneme.
class Judge {
 public:
  explicit Judge(const std::vector<Settled>& lossless) : lossless_(lossless) {}

  void take(GstBuffer* buffer, Outcome& o) {
    GstMapInfo map;
    if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) fail("cannot map output");
    PfapEventHeader h;
    if (pfap_markup_read_header(map.data, map.size, &h) != 0) fail("malformed x-pfap output");
    std::vector<pfap::Fap> faps;
    for (unsigned i = 0; i < h.n_faps; ++i) {
      PfapFap f;
      pfap_markup_read_fap(map.data, i, &f);
      faps.push_back({f.index, f.amplitude, f.transition_ms, static_cast<pfap::Curve>(f.curve)});
    }
    gst_buffer_unmap(buffer, &map);
    const auto at = static_cast<int64_t>(GST_BUFFER_PTS(buffer));
    if (h.kind == PFAP_EVENT_COMPLETE) state_.reset();
    for (const pfap::Fap& f : faps) state_.apply(f, at);
    if (h.kind != PFAP_EVENT_PHONEME) return;
    const int number = h.symbol + 256 * h.f0;
    if (number >= static_cast<int>(lossless_.size())) fail("unknown phoneme in output");
    ++o.received;
    const bool uncertain = (h.flags & PFAP_FLAG_UNCERTAIN) != 0;
    const bool wrong = settled_of(state_) != lossless_[number];
    o.uncertain += uncertain;
    o.differing += wrong;
    o.wrong_unflagged += wrong && !uncertain;
  }

 private:
  const std::vector<Settled>& lossless_;
  pfap::FapState state_;
};

GstHarness* harness(const std::string& description, GstCaps* caps) {
  GstHarness* h = gst_harness_new_parse(description.c_str());
  if (h == nullptr) fail("cannot make " + description);
  gst_harness_set_src_caps(h, gst_caps_ref(caps));
  return h;
}

GstElement* harness_element(GstHarness* h, const char* name) {
  GstElement* e = gst_bin_get_by_name(GST_BIN(h->element), name);
  if (e == nullptr) fail(std::string("no element ") + name);
  gst_object_unref(e);  // the bin keeps it
  return e;
}

GstPadProbeReturn count_redundant(GstPad*, GstPadProbeInfo* info, gpointer data) {
  if (GST_BUFFER_FLAG_IS_SET(GST_PAD_PROBE_INFO_BUFFER(info), GST_RTP_BUFFER_FLAG_REDUNDANT)) {
    ++*static_cast<guint*>(data);
  }
  return GST_PAD_PROBE_OK;
}

// An RTP packet from a RED packet's header fields and one of its blocks.
GstBuffer* rtp_from_block(GstRTPBuffer& red, uint16_t seq, uint32_t timestamp, uint8_t pt,
                          bool marker, const uint8_t* data, size_t size) {
  return pfap::testing::rtp_packet({data, size},
                                   {.seqnum = seq,
                                    .timestamp = timestamp,
                                    .ssrc = gst_rtp_buffer_get_ssrc(&red),
                                    .marker = marker,
                                    .payload_type = pt},
                                   GST_BUFFER_PTS(red.buffer));
}

// RFC 2198 decoded as a receiver could for a stream whose packets are not evenly spaced:
// rtpredenc puts at most one redundant block in a packet, that of the packet `distance`
// before it, so with distance 1 the block of packet seq - 1 precedes the primary of seq.
// (rtpreddec infers a lost packet's sequence number from timestamps, assuming even spacing;
// for PFAP it finds none.) Returns the packets to depayload, in order: the one rebuilt from
// the redundant block if `previous_lost`, then the primary.
std::vector<GstBuffer*> unred(GstBuffer* packet, bool previous_lost) {
  std::vector<GstBuffer*> out;
  GstRTPBuffer red = GST_RTP_BUFFER_INIT;
  if (!gst_rtp_buffer_map(packet, GST_MAP_READ, &red)) fail("RED packet is not RTP");
  const auto* p = static_cast<const uint8_t*>(gst_rtp_buffer_get_payload(&red));
  const size_t size = gst_rtp_buffer_get_payload_len(&red);
  const uint16_t seq = gst_rtp_buffer_get_seq(&red);
  const uint32_t ts = gst_rtp_buffer_get_timestamp(&red);
  size_t header = 0, block = 0;
  struct Redundant {
    uint8_t pt;
    uint32_t offset;
    size_t length;
  };
  std::vector<Redundant> redundant;
  while (header < size && (p[header] & 0x80)) {  // F = 1: a 4-byte redundant block header
    if (header + 4 > size) fail("truncated RED header");
    redundant.push_back({static_cast<uint8_t>(p[header] & 0x7f),
                         (uint32_t{p[header + 1]} << 6) | (p[header + 2] >> 2),
                         (size_t{p[header + 2] & 0x03u} << 8) | p[header + 3]});
    header += 4;
  }
  if (header >= size) fail("RED packet without a primary block");
  const auto primary_pt = static_cast<uint8_t>(p[header] & 0x7f);
  block = header + 1;
  for (const Redundant& r : redundant) {
    if (block + r.length > size) fail("truncated RED block");
    if (previous_lost && redundant.size() == 1) {
      out.push_back(rtp_from_block(red, static_cast<uint16_t>(seq - 1), ts - r.offset, r.pt, false,
                                   p + block, r.length));
    }
    block += r.length;
  }
  out.push_back(rtp_from_block(red, seq, ts, primary_pt, gst_rtp_buffer_get_marker(&red), p + block,
                               size - block));
  gst_rtp_buffer_unmap(&red);
  return out;
}

// rtppfapdepay alone, or after rtpreddec: no clock and no thread, so each packet is
// depayloaded when it is pushed.
Outcome receive_in_order(const Protection& protection, const Sent& sent, const LossPattern& loss,
                         const std::vector<Settled>& lossless) {
  const bool red = protection.receiver == Protection::Receiver::kRed;
  GstHarness* h = harness((red ? "rtpreddec pt=" + std::to_string(kRedPt) + " ! " : std::string()) +
                              "rtppfapdepay name=depay request-recovery=false",
                          sent.caps);
  Outcome o;
  GstPad* depay_sink = gst_element_get_static_pad(harness_element(h, "depay"), "sink");
  gst_pad_add_probe(depay_sink, GST_PAD_PROBE_TYPE_BUFFER, count_redundant, &o.recovered_packets,
                    nullptr);
  gst_object_unref(depay_sink);
  Judge judge(lossless);
  o.wire_packets = sent.packets.size();
  const bool by_seqnum = protection.receiver == Protection::Receiver::kRedBySeqnum;
  for (size_t i = 0; i < sent.packets.size(); ++i) {
    if (loss.drop[i]) {
      ++o.dropped;
      continue;
    }
    if (by_seqnum) {
      const std::vector<GstBuffer*> packets = unred(sent.packets[i], i > 0 && loss.drop[i - 1]);
      o.recovered_packets += static_cast<guint>(packets.size() - 1);
      for (GstBuffer* b : packets) {
        if (gst_harness_push(h, b) != GST_FLOW_OK) fail("push failed");
      }
    } else if (gst_harness_push(h, gst_buffer_ref(sent.packets[i])) != GST_FLOW_OK) {
      fail("push failed");
    }
    while (GstBuffer* b = gst_harness_try_pull(h)) {
      judge.take(b, o);
      gst_buffer_unref(b);
    }
  }
  gst_harness_push_event(h, gst_event_new_eos());
  while (GstBuffer* b = gst_harness_try_pull(h)) {
    judge.take(b, o);
    gst_buffer_unref(b);
  }
  o.depay_lost = stat(harness_element(h, "depay"), "lost");
  o.depay_lost_events = stat(harness_element(h, "depay"), "packet-lost-events");
  gst_harness_teardown(h);
  return o;
}

// The ULPFEC receiver, against a test clock.
//
// rtpjitterbuffer works in two threads of its own: a timer thread, which waits on the clock
// for the earliest timer (a lost packet's, or at the start the first packet's deadline) and
// fires every timer due by the clock's time, and a streaming thread, which pushes packets
// and packet-lost events, in sequence-number order, into rtpulpfecdec, which handles each
// before the next. With a GstTestClock every clock wait blocks until the harness releases
// it, so timers fire only when the harness moves time on. What the harness must also know
// is when those threads are done, so that no packet reaches rtpstorage before rtpulpfecdec
// has looked there for a packet declared lost earlier. It waits until
//  - the jitterbuffer has pushed every packet up to the first one it has not yet declared
//    lost,
//  - every packet-lost event the jitterbuffer made (g_lost_events_made) has been pushed and
//    answered by rtpulpfecdec, and
//  - while packets are missing that are not yet declared lost, the timer thread waits on
//    the clock (it does so only after firing every timer due),
// and these hold for three polls in a row. (Waiting for quiet alone, as a first version did,
// was not enough: a thread held up for a millisecond now and then changed a figure.)
// Three runs, also with three busy processes beside them, gave the same figures.
// Packet-lost events rtpjitterbuffer has made: its insert_lost_event() logs one debug
// message per event ("Packet #n lost" or "Packets #n -> #m lost") before it queues the event
// for its streaming thread, so counting those messages tells how many events are on their
// way. A merged event covers several packets, so its num-lost statistic cannot tell. See
// count_lost_events() in main().
std::atomic<guint64> g_lost_events_made{0};
GstDebugCategory* g_jitterbuffer_category = nullptr;
GstDebugLevel g_jitterbuffer_shown = GST_LEVEL_NONE;  // what GST_DEBUG asked to see of it

void log_function(GstDebugCategory* category, GstDebugLevel level, const gchar* file,
                  const gchar* function, gint line, GObject* object, GstDebugMessage* message,
                  gpointer) {
  if (category == g_jitterbuffer_category) {
    // (It also logs "signal event" there when it wakes the streaming thread.)
    if (level == GST_LEVEL_DEBUG && g_strcmp0(function, "insert_lost_event") == 0 &&
        g_str_has_prefix(gst_debug_message_get(message), "Packet")) {
      g_lost_events_made.fetch_add(1);
    }
    if (level > g_jitterbuffer_shown) return;
  }
  gst_debug_log_default(category, level, file, function, line, object, message, nullptr);
}

// Makes rtpjitterbuffer's DEBUG messages reach log_function(), and shows only what GST_DEBUG
// asked for: by default none of them (it logs an error for every FEC packet, see
// FecReceiver).
void count_lost_events() {
  GstElement* jb = gst_element_factory_make("rtpjitterbuffer", nullptr);  // registers it
  if (jb == nullptr) fail("no rtpjitterbuffer");
  gst_object_unref(jb);
  g_jitterbuffer_category = _gst_debug_get_category("rtpjitterbuffer");
  if (g_jitterbuffer_category == nullptr) fail("no rtpjitterbuffer debug category");
  const char* debug = g_getenv("GST_DEBUG");
  if (debug != nullptr && std::string(debug).find("rtpjitterbuffer") != std::string::npos) {
    g_jitterbuffer_shown = gst_debug_category_get_threshold(g_jitterbuffer_category);
  }
  gst_debug_category_set_threshold(g_jitterbuffer_category,
                                   std::max(g_jitterbuffer_shown, GST_LEVEL_DEBUG));
  // The functions, not gstinfo.h's macros of the same names (which compare a function
  // pointer with a void pointer: an error in ISO C++). NULL stands for
  // gst_debug_log_default there.
  (gst_debug_remove_log_function)(nullptr);
  (gst_debug_add_log_function)(log_function, nullptr, nullptr);
}

struct FecCounters {
  std::atomic<guint64> lost_events{0};  // GstRTPPacketLost out of rtpjitterbuffer
  std::atomic<guint64> handled{0};      // of those, answered by rtpulpfecdec
  std::atomic<bool> in_lost{false};     // rtpulpfecdec is handling one
  std::atomic<guint64> items{0};        // anything out of rtpjitterbuffer or rtpulpfecdec
  uint16_t first_seqnum = 0;            // of the first packet on the wire
  std::atomic<long> last_out{-1};       // wire position of the last packet out of the
                                        // jitterbuffer (sequence numbers are consecutive on
                                        // the wire, FEC packets included)
};

bool is_lost_event(GstPadProbeInfo* info) {
  if (!(GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM)) return false;
  GstEvent* e = GST_PAD_PROBE_INFO_EVENT(info);
  return GST_EVENT_TYPE(e) == GST_EVENT_CUSTOM_DOWNSTREAM &&
         gst_event_has_name(e, "GstRTPPacketLost");
}

GstPadProbeReturn on_jitterbuffer_out(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* c = static_cast<FecCounters*>(data);
  if (is_lost_event(info)) c->lost_events.fetch_add(1);
  if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_BUFFER) {
    GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
    if (gst_rtp_buffer_map(GST_PAD_PROBE_INFO_BUFFER(info), GST_MAP_READ, &rtp)) {
      const auto position = static_cast<uint16_t>(gst_rtp_buffer_get_seq(&rtp) - c->first_seqnum);
      gst_rtp_buffer_unmap(&rtp);
      c->last_out = std::max<long>(c->last_out, position);
    }
  }
  c->items.fetch_add(1);
  return GST_PAD_PROBE_OK;
}

GstPadProbeReturn on_fec_in(GstPad*, GstPadProbeInfo* info, gpointer data) {
  if (is_lost_event(info)) static_cast<FecCounters*>(data)->in_lost = true;
  return GST_PAD_PROBE_OK;
}

// Called in the thread that handles the event, while it handles it: the answer.
GstPadProbeReturn on_fec_out(GstPad*, GstPadProbeInfo*, gpointer data) {
  auto* c = static_cast<FecCounters*>(data);
  if (c->in_lost.exchange(false)) c->handled.fetch_add(1);
  c->items.fetch_add(1);
  return GST_PAD_PROBE_OK;
}

// The FEC packets go into rtpstorage and rtpjitterbuffer, but not into rtpulpfecdec, which
// finds them in the storage: as in rtpbin, where rtpptdemux sends each payload type its own
// way and the FEC decoder sits on the media's.
GstPadProbeReturn drop_fec_packets(GstPad*, GstPadProbeInfo* info, gpointer) {
  GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
  if (!gst_rtp_buffer_map(GST_PAD_PROBE_INFO_BUFFER(info), GST_MAP_READ, &rtp)) {
    return GST_PAD_PROBE_OK;
  }
  const bool fec = gst_rtp_buffer_get_payload_type(&rtp) == kFecPt;
  gst_rtp_buffer_unmap(&rtp);
  return fec ? GST_PAD_PROBE_DROP : GST_PAD_PROBE_OK;
}

GstCaps* on_request_pt_map(GstElement*, guint pt, gpointer data) {
  if (pt == kFecPt) return gst_caps_from_string("application/x-rtp,clock-rate=(int)44100");
  return gst_caps_ref(static_cast<GstCaps*>(data));
}

class FecReceiver {
 public:
  FecReceiver(const Sent& sent, unsigned latency_ms) {
    const std::string description =
        "rtpstorage name=storage size-time=" + std::to_string((latency_ms + 50) * GST_MSECOND) +
        " ! rtpjitterbuffer name=jb do-lost=true latency=" + std::to_string(latency_ms) +
        " ! rtpulpfecdec name=fec pt=" + std::to_string(kFecPt) +
        " ! rtppfapdepay name=depay request-recovery=false";
    h_ = gst_harness_new_parse(description.c_str());
    if (h_ == nullptr) fail("cannot make " + description);
    gst_harness_use_testclock(h_);
    clock_ = gst_harness_get_testclock(h_);
    GstElement* storage = harness_element(h_, "storage");
    jb_ = harness_element(h_, "jb");
    fec_ = harness_element(h_, "fec");
    GObject* internal = nullptr;
    g_object_get(storage, "internal-storage", &internal, nullptr);
    g_object_set(fec_, "storage", internal, nullptr);
    g_object_unref(internal);
    g_signal_connect(jb_, "request-pt-map", G_CALLBACK(on_request_pt_map), sent.caps);
    const auto items = static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER |
                                                    GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM);
    GstPad* pad = gst_element_get_static_pad(jb_, "src");
    gst_pad_add_probe(pad, items, on_jitterbuffer_out, &counters_, nullptr);
    gst_object_unref(pad);
    pad = gst_element_get_static_pad(fec_, "sink");
    gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, drop_fec_packets, nullptr, nullptr);
    gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM, on_fec_in, &counters_, nullptr);
    gst_object_unref(pad);
    pad = gst_element_get_static_pad(fec_, "src");
    gst_pad_add_probe(pad, items, on_fec_out, &counters_, nullptr);
    gst_object_unref(pad);
    // The caps keep payload=96: rtpulpfecdec checks a rebuilt packet's payload type against
    // it. rtpjitterbuffer then logs an error for each FEC packet (payload 122 is not the
    // caps' payload) before it takes the clock rate from request-pt-map, as in rtpbin.
    gst_harness_set_src_caps(h_, gst_caps_ref(sent.caps));
    latency_ = latency_ms * GST_MSECOND;
    GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
    if (!gst_rtp_buffer_map(sent.packets.front(), GST_MAP_READ, &rtp)) fail("not RTP");
    counters_.first_seqnum = gst_rtp_buffer_get_seq(&rtp);
    gst_rtp_buffer_unmap(&rtp);
  }
  ~FecReceiver() {
    gst_object_unref(clock_);
    gst_harness_teardown(h_);
  }
  FecReceiver(const FecReceiver&) = delete;
  FecReceiver& operator=(const FecReceiver&) = delete;

  Outcome run(const Sent& sent, const LossPattern& loss, const std::vector<Settled>& lossless) {
    Outcome o;
    o.wire_packets = sent.packets.size();
    Judge judge(lossless);
    GstClockTime last = 0;
    for (size_t i = 0; i < sent.packets.size(); ++i) {
      if (loss.drop[i]) {
        ++o.dropped;
        dropped_.push_back(static_cast<long>(i));
        continue;
      }
      GstBuffer* b = gst_buffer_copy(sent.packets[i]);
      const GstClockTime arrival = std::max(last, GST_BUFFER_PTS(b));
      last = arrival;
      advance_to(arrival);
      GST_BUFFER_DTS(b) = arrival;
      GST_BUFFER_PTS(b) = arrival;
      // With this packet the jitterbuffer sees every packet dropped before it as missing.
      // A packet in order sets no timer and leaves the timer thread waiting where it was,
      // on a time after `arrival` (advance_to released all before), so only the first packet
      // (its deadline) and those after a gap need the threads to settle.
      const bool gap = o.dropped != missing_;
      missing_ = o.dropped;
      pushed_.push_back(static_cast<long>(i));
      if (gst_harness_push(h_, b) != GST_FLOW_OK) fail("push into the FEC receiver failed");
      if (i == 0 || gap) settle();
      drain(judge, o);
    }
    advance_to(last + latency_ + 10 * GST_SECOND);
    gst_harness_push_event(h_, gst_event_new_eos());
    for (int k = 0; k < 10000 && !eos_; ++k) {
      settle();
      drain(judge, o);
      const GstClockTime next = gst_test_clock_get_next_entry_time(clock_);
      if (GST_CLOCK_TIME_IS_VALID(next)) advance_to(next);
    }
    if (!eos_) fail("no EOS out of the FEC receiver");
    guint recovered = 0;
    g_object_get(fec_, "recovered", &recovered, nullptr);
    o.recovered_packets = recovered;
    o.depay_lost = stat(harness_element(h_, "depay"), "lost");
    o.depay_lost_events = stat(harness_element(h_, "depay"), "packet-lost-events");
    return o;
  }

 private:
  struct Snapshot {
    bool idle;
    guint pending;
    guint64 lost, lost_events, items;
    long last_out;
    bool operator==(const Snapshot&) const = default;
  };

  Snapshot snapshot() {
    const guint pending = gst_test_clock_peek_id_count(clock_);
    const guint64 lost = stat(jb_, "num-lost");  // the timer thread counts them as it declares them
    const guint64 events = counters_.lost_events.load();
    const guint64 handled = counters_.handled.load();
    const long last_out = counters_.last_out.load();
    // The packets the jitterbuffer can push: those before the first missing packet it has
    // not declared lost. Before its first deadline it pushes none.
    const long first_missing = lost < missing_ ? dropped_[lost] : std::numeric_limits<long>::max();
    const auto before = std::lower_bound(pushed_.begin(), pushed_.end(), first_missing);
    const long can_push = before == pushed_.begin() ? -1 : *(before - 1);
    const bool pushed_all = !released_any_ || last_out >= can_push;
    const bool idle = pushed_all && events == g_lost_events_made.load() - made_before_ &&
                      events == handled && (lost >= missing_ || pending == 1);
    return {idle, pending, lost, events, counters_.items.load(), last_out};
  }

  void settle() {
    Snapshot last = snapshot();
    const gint64 deadline = g_get_monotonic_time() + 10 * G_USEC_PER_SEC;
    for (int quiet = 0; quiet < 3;) {
      g_usleep(20);
      const Snapshot now = snapshot();
      quiet = now == last && now.idle ? quiet + 1 : 0;
      last = now;
      if (g_get_monotonic_time() > deadline) {
        fail("the FEC receiver did not settle within 10 s: " + std::to_string(now.lost) +
             " packets declared lost of " + std::to_string(missing_) + " missing, " +
             std::to_string(now.lost_events) + " lost events pushed of " +
             std::to_string(g_lost_events_made.load() - made_before_) + " made, " +
             std::to_string(counters_.handled.load()) + " answered, last packet out " +
             std::to_string(now.last_out) + ", " + std::to_string(now.pending) +
             " clock waits pending");
      }
    }
  }

  // Releases every clock wait due by `t`, in time order, then sets the clock to `t`.
  void advance_to(GstClockTime t) {
    for (;;) {
      const GstClockTime next = gst_test_clock_get_next_entry_time(clock_);
      if (!GST_CLOCK_TIME_IS_VALID(next) || next > t) break;
      if (next > gst_clock_get_time(GST_CLOCK(clock_))) gst_test_clock_set_time(clock_, next);
      if (GstClockID id = gst_test_clock_process_next_clock_id(clock_)) {
        gst_clock_id_unref(id);
        released_any_ = true;
      }
      settle();
    }
    if (t > gst_clock_get_time(GST_CLOCK(clock_))) gst_test_clock_set_time(clock_, t);
  }

  void drain(Judge& judge, Outcome& o) {
    while (GstBuffer* b = gst_harness_try_pull(h_)) {
      judge.take(b, o);
      gst_buffer_unref(b);
    }
    while (GstEvent* e = gst_harness_try_pull_event(h_)) {
      eos_ = eos_ || GST_EVENT_TYPE(e) == GST_EVENT_EOS;
      gst_event_unref(e);
    }
  }

  GstHarness* h_ = nullptr;
  GstTestClock* clock_ = nullptr;
  GstElement* jb_ = nullptr;
  GstElement* fec_ = nullptr;
  FecCounters counters_;
  guint64 missing_ = 0;                 // packets the jitterbuffer knows to be missing
  std::vector<long> dropped_, pushed_;  // wire positions, in order
  bool released_any_ = false;           // a clock wait was released: the first deadline has passed
  guint64 made_before_ = g_lost_events_made.load();  // by earlier receivers
  GstClockTime latency_ = 0;
  bool eos_ = false;
};

Outcome receive(const Protection& protection, const Sent& sent, const LossPattern& loss,
                const std::vector<Settled>& lossless) {
  if (protection.receiver != Protection::Receiver::kFec) {
    return receive_in_order(protection, sent, loss, lossless);
  }
  FecReceiver receiver(sent, protection.fec_latency_ms);
  return receiver.run(sent, loss, lossless);
}

double percent(double part, double whole) { return whole > 0 ? 100.0 * part / whole : 0; }

}  // namespace

int main(int argc, char** argv) {
#ifdef PFAP_PLUGIN_DIR
  // Run by hand from the build tree: find the plugin there unless told otherwise.
  g_setenv("GST_PLUGIN_PATH", PFAP_PLUGIN_DIR, FALSE);
#endif
  gst_init(&argc, &argv);
  count_lost_events();
  const int n = argc > 1 ? std::atoi(argv[1]) : 3000;
  if (n <= 0 || n > 65536) fail("usage: bench_recovery [phonemes (at most 65536) [only]]");
  for (const char* name : {"rtppfappay", "rtppfapdepay", "rtpredenc", "rtpreddec", "rtpulpfecenc",
                           "rtpulpfecdec", "rtpstorage", "rtpjitterbuffer"}) {
    GstElementFactory* f = gst_element_factory_find(name);
    if (f == nullptr) fail(std::string("no element ") + name + " (GST_PLUGIN_PATH?)");
    gst_object_unref(f);
  }

  const std::vector<Phoneme> session = speech_session(1, n, 0.45);
  const std::vector<Settled> lossless = lossless_states(session);
  const GstClockTime length =
      session.back().start_ns + session.back().phoneme.duration_ms * GST_MSECOND;
  int with_faps = 0;
  for (const Phoneme& p : session) with_faps += !p.faps.empty();
  std::printf("session: %d phonemes over %.1f s of stream time (%.1f per s), %d with FAPs\n", n,
              static_cast<double>(length) / GST_SECOND,
              n / (static_cast<double>(length) / GST_SECOND), with_faps);

  const size_t wire = static_cast<size_t>(n) * 4 + 1000;
  const std::vector<LossPattern> patterns = {
      random_loss(0.01, 101, wire), random_loss(0.05, 105, wire), random_loss(0.10, 110, wire),
      random_loss(0.20, 120, wire), bursty_loss(0.0125, 0.25, 200, wire)};

  const std::string pay = "rtppfappay pt=96 complete-recovery-interval=0 recovery-depth=";
  const std::string red = " ! rtpredenc pt=" + std::to_string(kRedPt) + " distance=";
  const std::string fec = " ! rtpulpfecenc pt=" + std::to_string(kFecPt) + " percentage=";
  using R = Protection::Receiver;
  const std::vector<Protection> protections = {
      {"none", pay + "0", R::kPlain, 0},
      {"depth 1", pay + "1", R::kPlain, 0},
      {"depth 4", pay + "4", R::kPlain, 0},
      {"depth 7", pay + "7", R::kPlain, 0},
      {"depth 15", pay + "15", R::kPlain, 0},
      {"depth 4 + complete 1 s",
       "rtppfappay pt=96 recovery-depth=4 complete-recovery-interval=1000", R::kPlain, 0},
      {"RED distance=1", pay + "0" + red + "1", R::kRed, 0},
      {"RED distance=2", pay + "0" + red + "2", R::kRed, 0},
      {"RED distance=1, decoded by seqnum (not rtpreddec)", pay + "0" + red + "1", R::kRedBySeqnum,
       0},
      {"ULPFEC 25 %, latency 200 ms", pay + "0" + fec + "25", R::kFec, 200},
      {"ULPFEC 50 %, latency 200 ms", pay + "0" + fec + "50", R::kFec, 200},
      {"ULPFEC 100 %, latency 200 ms", pay + "0" + fec + "100", R::kFec, 200},
      {"ULPFEC 50 %, latency 2000 ms", pay + "0" + fec + "50", R::kFec, 2000},
      {"ULPFEC 100 % multipacket=false, latency 200 ms", pay + "0" + fec + "100 multipacket=false",
       R::kFec, 200},
      // Both at once: rtpulpfecdec renumbers what it passes, so the depayloader no longer
      // sees the losses FEC did not repair.
      {"depth 4 + ULPFEC 50 %, latency 200 ms", pay + "4" + fec + "50", R::kFec, 200},
  };

  struct Row {
    const Protection* protection;
    Sent sent;
    std::vector<Outcome> outcomes;
  };
  std::vector<Row> rows;
  const std::string only = argc > 2 ? argv[2] : "";
  for (const Protection& p : protections) {
    // "none" always runs: the overhead is relative to it.
    if (!only.empty() && p.name != "none" && p.name.find(only) == std::string::npos) continue;
    Row row{&p, send(session, p.sender), {}};
    if (row.sent.packets.size() > wire) fail("more packets than the loss patterns cover");
    for (const LossPattern& loss : patterns) {
      row.outcomes.push_back(receive(p, row.sent, loss, lossless));
    }
    std::fprintf(stderr, "%s done\n", p.name.c_str());
    rows.push_back(std::move(row));
  }
  const double base_bytes = static_cast<double>(rows.front().sent.payload_bytes);

  std::printf("\nloss patterns (drops by position on the wire; rates for the unprotected stream):");
  for (size_t k = 0; k < patterns.size(); ++k) {
    const Outcome& o = rows.front().outcomes[k];
    std::printf(" %s = %.2f %%;", patterns[k].name.c_str(), percent(o.dropped, o.wire_packets));
  }
  std::printf(
      "\n\nreceived phonemes whose settled FAP state differs from a lossless receiver's\n\n");
  // On the wire each packet also has 40 bytes of IPv4, UDP and RTP headers.
  const double base_wire =
      base_bytes + 40.0 * static_cast<double>(rows.front().sent.packets.size());
  const double seconds = static_cast<double>(length) / GST_SECOND;
  std::printf(
      "| protection | packets | payload bytes | payload bit/s | overhead | overhead with "
      "IPv4/UDP/RTP headers |");
  for (const LossPattern& loss : patterns) std::printf(" %s |", loss.name.c_str());
  std::printf("\n|---|---|---|---|---|---|");
  for (size_t k = 0; k < patterns.size(); ++k) std::printf("---|");
  std::printf("\n");
  for (const Row& row : rows) {
    const auto bytes = static_cast<double>(row.sent.payload_bytes);
    const double wire_bytes = bytes + 40.0 * static_cast<double>(row.sent.packets.size());
    std::printf("| %s | %zu | %llu | %.0f | %.1f %% | %.1f %% |", row.protection->name.c_str(),
                row.sent.packets.size(), static_cast<unsigned long long>(row.sent.payload_bytes),
                8 * bytes / seconds, percent(bytes - base_bytes, base_bytes),
                percent(wire_bytes - base_wire, base_wire));
    for (const Outcome& o : row.outcomes)
      std::printf(" %.1f %% |", percent(o.differing, o.received));
    std::printf("\n");
  }

  std::printf("\nphonemes received (of %d); packets rebuilt by RED or FEC in brackets\n\n", n);
  std::printf("| protection |");
  for (const LossPattern& loss : patterns) std::printf(" %s |", loss.name.c_str());
  std::printf("\n|---|");
  for (size_t k = 0; k < patterns.size(); ++k) std::printf("---|");
  std::printf("\n");
  for (const Row& row : rows) {
    std::printf("| %s |", row.protection->name.c_str());
    for (const Outcome& o : row.outcomes) {
      if (row.protection->receiver == Protection::Receiver::kPlain) {  // nothing rebuilt
        std::printf(" %.1f %% |", percent(o.received, n));
      } else {
        std::printf(" %.1f %% (%u) |", percent(o.received, n), o.recovered_packets);
      }
    }
    std::printf("\n");
  }

  std::printf(
      "\nreceived phonemes with a wrong FAP state that the depayloader did not flag "
      "uncertain\n\n| protection |");
  for (const LossPattern& loss : patterns) std::printf(" %s |", loss.name.c_str());
  std::printf("\n|---|");
  for (size_t k = 0; k < patterns.size(); ++k) std::printf("---|");
  std::printf("\n");
  for (const Row& row : rows) {
    std::printf("| %s |", row.protection->name.c_str());
    for (const Outcome& o : row.outcomes) {
      std::printf(" %.1f %% |", percent(o.wrong_unflagged, o.received));
    }
    std::printf("\n");
  }

  std::printf("\nreceived phonemes flagged uncertain by the depayloader\n\n| protection |");
  for (const LossPattern& loss : patterns) std::printf(" %s |", loss.name.c_str());
  std::printf("\n|---|");
  for (size_t k = 0; k < patterns.size(); ++k) std::printf("---|");
  std::printf("\n");
  for (const Row& row : rows) {
    std::printf("| %s |", row.protection->name.c_str());
    for (const Outcome& o : row.outcomes)
      std::printf(" %.1f %% |", percent(o.uncertain, o.received));
    std::printf("\n");
  }

  std::printf(
      "\nlosses rtppfapdepay saw at the first pattern (%s): packets dropped on the "
      "wire, packets it counted lost (sequence-number gaps), packet-lost events it "
      "received\n\n| protection | dropped | counted lost | packet-lost events |\n"
      "|---|---|---|---|\n",
      patterns.front().name.c_str());
  for (const Row& row : rows) {
    const Outcome& o = row.outcomes.front();
    std::printf("| %s | %zu | %llu | %llu |\n", row.protection->name.c_str(), o.dropped,
                static_cast<unsigned long long>(o.depay_lost),
                static_cast<unsigned long long>(o.depay_lost_events));
  }

  for (Row& row : rows) {
    for (GstBuffer* b : row.sent.packets) gst_buffer_unref(b);
    gst_caps_unref(row.sent.caps);
  }
  return 0;
}

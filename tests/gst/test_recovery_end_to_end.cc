// SPDX-License-Identifier: LGPL-2.1-or-later
// Loss recovery end to end (draft sections 6.1, 6.4 and 8; docs/recovery.md):
//
//  - RecoveryLoop.PliBringsACompleteStateAfterALongBurst: a sender and a receiver rtpbin over
//    loopback UDP with RTCP both ways. The receiver's caps allow RTCP PLI; a burst of lost
//    packets longer than the payloader's coverage makes rtppfapdepay ask for a complete state,
//    rtpbin carries the request to the payloader as PLI, the payloader answers with a
//    complete-recovery packet, and from there on the receiver's FAP state is the sender's.
//  - RecoveryRandomLoss.*: a seeded session of 3000 phonemes through
//    appsrc ! rtppfappay ! (drop) ! rtppfapdepay ! appsink in one process, where sequence
//    numbers are consecutive so every drop is a gap. Whenever the depayloader does not flag a
//    phoneme uncertain, the FAP state built from its output equals a lossless receiver's.
//  - RecoverySoak.AnHourThroughNetsimAndRtpjitterbuffer: an hour of stream time of speech
//    with FAPs through rtppfappay ! netsim ! (reorder) ! rtpjitterbuffer ! rtppfapdepay in a
//    GstHarness on a GstTestClock, run as fast as the elements go; random loss, duplicates and
//    reordering; every phoneme not flagged uncertain has the sender's state, the session ends
//    with the sender's state, and the heap does not grow after the first minutes.
//
// A receiver's FAP state is built from the depayloader's events as an application would:
// a phoneme's FAPs at its PTS, a recovered event's entries at its PTS, a complete event as
// reset() and then its entries. States are compared by settled values (FapState::settled),
// which depend only on the order of bookmarks, not on their times.
//
// The plugin comes from GST_PLUGIN_PATH, which meson sets to the build's gst/ directory.
#include <gst/check/gstharness.h>
#include <gst/check/gsttestclock.h>
#include <gst/gst.h>
#include <gst/rtp/gstrtpbuffer.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <iostream>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "element_stats.h"
#include "heap.h"
#include "pfap/fap_state.h"
#include "pfap/markup.h"
#include "pfap/model.h"
#include "live_source.h"
#include "pfap_buffers.h"
#include "rtpbin_sessions.h"
#include "pipeline.h"
#include "speech_session.h"

namespace {

using pfap::testing::Event;
using pfap::testing::lossless_states;
using pfap::testing::number_of;
using pfap::testing::Settled;
using pfap::testing::settled_of;
using pfap::testing::speech_session;
using pfap::testing::SpeechPhoneme;
using pfap::testing::stat;
using pfap::testing::stats_text;
using Clock = std::chrono::steady_clock;

constexpr const char* kElements[] = {"rtppfappay", "rtppfapdepay"};  // the plugin's, under test

// ---------------------------------------------------------------------------------------------
// Sessions and FAP states

// A seeded speech session of speech_session.h as x-pfap phoneme events.
std::vector<Event> events_of(const std::vector<SpeechPhoneme>& session) {
  std::vector<Event> events;
  for (const SpeechPhoneme& p : session) {
    Event e;
    e.phoneme = p.phoneme;
    e.faps = p.faps;
    e.flags = pfap::testing::phoneme_flags(p.phoneme, p.sentence_start);
    e.pts = p.start_ns;
    e.duration = p.phoneme.duration_ms * GST_MSECOND;
    events.push_back(e);
  }
  return events;
}

std::string differences(const Settled& got, const Settled& want) {
  std::ostringstream s;
  for (int f = pfap::kMinFapIndex; f <= pfap::kMaxFapIndex; ++f) {
    if (got[f] != want[f]) s << " FAP " << f << ": " << got[f] << " (want " << want[f] << ")";
  }
  return s.str();
}

// A phoneme as a receiver saw it: its number, its flag, and the settled state after it.
struct Received {
  int number = -1;
  bool uncertain = false;
  Settled settled{};
};

// Builds a receiver's FAP state from the depayloader's events.
class ReceiverState {
 public:
  // Returns the phoneme, or nothing (number -1) for a state event.
  Received apply(const Event& e) {
    const auto at = static_cast<int64_t>(e.pts);
    switch (e.kind) {
      case PFAP_EVENT_COMPLETE:
        ++complete_events;
        state_.reset();
        for (const pfap::Fap& f : e.faps) state_.apply(f, at);
        return {};
      case PFAP_EVENT_RECOVERED:
        ++recovered_events;
        for (const pfap::Fap& f : e.faps) state_.apply(f, at);
        return {};
      case PFAP_EVENT_PHONEME:
        break;
    }
    for (const pfap::Fap& f : e.faps) state_.apply(f, at);
    return {number_of(e.phoneme), (e.flags & PFAP_FLAG_UNCERTAIN) != 0, settled_of(state_)};
  }

  int complete_events = 0;
  int recovered_events = 0;

 private:
  pfap::FapState state_;
};

// ---------------------------------------------------------------------------------------------
// Pipelines

using pfap::testing::bound_port;
using pfap::testing::fast_rtcp;
using pfap::testing::Pipeline;
using pfap::testing::plugin_available;
using pfap::testing::push_live;
using pfap::testing::rtpbin_receive_session;
using pfap::testing::rtpbin_send_session;

GstFlowReturn push(GstElement* appsrc, const Event& e) {
  return pfap::testing::push(appsrc, pfap::testing::phoneme_buffer(e));
}

GstFlowReturn push_harness(GstHarness* h, const Event& e) {
  return gst_harness_push(h, pfap::testing::phoneme_buffer(e));
}

// Whether an RTP packet is a complete recovery (C = 1 in the payload's first byte).
bool is_complete_recovery(GstBuffer* buffer) {
  GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
  if (!gst_rtp_buffer_map(buffer, GST_MAP_READ, &rtp)) return false;
  const bool complete = gst_rtp_buffer_get_payload_len(&rtp) > 0 &&
                        (static_cast<const uint8_t*>(gst_rtp_buffer_get_payload(&rtp))[0] & 0x80);
  gst_rtp_buffer_unmap(&rtp);
  return complete;
}

// ---------------------------------------------------------------------------------------------
// The real loop: two rtpbins over loopback UDP, PLI in RTCP.

// The receiving side's record, written from streaming threads.
struct LoopRecord {
  std::mutex mutex;
  std::condition_variable changed;
  ReceiverState state;
  std::vector<Received> phonemes;          // in arrival order
  std::vector<size_t> complete_events_at;  // index into phonemes where each complete came

  // RTP packets reaching the receiver's udpsrc; those in [drop_from, drop_to) are dropped.
  size_t packets = 0;
  size_t drop_from = 0, drop_to = 0;
  std::vector<size_t> complete_packets_at;  // packet indexes with C = 1 (dropped ones too)
};

GstPadProbeReturn drop_burst(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* r = static_cast<LoopRecord*>(data);
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  std::lock_guard lock(r->mutex);
  const size_t index = r->packets++;
  if (is_complete_recovery(buffer)) r->complete_packets_at.push_back(index);
  return index >= r->drop_from && index < r->drop_to ? GST_PAD_PROBE_DROP : GST_PAD_PROBE_OK;
}

GstPadProbeReturn count_force_key_unit(GstPad*, GstPadProbeInfo* info, gpointer data) {
  GstEvent* event = GST_PAD_PROBE_INFO_EVENT(info);
  if (GST_EVENT_TYPE(event) == GST_EVENT_CUSTOM_UPSTREAM &&
      gst_event_has_name(event, "GstForceKeyUnit")) {
    static_cast<std::atomic<int>*>(data)->fetch_add(1);
  }
  return GST_PAD_PROBE_OK;
}

GstFlowReturn on_loop_sample(GstElement* sink, gpointer data) {
  auto* r = static_cast<LoopRecord*>(data);
  GstSample* sample = nullptr;
  g_signal_emit_by_name(sink, "pull-sample", &sample);
  if (sample == nullptr) return GST_FLOW_ERROR;
  const Event e = pfap::testing::read_event(gst_sample_get_buffer(sample));
  gst_sample_unref(sample);
  std::lock_guard lock(r->mutex);
  const int completes = r->state.complete_events;
  const Received got = r->state.apply(e);
  if (r->state.complete_events != completes) r->complete_events_at.push_back(r->phonemes.size());
  if (got.number >= 0) r->phonemes.push_back(got);
  r->changed.notify_all();
  return GST_FLOW_OK;
}

// The receiving caps, also given to rtpbin's request-pt-map: PLI is allowed for the PFAP
// payload type.
constexpr const char* kReceiveCaps =
    "application/x-rtp,media=application,clock-rate=44100,encoding-name=PFAP,payload=97,"
    "rtcp-fb-nack-pli=(boolean)true";

GstCaps* on_request_pt_map(GstElement*, guint, guint pt, gpointer) {
  return pt == 97 ? gst_caps_from_string(kReceiveCaps) : nullptr;
}

TEST(RecoveryLoop, PliBringsACompleteStateAfterALongBurst) {
  ASSERT_TRUE(plugin_available(kElements));
  // About 4 s of speech from 300 ms on; nearly every phoneme moves a FAP, so the burst surely
  // loses state.
  const std::vector<SpeechPhoneme> session = speech_session(11, 44, 0.9, 300 * GST_MSECOND);
  const std::vector<Event> sent = events_of(session);
  const std::vector<Settled> want = lossless_states(session);
  LoopRecord record;
  // Packets 12..16 are lost: 5 in a row, more than the coverage of 1. Packet 0 is the
  // complete recovery every stream starts with.
  record.drop_from = 12;
  record.drop_to = 17;
  std::atomic<int> force_key_units{0};

  Pipeline receiver("rtpbin name=rtpbin rtp-profile=avpf " +
                    rtpbin_receive_session(0, "", kReceiveCaps) +
                    "rtpbin. ! rtppfapdepay name=depay ! appsink name=sink sync=false "
                    "emit-signals=true");
  ASSERT_TRUE(receiver.ok()) << receiver.error();
  Pipeline sender("rtpbin name=rtpbin rtp-profile=avpf " +
                  rtpbin_send_session(0, "",
                                      "appsrc name=src is-live=true format=time "
                                      "caps=application/x-pfap ! rtppfappay name=pay pt=97 "
                                      "recovery-depth=1 complete-recovery-interval=0"));
  ASSERT_TRUE(sender.ok()) << sender.error();

  GstElement* receiver_rtpbin = receiver.by_name("rtpbin");
  g_signal_connect(receiver_rtpbin, "request-pt-map", G_CALLBACK(on_request_pt_map), nullptr);
  g_signal_connect(receiver.by_name("sink"), "new-sample", G_CALLBACK(on_loop_sample), &record);
  GstPad* rtp_in = gst_element_get_static_pad(receiver.by_name("rtp"), "src");
  gst_pad_add_probe(rtp_in, GST_PAD_PROBE_TYPE_BUFFER, drop_burst, &record, nullptr);
  gst_object_unref(rtp_in);
  GstPad* pay_src = gst_element_get_static_pad(sender.by_name("pay"), "src");
  gst_pad_add_probe(pay_src, GST_PAD_PROBE_TYPE_EVENT_UPSTREAM, count_force_key_unit,
                    &force_key_units, nullptr);
  gst_object_unref(pay_src);

  // Sockets bind to free ports of 127.0.0.1 in READY; each sink then gets its peer's port.
  ASSERT_EQ(receiver.set_state(GST_STATE_READY), "");
  ASSERT_EQ(sender.set_state(GST_STATE_READY), "");
  for (const char* name : {"rtp", "rtcp"}) {
    const guint port = bound_port(receiver.by_name(name));
    ASSERT_NE(port, 0u) << name;
    g_object_set(sender.by_name(name), "port", port, nullptr);
  }
  const guint rr_port = bound_port(sender.by_name("rr"));
  ASSERT_NE(rr_port, 0u);
  g_object_set(receiver.by_name("rr"), "port", rr_port, nullptr);
  fast_rtcp(sender.by_name("rtpbin"));
  fast_rtcp(receiver_rtpbin);

  ASSERT_EQ(receiver.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(sender.set_state(GST_STATE_PLAYING), "");
  GstState state = GST_STATE_NULL;
  const GstStateChangeReturn ret =
      gst_element_get_state(sender.get(), &state, nullptr, 10 * GST_SECOND);
  ASSERT_TRUE(ret != GST_STATE_CHANGE_FAILURE && ret != GST_STATE_CHANGE_ASYNC &&
              state == GST_STATE_PLAYING)
      << "sender did not reach PLAYING within 10 s: " << sender.poll_error();
  std::unique_ptr<GstClock, decltype(&gst_object_unref)> clock(
      gst_pipeline_get_clock(GST_PIPELINE(sender.get())), &gst_object_unref);
  ASSERT_NE(clock, nullptr);
  const GstClockTime base_time = gst_element_get_base_time(sender.get());

  std::atomic<bool> stop{false};
  std::thread pusher(push_live, sender.by_name("src"), clock.get(), base_time, std::cref(sent),
                     std::cref(stop));

  // Until the last phoneme is in, or a deadline: the session's length and 10 s.
  const int last = number_of(sent.back().phoneme);
  const auto deadline =
      Clock::now() + std::chrono::nanoseconds(sent.back().pts) + std::chrono::seconds(10);
  std::string failure;
  {
    std::unique_lock lock(record.mutex);
    for (;;) {
      if (!record.phonemes.empty() && record.phonemes.back().number == last) break;
      lock.unlock();
      failure = sender.poll_error();
      if (failure.empty()) failure = receiver.poll_error();
      lock.lock();
      if (!failure.empty()) break;
      if (Clock::now() > deadline) {
        failure = "timed out with " + std::to_string(record.phonemes.size()) + " of " +
                  std::to_string(sent.size()) + " phonemes received";
        break;
      }
      record.changed.wait_for(lock, std::chrono::milliseconds(50));
    }
  }
  stop = true;
  pusher.join();
  const std::string depay_stats = stats_text(receiver.by_name("depay"));
  const std::string pay_stats = stats_text(sender.by_name("pay"));
  const guint64 requests = stat(receiver.by_name("depay"), "requests");
  sender.set_state(GST_STATE_NULL);
  receiver.set_state(GST_STATE_NULL);
  ASSERT_EQ(failure, "") << "depayloader " << depay_stats << "\npayloader " << pay_stats;
  SCOPED_TRACE("depayloader " + depay_stats + "\npayloader " + pay_stats);

  std::lock_guard lock(record.mutex);
  // The burst happened, the receiver asked, rtpbin carried the request as PLI to the
  // payloader, and a complete recovery came back after the burst.
  ASSERT_GE(record.packets, record.drop_to);
  EXPECT_GE(requests, 1u) << "the depayloader asked for no complete state";
  EXPECT_GE(force_key_units.load(), 1) << "no GstForceKeyUnit reached the payloader";
  ASSERT_FALSE(record.complete_packets_at.empty());
  EXPECT_EQ(record.complete_packets_at.front(), 0u) << "the stream starts with a complete state";
  const auto answer =
      std::find_if(record.complete_packets_at.begin(), record.complete_packets_at.end(),
                   [&](size_t i) { return i >= record.drop_to; });
  ASSERT_NE(answer, record.complete_packets_at.end())
      << "no complete-recovery packet after the burst";

  // Before the burst the receiver is whole and right; after it, uncertain until a complete
  // state; from the complete state on, whole and equal to the sender.
  ASSERT_FALSE(record.complete_events_at.empty()) << "no complete event came out";
  const size_t healed = record.complete_events_at.back();
  int uncertain_before = 0, compared_after = 0;
  for (size_t k = 0; k < record.phonemes.size(); ++k) {
    const Received& r = record.phonemes[k];
    ASSERT_GE(r.number, 0);
    ASSERT_LT(r.number, static_cast<int>(sent.size()));
    if (k < healed) {
      if (r.uncertain) {
        ++uncertain_before;
      } else {
        EXPECT_EQ(r.settled, want[r.number])
            << "phoneme " << r.number
            << " not flagged uncertain:" << differences(r.settled, want[r.number]);
      }
      continue;
    }
    ++compared_after;
    EXPECT_FALSE(r.uncertain) << "phoneme " << r.number << " after the complete state";
    EXPECT_EQ(r.settled, want[r.number])
        << "phoneme " << r.number
        << " after the complete state:" << differences(r.settled, want[r.number]);
  }
  EXPECT_GT(uncertain_before, 0) << "the burst never made the receiver uncertain";
  EXPECT_GT(compared_after, 5) << "too few phonemes after the complete state";
  if (g_getenv("PFAP_TEST_VERBOSE") != nullptr) {
    std::cout << "packets " << record.packets << ", dropped " << record.drop_from << ".."
              << record.drop_to - 1 << ", complete packets at";
    for (size_t i : record.complete_packets_at) std::cout << " " << i;
    std::cout << "; requests " << requests << ", GstForceKeyUnit at the payloader "
              << force_key_units.load() << "; phonemes " << record.phonemes.size() << ", uncertain "
              << uncertain_before << ", whole again from phoneme " << healed << "\n";
  }
}

// ---------------------------------------------------------------------------------------------
// A long seeded session in one process.

// Which packets between payloader and depayloader are lost. Packet 0, the complete
// recovery that starts the stream, always arrives.
struct LossPattern {
  enum class Kind { kNone, kWithinDepth, kBursts } kind = Kind::kNone;
  double loss = 0;         // the fraction of packets lost, about
  unsigned max_burst = 0;  // kWithinDepth: the depth; kBursts: the longest burst
  uint32_t seed = 0;
};

struct Dropper {
  explicit Dropper(const LossPattern& p) : pattern(p), rng(p.seed) {}

  bool drop_next() {
    const size_t index = packets++;
    bool drop = false;
    switch (pattern.kind) {
      case LossPattern::Kind::kNone:
        break;
      case LossPattern::Kind::kWithinDepth:
        // Random loss, but never more in a row than the depth.
        drop =
            index > 0 && run < pattern.max_burst && std::bernoulli_distribution(pattern.loss)(rng);
        break;
      case LossPattern::Kind::kBursts:
        // Bursts of 1..max_burst packets (mean (1 + max_burst) / 2), starting at random.
        if (left > 0) {
          drop = true;
        } else if (index > 0 &&
                   std::bernoulli_distribution(pattern.loss * 2.0 / (1 + pattern.max_burst))(rng)) {
          left = std::uniform_int_distribution<unsigned>(1, pattern.max_burst)(rng);
          drop = true;
        }
        if (drop) --left;
        break;
    }
    run = drop ? run + 1 : 0;
    longest_run = std::max(longest_run, run);
    dropped += drop;
    trailing = drop ? trailing + 1 : 0;
    return drop;
  }

  LossPattern pattern;
  std::mt19937 rng;
  size_t packets = 0;
  size_t dropped = 0;
  size_t trailing = 0;  // dropped after the last packet that arrived
  unsigned run = 0, left = 0, longest_run = 0;
};

GstPadProbeReturn drop_by_pattern(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* dropper = static_cast<Dropper*>(data);
  if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_BUFFER_LIST) {
    GstBufferList* list = gst_buffer_list_make_writable(GST_PAD_PROBE_INFO_BUFFER_LIST(info));
    GST_PAD_PROBE_INFO_DATA(info) = list;
    for (guint i = 0; i < gst_buffer_list_length(list);) {
      if (dropper->drop_next()) {
        gst_buffer_list_remove(list, i, 1);
      } else {
        ++i;
      }
    }
    return gst_buffer_list_length(list) == 0 ? GST_PAD_PROBE_DROP : GST_PAD_PROBE_OK;
  }
  return dropper->drop_next() ? GST_PAD_PROBE_DROP : GST_PAD_PROBE_OK;
}

struct SessionRun {
  std::vector<Received> phonemes;
  int complete_events = 0;
  int recovered_events = 0;
  size_t packets = 0, dropped = 0;
  size_t dropped_seen = 0;  // dropped before the last packet that arrived: what a receiver
                            // can know was lost
  unsigned longest_burst = 0;
  guint64 lost = 0, gaps = 0, recovered = 0, requests = 0, faps_recovered = 0;
  std::string depay_stats;
};

// The session through appsrc ! rtppfappay ! (drop) ! rtppfapdepay ! appsink.
SessionRun run_session(const std::vector<Event>& sent, const std::string& pay_properties,
                       bool request_recovery, const LossPattern& pattern) {
  SessionRun out;
  Pipeline p(
      "appsrc name=src format=time max-bytes=0 caps=application/x-pfap "
      "! rtppfappay name=pay " +
      pay_properties +
      " ! rtppfapdepay name=depay request-recovery=" + (request_recovery ? "true" : "false") +
      " ! appsink name=sink sync=false emit-signals=false wait-on-eos=false");
  EXPECT_TRUE(p.ok()) << p.error();
  if (!p.ok()) return out;
  Dropper dropper(pattern);
  GstPad* depay_sink = gst_element_get_static_pad(p.by_name("depay"), "sink");
  gst_pad_add_probe(
      depay_sink,
      static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_BUFFER_LIST),
      drop_by_pattern, &dropper, nullptr);
  gst_object_unref(depay_sink);
  EXPECT_EQ(p.set_state(GST_STATE_PLAYING), "");
  GstElement* src = p.by_name("src");
  for (const Event& e : sent) {
    if (push(src, e) != GST_FLOW_OK) {
      ADD_FAILURE() << "push-buffer failed: " << p.poll_error();
      return out;
    }
  }
  pfap::testing::end_of_stream(src);
  const std::string eos = p.wait_eos(std::chrono::seconds(30));
  EXPECT_EQ(eos, "");
  if (!eos.empty()) return out;

  ReceiverState state;
  for (GstSample* sample : pfap::testing::pull_all(p.by_name("sink"))) {
    const Received r = state.apply(pfap::testing::read_event(gst_sample_get_buffer(sample)));
    gst_sample_unref(sample);
    if (r.number >= 0) out.phonemes.push_back(r);
  }
  out.complete_events = state.complete_events;
  out.recovered_events = state.recovered_events;
  out.packets = dropper.packets;
  out.dropped = dropper.dropped;
  out.dropped_seen = dropper.dropped - dropper.trailing;
  out.longest_burst = dropper.longest_run;
  GstElement* depay = p.by_name("depay");
  out.lost = stat(depay, "lost");
  out.gaps = stat(depay, "gaps");
  out.recovered = stat(depay, "recovered");
  out.requests = stat(depay, "requests");
  out.faps_recovered = stat(depay, "faps-recovered");
  out.depay_stats = stats_text(depay);
  return out;
}

// How a lossy run compares with the lossless receiver, phoneme by phoneme.
struct Comparison {
  int received = 0;
  int uncertain = 0;
  int compared = 0;                 // not flagged uncertain
  int differing = 0;                // of those, with some settled value not the lossless receiver's
  int differing_any = 0;            // of all received, flagged or not
  int certain_after_uncertain = 0;  // certain phonemes after the first uncertain one
  std::string first_difference;
};

Comparison compare(const SessionRun& run, const std::vector<Settled>& lossless) {
  Comparison c;
  int previous = -1;
  bool seen_uncertain = false;
  for (const Received& r : run.phonemes) {
    ++c.received;
    if (r.number <= previous || r.number >= static_cast<int>(lossless.size())) {
      if (c.first_difference.empty()) {
        c.first_difference =
            "phoneme " + std::to_string(r.number) + " after " + std::to_string(previous);
      }
      ++c.differing;
      continue;
    }
    previous = r.number;
    const bool same = r.settled == lossless[r.number];
    c.differing_any += !same;
    if (r.uncertain) {
      ++c.uncertain;
      seen_uncertain = true;
      continue;
    }
    c.certain_after_uncertain += seen_uncertain;
    ++c.compared;
    if (!same) {
      ++c.differing;
      if (c.first_difference.empty()) {
        c.first_difference = "phoneme " + std::to_string(r.number) + ":" +
                             differences(r.settled, lossless[r.number]);
      }
    }
  }
  return c;
}

// With PFAP_TEST_VERBOSE set, one line per run on stdout.
void report(const std::string& what, const SessionRun& run, const Comparison& c) {
  if (g_getenv("PFAP_TEST_VERBOSE") == nullptr) return;
  std::cout << what << ": " << run.dropped << "/" << run.packets << " packets dropped (longest "
            << run.longest_burst << "), " << c.received << " phonemes received, " << c.uncertain
            << " uncertain, " << c.compared << " compared, " << c.differing << " differing ("
            << c.differing_any << " with uncertain ones); gaps " << run.gaps << ", recovered "
            << run.recovered << ", requests " << run.requests << ", complete events "
            << run.complete_events << "\n";
}

std::string describe(const LossPattern& p, const SessionRun& run) {
  std::ostringstream s;
  s << "loss " << p.loss * 100 << " %, bursts up to " << p.max_burst << ", seed " << p.seed << ": "
    << run.dropped << " of " << run.packets << " packets dropped, longest burst "
    << run.longest_burst << "; depayloader " << run.depay_stats;
  return s.str();
}

class RecoveryRandomLoss : public ::testing::Test {
 protected:
  static constexpr int kPhonemes = 3000;

  static void SetUpTestSuite() {
    const std::vector<SpeechPhoneme> session = speech_session(2024, kPhonemes, 0.45);
    session_ = new std::vector<Event>(events_of(session));
    lossless_ = new std::vector<Settled>(lossless_states(session));
  }
  static void TearDownTestSuite() {
    delete session_;
    delete lossless_;
    session_ = nullptr;
    lossless_ = nullptr;
  }

  static std::string pay(unsigned depth) {
    return "recovery-depth=" + std::to_string(depth) + " complete-recovery-interval=0";
  }

  static std::vector<Event>* session_;
  static std::vector<Settled>* lossless_;
};

std::vector<Event>* RecoveryRandomLoss::session_ = nullptr;
std::vector<Settled>* RecoveryRandomLoss::lossless_ = nullptr;

// The lossless receiver: every phoneme, whole, with the sender's state. The other tests
// compare with the sender's states, which this shows to be the lossless receiver's.
TEST_F(RecoveryRandomLoss, LosslessReceiverHasTheSendersState) {
  ASSERT_TRUE(plugin_available(kElements));
  for (unsigned depth : {0u, 4u}) {
    SCOPED_TRACE("recovery-depth " + std::to_string(depth));
    const SessionRun run = run_session(*session_, pay(depth), true, {});
    ASSERT_EQ(run.phonemes.size(), session_->size()) << run.depay_stats;
    for (size_t i = 0; i < run.phonemes.size(); ++i) {
      const Received& r = run.phonemes[i];
      ASSERT_EQ(r.number, static_cast<int>(i));
      ASSERT_FALSE(r.uncertain) << "phoneme " << i;
      ASSERT_EQ(r.settled, (*lossless_)[i])
          << "phoneme " << i << ":" << differences(r.settled, (*lossless_)[i]);
    }
    EXPECT_EQ(run.lost, 0u);
    EXPECT_EQ(run.requests, 0u);
    EXPECT_EQ(run.recovered_events, 0);
  }
}

TEST_F(RecoveryRandomLoss, BurstsWithinTheDepthLeaveTheStateExact) {
  ASSERT_TRUE(plugin_available(kElements));
  for (unsigned depth : {1u, 4u, 15u}) {
    for (double loss : {0.01, 0.05, 0.10, 0.20}) {
      const LossPattern pattern{LossPattern::Kind::kWithinDepth, loss, depth,
                                depth * 100 + static_cast<uint32_t>(loss * 100)};
      const SessionRun run = run_session(*session_, pay(depth), true, pattern);
      SCOPED_TRACE("recovery-depth " + std::to_string(depth) + ", " + describe(pattern, run));
      const Comparison c = compare(run, *lossless_);
      report("depth " + std::to_string(depth) + " loss " + std::to_string(loss), run, c);
      EXPECT_GT(run.dropped, 0u);
      EXPECT_LE(run.longest_burst, depth);
      EXPECT_EQ(c.uncertain, 0);
      EXPECT_EQ(c.differing, 0) << c.first_difference;
      EXPECT_GT(c.received, kPhonemes * (1 - 2 * loss) - 50);
      // The depayloader saw every drop (but those after the last packet), found every gap
      // covered, and asked for nothing.
      EXPECT_EQ(run.lost, run.dropped_seen);
      EXPECT_GT(run.gaps, 0u);
      EXPECT_EQ(run.recovered, run.gaps);
      EXPECT_EQ(run.requests, 0u);
      EXPECT_GT(run.faps_recovered, 0u);
    }
  }
}

// Bursts up to 12 packets against a coverage of 4: phonemes after a burst longer than the
// coverage are flagged uncertain until the complete state the depayloader asks for (the
// request goes upstream to the payloader in the same pipeline); every phoneme not flagged
// is exact.
TEST_F(RecoveryRandomLoss, LongerBurstsAreExactWheneverNotUncertain) {
  ASSERT_TRUE(plugin_available(kElements));
  constexpr unsigned kDepth = 4;
  for (double loss : {0.01, 0.05, 0.10, 0.20}) {
    const LossPattern pattern{LossPattern::Kind::kBursts, loss, 12,
                              7000 + static_cast<uint32_t>(loss * 100)};
    const SessionRun run = run_session(*session_, pay(kDepth), true, pattern);
    SCOPED_TRACE(describe(pattern, run));
    const Comparison c = compare(run, *lossless_);
    report("bursts to 12, depth 4, loss " + std::to_string(loss), run, c);
    EXPECT_GT(run.dropped, 0u);
    EXPECT_EQ(c.differing, 0) << c.first_difference;
    EXPECT_GT(c.compared, kPhonemes / 2);
    EXPECT_EQ(run.lost, run.dropped_seen);
    if (run.longest_burst > kDepth) {
      EXPECT_GT(c.uncertain, 0) << "a burst over the coverage left nothing uncertain";
      EXPECT_GE(run.requests, 1u);
      EXPECT_GE(run.complete_events, 1) << "no complete state came back";
      EXPECT_GT(c.certain_after_uncertain, 0) << "never whole again";
    }
  }
}

// The comparison can see lost FAPs: without recovery, the same kind of loss leaves the
// state wrong for a large share of the phonemes (over a third at 5 % loss, over half at 20 %).
TEST_F(RecoveryRandomLoss, WithoutRecoveryTheStateDiffers) {
  ASSERT_TRUE(plugin_available(kElements));
  for (double loss : {0.05, 0.20}) {
    const LossPattern pattern{LossPattern::Kind::kWithinDepth, loss, 4,
                              400 + static_cast<uint32_t>(loss * 100)};
    const SessionRun run = run_session(*session_, pay(0), false, pattern);
    SCOPED_TRACE(describe(pattern, run));
    const Comparison c = compare(run, *lossless_);
    report("depth 0 loss " + std::to_string(loss), run, c);
    EXPECT_GT(c.differing_any, c.received / 4)
        << c.differing_any << " of " << c.received << " received phonemes differ";
    // Honest about it: after the first loss every phoneme is flagged.
    EXPECT_EQ(c.compared + c.uncertain, c.received);
    EXPECT_GT(c.uncertain, c.received / 2);
    EXPECT_EQ(c.differing, 0) << "a phoneme with a wrong state was not flagged: "
                              << c.first_difference;
  }
}

// ---------------------------------------------------------------------------------------------
// Soak: an hour of stream time through netsim and rtpjitterbuffer.
//
// netsim drops and duplicates packets at random (it has no seed: every run differs, and what
// the test asserts holds for any pattern). Its reordering needs real-time delays, which a
// test running an hour in seconds cannot give, so a pad probe after it reorders instead:
// now and then it holds a packet back until 1 to 3 later ones have gone. rtpjitterbuffer
// runs on a GstTestClock that the test moves to each phoneme's start before pushing it, so
// that packets arrive as from a sender in real time and the jitterbuffer's timers (its start
// deadline, lost packets) fire at their stream times. Requests for a complete state go
// upstream from rtppfapdepay through the jitterbuffer and netsim to rtppfappay, whose
// complete-recovery-interval is 0: it sends a complete state at the start and on request only.

struct Reorderer {
  explicit Reorderer(GstPad* peer) : peer(peer) {}

  // Sends the held packet on, if any.
  void release() {
    if (held == nullptr) return;
    gst_pad_chain(peer, held);
    held = nullptr;
  }

  std::mt19937 rng{6};
  std::atomic<double> chance{0.02};
  GstPad* peer;               // rtpjitterbuffer's sink pad
  GstBuffer* held = nullptr;  // the packet held back
  int behind = 0;             // how many later packets go before it
  std::atomic<size_t> reordered{0};
};

// Runs under rtppfappay's stream lock, complete states sent from the depayloader's thread
// included (rtppfapdepay asks, rtppfappay answers from that thread only when its stream lock
// is free), so never in two threads at once.
GstPadProbeReturn reorder(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* r = static_cast<Reorderer*>(data);
  if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM) {
    // Nothing held crosses an event (EOS above all).
    const auto type = static_cast<unsigned>(GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)));
    if (type & GST_EVENT_TYPE_SERIALIZED) r->release();
    return GST_PAD_PROBE_OK;
  }
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  if (r->held == nullptr) {
    if (!std::bernoulli_distribution(r->chance)(r->rng)) return GST_PAD_PROBE_OK;
    r->held = gst_buffer_ref(buffer);
    r->behind = std::uniform_int_distribution<int>(1, 3)(r->rng);
    ++r->reordered;
    return GST_PAD_PROBE_DROP;
  }
  // This packet overtakes the held one: straight to the jitterbuffer.
  gst_pad_chain(r->peer, gst_buffer_ref(buffer));
  if (--r->behind > 0) return GST_PAD_PROBE_DROP;
  // Then the held one, in this packet's place.
  GST_PAD_PROBE_INFO_DATA(info) = r->held;
  r->held = nullptr;
  gst_buffer_unref(buffer);
  return GST_PAD_PROBE_OK;
}

// Releases every clock wait due by `t`, in time order, then sets the clock to `t`. A wait
// that a thread makes just after this looks is released by the next call.
void advance_to(GstTestClock* clock, GstClockTime t) {
  for (;;) {
    const GstClockTime next = gst_test_clock_get_next_entry_time(clock);
    if (!GST_CLOCK_TIME_IS_VALID(next) || next > t) break;
    if (next > gst_clock_get_time(GST_CLOCK(clock))) gst_test_clock_set_time(clock, next);
    if (GstClockID id = gst_test_clock_process_next_clock_id(clock)) gst_clock_id_unref(id);
  }
  if (t > gst_clock_get_time(GST_CLOCK(clock))) gst_test_clock_set_time(clock, t);
}

GstElement* harness_element(GstHarness* h, const char* name) {
  GstElement* e = gst_bin_get_by_name(GST_BIN(h->element), name);
  if (e != nullptr) gst_object_unref(e);  // the bin keeps it
  return e;
}

// The packets rtpjitterbuffer has handled: pushed on, or dropped as late or duplicate.
guint64 jitterbuffer_handled(GstElement* jb) {
  GstStructure* s = nullptr;
  g_object_get(jb, "stats", &s, nullptr);
  guint64 handled = 0;
  for (const char* field : {"num-pushed", "num-late", "num-duplicates"}) {
    guint64 value = 0;
    gst_structure_get_uint64(s, field, &value);
    handled += value;
  }
  gst_structure_free(s);
  return handled;
}

// What the receiver made of the session, phoneme by phoneme, counted as it came: nothing
// grows with the session's length, so that the heap measures the elements.
struct SoakCount {
  int phonemes = 0, uncertain = 0, compared = 0, differing = 0, out_of_order = 0;
  int previous = -1;
  Received last;
  std::string first_difference;
};

void take_output(GstHarness* h, ReceiverState& state, const std::vector<Settled>& lossless,
                 SoakCount& c, bool& eos) {
  while (GstBuffer* b = gst_harness_try_pull(h)) {
    const Received r = state.apply(pfap::testing::read_event(b));
    gst_buffer_unref(b);
    if (r.number < 0) continue;
    ++c.phonemes;
    c.last = r;
    if (r.number <= c.previous || r.number >= static_cast<int>(lossless.size())) {
      ++c.out_of_order;
      continue;
    }
    c.previous = r.number;
    if (r.uncertain) {
      ++c.uncertain;
      continue;
    }
    ++c.compared;
    if (r.settled != lossless[r.number]) {
      ++c.differing;
      if (c.first_difference.empty()) {
        c.first_difference = "phoneme " + std::to_string(r.number) + ":" +
                             differences(r.settled, lossless[r.number]);
      }
    }
  }
  while (GstEvent* e = gst_harness_try_pull_event(h)) {
    eos = eos || GST_EVENT_TYPE(e) == GST_EVENT_EOS;
    gst_event_unref(e);
  }
  while (GstEvent* e = gst_harness_try_pull_upstream_event(h)) gst_event_unref(e);
}

GstPadProbeReturn count_buffer(GstPad*, GstPadProbeInfo*, gpointer data) {
  static_cast<std::atomic<guint64>*>(data)->fetch_add(1);
  return GST_PAD_PROBE_OK;
}

// Packets that reached rtpjitterbuffer, and those it dropped without counting them.
struct JitterbufferInput {
  std::atomic<guint64> arrived{0};
  guint64 uncounted = 0;
};

// Waits until rtpjitterbuffer has handled every packet that reached it, or waits on the clock
// behind a gap, which only moving time on releases, or has done nothing for a while (it
// dropped a packet without counting it); takes the output as it comes. Without this the test
// thread would run seconds of stream time ahead of the jitterbuffer's, and a complete state
// asked for would queue behind all of it: a receiver does not lag its sender so in real time.
void catch_up(GstHarness* h, GstElement* jb, GstTestClock* clock, JitterbufferInput& in,
              ReceiverState& state, const std::vector<Settled>& lossless, SoakCount& c, bool& eos) {
  guint64 last = G_MAXUINT64;
  for (int still = 0;; g_usleep(20)) {
    take_output(h, state, lossless, c, eos);
    const guint64 handled = jitterbuffer_handled(jb) + in.uncounted;
    const guint64 arrived = in.arrived.load();
    if (handled >= arrived) return;
    still = handled == last ? still + 1 : 0;
    last = handled;
    if (gst_test_clock_peek_id_count(clock) > 0 && still >= 3) return;
    if (still >= 100) {
      in.uncounted += arrived - handled;
      return;
    }
  }
}

// PFAP_SOAK_MINUTES sets the stream time (default 60).
TEST(RecoverySoak, AnHourThroughNetsimAndRtpjitterbuffer) {
  ASSERT_TRUE(plugin_available(kElements));
  const char* minutes_env = g_getenv("PFAP_SOAK_MINUTES");
  const int minutes = minutes_env != nullptr ? std::atoi(minutes_env) : 60;
  ASSERT_GT(minutes, 1);
  const GstClockTime length = static_cast<GstClockTime>(minutes) * 60 * GST_SECOND;
  // About 11 phonemes per second of stream time; one phoneme in three moves FAPs.
  const int n = static_cast<int>(minutes * 60 * 12);
  ASSERT_LT(n, 65536) << "phoneme numbers are 16 bits";
  const std::vector<SpeechPhoneme> session = speech_session(60, n, 0.35);
  const std::vector<Event> sent = events_of(session);
  ASSERT_GE(sent.back().pts, length);
  const std::vector<Settled> lossless = lossless_states(session);

  // Coverage 1: a single loss is repaired, two in a row are not (about one packet in a
  // hundred at 10 % loss): the test sees both.
  GstHarness* h = gst_harness_new_parse(
      "rtppfappay name=pay recovery-depth=1 complete-recovery-interval=0 "
      "! netsim name=net drop-probability=0.1 duplicate-probability=0.02 "
      "! rtpjitterbuffer name=jb latency=200 do-lost=true "
      "! rtppfapdepay name=depay");
  ASSERT_NE(h, nullptr);
  gst_harness_use_testclock(h);
  GstTestClock* clock = gst_harness_get_testclock(h);
  gst_harness_set_src_caps_str(h, "application/x-pfap");
  GstPad* net_src = gst_element_get_static_pad(harness_element(h, "net"), "src");
  GstElement* jb = harness_element(h, "jb");
  GstPad* jb_sink = gst_element_get_static_pad(jb, "sink");
  Reorderer reorderer(jb_sink);
  JitterbufferInput jb_input;
  gst_pad_add_probe(jb_sink, GST_PAD_PROBE_TYPE_BUFFER, count_buffer, &jb_input.arrived, nullptr);
  const gulong reorder_probe = gst_pad_add_probe(
      net_src,
      static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM),
      reorder, &reorderer, nullptr);

  // The last 30 s are without loss, duplicates or reordering: the session ends whole.
  const GstClockTime calm = sent.back().pts - 30 * GST_SECOND;
  const GstClockTime warm_up = std::min<GstClockTime>(length / 10, 5 * 60 * GST_SECOND);
  ReceiverState state;
  SoakCount count;
  bool eos = false;
  size_t heap_warm = 0, heap_most = 0;
  std::vector<std::pair<GstClockTime, size_t>> heap_samples;  // reserved: no growth here
  heap_samples.reserve(64);
  GstClockTime next_sample = warm_up;
  bool calm_set = false;
  const auto started = Clock::now();
  for (const Event& e : sent) {
    advance_to(clock, e.pts);
    if (!calm_set && e.pts >= calm) {
      g_object_set(harness_element(h, "net"), "drop-probability", 0.0f, "duplicate-probability",
                   0.0f, nullptr);
      reorderer.chance = 0;
      calm_set = true;
    }
    ASSERT_EQ(push_harness(h, e), GST_FLOW_OK);
    catch_up(h, jb, clock, jb_input, state, lossless, count, eos);
    if (e.pts >= next_sample) {
      const size_t heap = pfap::testing::heap_bytes();
      if (heap_warm == 0) heap_warm = heap;
      heap_most = std::max(heap_most, heap);
      heap_samples.emplace_back(e.pts, heap);
      next_sample += length / 12;
    }
  }
  gst_harness_push_event(h, gst_event_new_eos());
  // The jitterbuffer pushes what it holds, then EOS; move time on until it has.
  const auto deadline = Clock::now() + std::chrono::seconds(30);
  GstClockTime t = gst_clock_get_time(GST_CLOCK(clock));
  while (!eos && Clock::now() < deadline) {
    t += 100 * GST_MSECOND;
    advance_to(clock, t);
    g_usleep(1000);
    take_output(h, state, lossless, count, eos);
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - started).count();
  EXPECT_TRUE(eos) << "no EOS out of the jitterbuffer";

  GstElement* depay = harness_element(h, "depay");
  const std::string stats = stats_text(depay);
  SCOPED_TRACE("depayloader " + stats);
  const guint64 lost = stat(depay, "lost"), recovered = stat(depay, "recovered"),
                requests = stat(depay, "requests");
  const guint64 duplicates = stat(jb, "num-duplicates");
  const guint64 pushed = stat(jb, "num-pushed");

  // Every phoneme not flagged uncertain has the sender's state, in order.
  EXPECT_EQ(count.differing, 0) << count.first_difference;
  EXPECT_EQ(count.out_of_order, 0);
  EXPECT_GT(count.compared, n / 2);
  // Loss within the coverage was repaired, loss beyond it flagged and asked about...
  EXPECT_GT(lost, 0u);
  EXPECT_GT(recovered, 0u);
  EXPECT_GT(count.uncertain, 0);
  EXPECT_GT(requests, 0u);
  EXPECT_GT(state.complete_events, 0);
  EXPECT_GT(duplicates, 0u);
  EXPECT_GT(reorderer.reordered.load(), 0u);
  // ... and the session ends with the sender's state.
  EXPECT_EQ(count.last.number, n - 1);
  EXPECT_FALSE(count.last.uncertain);
  EXPECT_EQ(count.last.settled, lossless.back())
      << differences(count.last.settled, lossless.back());

  // No growth of the heap after the warm-up (the harness drops nothing: the test takes each
  // buffer and event as it comes). The bound allows for what is in flight at a sample.
  constexpr size_t kGrowthBound = 64 * 1024;
  EXPECT_LE(heap_most - heap_warm, kGrowthBound);
  if (g_getenv("PFAP_TEST_VERBOSE") != nullptr) {
    std::cout << minutes << " min of stream time, " << n << " phonemes in " << seconds
              << " s; received " << count.phonemes << ", uncertain " << count.uncertain
              << ", compared " << count.compared << "; netsim/reorder: jitterbuffer pushed "
              << pushed << ", duplicates " << duplicates << ", reordered "
              << reorderer.reordered.load() << "; depayloader lost " << lost << ", recovered "
              << recovered << ", requests " << requests << ", complete events "
              << state.complete_events << ", packets the jitterbuffer dropped uncounted "
              << jb_input.uncounted << "\nheap (stream time: bytes):";
    for (const auto& [at, bytes] : heap_samples) {
      std::cout << " " << at / GST_SECOND << " s: " << bytes;
    }
    std::cout << "\nheap growth after warm-up: " << heap_most - heap_warm << " bytes, RSS "
              << (pfap::testing::rss_bytes() >> 10) << " KiB\n";
  }

  gst_pad_remove_probe(net_src, reorder_probe);
  reorderer.release();  // nothing, unless EOS never came
  gst_object_unref(net_src);
  gst_object_unref(jb_sink);
  gst_object_unref(clock);
  gst_harness_teardown(h);
}

}  // namespace

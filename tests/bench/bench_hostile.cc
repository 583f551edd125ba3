// SPDX-License-Identifier: LGPL-2.1-or-later
// What a hostile sender can make a receiver pay (issue 6; docs/security.md, "Bounded cost"
// and "Memory per depayloader").
//
// 1. Cost per payload byte of the packets a sender can make worst, beside a typical speech
//    packet, all at most 1388 bytes (a 1400-byte MTU less the RTP header):
//    - library: what rtppfapdepay does per packet, without GStreamer: decode_payload,
//      RecoveryReceiver::receive (FapState::apply of every recovery entry and FAP), and each
//      x-pfap event (MarkupEvent, write_markup) into a reused byte buffer;
//    - element: the same packets as RTP buffers pushed into rtppfapdepay in a GstHarness
//      that drops its output, CPU time of the pushing thread (the harness is synchronous).
//    Each case runs its bytes in turn with the others, repeatedly; the median is printed.
// 2. Memory of one rtppfapdepay fed a long hostile stream: the process's heap in use and its
//    RSS after a warm-up and along the rest of the run, with every buffer and event released.
// 3. Readers and writers (issue 27): the peak RSS of a process running one pipeline to EOS
//    over an input at a reader's or writer's limits, and the bytes the sink got; each in a
//    child process of its own (this program run again with --peak), so that each peak is its
//    own. GST_PLUGIN_PATH may name another build's plugins, to compare.
//
// Run: meson test -C build --benchmark --verbose hostile
//  or: build/tests/bench/bench_hostile [scale [memory-packets [case [readers]]]]
//      scale 1 takes ~20 s; memory-packets 0 skips part 2; case: only typical speech and the
//      cases whose name holds it (to profile one: valgrind --tool=callgrind ... 1 0 smallest);
//      readers 0 skips part 3 (about a minute, and 0.5 GB of files in $TMPDIR while it runs)
//  or: build/tests/bench/bench_hostile readers   (part 3 alone)
#include <glib/gstdio.h>
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gst/rtp/gstrtpbuffer.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "clocks.h"
#include "element_stats.h"
#include "heap.h"
#include "pfap/fap_file.h"
#include "pfap/markup_event.h"
#include "pfap/payload.h"
#include "pfap/recovery.h"
#include "random_markup.h"
#include "rtp_packet.h"

namespace {

using pfap::Fap;
using pfap::Packet;
using pfap::Phoneme;
using pfap::RecoveryKind;
using pfap::testing::median;
using pfap::testing::RandomMarkup;

constexpr size_t kMaxPayload = 1388;
constexpr const char* kCaps =
    "application/x-rtp,media=application,clock-rate=44100,encoding-name=PFAP,payload=96";

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "bench_hostile: %s\n", what.c_str());
  std::exit(1);
}

std::vector<uint8_t> encode(const Packet& packet) {
  std::vector<uint8_t> bytes(pfap::encoded_size(packet));
  if (pfap::encode_payload(packet, bytes) != pfap::EncodeStatus::kOk) fail("cannot encode");
  if (bytes.size() > kMaxPayload) fail("payload over the MTU");
  return bytes;
}

// ---------------------------------------------------------------------------------------------
// The cases

struct Case {
  const char* name;
  // Payloads sent in turn (two that alternate make a complete state change every time).
  std::vector<std::vector<uint8_t>> payloads;
  // How far the sequence number moves from one packet to the next: more than 1 is a loss
  // before each packet, which makes the receiver apply dynamic recovery entries.
  uint16_t seqnum_step = 1;
  int64_t time_step_ns = 20'000'000;           // packet times this far apart
  std::vector<double> library_ns, element_ns;  // per byte, one per repetition
};

// Speech as bench_payload.cc has it: dynamic recovery over 4 packets with 3 entries (not
// applied: nothing is lost), then phonemes of which one in four carries 2 FAPs.
Packet typical(RandomMarkup& random) {
  Packet packet;
  packet.recovery_kind = RecoveryKind::kDynamic;
  packet.covered_packets = 4;
  for (int i = 0; i < 3; ++i) packet.recovery.push_back(random.fap());
  for (int i = 0;; ++i) {
    std::vector<Fap> faps;
    if (i % 4 == 0) faps = {random.fap(), random.fap()};
    if (pfap::encoded_size(packet) + 4 + 6 * faps.size() > kMaxPayload) break;
    packet.add_phoneme(random.phoneme(), faps);
  }
  return packet;
}

// The longest recovery list that fits: 231 entries.
Packet longest_recovery(RandomMarkup& random, RecoveryKind kind) {
  Packet packet;
  packet.recovery_kind = kind;
  packet.covered_packets = kind == RecoveryKind::kDynamic ? 40 : 0;
  while (pfap::encoded_size(packet) + pfap::kFapDescriptorBytes <= kMaxPayload) {
    packet.recovery.push_back(random.fap());
  }
  return packet;
}

// A complete state of every FAP, 3..74, each at amplitude `sign` * something.
Packet complete_every_fap(RandomMarkup& random, int sign) {
  Packet packet;
  packet.recovery_kind = RecoveryKind::kComplete;
  for (int index = pfap::kMinFapIndex; index <= pfap::kMaxFapIndex; ++index) {
    Fap f = random.fap();
    f.index = static_cast<uint8_t>(index);
    f.amplitude = sign * std::max(1, std::abs(f.amplitude));
    packet.recovery.push_back(f);
  }
  return packet;
}

// Phonemes with `faps_each` FAPs before each, as many as fit.
Packet phonemes_with_faps(RandomMarkup& random, size_t faps_each) {
  Packet packet;
  for (;;) {
    const size_t room = kMaxPayload - pfap::encoded_size(packet);
    if (room < pfap::kPhonemeDescriptorBytes) break;
    const size_t n =
        std::min(faps_each, (room - pfap::kPhonemeDescriptorBytes) / pfap::kFapDescriptorBytes);
    std::vector<Fap> faps;
    for (size_t k = 0; k < n; ++k) faps.push_back(random.fap());
    packet.add_phoneme(random.phoneme(), faps);
  }
  return packet;
}

// As many phonemes of 0 and 1 ms without FAPs as fit: 346, each its own x-pfap buffer.
Packet tiny_phonemes(RandomMarkup& random) {
  Packet packet;
  for (int i = 0; pfap::encoded_size(packet) + pfap::kPhonemeDescriptorBytes <= kMaxPayload; ++i) {
    Phoneme p = random.phoneme();
    p.duration_ms = static_cast<uint16_t>(i % 2);
    packet.add_phoneme(p, {});
  }
  return packet;
}

std::vector<Case> make_cases() {
  RandomMarkup random(6);
  std::vector<Case> cases;
  const auto add = [&cases](const char* name, std::vector<std::vector<uint8_t>> payloads,
                            uint16_t seqnum_step = 1, int64_t time_step_ns = 20'000'000) {
    Case c;
    c.name = name;
    c.payloads = std::move(payloads);
    c.seqnum_step = seqnum_step;
    c.time_step_ns = time_step_ns;
    cases.push_back(std::move(c));
  };
  add("typical speech", {encode(typical(random))});
  add("dynamic recovery, 231 entries over 40 packets",
      {encode(longest_recovery(random, RecoveryKind::kDynamic))}, 40);
  add("complete state, every FAP (72), changing",
      {encode(complete_every_fap(random, 1)), encode(complete_every_fap(random, -1))});
  add("complete state, 231 entries, changing",
      {encode(longest_recovery(random, RecoveryKind::kComplete)),
       encode(longest_recovery(random, RecoveryKind::kComplete))});
  add("40 bookmarks (80 FAPs) per phoneme", {encode(phonemes_with_faps(random, 80))});
  add("230 FAPs before one phoneme", {encode(phonemes_with_faps(random, 1000))});
  add("346 phonemes of 0/1 ms", {encode(tiny_phonemes(random))});
  add("1 FAP per phoneme", {encode(phonemes_with_faps(random, 1))});
  // Malformed at the last byte: decoded whole, then dropped.
  std::vector<uint8_t> late = encode(phonemes_with_faps(random, 1000));
  late.push_back(0);
  add("malformed at its last byte", {late});
  // The smallest packets: one phoneme. Their cost is the element's and GstRTPBaseDepayload's
  // per packet, spread over 5 bytes.
  Packet one;
  one.add_phoneme(random.phoneme(), {});
  add("smallest: one phoneme", {encode(one)});
  // ... with a loss beyond the coverage before each and 1 s between them: the receiver is
  // never whole and asks for a complete state with every packet.
  add("smallest, each asking for a complete state", {encode(one)}, 100, 1'000'000'000);
  return cases;
}

// ---------------------------------------------------------------------------------------------
// Timing

// rtppfapdepay's work per packet (gst/gstrtppfapdepay.cc) with library types only.
class LibraryDepay {
 public:
  // Returns the number of events made, so that nothing is optimised away.
  size_t process(std::span<const uint8_t> payload, uint16_t seqnum, int64_t time_ns) {
    if (!pfap::decode_payload(payload, packet_).ok()) return 0;
    const pfap::ReceiveResult r = receiver_.receive(packet_, seqnum, time_ns);
    using Recovery = pfap::ReceiveResult::Recovery;
    size_t events = 0;
    if (r.recovery == Recovery::kRecovered || (r.recovery == Recovery::kComplete && r.changed)) {
      event_.kind = r.recovery == Recovery::kRecovered ? PFAP_EVENT_RECOVERED : PFAP_EVENT_COMPLETE;
      event_.phoneme = {};
      event_.faps = packet_.recovery;
      events += write();
    }
    for (size_t i = 0; i < packet_.phonemes.size(); ++i) {
      const std::span<const Fap> faps = packet_.faps_of(i);
      event_.kind = PFAP_EVENT_PHONEME;
      event_.phoneme = packet_.phonemes[i].phoneme;
      event_.sentence_start = i == 0;
      event_.uncertain = !r.state_whole;
      event_.faps.assign(faps.begin(), faps.end());
      events += write();
    }
    return events;
  }

 private:
  size_t write() {
    bytes_.resize(pfap::markup_size(event_));
    if (!pfap::write_markup(event_, bytes_)) fail("cannot write an event");
    return 1;
  }

  Packet packet_;
  pfap::MarkupEvent event_;
  pfap::RecoveryReceiver receiver_;
  std::vector<uint8_t> bytes_;
};

// One repetition of a case at library level: `total` bytes or more. Returns ns per byte.
double run_library(LibraryDepay& depay, const Case& c, uint16_t& seqnum, int64_t& time_ns,
                   size_t total) {
  size_t bytes = 0, events = 0;
  const double t0 = pfap::testing::thread_cpu_seconds() * 1e9;
  while (bytes < total) {
    for (const auto& payload : c.payloads) {
      seqnum = static_cast<uint16_t>(seqnum + c.seqnum_step);
      time_ns += c.time_step_ns;
      events += depay.process(payload, seqnum, time_ns);
      bytes += payload.size();
    }
  }
  const double ns = pfap::testing::thread_cpu_seconds() * 1e9 - t0;
  if (events == 0 && std::string(c.name).find("malformed") == std::string::npos) {
    fail(std::string("no event from ") + c.name);
  }
  return ns / static_cast<double>(bytes);
}

GstBuffer* rtp_packet(std::span<const uint8_t> payload, guint16 seqnum, guint32 rtp_time,
                      guint32 ssrc, bool marker, GstClockTime pts) {
  return pfap::testing::rtp_packet(
      payload, {.seqnum = seqnum, .timestamp = rtp_time, .ssrc = ssrc, .marker = marker}, pts);
}

// Everything the harness holds but the output buffers it drops: events both ways.
void drain_events(GstHarness* h) {
  while (GstEvent* e = gst_harness_try_pull_event(h)) gst_event_unref(e);
  while (GstEvent* e = gst_harness_try_pull_upstream_event(h)) gst_event_unref(e);
}

GstHarness* new_depayloader() {
  GstHarness* h = gst_harness_new("rtppfapdepay");
  gst_harness_set_src_caps_str(h, kCaps);
  gst_harness_set_drop_buffers(h, TRUE);
  return h;
}

// One repetition of a case through the element: the RTP buffers are made first, then
// pushed, timed. Returns ns per payload byte.
double run_element(GstHarness* h, const Case& c, uint16_t& seqnum, GstClockTime& pts,
                   size_t total) {
  std::vector<GstBuffer*> buffers;
  size_t bytes = 0;
  while (bytes < total) {
    for (const auto& payload : c.payloads) {
      seqnum = static_cast<uint16_t>(seqnum + c.seqnum_step);
      pts += static_cast<GstClockTime>(c.time_step_ns);
      buffers.push_back(
          rtp_packet(payload, seqnum, static_cast<guint32>(pts / 22676), 0x5eed, true, pts));
      bytes += payload.size();
    }
  }
  const double t0 = pfap::testing::thread_cpu_seconds() * 1e9;
  for (GstBuffer* b : buffers) {
    if (gst_harness_push(h, b) != GST_FLOW_OK) fail(std::string("push failed: ") + c.name);
  }
  const double ns = pfap::testing::thread_cpu_seconds() * 1e9 - t0;
  drain_events(h);
  return ns / static_cast<double>(bytes);
}

// What a depayloader of GStreamer's own costs per packet, for the smallest packets: rtpL16depay
// with 4-byte payloads (two samples), one output buffer per packet.
void reference_per_packet(int packets) {
  GstHarness* h = gst_harness_new("rtpL16depay");
  gst_harness_set_src_caps_str(h,
                               "application/x-rtp,media=audio,clock-rate=44100,encoding-name=L16,"
                               "encoding-params=(string)1,channels=1,payload=96");
  gst_harness_set_drop_buffers(h, TRUE);
  const uint8_t samples[4] = {1, 2, 3, 4};
  std::vector<double> runs;
  for (int r = 0; r < 5; ++r) {
    std::vector<GstBuffer*> buffers;
    for (int i = 0; i < packets / 5; ++i) {
      const auto n = static_cast<guint>(r * packets / 5 + i);
      buffers.push_back(rtp_packet(samples, static_cast<guint16>(n), n * 2, 0x5eed, false,
                                   n * 2 * GST_SECOND / 44100));
    }
    const double t0 = pfap::testing::thread_cpu_seconds() * 1e9;
    for (GstBuffer* b : buffers) {
      if (gst_harness_push(h, b) != GST_FLOW_OK) fail("push failed: rtpL16depay");
    }
    runs.push_back((pfap::testing::thread_cpu_seconds() * 1e9 - t0) / (packets / 5));
    drain_events(h);
  }
  gst_harness_teardown(h);
  std::printf("reference: rtpL16depay, 4-byte payloads: %.2f us per packet\n\n",
              median(runs) / 1000);
}

// Typical speech and the cases whose name holds `only` (all when empty).
void cost(int scale, const std::string& only) {
  std::vector<Case> cases = make_cases();
  const std::string typical_name = cases[0].name;
  std::erase_if(cases, [&](const Case& c) {
    const std::string name = c.name;
    return name != typical_name && name.find(only) == std::string::npos;
  });
  constexpr int kRepetitions = 5;
  const size_t library_bytes = size_t{8} << 20;
  const size_t element_bytes = size_t{1} << 20;
  std::vector<LibraryDepay> library(cases.size());
  std::vector<GstHarness*> harnesses;
  std::vector<uint16_t> seqnums(cases.size(), 0);
  std::vector<int64_t> times(cases.size(), 0);
  std::vector<GstClockTime> ptss(cases.size(), 0);
  for (size_t k = 0; k < cases.size(); ++k) {
    harnesses.push_back(new_depayloader());
    // Warm-up: first allocations, the reused vectors grown.
    run_library(library[k], cases[k], seqnums[k], times[k], 1 << 16);
    run_element(harnesses[k], cases[k], seqnums[k], ptss[k], 1 << 16);
  }
  for (int r = 0; r < kRepetitions; ++r) {
    // Rotate the order so that no case always runs first.
    for (size_t i = 0; i < cases.size(); ++i) {
      const size_t k = (i + static_cast<size_t>(r)) % cases.size();
      Case& c = cases[k];
      c.library_ns.push_back(
          run_library(library[k], c, seqnums[k], times[k], library_bytes * scale));
      c.element_ns.push_back(
          run_element(harnesses[k], c, seqnums[k], ptss[k], element_bytes * scale));
    }
  }

  // A datagram carries 40 bytes more than its payload: the IPv4, UDP and RTP headers.
  constexpr double kHeaderBytes = 40;
  std::printf("Cost per payload byte, median of %d (library %zu MiB, element %zu MiB per run)\n",
              kRepetitions, library_bytes * scale >> 20, element_bytes * scale >> 20);
  std::printf("%-44s %6s %9s %6s %12s %6s %10s %10s\n", "case", "bytes", "library", "x",
              "rtppfapdepay", "x", "per packet", "x per IP byte");
  const double typical_library = median(cases[0].library_ns);
  const double typical_element = median(cases[0].element_ns);
  const auto datagram_ns = [&](const Case& c, double ns_per_byte) {
    const double payload = static_cast<double>(c.payloads[0].size());
    return ns_per_byte * payload / (payload + kHeaderBytes);
  };
  const double typical_datagram = datagram_ns(cases[0], typical_element);
  for (const Case& c : cases) {
    const double l = median(c.library_ns), e = median(c.element_ns);
    const std::string bytes =
        std::to_string(c.payloads[0].size()) + (c.payloads.size() > 1 ? "+" : "");
    std::printf("%-44s %6s %6.2f ns %6.2f %9.1f ns %6.2f %7.2f us %10.2f\n", c.name, bytes.c_str(),
                l, l / typical_library, e, e / typical_element,
                e * static_cast<double>(c.payloads[0].size()) / 1000,
                datagram_ns(c, e) / typical_datagram);
  }
  std::printf(
      "(x: per payload byte, to typical speech; x per IP byte: per byte of the datagram, "
      "payload and %g bytes of IPv4, UDP and RTP headers)\n",
      kHeaderBytes);
  for (GstHarness* h : harnesses) gst_harness_teardown(h);
  reference_per_packet(200000 * scale);
}

// ---------------------------------------------------------------------------------------------
// Memory

// A hostile stream for one depayloader: every kind of packet above and the largest payloads
// RTP can carry (64 KB of FAPs before one phoneme), malformed packets (random bytes, cut
// packets), sequence numbers and timestamps jumping anywhere, SSRC changes, caps changes,
// flushes, and rtpjitterbuffer's packet-lost events with and without a sequence number.
class HostileStream {
 public:
  HostileStream() : random_(66) {
    for (const Case& c : make_cases()) {
      for (const auto& p : c.payloads) payloads_.push_back(p);
    }
    // The largest a UDP datagram allows: 65507 bytes less the RTP header.
    Packet huge;
    std::vector<Fap> faps;
    while (faps.size() * pfap::kFapDescriptorBytes + 1 + 4 + 6 <= 65495) {
      faps.push_back(random_.fap());
    }
    huge.add_phoneme(random_.phoneme(), faps);
    huge_ = std::vector<uint8_t>(pfap::encoded_size(huge));
    if (pfap::encode_payload(huge, huge_) != pfap::EncodeStatus::kOk) fail("huge payload");
  }

  void push_next(GstHarness* h) {
    const int what = random_.uniform(0, 99);
    if (what < 2) {
      const bool other = random_.chance(0.5);
      gst_harness_set_src_caps_str(h, other
                                          ? "application/x-rtp,media=application,clock-rate=48000,"
                                            "encoding-name=PFAP,payload=96,alphabet=x-hostile"
                                          : kCaps);
    } else if (what < 4) {
      gst_harness_push_event(h, gst_event_new_flush_start());
      gst_harness_push_event(h, gst_event_new_flush_stop(TRUE));
      GstSegment segment;
      gst_segment_init(&segment, GST_FORMAT_TIME);
      gst_harness_push_event(h, gst_event_new_segment(&segment));
    } else if (what < 8) {
      GstStructure* s =
          gst_structure_new("GstRTPPacketLost", "timestamp", G_TYPE_UINT64, guint64{pts_},
                            "duration", G_TYPE_UINT64, guint64{20 * GST_MSECOND}, nullptr);
      if (random_.chance(0.5)) {
        gst_structure_set(s, "seqnum", G_TYPE_UINT, guint{static_cast<guint16>(seqnum_ + 1)},
                          nullptr);
      }
      gst_harness_push_event(h, gst_event_new_custom(GST_EVENT_CUSTOM_DOWNSTREAM, s));
    }
    // Sequence numbers: mostly forward by 1..40, sometimes anywhere; timestamps likewise.
    seqnum_ = static_cast<uint16_t>(random_.chance(0.05) ? random_.uniform(0, 65535)
                                                         : seqnum_ + random_.uniform(1, 40));
    pts_ += random_.chance(0.02) ? static_cast<GstClockTime>(random_.uniform(0, 1 << 30)) * 1000
                                 : 20 * GST_MSECOND;
    const guint32 ssrc =
        random_.chance(0.01) ? static_cast<guint32>(random_.uniform(0, 1 << 30)) : ssrc_;
    ssrc_ = ssrc;

    std::vector<uint8_t> payload;
    const int kind = random_.uniform(0, 99);
    if (kind < 1) {
      payload = huge_;
    } else if (kind < 20) {
      payload.resize(static_cast<size_t>(random_.uniform(0, 1400)));
      for (uint8_t& b : payload) b = static_cast<uint8_t>(random_.uniform(0, 255));
    } else if (kind < 30) {
      payload = payloads_[static_cast<size_t>(
          random_.uniform(0, static_cast<int>(payloads_.size()) - 1))];
      payload.resize(static_cast<size_t>(random_.uniform(0, static_cast<int>(payload.size()))));
    } else {
      payload = payloads_[static_cast<size_t>(
          random_.uniform(0, static_cast<int>(payloads_.size()) - 1))];
    }
    const auto rtp_time =
        static_cast<guint32>(random_.chance(0.02) ? random_.uniform(0, INT32_MAX) : pts_ / 22676);
    if (gst_harness_push(h, rtp_packet(payload, seqnum_, rtp_time, ssrc, random_.chance(0.2),
                                       pts_)) != GST_FLOW_OK) {
      fail("push failed");
    }
    drain_events(h);
  }

 private:
  RandomMarkup random_;
  std::vector<std::vector<uint8_t>> payloads_;
  std::vector<uint8_t> huge_;
  uint16_t seqnum_ = 0;
  GstClockTime pts_ = 0;
  guint32 ssrc_ = 0x5eed;
};

void memory(long packets) {
  using pfap::testing::heap_bytes;
  using pfap::testing::rss_bytes;
  const size_t heap_before = heap_bytes();
  GstHarness* h = new_depayloader();
  HostileStream stream;
  const long warm_up = packets / 10;
  for (long i = 0; i < warm_up; ++i) stream.push_next(h);
  const size_t heap_warm = heap_bytes(), rss_warm = rss_bytes();
  std::printf("Memory of one rtppfapdepay fed %ld hostile packets (%ld of warm-up)\n", packets,
              warm_up);
  std::printf("%10s %14s %14s %10s\n", "packets", "heap", "vs warm-up", "RSS");
  std::printf("%10ld %14zu %14s %7zu KiB\n", warm_up, heap_warm, "", rss_warm >> 10);
  size_t largest = heap_warm;
  for (long i = warm_up; i < packets;) {
    const long next = std::min(packets, i + (packets - warm_up) / 9);
    for (; i < next; ++i) stream.push_next(h);
    const size_t heap = heap_bytes();
    largest = std::max(largest, heap);
    std::printf("%10ld %14zu %+14ld %7zu KiB\n", i, heap,
                static_cast<long>(heap) - static_cast<long>(heap_warm), rss_bytes() >> 10);
  }
  std::printf("stats: %s\n", pfap::testing::stats_text(h->element).c_str());
  gst_harness_teardown(h);
  const size_t heap_after = heap_bytes();
  std::printf(
      "heap: %zu before the harness, %zu after warm-up, at most %zu after (+%ld), %zu after "
      "teardown\n",
      heap_before, heap_warm, largest, static_cast<long>(largest) - static_cast<long>(heap_warm),
      heap_after);
}

// ---------------------------------------------------------------------------------------------
// Readers and writers

// The child: runs `description` to EOS; prints the bytes its fakesink "out" got.
int run_peak(const char* description) {
  GError* error = nullptr;
  GstElement* pipeline = gst_parse_launch(description, &error);
  if (pipeline == nullptr) fail(std::string("cannot make the pipeline: ") + error->message);
  guint64 bytes = 0;
  GstElement* out = gst_bin_get_by_name(GST_BIN(pipeline), "out");
  if (out == nullptr) fail("no element named out");
  g_object_set(out, "signal-handoffs", TRUE, nullptr);
  g_signal_connect(out, "handoff",
                   G_CALLBACK(+[](GstElement*, GstBuffer* buffer, GstPad*, gpointer total) {
                     *static_cast<guint64*>(total) += gst_buffer_get_size(buffer);
                   }),
                   &bytes);
  gst_object_unref(out);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  GstBus* bus = gst_element_get_bus(pipeline);
  GstMessage* m = gst_bus_timed_pop_filtered(
      bus, GST_CLOCK_TIME_NONE, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
  const bool eos = GST_MESSAGE_TYPE(m) == GST_MESSAGE_EOS;
  gst_message_unref(m);
  gst_object_unref(bus);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
  std::printf("%" G_GUINT64_FORMAT " %d\n", bytes, eos ? 1 : 0);
  return 0;
}

struct Peak {
  long rss_kib = 0;
  unsigned long long bytes = 0;
  bool eos = false;
  double seconds = 0;
};

// Runs `description` in a child process (this program with --peak).
Peak peak_of(const std::string& description) {
  int fds[2];
  if (pipe(fds) != 0) fail("pipe");
  const double start = pfap::testing::wall_seconds();
  const pid_t pid = fork();
  if (pid < 0) fail("fork");
  if (pid == 0) {
    dup2(fds[1], STDOUT_FILENO);
    close(fds[0]);
    close(fds[1]);
    execl("/proc/self/exe", "bench_hostile", "--peak", description.c_str(), nullptr);
    _exit(127);
  }
  close(fds[1]);
  std::string text;
  char buffer[256];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, n);
  close(fds[0]);
  int status = 0;
  struct rusage usage {};
  if (wait4(pid, &status, 0, &usage) != pid) fail("wait4");
  Peak peak;
  peak.seconds = pfap::testing::wall_seconds() - start;
  peak.rss_kib = usage.ru_maxrss;
  int eos = 0;
  if (std::sscanf(text.c_str(), "%llu %d", &peak.bytes, &eos) != 2) fail("child: " + text);
  peak.eos = eos == 1;
  return peak;
}

void write_text(const std::string& path, const std::function<void(std::string&)>& fill) {
  std::string text;
  fill(text);
  if (!g_file_set_contents(path.c_str(), text.data(), static_cast<gssize>(text.size()), nullptr)) {
    fail("cannot write " + path);
  }
}

size_t file_size(const std::string& path) {
  GStatBuf st;
  return g_stat(path.c_str(), &st) == 0 ? static_cast<size_t>(st.st_size) : 0;
}

void readers_and_writers() {
  gchar* dir_name = g_dir_make_tmp("bench_hostile-XXXXXX", nullptr);
  if (dir_name == nullptr) fail("no temporary directory");
  const std::string dir = dir_name;
  g_free(dir_name);
  const std::string fap = dir + "/limit.fap", speech = dir + "/speech.pfap",
                    late = dir + "/late.pfap", far = dir + "/far.pfap";
  // The frame limit, every FAP 3..68 changing in every frame by the most digits a value has.
  write_text(fap, [](std::string& out) {
    out = "2.1 hostile 25 " + std::to_string(pfap::kMaxFapFileFrames) + "\n";
    std::string mask = "0 0";
    for (int fap = 3; fap <= pfap::kFapFileFaps; ++fap) mask += " 1";
    for (uint32_t k = 0; k < pfap::kMaxFapFileFrames; ++k) {
      out += mask;
      out += '\n';
      out += std::to_string(k);
      for (int fap = 3; fap <= pfap::kFapFileFaps; ++fap) {
        out += k % 2 == 0 ? " -2500000" : " 2500000";
      }
      out += '\n';
    }
  });
  write_text(speech, [](std::string& out) { out = "0 1 100 100 -\n100 2 100 100 E\n"; });
  // Every FAP at 0, then one event 4 hours later: pfapfapenc's frame limit at 25 frames/s,
  // each frame with every FAP.
  write_text(late, [](std::string& out) {
    out = "0 state complete";
    for (int fap = pfap::kMinFapIndex; fap <= pfap::kFapFileFaps; ++fap) {
      out += " <FAP " + std::to_string(fap) + " 1000 0 1>";
    }
    out += "\n14400000 0 100 0 E\n";
  });
  // The tester's: 2,000 phonemes, each 11.6 days (10^9 ms) after the last.
  write_text(far, [](std::string& out) {
    for (int i = 0; i < 2000; ++i) {
      out += std::to_string(int64_t{i} * 1'000'000'000) + " 1 100 100 -\n";
    }
  });
  const struct {
    const char* what;
    std::string input;
    std::string pipeline;
  } cases[] = {
      {"nothing read (the process's own)", "", "fakesrc num-buffers=1 ! fakesink name=out"},
      {"pfapfapparse, a FAP file at the frame limit", fap,
       "filesrc location=" + fap + " ! pfapfapparse ! fakesink name=out"},
      {"pfapfapparse with the speech pad, the same file", fap,
       "filesrc location=" + fap + " ! pfapfapparse name=p ! fakesink name=out filesrc location=" +
           speech + " ! pfaptextparse ! p.speech"},
      {"pfapfapenc at its frame limit (66 FAPs, an event 4 h late)", late,
       "filesrc location=" + late + " ! pfaptextparse ! pfapfapenc ! fakesink name=out"},
      {"pfapmarksenc arkit-json 240 frames/s, 2,000 phonemes 11.6 days apart", far,
       "filesrc location=" + far +
           " ! pfaptextparse alphabet=x-pfap-arpabet ! pfapmarksenc format=arkit-json "
           "frame-rate=240 "
           "! fakesink name=out"},
  };
  std::printf("\nReaders and writers: peak RSS of a process running one pipeline to EOS\n");
  std::printf("%-70s %12s %10s %14s %8s\n", "case", "input bytes", "peak RSS", "output bytes",
              "seconds");
  for (const auto& c : cases) {
    const Peak peak = peak_of(c.pipeline);
    std::printf("%-70s %12zu %6ld MiB %14llu %8.1f%s\n", c.what,
                c.input.empty() ? 0 : file_size(c.input), peak.rss_kib >> 10, peak.bytes,
                peak.seconds, peak.eos ? "" : " (no EOS: an error)");
  }
  for (const std::string& path : {fap, speech, late, far}) g_remove(path.c_str());
  g_rmdir(dir.c_str());
}

}  // namespace

int main(int argc, char** argv) {
#ifdef PFAP_PLUGIN_DIR
  // Run by hand from the build tree: find the plugin there unless told otherwise.
  g_setenv("GST_PLUGIN_PATH", PFAP_PLUGIN_DIR, FALSE);
#endif
  // GLib 2.74's GSlice keeps freed blocks in caches of its own, which malloc counts as in use:
  // send them back to malloc. GLib reads G_SLICE before main, so run again with it set.
  if (g_strcmp0(g_getenv("G_SLICE"), "always-malloc") != 0) {
    g_setenv("G_SLICE", "always-malloc", TRUE);
    execv("/proc/self/exe", argv);
    fail("cannot run again with G_SLICE=always-malloc");
  }
  gst_init(&argc, &argv);
  if (argc == 3 && std::string(argv[1]) == "--peak") return run_peak(argv[2]);
  if (argc == 2 && std::string(argv[1]) == "readers") {
    readers_and_writers();
    return 0;
  }
  const int scale = argc > 1 ? std::atoi(argv[1]) : 1;
  const long packets = argc > 2 ? std::atol(argv[2]) : 200000;
  if (scale <= 0 || (packets != 0 && packets < 10)) {
    fail("usage: bench_hostile [scale [memory-packets [case]]]");
  }
  GstElementFactory* f = gst_element_factory_find("rtppfapdepay");
  if (f == nullptr) fail("no element rtppfapdepay (GST_PLUGIN_PATH?)");
  gst_object_unref(f);
  cost(scale, argc > 3 ? argv[3] : "");
  if (packets > 0) memory(packets);
  if (argc <= 4 || std::atoi(argv[4]) != 0) readers_and_writers();
  return 0;
}

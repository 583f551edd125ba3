// SPDX-License-Identifier: LGPL-2.1-or-later
// A receiver a hostile sender cannot silence (docs/security.md, "Floods"): a good PFAP stream
// over UDP on 127.0.0.1 (one packet per 40 ms phoneme), and in the middle of it, within one
// second, a flood of 20,000 copies of its packets with random sequence numbers and random or
// their own timestamps (its SSRC spoofed, or random), into the receivers docs/elements.md
// shows. Each must reach EOS after the flood, its heap grow by less than 32 MiB, and decode
// every good packet from one second after the flood on; those protected against the flood
// (SRTP, rtpbin against other SSRCs) every good packet after it. About 3.5 s per case.
#include <arpa/inet.h>
#include <gst/gst.h>
#include <gst/rtp/gstrtpbuffer.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <mutex>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "heap.h"
#include "pfap/markup_event.h"
#include "pfap_buffers.h"
#include "pipeline.h"

namespace {

using Packet = std::vector<uint8_t>;
using pfap::testing::Pipeline;

constexpr GstClockTime kPhoneme = 40 * GST_MSECOND;

// The bytes of every buffer the appsink "out" of `p` holds.
std::vector<Packet> pulled_packets(Pipeline& p) {
  std::vector<Packet> out;
  for (GstSample* s : pfap::testing::pull_all(p.by_name("out"))) {
    GstMapInfo map;
    gst_buffer_map(gst_sample_get_buffer(s), &map, GST_MAP_READ);
    out.emplace_back(map.data, map.data + map.size);
    gst_buffer_unmap(gst_sample_get_buffer(s), &map);
    gst_sample_unref(s);
  }
  return out;
}

// `n` phonemes of 40 ms, one RTP packet each (max-delay=0), as rtppfappay makes them.
std::vector<Packet> good_packets(int n) {
  Pipeline p(
      "appsrc name=src format=time caps=application/x-pfap ! rtppfappay max-delay=0 pt=97 "
      "ssrc=1234 ! appsink name=out sync=false emit-signals=false wait-on-eos=false");
  EXPECT_TRUE(p.ok()) << p.error();
  EXPECT_EQ(p.set_state(GST_STATE_PLAYING), "");
  for (int i = 0; i < n; ++i) {
    pfap::MarkupEvent event;
    event.phoneme.symbol = static_cast<uint8_t>(1 + i % 39);
    event.phoneme.duration_ms = 40;
    if (i % 5 == 0) event.faps.push_back({3, 10 * (i % 7), 40, pfap::Curve::kLinear});
    EXPECT_EQ(pfap::testing::push(p.by_name("src"), pfap::testing::markup_buffer(event, i * kPhoneme)),
              GST_FLOW_OK);
  }
  pfap::testing::end_of_stream(p.by_name("src"));
  EXPECT_EQ(p.wait_eos(std::chrono::seconds(10)), "");
  return pulled_packets(p);
}

// The documented SRTP key (docs/security.md): 30 bytes, AES-128-ICM and HMAC-SHA1-80.
constexpr const char* kSrtpKey = "4142434445464748494A4B4C4D4E4F505152535455565758595A31323334";

// The packets as srtpenc sends them with that key.
std::vector<Packet> srtp_protect(const std::vector<Packet>& packets) {
  Pipeline p(std::string("appsrc name=src format=time caps=\"application/x-rtp,media=application,"
                         "clock-rate=44100,encoding-name=PFAP,payload=97\" ! srtpenc key=") +
             kSrtpKey + " ! appsink name=out sync=false emit-signals=false wait-on-eos=false");
  EXPECT_TRUE(p.ok()) << p.error();
  EXPECT_EQ(p.set_state(GST_STATE_PLAYING), "");
  for (const Packet& packet : packets) {
    EXPECT_EQ(pfap::testing::push(p.by_name("src"), gst_buffer_new_memdup(packet.data(), packet.size())),
              GST_FLOW_OK);
  }
  pfap::testing::end_of_stream(p.by_name("src"));
  EXPECT_EQ(p.wait_eos(std::chrono::seconds(10)), "");
  std::vector<Packet> out = pulled_packets(p);
  EXPECT_EQ(out.size(), packets.size());
  return out;
}

struct Received {
  std::mutex mutex;
  std::set<Packet> packets;
  static GstPadProbeReturn on_buffer(GstPad*, GstPadProbeInfo* info, gpointer data) {
    auto* r = static_cast<Received*>(data);
    GstMapInfo map;
    GstBuffer* b = GST_PAD_PROBE_INFO_BUFFER(info);
    gst_buffer_map(b, &map, GST_MAP_READ);
    Packet p(map.data, map.data + map.size);
    gst_buffer_unmap(b, &map);
    std::lock_guard lock(r->mutex);
    r->packets.insert(std::move(p));
    return GST_PAD_PROBE_OK;
  }
  // The indices in `wanted` of the packets not received.
  std::string missing(const std::vector<Packet>& wanted) {
    std::lock_guard lock(mutex);
    std::string out;
    for (size_t i = 0; i < wanted.size(); ++i) {
      if (packets.count(wanted[i]) == 0) out += " " + std::to_string(i);
    }
    return out;
  }
  size_t count_of(const std::vector<Packet>& wanted) {
    std::lock_guard lock(mutex);
    size_t n = 0;
    for (const Packet& p : wanted) n += packets.count(p);
    return n;
  }
};

struct FloodOptions {
  int flood = 20000;        // mutated packets
  bool same_ssrc = true;    // the flood spoofs the good stream's SSRC
  bool same_pt = true;
  int flood_packets = 25;   // good packets sent during the flood, 40 ms apart
  bool sequential = false;  // the flood's sequence numbers count up from a random one
  // Random timestamps; without, the copied packet's own (the stream's range), which drive
  // rtpjitterbuffer's packet-rate estimate up (docs/security.md, "Floods").
  bool random_timestamps = true;
  bool srtp = false;  // the good stream is SRTP, the flood mutated copies of its packets
};

struct FloodResult {
  size_t after_sent = 0;      // good packets sent after the flood
  size_t after_received = 0;  // of those, received by the depayloader
  size_t tail_sent = 0;       // those sent 1 s or more after the flood
  size_t tail_received = 0;
  size_t before_received = 0;
  size_t during_sent = 0;     // good packets sent during the flood
  size_t during_received = 0;
  long heap_growth = 0;       // bytes, from before the flood to the end
  std::string eos;            // why the receiver did not reach EOS after it ("": it did)
  std::string missing;        // which of those sent after the flood did not arrive (0: the first)
  unsigned long kernel_drops = 0;  // datagrams the kernel dropped, the socket's queue full
  std::string jitterbuffers;  // each rtpjitterbuffer's stats when the wait ended: what it dropped
};

// The stats of every rtpjitterbuffer in the pipeline (rtpbin holds one per source), so that a
// failure says whether the good packets were dropped as late, lost, or still held.
std::string jitterbuffer_stats(GstElement* pipeline) {
  std::string stats;
  GstIterator* it = gst_bin_iterate_recurse(GST_BIN(pipeline));
  GValue item = G_VALUE_INIT;
  while (gst_iterator_next(it, &item) == GST_ITERATOR_OK) {
    GstElement* e = GST_ELEMENT(g_value_get_object(&item));
    GstElementFactory* factory = gst_element_get_factory(e);
    if (factory != nullptr &&
        g_strcmp0(gst_plugin_feature_get_name(GST_PLUGIN_FEATURE(factory)), "rtpjitterbuffer") == 0) {
      GstStructure* s = nullptr;
      g_object_get(e, "stats", &s, nullptr);
      gchar* text = gst_structure_to_string(s);
      stats += std::string(" ") + text;
      g_free(text);
      gst_structure_free(s);
    }
    g_value_reset(&item);
  }
  g_value_unset(&item);
  gst_iterator_free(it);
  return stats;
}

// The receiving socket's queue (bytes) and the datagrams the kernel dropped at it, from
// /proc/net/udp: what the kernel drops never reaches udpsrc, whatever the receiver does.
struct SocketQueue {
  unsigned long queued = 0;
  unsigned long drops = 0;
};
SocketQueue socket_queue(guint port) {
  std::ifstream in("/proc/net/udp");
  std::string line;
  std::getline(in, line);  // the heading
  char local_port[8];
  snprintf(local_port, sizeof local_port, ":%04X", port);
  SocketQueue q;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string slot, local, remote, state, queues, timer, retransmits, uid, timeout, inode, refs,
        pointer;
    fields >> slot >> local >> remote >> state >> queues >> timer >> retransmits >> uid >> timeout >>
        inode >> refs >> pointer >> q.drops;
    if (local.size() < 5 || local.compare(local.size() - 5, 5, local_port) != 0) continue;
    q.queued = std::stoul(queues.substr(queues.find(':') + 1), nullptr, 16);
    return q;
  }
  return q;
}

class Sender {
 public:
  explicit Sender(guint port) : fd_(socket(AF_INET, SOCK_DGRAM, 0)) {
    to_.sin_family = AF_INET;
    to_.sin_port = htons(static_cast<uint16_t>(port));
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~Sender() { close(fd_); }
  void send(const Packet& p) {
    sendto(fd_, p.data(), p.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_);
  }

 private:
  int fd_;
  sockaddr_in to_{};
};

FloodResult flood_through(const std::string& receiver, const FloodOptions& options) {
  FloodResult result;
  const std::vector<Packet> good = good_packets(60 + options.flood_packets);
  const std::vector<Packet> wire = options.srtp ? srtp_protect(good) : good;
  if (wire.size() != good.size()) return result;
  Pipeline p(receiver);
  EXPECT_TRUE(p.ok()) << p.error();
  if (!p.ok()) return result;
  Received received;
  GstPad* pad = gst_element_get_static_pad(p.by_name("depay"), "sink");
  gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, Received::on_buffer, &received, nullptr);
  gst_object_unref(pad);
  EXPECT_EQ(p.set_state(GST_STATE_PLAYING), "");
  const guint port = pfap::testing::bound_port(p.by_name("udp"));
  Sender sender(port);

  auto start = std::chrono::steady_clock::now();
  auto send_at = [&](size_t i) {
    std::this_thread::sleep_until(start + std::chrono::milliseconds(40 * i));
    sender.send(wire[i]);
  };
  // 1 s of the good stream, then the flood over the next second with the good stream going
  // on through it, then the rest.
  const size_t flood_from = 10, flood_to = flood_from + options.flood_packets;
  for (size_t i = 0; i < flood_from; ++i) send_at(i);
  const size_t heap_before = pfap::testing::heap_bytes();
  const unsigned long drops_before = socket_queue(port).drops;
  std::mt19937 random(22);
  uint16_t flood_seq = static_cast<uint16_t>(random());
  const int per_good = options.flood / static_cast<int>(flood_to - flood_from);
  for (size_t i = flood_from; i < flood_to; ++i) {
    for (int k = 0; k < per_good; ++k) {
      // A copy of a packet already sent: a copy of one not sent yet could be that very
      // packet (1 in 65,536 keeps its sequence number), which no receiver can tell apart.
      Packet m = wire[random() % i];
      if (options.sequential) {
        m[2] = static_cast<uint8_t>(flood_seq >> 8);
        m[3] = static_cast<uint8_t>(flood_seq++);
      } else {
        m[2] = static_cast<uint8_t>(random());
        m[3] = static_cast<uint8_t>(random());
      }
      if (options.random_timestamps) {
        for (int b = 4; b < 8; ++b) m[b] = static_cast<uint8_t>(random());
      }
      if (!options.same_ssrc) {
        for (int b = 8; b < 12; ++b) m[b] = static_cast<uint8_t>(random());
      }
      if (!options.same_pt) m[1] = static_cast<uint8_t>((m[1] & 0x80) | (random() % 128));
      sender.send(m);
    }
    send_at(i);
  }
  // The flood is over for the receiver once udpsrc has read it: until then a good packet
  // may find the socket's queue full (at 20,000 packets a second, the sanitizer build reads
  // more slowly than that). The good stream waits for that, then goes on 40 ms a packet.
  const auto drained_by = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  const auto waiting_from = std::chrono::steady_clock::now();
  while (socket_queue(port).queued > 0 && std::chrono::steady_clock::now() < drained_by) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  start += std::chrono::steady_clock::now() - waiting_from;
  for (size_t i = flood_to; i < good.size(); ++i) send_at(i);
  const std::vector<Packet> before(good.begin(), good.begin() + flood_from);
  const std::vector<Packet> after(good.begin() + flood_to, good.end());
  result.after_sent = after.size();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (received.count_of(after) < after.size() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  result.after_received = received.count_of(after);
  result.jitterbuffers = jitterbuffer_stats(p.get());
  result.missing = received.missing(after);
  result.kernel_drops = socket_queue(port).drops - drops_before;
  const std::vector<Packet> tail(after.begin() + 25, after.end());
  result.tail_sent = tail.size();
  result.tail_received = received.count_of(tail);
  result.before_received = received.count_of(before);
  const std::vector<Packet> during(good.begin() + flood_from, good.begin() + flood_to);
  result.during_sent = during.size();
  result.during_received = received.count_of(during);
  result.heap_growth = static_cast<long>(pfap::testing::heap_bytes()) - static_cast<long>(heap_before);
  result.eos = p.end(std::chrono::seconds(5));
  return result;
}

constexpr const char* kPfapCaps =
    "caps=\"application/x-rtp,media=application,clock-rate=44100,encoding-name=PFAP,payload=97\"";

// The receivers of docs/elements.md, with a free port and a fakesink at the end.
std::string plain_receiver() {
  return std::string("udpsrc address=127.0.0.1 port=0 name=udp ") + kPfapCaps +
         " ! rtpjitterbuffer max-dropout-time=0 max-misorder-time=0 ! rtppfapdepay name=depay "
         "! fakesink sync=false";
}
std::string rtpbin_receiver() {
  return std::string(
             "rtpbin name=rtpbin max-dropout-time=0 max-misorder-time=0 udpsrc address=127.0.0.1 "
             "port=0 name=udp ") +
         kPfapCaps + " ! rtpbin.recv_rtp_sink_1 rtpbin. ! rtppfapdepay name=depay ! fakesink sync=false";
}
// docs/security.md's SRTP receiver: the plain one behind srtpdec, with the test's key.
std::string srtp_receiver() {
  return std::string(
             "udpsrc address=127.0.0.1 port=0 name=udp caps=\"application/x-srtp,media=application,"
             "clock-rate=44100,encoding-name=PFAP,payload=97,ssrc=(uint)1234,srtp-key=(buffer)") +
         kSrtpKey +
         ",srtp-cipher=aes-128-icm,srtp-auth=hmac-sha1-80,srtcp-cipher=aes-128-icm,"
         "srtcp-auth=hmac-sha1-80\" ! srtpdec ! rtpjitterbuffer max-dropout-time=0 "
         "max-misorder-time=0 ! rtppfapdepay name=depay ! fakesink sync=false";
}

void report(const FloodResult& f) {
  if (g_getenv("PFAP_TEST_VERBOSE") != nullptr) {
    std::cerr << f.during_received << "/" << f.during_sent << " during the flood, "
              << f.after_received << "/" << f.after_sent << " after the flood, "
              << f.tail_received << "/" << f.tail_sent << " from 1 s on, heap "
              << f.heap_growth / 1024 << " KiB, EOS: " << (f.eos.empty() ? "yes" : f.eos)
              << ", kernel drops " << f.kernel_drops << ", missing:" << f.missing
              << ", jitterbuffers:" << f.jitterbuffers << "\n";
  }
}

// Not silenced: from one second after the flood on, every good packet arrives, and EOS goes
// through. The first ones after it may be lost or replaced: with the good stream's SSRC, a
// flood packet can take a good one's sequence number (docs/security.md, "Floods").
void expect_survives(const std::string& receiver, const FloodOptions& options) {
  SCOPED_TRACE(receiver);
  const FloodResult f = flood_through(receiver, options);
  report(f);
  EXPECT_EQ(f.tail_received, f.tail_sent)
      << "good packets sent 1 s or more after the flood; " << f.after_received << " of "
      << f.after_sent << " after it; missing:" << f.missing << "; the kernel dropped "
      << f.kernel_drops << "; jitterbuffers:" << f.jitterbuffers;
  EXPECT_EQ(f.eos, "");
  EXPECT_LT(f.heap_growth, 32l << 20) << "bytes of heap after the flood";
}

// Protected: every good packet sent after the flood arrives.
void expect_loses_nothing_after(const std::string& receiver, const FloodOptions& options) {
  SCOPED_TRACE(receiver);
  const FloodResult f = flood_through(receiver, options);
  report(f);
  EXPECT_EQ(f.after_received, f.after_sent)
      << "good packets sent after the flood; missing:" << f.missing << "; the kernel dropped "
      << f.kernel_drops << "; jitterbuffers:" << f.jitterbuffers;
  EXPECT_EQ(f.eos, "");
  EXPECT_LT(f.heap_growth, 32l << 20) << "bytes of heap after the flood";
}

FloodOptions plausible_timestamps() {
  FloodOptions o;
  o.random_timestamps = false;
  return o;
}

TEST(Flood, PlainReceiverKeepsDecoding) { expect_survives(plain_receiver(), {}); }
TEST(Flood, PlainReceiverKeepsDecodingThroughPlausibleTimestamps) {
  expect_survives(plain_receiver(), plausible_timestamps());
}
TEST(Flood, RtpbinReceiverKeepsDecoding) { expect_survives(rtpbin_receiver(), {}); }
TEST(Flood, RtpbinReceiverKeepsDecodingThroughPlausibleTimestamps) {
  expect_survives(rtpbin_receiver(), plausible_timestamps());
}
TEST(Flood, RtpbinReceiverLosesNothingThroughManySsrcs) {
  FloodOptions o;
  o.same_ssrc = false;
  expect_loses_nothing_after(rtpbin_receiver(), o);
}
TEST(Flood, SrtpReceiverLosesNothing) {
  FloodOptions o;
  o.srtp = true;
  expect_loses_nothing_after(srtp_receiver(), o);
}
TEST(Flood, SrtpReceiverLosesNothingThroughPlausibleTimestamps) {
  FloodOptions o = plausible_timestamps();
  o.srtp = true;
  expect_loses_nothing_after(srtp_receiver(), o);
}

// GStreamer's generic state-change test (core's tests/check/generic/states.c) over our six
// elements, alone and unlinked: up to PLAYING and down, then random changes; every change
// succeeds, and each element is freed (the sanitizer build's LeakSanitizer checks that).
TEST(StateChanges, EveryElementGoesThroughEveryStateAndBack) {
  const GstState up[] = {GST_STATE_READY, GST_STATE_PAUSED, GST_STATE_PLAYING};
  const GstState down[] = {GST_STATE_PAUSED, GST_STATE_READY, GST_STATE_NULL};
  std::mt19937 random(22);
  for (const char* name :
       {"rtppfappay", "rtppfapdepay", "pfaptextparse", "pfaptextenc", "pfaptts", "pfapface"}) {
    SCOPED_TRACE(name);
    GstElement* element = gst_element_factory_make(name, nullptr);
    ASSERT_NE(element, nullptr);
    GstBus* bus = gst_bus_new();
    gst_element_set_bus(element, bus);
    for (GstState state : up) {
      EXPECT_NE(gst_element_set_state(element, state), GST_STATE_CHANGE_FAILURE)
          << gst_element_state_get_name(state);
    }
    for (GstState state : down) {
      EXPECT_NE(gst_element_set_state(element, state), GST_STATE_CHANGE_FAILURE)
          << gst_element_state_get_name(state);
    }
    for (int i = 0; i < 30; ++i) {
      const auto state = static_cast<GstState>(GST_STATE_NULL + random() % 4);
      EXPECT_NE(gst_element_set_state(element, state), GST_STATE_CHANGE_FAILURE)
          << gst_element_state_get_name(state);
    }
    EXPECT_EQ(gst_element_set_state(element, GST_STATE_NULL), GST_STATE_CHANGE_SUCCESS);
    EXPECT_EQ(pfap::testing::pop_messages(bus, GST_MESSAGE_ERROR), std::vector<std::string>{});
    gst_bus_set_flushing(bus, TRUE);
    gst_object_unref(bus);
    gst_object_unref(element);
  }
}

}  // namespace

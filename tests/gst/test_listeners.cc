// SPDX-License-Identifier: LGPL-2.1-or-later
// Many listeners (docs/recovery.md, "Many listeners: multicast"): one PFAP stream sent once to
// a multicast group, 100 receivers joining it at random times. Each must be whole (no event
// flagged uncertain) from its first complete state on, which comes within one
// complete-recovery-interval of joining; the sender's work is the same whatever the number of
// receivers (it sends each packet once and is asked for nothing).
//
// It runs in a network namespace of its own with only `lo` (unshare -n, multicast on lo, a
// route for 224.0.0.0/4), so it needs root: the outer test re-runs this program there, and
// skips, saying why, where it cannot. About 6 s.
#include <gst/gst.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <iostream>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "pfap/markup.h"
#include "pfap/markup_event.h"
#include "pfap_buffers.h"
#include "pipeline.h"

namespace {

using pfap::testing::Pipeline;
using Clock = std::chrono::steady_clock;

constexpr int kListeners = 100;
constexpr int kIntervalMs = 1000;     // the payloader's complete-recovery-interval
constexpr int kSessionMs = 6000;      // the stream, sent in real time
constexpr int kLastJoinMs = 4000;     // receivers join in [300, 4000] ms
constexpr int kJitterbufferMs = 200;  // rtpjitterbuffer's default latency
constexpr const char* kGroup = "239.255.42.42";
constexpr int kPort = 5004;

// What one receiver saw: when it joined, and when its first event and its first certain event
// (not PFAP_FLAG_UNCERTAIN) came out of its depayloader; uncertain events after that one.
struct Listener {
  std::unique_ptr<Pipeline> pipeline;
  std::mutex mutex;
  Clock::time_point joined{};
  Clock::time_point first_event{};
  Clock::time_point first_certain{};
  int events = 0;
  int uncertain_after_certain = 0;

  static GstPadProbeReturn on_event(GstPad*, GstPadProbeInfo* info, gpointer data) {
    auto* l = static_cast<Listener*>(data);
    const pfap::testing::Event e = pfap::testing::read_event(GST_PAD_PROBE_INFO_BUFFER(info));
    const bool uncertain = (e.flags & PFAP_FLAG_UNCERTAIN) != 0;
    std::lock_guard lock(l->mutex);
    const auto now = Clock::now();
    if (l->events++ == 0) l->first_event = now;
    if (!uncertain && l->first_certain == Clock::time_point{}) l->first_certain = now;
    if (uncertain && l->first_certain != Clock::time_point{}) ++l->uncertain_after_certain;
    return GST_PAD_PROBE_OK;
  }
};

std::string self_path() {
  gchar* path = g_file_read_link("/proc/self/exe", nullptr);
  std::string out = path != nullptr ? path : "";
  g_free(path);
  return out;
}

TEST(ManyListeners, HundredJoinAtRandomTimesOverMulticast) {
  if (g_getenv("PFAP_IN_NETNS") != nullptr) GTEST_SKIP() << "the run inside the namespace";
  if (geteuid() != 0) {
    GTEST_SKIP() << "needs root: unshare -n makes the network namespace with only lo that this "
                    "test sends multicast in (CI runs as root)";
  }
  for (const char* tool : {"unshare", "ip", "timeout"}) {
    gchar* found = g_find_program_in_path(tool);
    if (found == nullptr) GTEST_SKIP() << "no " << tool << " (util-linux, iproute2, coreutils)";
    g_free(found);
  }
  const std::string self = self_path();
  ASSERT_FALSE(self.empty());
  const gchar* argv[] = {"timeout", "60", "unshare", "-n", "sh", "-c",
                         "ip link set lo up multicast on && ip route add 224.0.0.0/4 dev lo && "
                         "exec env LD_PRELOAD=\"$PFAP_PRELOAD\" \"$0\" "
                         "--gtest_filter=ManyListenersInNamespace.*",
                         self.c_str(), nullptr};
  gchar** envp = g_environ_setenv(g_get_environ(), "PFAP_IN_NETNS", "1", TRUE);
  // The sanitizer build preloads its runtimes into every process (tests/meson.build): only
  // this program gets them back, not timeout, unshare, sh and ip, which LeakSanitizer would
  // fail.
  const gchar* preload = g_environ_getenv(envp, "LD_PRELOAD");
  envp = g_environ_setenv(envp, "PFAP_PRELOAD", preload != nullptr ? preload : "", TRUE);
  envp = g_environ_unsetenv(envp, "LD_PRELOAD");
  gchar* out = nullptr;
  gchar* err = nullptr;
  gint status = 0;
  GError* error = nullptr;
  ASSERT_TRUE(g_spawn_sync(nullptr, const_cast<gchar**>(argv), envp, G_SPAWN_SEARCH_PATH, nullptr,
                           nullptr, &out, &err, &status, &error))
      << (error != nullptr ? error->message : "");
  g_strfreev(envp);
  const std::string output = std::string(out) + err;
  g_free(out);
  g_free(err);
  EXPECT_TRUE(g_spawn_check_wait_status(status, nullptr)) << output;
  EXPECT_NE(output.find("[  PASSED  ] 1 test"), std::string::npos) << output;
  if (g_getenv("PFAP_TEST_VERBOSE") != nullptr) std::cerr << output;
}

TEST(ManyListenersInNamespace, EveryListenerIsWholeWithinOneInterval) {
  if (g_getenv("PFAP_IN_NETNS") == nullptr) GTEST_SKIP() << "run by ManyListeners.*";
  // The speaker: a phoneme every 40 ms with a FAP on every fifth, sent once to the group,
  // in real time (udpsink sync=true), with a complete state every second.
  Pipeline server(std::string("appsrc name=src format=time caps=application/x-pfap ! "
                              "rtppfappay name=pay pt=97 max-delay=0 complete-recovery-interval=") +
                  std::to_string(kIntervalMs) + " ! udpsink host=" + kGroup +
                  " port=" + std::to_string(kPort) + " auto-multicast=true sync=true");
  ASSERT_TRUE(server.ok()) << server.error();
  for (int i = 0; i * 40 < kSessionMs; ++i) {
    pfap::MarkupEvent event;
    event.phoneme.symbol = static_cast<uint8_t>(1 + i % 39);
    event.phoneme.duration_ms = 40;
    if (i % 5 == 0) event.faps.push_back({3, 20 * (i % 11), 40, pfap::Curve::kLinear});
    ASSERT_EQ(pfap::testing::push(server.by_name("src"),
                                  pfap::testing::markup_buffer(event, i * 40 * GST_MSECOND)),
              GST_FLOW_OK);
  }
  pfap::testing::end_of_stream(server.by_name("src"));

  std::vector<std::unique_ptr<Listener>> listeners;
  std::mt19937 random(22);
  std::vector<int> join_ms;
  for (int i = 0; i < kListeners; ++i) join_ms.push_back(300 + random() % (kLastJoinMs - 300));
  std::sort(join_ms.begin(), join_ms.end());

  const auto start = Clock::now();
  ASSERT_EQ(server.set_state(GST_STATE_PLAYING), "");
  for (int ms : join_ms) {
    std::this_thread::sleep_until(start + std::chrono::milliseconds(ms));
    auto l = std::make_unique<Listener>();
    // The documented receiver (docs/elements.md), on the group.
    l->pipeline = std::make_unique<Pipeline>(
        std::string("udpsrc address=") + kGroup + " port=" + std::to_string(kPort) +
        " auto-multicast=true caps=\"application/x-rtp,media=application,clock-rate=44100,"
        "encoding-name=PFAP,payload=97\" ! rtpjitterbuffer max-dropout-time=0 max-misorder-time=0 "
        "! rtppfapdepay name=depay ! "
        "fakesink sync=false");
    ASSERT_TRUE(l->pipeline->ok()) << l->pipeline->error();
    GstPad* pad = gst_element_get_static_pad(l->pipeline->by_name("depay"), "src");
    gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, Listener::on_event, l.get(), nullptr);
    gst_object_unref(pad);
    l->joined = Clock::now();
    ASSERT_EQ(l->pipeline->set_state(GST_STATE_PLAYING), "");
    listeners.push_back(std::move(l));
  }
  ASSERT_EQ(server.wait_eos(std::chrono::milliseconds(kSessionMs + 5000)), "");
  std::this_thread::sleep_for(std::chrono::milliseconds(kJitterbufferMs + 100));

  // One interval, plus the jitterbuffer's latency, plus scheduling on a shared 2-core machine.
  const auto bound = std::chrono::milliseconds(kIntervalMs + kJitterbufferMs + 300);
  Clock::duration worst{};
  for (size_t i = 0; i < listeners.size(); ++i) {
    Listener& l = *listeners[i];
    std::lock_guard lock(l.mutex);
    SCOPED_TRACE("listener " + std::to_string(i));
    ASSERT_GT(l.events, 0);
    ASSERT_NE(l.first_certain, Clock::time_point{}) << "never whole";
    EXPECT_LE(l.first_certain - l.joined, bound);
    EXPECT_EQ(l.uncertain_after_certain, 0);
    worst = std::max(worst, l.first_certain - l.joined);
  }
  // The sender's work does not depend on the listeners: each packet sent once, no requests.
  GstStructure* stats = nullptr;
  g_object_get(server.by_name("pay"), "stats", &stats, nullptr);
  guint64 packets = 0, complete = 0, requests = 0;
  gst_structure_get_uint64(stats, "packets", &packets);
  gst_structure_get_uint64(stats, "complete-recoveries", &complete);
  gst_structure_get_uint64(stats, "requests", &requests);
  gst_structure_free(stats);
  EXPECT_EQ(packets, static_cast<guint64>(kSessionMs / 40));
  EXPECT_LE(complete, static_cast<guint64>(kSessionMs / kIntervalMs + 1));
  EXPECT_EQ(requests, 0u);
  std::cerr << kListeners << " listeners: whole at most "
            << std::chrono::duration_cast<std::chrono::milliseconds>(worst).count()
            << " ms after joining; the sender sent " << packets << " data and " << complete
            << " complete packets\n";
  for (auto& l : listeners) l->pipeline->set_state(GST_STATE_NULL);
}

}  // namespace

// SPDX-License-Identifier: LGPL-2.1-or-later
// Many listeners, one server: what each concurrent PFAP stream costs a process that runs N of
// them, in CPU time per second of stream and in memory, for N = 1, 100 and 1000.
//
// A pair is one sender and one receiver, linked in one GstHarness (one thread calls everything,
// no queue between them):
//
//   harness src ! rtppfappay ! rtppfapdepay ! harness sink    pfap: defaults, recovery on
//   harness src ! rtpgstpay  ! rtpgstdepay  ! harness sink    rtpgst: GStreamer's generic
//                                                             payloader, for reference
//   harness src ! identity   ! identity     ! harness sink    identity: the baseline, every
//                                                             cost but the elements'
//
// Every pair speaks: a shared speech script (sentences of 6..14 phonemes of 40..90 ms,
// pauses of 100..300 ms, about 12 phonemes per second; a bookmark before 45 % of the
// phonemes, 1..3 FAPs of the indexes 3..12 and 69..74 with every curve), each pair from its
// own place in it. The receiving application reads each x-pfap buffer that comes out and
// applies it to a pfap::FapState of its own (phonemes' FAPs, recovered and complete states),
// as a renderer would before drawing.
//
// One thread steps all pairs through stream time, faster than real time: in each step of
// 100 ms of stream time it pushes each pair's phonemes that start in it (a new GstBuffer
// each, as a TTS source makes them), then pulls and applies what came out. This is what one
// server process does for N streams in real time, with the network left out: the work per
// stream-second is the same, only sooner. Measured over the whole run (EOS included):
//
//  - CPU time of the process per stream-second (N pairs × the stream's duration), and as a
//    share of one core for the N pairs in real time (CPU time / stream duration);
//  - memory per pair: the growth of RSS (/proc/self/statm) and of the malloc heap in use
//    (mallinfo2) divided by N, after setting up the N pairs (PLAYING, caps negotiated) and
//    after the run. Plugin loading and the first element of each kind are made before the
//    first reading, so that only what each pair adds is counted.
//
// Each (variant, N) runs in a child process of its own, so that no run reuses memory another
// freed. The duration per pair is max(60 s, 60000 s / N): every run handles 60000
// stream-seconds, about 700,000 phonemes.
//
// Run: scripts/bench, meson test -C build --benchmark --verbose scale
//  or: build/tests/bench/bench_scale                    (every variant and N, a table)
//      build/tests/bench/bench_scale VARIANT N [SECONDS] (one run in this process, for
//        valgrind --tool=callgrind; VARIANT is pfap, rtpgst, identity or any two elements,
//        e.g. "rtppfappay max-delay=0 ! rtppfapdepay")
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "clocks.h"
#include "heap.h"
#include "pfap/fap_state.h"
#include "pfap/markup_event.h"
#include "pfap/model.h"
#include "random_markup.h"

namespace {

using pfap::testing::cpu_seconds;
using pfap::testing::wall_seconds;

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "bench_scale: %s\n", what.c_str());
  std::exit(1);
}

struct Variant {
  const char* name;
  const char* description;  // the pair's elements, for gst_harness_new_parse
};

constexpr Variant kVariants[] = {
    {"pfap", "rtppfappay ! rtppfapdepay"},
    {"rtpgst", "rtpgstpay ! rtpgstdepay"},
    {"identity", "identity ! identity"},
};

const Variant* find_variant(const char* name) {
  for (const Variant& v : kVariants) {
    if (std::strcmp(v.name, name) == 0) return &v;
  }
  return nullptr;
}

// ---- The speech every pair speaks ----

struct ScriptEvent {
  int64_t start_ns;
  int64_t duration_ns;
  std::vector<uint8_t> bytes;  // the x-pfap phoneme event
};

struct Script {
  std::vector<ScriptEvent> events;
  int64_t duration_ns = 0;  // one pass, pause after the last sentence included
};

Script speech_script(int64_t duration_ns) {
  pfap::testing::RandomMarkup random(9);
  Script script;
  int64_t t = 0;
  while (t < duration_ns) {
    const int phonemes = random.uniform(6, 14);
    for (int i = 0; i < phonemes; ++i) {
      pfap::MarkupEvent event;
      event.phoneme = random.phoneme();
      event.phoneme.duration_ms = static_cast<uint16_t>(random.uniform(40, 90));
      event.phoneme.end_of_text = i == phonemes - 1;
      event.sentence_start = i == 0;
      if (random.chance(0.45)) {
        for (int k = random.uniform(1, 3); k > 0; --k) {
          pfap::Fap f = random.fap();
          const int slot = random.uniform(0, 15);
          f.index = static_cast<uint8_t>(slot < 10 ? pfap::kMinFapIndex + slot
                                                   : pfap::kFirstExpressionIndex + slot - 10);
          f.transition_ms = static_cast<uint16_t>(random.uniform(50, 500));
          event.faps.push_back(f);
        }
      }
      std::vector<uint8_t> bytes(pfap::markup_size(event));
      if (!pfap::write_markup(event, bytes)) fail("cannot write a phoneme event");
      const int64_t d = int64_t{event.phoneme.duration_ms} * pfap::kNsPerMs;
      script.events.push_back({t, d, std::move(bytes)});
      t += d;
    }
    t += int64_t{random.uniform(100, 300)} * pfap::kNsPerMs;
  }
  script.duration_ns = t;
  return script;
}

// ---- One pair ----

struct Pair {
  GstHarness* harness = nullptr;
  pfap::FapState state;  // the receiving application's
  size_t next = 0;       // the next script event
  int64_t shift_ns = 0;  // stream time = script time + shift
  long phonemes_in = 0;
  long phonemes_out = 0;
};

GstHarness* make_harness(const Variant& variant) {
  GstHarness* h = gst_harness_new_parse(variant.description);
  if (h == nullptr) fail(std::string("cannot make ") + variant.description);
  gst_harness_set_src_caps_str(h, "application/x-pfap");
  return h;
}

// Pair i starts at its own place in the script.
void start_pair(Pair& pair, const Script& script, size_t i) {
  pair.next = (i * 7919) % script.events.size();
  pair.shift_ns = -script.events[pair.next].start_ns;
}

int64_t next_start(const Pair& pair, const Script& script) {
  return script.events[pair.next].start_ns + pair.shift_ns;
}

void push_next(Pair& pair, const Script& script) {
  const ScriptEvent& e = script.events[pair.next];
  GstBuffer* buffer = gst_buffer_new_memdup(e.bytes.data(), e.bytes.size());
  GST_BUFFER_PTS(buffer) = static_cast<GstClockTime>(e.start_ns + pair.shift_ns);
  GST_BUFFER_DURATION(buffer) = static_cast<GstClockTime>(e.duration_ns);
  if (gst_harness_push(pair.harness, buffer) != GST_FLOW_OK) fail("push failed");
  ++pair.phonemes_in;
  if (++pair.next == script.events.size()) {
    pair.next = 0;
    pair.shift_ns += script.duration_ns;
  }
}

// What the receiving application does with each buffer that comes out.
void receive(Pair& pair, pfap::MarkupEvent& event) {
  while (GstBuffer* buffer = gst_harness_try_pull(pair.harness)) {
    GstMapInfo map;
    gst_buffer_map(buffer, &map, GST_MAP_READ);
    const bool ok = pfap::read_markup({map.data, map.size}, event);
    gst_buffer_unmap(buffer, &map);
    if (!ok) fail("a buffer out is not an x-pfap event");
    const auto t = static_cast<int64_t>(GST_BUFFER_PTS(buffer));
    gst_buffer_unref(buffer);
    if (event.kind == PFAP_EVENT_COMPLETE) pair.state.reset();
    for (const pfap::Fap& f : event.faps) pair.state.apply(f, t);
    pair.phonemes_out += event.kind == PFAP_EVENT_PHONEME;
  }
}

// All pairs through `duration_ns` of stream time, in steps of 100 ms, then EOS. What is
// measured: valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*speak*' counts
// only this, hence noinline.
[[gnu::noinline]] void speak(std::vector<Pair>& pairs, const Script& script, int64_t duration_ns) {
  constexpr int64_t kStepNs = 100'000'000;
  pfap::MarkupEvent event;  // the application's, reused
  for (int64_t step_end = kStepNs; step_end <= duration_ns; step_end += kStepNs) {
    for (Pair& pair : pairs) {
      while (next_start(pair, script) < step_end) push_next(pair, script);
      receive(pair, event);
    }
  }
  for (Pair& pair : pairs) {
    if (!gst_harness_push_event(pair.harness, gst_event_new_eos())) fail("EOS refused");
    receive(pair, event);
  }
}

// ---- Measures ----

struct Memory {
  double rss = 0;   // bytes resident
  double heap = 0;  // bytes malloc has handed out and not had back
};

Memory memory() {
  Memory m;
  m.rss = static_cast<double>(pfap::testing::rss_bytes());
  const struct mallinfo2 info = mallinfo2();
  m.heap = static_cast<double>(info.uordblks + info.hblkhd);
  return m;
}

struct Result {
  int n = 0;
  double stream_seconds = 0;  // per pair
  double cpu = 0, wall = 0, setup_cpu = 0;
  long phonemes = 0;  // in, all pairs
  Memory before, setup, after;
};

Result run(const Variant& variant, int n, double seconds) {
  const Script script = speech_script(600 * GST_SECOND);
  // Plugin loading, type registration and the first instances' class data: not per pair.
  gst_harness_teardown(make_harness(variant));

  Result r;
  r.n = n;
  r.stream_seconds = seconds;
  std::vector<Pair> pairs(static_cast<size_t>(n));
  r.before = memory();
  const double setup0 = cpu_seconds();
  for (size_t i = 0; i < pairs.size(); ++i) {
    pairs[i].harness = make_harness(variant);
    start_pair(pairs[i], script, i);
  }
  r.setup_cpu = cpu_seconds() - setup0;
  r.setup = memory();

  const double cpu0 = cpu_seconds();
  const double wall0 = wall_seconds();
  speak(pairs, script, static_cast<int64_t>(seconds * 1e9));
  r.cpu = cpu_seconds() - cpu0;
  r.wall = wall_seconds() - wall0;
  r.after = memory();

  for (const Pair& pair : pairs) {
    if (pair.phonemes_out != pair.phonemes_in) {
      fail(std::string(variant.name) + ": " + std::to_string(pair.phonemes_out) +
           " phonemes out for " + std::to_string(pair.phonemes_in) + " in");
    }
    r.phonemes += pair.phonemes_in;
  }
  for (Pair& pair : pairs) gst_harness_teardown(pair.harness);
  return r;
}

double seconds_for(int n) { return std::max(60.0, 60000.0 / n); }

void print_header() {
  std::printf(
      "variant      N  s/pair  phonemes/s   CPU s   µs/stream-s  %%core(N real time)  "
      "RSS KiB/pair (setup, run)  heap KiB/pair (setup, run)\n");
}

void print_row(const char* name, const Result& r) {
  const double stream_seconds = r.n * r.stream_seconds;
  std::printf("%-9s %4d %7.0f %11.2f %7.3f %13.2f %19.3f %14.1f %9.1f %15.1f %9.1f\n", name, r.n,
              r.stream_seconds, static_cast<double>(r.phonemes) / stream_seconds, r.cpu,
              r.cpu / stream_seconds * 1e6, r.cpu / r.stream_seconds * 100,
              (r.setup.rss - r.before.rss) / r.n / 1024, (r.after.rss - r.before.rss) / r.n / 1024,
              (r.setup.heap - r.before.heap) / r.n / 1024,
              (r.after.heap - r.before.heap) / r.n / 1024);
  std::fflush(stdout);
}

void init_gst(int* argc, char*** argv) {
#ifdef PFAP_PLUGIN_DIR
  // Run by hand from the build tree: find the plugin there unless told otherwise.
  g_setenv("GST_PLUGIN_PATH", PFAP_PLUGIN_DIR, FALSE);
#endif
  gst_init(argc, argv);
}

// One run in a child process, so that it starts from a fresh heap; its Result comes back
// through a pipe.
Result run_in_child(const Variant& variant, int n, int argc, char** argv) {
  int fds[2];
  if (pipe(fds) != 0) fail("pipe");
  const pid_t pid = fork();
  if (pid < 0) fail("fork");
  if (pid == 0) {
    close(fds[0]);
    init_gst(&argc, &argv);
    const Result r = run(variant, n, seconds_for(n));
    if (write(fds[1], &r, sizeof r) != static_cast<ssize_t>(sizeof r)) _exit(2);
    _exit(0);
  }
  close(fds[1]);
  Result r;
  const ssize_t got = read(fds[0], &r, sizeof r);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (got != static_cast<ssize_t>(sizeof r) || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    fail(std::string("the run of ") + variant.name + " with N = " + std::to_string(n) + " failed");
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kUsage = "usage: bench_scale [VARIANT N [SECONDS]]";
  if (argc >= 3) {
    // A variant's name, or any pair of elements, e.g. "rtppfappay max-delay=0 ! rtppfapdepay".
    const Variant* known = find_variant(argv[1]);
    const Variant variant = known != nullptr ? *known : Variant{"custom", argv[1]};
    const int n = std::atoi(argv[2]);
    const double seconds = argc > 3 ? std::atof(argv[3]) : seconds_for(n);
    if (n <= 0 || seconds <= 0) fail(kUsage);
    init_gst(&argc, &argv);
    print_header();
    print_row(variant.name, run(variant, n, seconds));
    return 0;
  }
  if (argc != 1) fail(kUsage);

  print_header();
  std::vector<Result> pfap, identity;
  for (const int n : {1, 100, 1000}) {
    for (const Variant& variant : kVariants) {
      const Result r = run_in_child(variant, n, argc, argv);
      print_row(variant.name, r);
      if (std::strcmp(variant.name, "pfap") == 0) pfap.push_back(r);
      if (std::strcmp(variant.name, "identity") == 0) identity.push_back(r);
    }
  }
  // What the PFAP elements themselves add over the baseline.
  std::printf("\npfap less identity (the elements alone):\n");
  std::printf(
      "    N   µs/stream-s  %%core(N real time)  RSS KiB/pair (setup, run)  heap KiB/pair "
      "(setup, run)\n");
  for (size_t i = 0; i < pfap.size(); ++i) {
    const Result& p = pfap[i];
    const Result& b = identity[i];
    const double per_pair = 1.0 / p.n / 1024;
    std::printf("%5d %13.2f %19.3f %14.1f %9.1f %15.1f %9.1f\n", p.n,
                (p.cpu - b.cpu) / (p.n * p.stream_seconds) * 1e6,
                (p.cpu - b.cpu) / p.stream_seconds * 100,
                ((p.setup.rss - p.before.rss) - (b.setup.rss - b.before.rss)) * per_pair,
                ((p.after.rss - p.before.rss) - (b.after.rss - b.before.rss)) * per_pair,
                ((p.setup.heap - p.before.heap) - (b.setup.heap - b.before.heap)) * per_pair,
                ((p.after.heap - p.before.heap) - (b.after.heap - b.before.heap)) * per_pair);
  }
  return 0;
}

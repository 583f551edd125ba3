// SPDX-License-Identifier: LGPL-2.1-or-later
// Integration tests: rtppfappay and rtppfapdepay in real pipelines.
//
//  - LoopbackUdp.PhonemesKeepLipSyncWithAudio: audio (L16) and PFAP sent through one rtpbin
//    over UDP on 127.0.0.1 and received by another rtpbin; with rtpbin's RTCP sync each
//    phoneme comes out within 1 ms of the audio that was sent with it.
//  - RoundTrip.KeepsEveryField: seeded random sessions through pay ! depay, several MTUs.
//  - Sdp.*: the payloader's caps as SDP (a=rtpmap, a=fmtp) and back into the depayloader.
//  - GstInspect.*: what gst-inspect-1.0 shows of the elements and the plugin.
//
// The plugin comes from GST_PLUGIN_PATH, which meson sets to the build's gst/ directory.
#include <gst/gst.h>
#include <gst/rtp/gstrtpbuffer.h>
#include <gst/sdp/gstsdpmessage.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <tuple>
#include <vector>

#include "lip_sync.h"
#include "pfap/markup.h"
#include "pfap/model.h"
#include "live_source.h"
#include "pfap_buffers.h"
#include "rtpbin_sessions.h"
#include "pipeline.h"
#include "random_markup.h"
#include "speech_session.h"

namespace {

using pfap::testing::Event;
using pfap::testing::number_of;
using pfap::testing::RandomMarkup;
using Clock = std::chrono::steady_clock;

constexpr const char* kPay = "rtppfappay";
constexpr const char* kDepay = "rtppfapdepay";
constexpr const char* kElements[] = {kPay, kDepay};  // what plugin_available() looks for

// ---------------------------------------------------------------------------------------------
// Small helpers

std::string describe(const Event& e) {
  std::ostringstream s;
  s << "kind " << e.kind << " flags 0x" << std::hex << unsigned{e.flags} << std::dec << " symbol "
    << unsigned{e.phoneme.symbol} << " " << e.phoneme.duration_ms << " ms f0 "
    << unsigned{e.phoneme.f0} << " S" << e.phoneme.stress << " W" << e.phoneme.word_begin << " EOT"
    << e.phoneme.end_of_text << " pts ";
  if (GST_CLOCK_TIME_IS_VALID(e.pts)) {
    s << e.pts;
  } else {
    s << "none";
  }
  s << " duration ";
  if (GST_CLOCK_TIME_IS_VALID(e.duration)) {
    s << e.duration;
  } else {
    s << "none";
  }
  s << " faps [";
  for (const pfap::Fap& f : e.faps) {
    s << " (" << unsigned{f.index} << " " << f.amplitude << " " << f.transition_ms << " "
      << static_cast<unsigned>(f.curve) << ")";
  }
  s << " ]";
  return s.str();
}

GstBuffer* make_buffer(const Event& e) { return pfap::testing::phoneme_buffer(e); }

using pfap::testing::bound_port;
using pfap::testing::end_of_stream;
using pfap::testing::fast_rtcp;
using pfap::testing::Pipeline;
using pfap::testing::plugin_available;
using pfap::testing::push_live;
using pfap::testing::rtpbin_receive_session;
using pfap::testing::rtpbin_send_session;
using pfap::testing::pull_all;
using pfap::testing::push;

// ---------------------------------------------------------------------------------------------
// Round trip: appsrc ! rtppfappay ! rtppfapdepay ! appsink keeps every field.

// A seeded session as a TTS engine gives it: contiguous phonemes, 0..5 FAPs each, sentences
// that end with end of text and are followed by a pause and a sentence start, and a few gaps
// inside sentences. Starts are at arbitrary nanoseconds after a pause or gap, so the PTS must
// come back from the buffers' times, not from the 44.1 kHz RTP clock.
std::vector<Event> random_session(uint32_t seed, int n_phonemes) {
  RandomMarkup random(seed);
  std::vector<Event> events;
  GstClockTime t = GST_SECOND + static_cast<GstClockTime>(random.uniform(0, 999'999'999));
  bool sentence_start = true;
  for (int i = 0; i < n_phonemes; ++i) {
    Event e;
    e.phoneme = random.phoneme();
    e.phoneme.end_of_text = i + 1 == n_phonemes || random.chance(0.06);
    const int n_faps = random.uniform(0, 5);
    for (int k = 0; k < n_faps; ++k) e.faps.push_back(random.fap());
    e.flags = pfap::testing::phoneme_flags(e.phoneme, sentence_start);
    e.pts = t;
    e.duration = e.phoneme.duration_ms * GST_MSECOND;
    events.push_back(e);
    t += e.duration;
    sentence_start = e.phoneme.end_of_text;
    if (sentence_start) {
      // The pause after a sentence.
      t += static_cast<GstClockTime>(random.uniform(1, 1500)) * GST_MSECOND +
           static_cast<GstClockTime>(random.uniform(0, 999'999));
    } else if (random.chance(0.03)) {
      // A gap inside a sentence: at least 1 ms, so it is never taken for contiguous.
      t += static_cast<GstClockTime>(random.uniform(1, 300)) * GST_MSECOND +
           static_cast<GstClockTime>(random.uniform(0, 999'999));
    }
  }
  return events;
}

TEST(RoundTrip, KeepsEveryField) {
  ASSERT_TRUE(plugin_available(kElements));
  struct Config {
    unsigned mtu;
    unsigned max_delay_ms;
    unsigned clock_rate;  // fixed by a capsfilter between the elements; 0: none
  };
  // mtu 48 leaves a 36-byte payload: a phoneme with 5 FAPs (35 bytes) only just fits, so
  // some packets are oversized (and warned about). 1400 is the default; max-delay 0 sends a
  // packet per phoneme, 5000 lets packets fill up to the MTU; a 90 kHz RTP clock.
  for (const Config c :
       {Config{48, 100, 0}, Config{100, 100, 0}, Config{576, 100, 0}, Config{1400, 100, 0},
        Config{1400, 0, 0}, Config{1400, 5000, 0}, Config{576, 100, 90000}}) {
    for (const uint32_t seed : {1u, 2u, 3u, 4u, 5u}) {
      SCOPED_TRACE("mtu " + std::to_string(c.mtu) + ", max-delay " +
                   std::to_string(c.max_delay_ms) + ", clock-rate " + std::to_string(c.clock_rate) +
                   ", seed " + std::to_string(seed));
      const std::vector<Event> sent = random_session(seed, 300);

      const std::string rate =
          c.clock_rate == 0 ? ""
                            : " ! application/x-rtp,clock-rate=" + std::to_string(c.clock_rate);
      Pipeline p("appsrc name=src format=time caps=application/x-pfap ! rtppfappay mtu=" +
                 std::to_string(c.mtu) + " max-delay=" + std::to_string(c.max_delay_ms) + rate +
                 " ! rtppfapdepay ! appsink name=sink sync=false emit-signals=false "
                 "wait-on-eos=false");
      ASSERT_TRUE(p.ok()) << p.error();
      ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
      GstElement* src = p.by_name("src");
      for (const Event& e : sent) ASSERT_EQ(push(src, make_buffer(e)), GST_FLOW_OK);
      end_of_stream(src);
      ASSERT_EQ(p.wait_eos(std::chrono::seconds(20)), "");

      std::vector<Event> got;
      for (GstSample* sample : pull_all(p.by_name("sink"))) {
        Event e = pfap::testing::read_event(gst_sample_get_buffer(sample));
        e.discont = false;
        got.push_back(e);
        gst_sample_unref(sample);
      }
      const size_t n = std::min(got.size(), sent.size());
      for (size_t i = 0; i < n; ++i) {
        if (!(got[i] == sent[i])) {
          ADD_FAILURE() << "event " << i << " of " << sent.size() << " differs\n  sent "
                        << describe(sent[i]) << "\n  got  " << describe(got[i]);
          break;
        }
      }
      EXPECT_EQ(got.size(), sent.size()) << "events out, after " << n << " compared";
    }
  }
}

// ---------------------------------------------------------------------------------------------
// SDP: the payloader's caps as an SDP media, and back.

TEST(Sdp, PayloaderCapsGiveFmtpAndBackIntoDepayloader) {
  ASSERT_TRUE(plugin_available(kElements));
  Event e;
  e.phoneme = {42, 80, 60, true, true, true};
  e.faps = {{69, 40, 2000, pfap::Curve::kSpline}};
  e.flags = pfap::testing::phoneme_flags(e.phoneme, true);
  e.pts = 0;
  e.duration = 80 * GST_MSECOND;

  // 1. The payloader's output caps and its packets: the complete state every stream opens
  // with, then the phoneme.
  Pipeline pay(
      "appsrc name=src format=time caps=\"application/x-pfap,alphabet=(string)x-sampa\" "
      "! rtppfappay pt=96 ! appsink name=sink sync=false emit-signals=false wait-on-eos=false");
  ASSERT_TRUE(pay.ok()) << pay.error();
  ASSERT_EQ(pay.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(push(pay.by_name("src"), make_buffer(e)), GST_FLOW_OK);
  end_of_stream(pay.by_name("src"));
  ASSERT_EQ(pay.wait_eos(std::chrono::seconds(10)), "");
  std::vector<GstSample*> packets = pull_all(pay.by_name("sink"));
  ASSERT_EQ(packets.size(), 2u);
  GstCaps* rtp_caps = gst_caps_ref(gst_sample_get_caps(packets[1]));
  std::vector<GstBuffer*> sent;
  for (GstSample* sample : packets) {
    sent.push_back(gst_buffer_ref(gst_sample_get_buffer(sample)));
    gst_sample_unref(sample);
  }
  gchar* caps_text = gst_caps_to_string(rtp_caps);
  SCOPED_TRACE(std::string("payloader caps: ") + caps_text);
  g_free(caps_text);

  // 2. Caps to SDP.
  GstSDPMedia* media = nullptr;
  ASSERT_EQ(gst_sdp_media_new(&media), GST_SDP_OK);
  ASSERT_EQ(gst_sdp_media_set_media_from_caps(rtp_caps, media), GST_SDP_OK);
  gst_sdp_media_set_port_info(media, 5004, 1);
  gst_sdp_media_set_proto(media, "RTP/AVP");
  gchar* text = gst_sdp_media_as_text(media);
  const std::string sdp = text;
  g_free(text);
  SCOPED_TRACE("SDP media:\n" + sdp);
  EXPECT_STREQ(gst_sdp_media_get_media(media), "application");
  ASSERT_EQ(gst_sdp_media_formats_len(media), 1u);
  EXPECT_STREQ(gst_sdp_media_get_format(media, 0), "96");
  EXPECT_STREQ(gst_sdp_media_get_attribute_val(media, "rtpmap"), "96 PFAP/44100");
  EXPECT_STREQ(gst_sdp_media_get_attribute_val(media, "fmtp"), "96 alphabet=x-sampa");
  EXPECT_NE(sdp.find("a=rtpmap:96 PFAP/44100\r\n"), std::string::npos);
  EXPECT_NE(sdp.find("a=fmtp:96 alphabet=x-sampa\r\n"), std::string::npos);

  // 3. SDP back to caps, as a receiver (rtspsrc, webrtcbin) makes them: the SDP library
  // names the structure application/x-unknown and the receiver renames it.
  GstCaps* caps = gst_sdp_media_get_caps_from_media(media, 96);
  ASSERT_NE(caps, nullptr);
  ASSERT_EQ(gst_sdp_media_attributes_to_caps(media, caps), GST_SDP_OK);
  gst_structure_set_name(gst_caps_get_structure(caps, 0), "application/x-rtp");
  gchar* back_text = gst_caps_to_string(caps);
  const std::string back = back_text;
  g_free(back_text);
  SCOPED_TRACE("caps from SDP: " + back);
  const GstStructure* s = gst_caps_get_structure(caps, 0);
  EXPECT_STREQ(gst_structure_get_string(s, "encoding-name"), "PFAP");
  EXPECT_STREQ(gst_structure_get_string(s, "alphabet"), "x-sampa");
  gint rate = 0;
  EXPECT_TRUE(gst_structure_get_int(s, "clock-rate", &rate));
  EXPECT_EQ(rate, 44100);

  // 4. Those caps into the depayloader, with the packets from step 1: the all-zero complete
  // state changes nothing and gives no event.
  gchar* depay_caps = gst_caps_to_string(caps);
  Pipeline depay(
      std::string("appsrc name=src format=time caps=\"") + depay_caps +
      "\" ! rtppfapdepay ! appsink name=sink sync=false emit-signals=false wait-on-eos=false");
  g_free(depay_caps);
  ASSERT_TRUE(depay.ok()) << depay.error();
  ASSERT_EQ(depay.set_state(GST_STATE_PLAYING), "");
  for (GstBuffer* packet : sent) EXPECT_EQ(push(depay.by_name("src"), packet), GST_FLOW_OK);
  end_of_stream(depay.by_name("src"));
  ASSERT_EQ(depay.wait_eos(std::chrono::seconds(10)), "");
  std::vector<GstSample*> out = pull_all(depay.by_name("sink"));
  ASSERT_EQ(out.size(), 1u);
  Event got = pfap::testing::read_event(gst_sample_get_buffer(out[0]));
  got.discont = false;
  EXPECT_EQ(got, e) << "sent " << describe(e) << "\ngot  " << describe(got);
  // The alphabet reaches the depayloader's output caps too.
  EXPECT_STREQ(
      gst_structure_get_string(gst_caps_get_structure(gst_sample_get_caps(out[0]), 0), "alphabet"),
      "x-sampa");
  for (GstSample* sample : out) gst_sample_unref(sample);

  gst_caps_unref(caps);
  gst_sdp_media_free(media);
  gst_caps_unref(rtp_caps);
}

// ---------------------------------------------------------------------------------------------
// gst-inspect-1.0

struct Inspect {
  int exit_status = -1;
  std::string out;
  std::string err;
};

// Runs gst-inspect-1.0 with the test's environment (GST_PLUGIN_PATH, GST_REGISTRY_1_0). In
// a sanitizer build, without LeakSanitizer: gst-inspect-1.0 does not free all it allocates
// (a feature list of gst_registry_feature_filter), and it is not ours; the plugin's code it
// runs, the test runs in its own process too. `option` goes before `what` (--plugin: a
// plugin of that name, not an element).
Inspect gst_inspect(const char* what, const char* option = nullptr) {
  Inspect result;
  gchar* argv[] = {const_cast<gchar*>("gst-inspect-1.0"),
                   const_cast<gchar*>(option != nullptr ? option : what),
                   option != nullptr ? const_cast<gchar*>(what) : nullptr, nullptr};
  gchar** envp = g_get_environ();
  if (const gchar* asan = g_environ_getenv(envp, "ASAN_OPTIONS")) {
    const std::string options = std::string(asan) + ":detect_leaks=0";
    envp = g_environ_setenv(envp, "ASAN_OPTIONS", options.c_str(), TRUE);
  }
  gchar* out = nullptr;
  gchar* err = nullptr;
  gint status = 0;
  GError* error = nullptr;
  const gboolean ran = g_spawn_sync(nullptr, argv, envp, G_SPAWN_SEARCH_PATH, nullptr, nullptr,
                                    &out, &err, &status, &error);
  g_strfreev(envp);
  if (!ran) {
    result.err = std::string("cannot run gst-inspect-1.0: ") + error->message;
    g_error_free(error);
    return result;
  }
  result.out = out != nullptr ? out : "";
  result.err = err != nullptr ? err : "";
  g_free(out);
  g_free(err);
  result.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

// The value of a "  Key   value" line in the factory details, or "" when there is none.
std::string detail(const std::vector<std::string>& lines, const std::string& key) {
  for (const std::string& line : lines) {
    if (line.rfind("  " + key + " ", 0) == 0) return trim(line.substr(key.size() + 2));
  }
  return "";
}

// The lines of a pad template block ("  SINK template: 'sink'" up to the next blank line).
std::string template_block(const std::vector<std::string>& lines, const std::string& header) {
  std::string block;
  bool in = false;
  for (const std::string& line : lines) {
    if (line == header) {
      in = true;
      continue;
    }
    if (in && trim(line).empty()) break;
    if (in) block += line + "\n";
  }
  return block;
}

// The blurb gst-inspect gives for a property ("  name   : blurb"), or "" when it has none.
std::string property_blurb(const std::vector<std::string>& lines, const std::string& name) {
  for (const std::string& line : lines) {
    if (line.rfind("  " + name, 0) != 0) continue;
    const std::string rest = line.substr(2 + name.size());
    const size_t colon = rest.find(':');
    if (colon == std::string::npos || !trim(rest.substr(0, colon)).empty()) continue;
    return trim(rest.substr(colon + 1));
  }
  return "";
}

void check_element_inspect(const char* name, const char* own_property) {
  SCOPED_TRACE(name);
  GstElementFactory* factory = gst_element_factory_find(name);
  ASSERT_NE(factory, nullptr);
  const std::string long_name =
      gst_element_factory_get_metadata(factory, GST_ELEMENT_METADATA_LONGNAME);
  const std::string klass = gst_element_factory_get_metadata(factory, GST_ELEMENT_METADATA_KLASS);

  const Inspect r = gst_inspect(name);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::vector<std::string> lines = lines_of(r.out);
  SCOPED_TRACE("gst-inspect-1.0 " + std::string(name) + ":\n" + r.out);

  EXPECT_FALSE(long_name.empty());
  EXPECT_EQ(detail(lines, "Long-name"), long_name);
  EXPECT_FALSE(klass.empty());
  EXPECT_EQ(detail(lines, "Klass"), klass);
  EXPECT_NE(klass.find(std::string_view(name).ends_with("depay") ? "Depayloader" : "Payloader"),
            std::string::npos);
  EXPECT_EQ(detail(lines, "Name"), "pfap") << "plugin name";

  // Both pad templates, each with the structures and fields of its caps.
  const GList* templates = gst_element_factory_get_static_pad_templates(factory);
  int sinks = 0, srcs = 0;
  for (const GList* l = templates; l != nullptr; l = l->next) {
    auto* t = static_cast<GstStaticPadTemplate*>(l->data);
    const bool sink = t->direction == GST_PAD_SINK;
    (sink ? sinks : srcs)++;
    const std::string header =
        std::string("  ") + (sink ? "SINK" : "SRC") + " template: '" + t->name_template + "'";
    const std::string block = template_block(lines, header);
    ASSERT_FALSE(block.empty()) << "no block " << header;
    EXPECT_NE(block.find("Capabilities:"), std::string::npos) << header;
    GstCaps* caps = gst_static_caps_get(&t->static_caps);
    for (guint i = 0; i < gst_caps_get_size(caps); ++i) {
      const GstStructure* s = gst_caps_get_structure(caps, i);
      EXPECT_NE(block.find(std::string("      ") + gst_structure_get_name(s) + "\n"),
                std::string::npos)
          << header << " lacks " << gst_structure_get_name(s);
      for (int f = 0; f < gst_structure_n_fields(s); ++f) {
        const std::string field = gst_structure_nth_field_name(s, f);
        const gchar* value = gst_structure_get_string(s, field.c_str());
        const std::string shown = value != nullptr ? field + ": " + value : field + ": ";
        EXPECT_NE(block.find(shown), std::string::npos) << header << " lacks " << shown;
      }
    }
    gst_caps_unref(caps);
  }
  EXPECT_EQ(sinks, 1);
  EXPECT_EQ(srcs, 1);
  if (std::string_view(name) == kPay) {
    EXPECT_NE(template_block(lines, "  SINK template: 'sink'").find("application/x-pfap"),
              std::string::npos);
    EXPECT_NE(template_block(lines, "  SRC template: 'src'").find("encoding-name: PFAP"),
              std::string::npos);
  } else {
    EXPECT_NE(template_block(lines, "  SINK template: 'sink'").find("encoding-name: PFAP"),
              std::string::npos);
    EXPECT_NE(template_block(lines, "  SRC template: 'src'").find("application/x-pfap"),
              std::string::npos);
  }

  // Every property the element adds to its base class, with its blurb.
  GstElement* element = gst_element_factory_create(factory, nullptr);
  ASSERT_NE(element, nullptr);
  const GType type = G_OBJECT_TYPE(element);
  guint n_specs = 0;
  GParamSpec** specs = g_object_class_list_properties(G_OBJECT_GET_CLASS(element), &n_specs);
  bool found_own = false;
  for (guint i = 0; i < n_specs; ++i) {
    if (specs[i]->owner_type != type) continue;
    const std::string prop = g_param_spec_get_name(specs[i]);
    found_own |= prop == own_property;
    const gchar* blurb = g_param_spec_get_blurb(specs[i]);
    EXPECT_TRUE(blurb != nullptr && *blurb != '\0') << prop << " has no blurb";
    const std::string shown = property_blurb(lines, prop);
    EXPECT_FALSE(shown.empty()) << "gst-inspect shows no blurb for " << prop;
    if (blurb != nullptr) {
      EXPECT_EQ(shown, blurb) << prop;
    }
  }
  EXPECT_TRUE(found_own) << name << " has no property " << own_property << " of its own";
  g_free(specs);
  gst_object_unref(element);
  gst_object_unref(factory);
}

TEST(GstInspect, Payloader) {
  ASSERT_TRUE(plugin_available(kElements));
  check_element_inspect(kPay, "max-delay");
}

TEST(GstInspect, Depayloader) {
  ASSERT_TRUE(plugin_available(kElements));
  check_element_inspect(kDepay, "request-recovery");
}

// The readers' deprecated names (docs/elements.md, "Names") are inspected as the element they
// name: its pads and properties, a description that names the new name.
TEST(GstInspect, DeprecatedNamesShowTheElementTheyName) {
  ASSERT_TRUE(plugin_available(kElements));
  for (const auto& [old_name, name, property] :
       {std::tuple{"pfapparse", "pfaptextparse", "skip-bad-lines"},
        std::tuple{"fapparse", "pfapfapparse", "silence-symbol"}}) {
    const Inspect r = gst_inspect(old_name);
    ASSERT_EQ(r.exit_status, 0) << r.err;
    SCOPED_TRACE(std::string("gst-inspect-1.0 ") + old_name + ":\n" + r.out);
    EXPECT_NE(r.out.find(std::string("Deprecated name of ") + name), std::string::npos);
    EXPECT_NE(r.out.find(std::string("  ") + property), std::string::npos);
    EXPECT_NE(r.out.find("Rank                     none (0)"), std::string::npos);
  }
}

// Each plugin needs only what its elements use (docs/elements.md): the RTP and text elements
// in pfap, the espeak-ng speaker in pfaptts, the cairo head in pfapface.
TEST(GstInspect, EachPluginListsItsElements) {
  ASSERT_TRUE(plugin_available(kElements));
  // And its typefinders: .pfap text's in pfap.
  const std::vector<std::tuple<const char*, std::vector<const char*>, int>> plugins = {
      {"pfap",
       {kPay, kDepay, "pfaptextparse", "pfaptextenc", "pfapfapparse", "pfapfapenc", "pfapmarksenc",
        "pfapmarksparse", "pfapparse", "fapparse"},
       1},
      {"pfaptts", {"pfaptts"}, 0},
      {"pfapface", {"pfapface"}, 0},
      {"pfapalign", {"pfapalign"}, 0},
  };
  for (const auto& [plugin, elements, typefinders] : plugins) {
    const Inspect r = gst_inspect(plugin, "--plugin");
    ASSERT_EQ(r.exit_status, 0) << r.err;
    SCOPED_TRACE(std::string("gst-inspect-1.0 ") + plugin + ":\n" + r.out);
    const std::vector<std::string> lines = lines_of(r.out);
    EXPECT_EQ(detail(lines, "Name"), plugin);
    for (const char* name : elements) {
      SCOPED_TRACE(name);
      GstElementFactory* factory = gst_element_factory_find(name);
      ASSERT_NE(factory, nullptr);
      const std::string line =
          std::string("  ") + name + ": " +
          gst_element_factory_get_metadata(factory, GST_ELEMENT_METADATA_LONGNAME);
      gst_object_unref(factory);
      EXPECT_NE(std::find(lines.begin(), lines.end(), line), lines.end()) << "no line: " << line;
    }
    const std::string count = std::to_string(elements.size());
    EXPECT_NE(r.out.find(std::to_string(elements.size() + typefinders) + " features:"),
              std::string::npos);
    EXPECT_NE(r.out.find("+-- " + count + " elements"), std::string::npos);
    if (typefinders > 0) {
      EXPECT_NE(r.out.find("+-- " + std::to_string(typefinders) + " typefinders"),
                std::string::npos);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Loopback UDP through rtpbin, audio beside PFAP: lip sync within 1 ms.
//
// Sender: audiotestsrc (live, white noise) ! audioconvert ! rtpL16pay and a live appsrc of
// x-pfap phonemes ! rtppfappay, sessions 0 and 1 of one rtpbin, RTP and RTCP to the receiver
// by udpsink. Receiver: udpsrc ! rtpbin (sessions 0 and 1, RTCP receiver reports back to the
// sender) ! rtpL16depay ! appsink and rtppfapdepay ! appsink. Every socket is on 127.0.0.1
// and bound to a free port (port=0, read back in READY).
//
// How it is measured. For every item the test knows the running time at which the sender
// sent it (T) and the running time at which the receiver outputs it (R):
//  - a phoneme: T is its PTS at the sender's appsrc (running time, segment from 0; the
//    appsrc pushes each phoneme when the clock reaches it); the receiver finds it again by
//    its number (symbol + 256 * f0);
//  - audio: the sender's L16 samples are recorded at rtpL16pay's sink pad with their running
//    times; audiotestsrc makes white noise, so each received buffer is found again in that
//    recording by its bytes, which gives T for its first sample.
// R is the running time (appsink segment) of the depayloaded buffer. The offset R - T is how
// a stream is mapped from the sender's timeline to the receiver's. For the phoneme sent at T
// and the audio sample sent at T, |R_p - R_a| = |offset_p(T) - offset_a(T)|, with offset_a
// from the received audio buffer that holds the sample sent at T. The test requires <= 1 ms
// for every phoneme once sync is in place, and that there are at least 10 such phonemes.
//
// What maps the two streams consistently is rtpbin's RTCP sync (rtcp-sync=always, the
// default): from the sender reports of both sessions (same CNAME) it sets the receiving
// jitterbuffers' ts-offset. A phoneme counts once both jitterbuffers have handed rtpbin at
// least two sender reports (counted in a handle-sync handler connected after rtpbin's, which
// applies the sync). Before that the PFAP stream is off by ~300 ms: its timeline starts at
// its first packet (the first phoneme, at 300 ms) and the audio's at 0. That also makes the
// first correction far above rtpbin's min-ts-offset (4 ms), so it is applied.
//
// The receiving rtpbin runs with buffer-mode=none: timestamps from the RTP timestamps alone,
// no estimate of the sender's clock skew from arrival times. Both pipelines share one clock,
// so there is no skew to estimate; in the default (slave) mode the estimate settles over the
// jitterbuffer's 2 s window, and rtpbin ignores ts-offset changes below min-ts-offset (4 ms),
// which measured as up to 16 ms of difference in the first 2 s and a lasting 1.4 ms after
// (with min-ts-offset=0 slave mode settles to +-25 us after ~2.3 s). Those are rtpbin's
// tolerances, not the payload format's; with buffer-mode=none the measured difference is
// within +-25 us (the 44.1 kHz RTP tick is 22.7 us) from the first sync on.
//
// Settings that only make the test fast: RTCP every ~100 ms instead of every 5 s
// (rtcp-min-interval and rtcp-fraction of the internal sessions). PFAP_TEST_VERBOSE=1 prints
// the per-phoneme table.

constexpr int kAudioRate = 44100;
constexpr GstClockTime kTolerance = GST_MSECOND;

using pfap::testing::AudioOffset;
using pfap::testing::on_audio;
using pfap::testing::on_new_jitterbuffer;
using pfap::testing::on_phoneme;
using pfap::testing::on_rtpbin_pad;
using pfap::testing::Received;
using pfap::testing::ReceiverLinks;
using pfap::testing::record_sent_audio;
using pfap::testing::SentAudio;

// The phonemes the sender sends: sentences of contiguous phonemes with pauses between them,
// from 300 ms (plus a fraction of a ms) for about 4 s. Each is numbered by symbol + 256 * f0.
std::vector<Event> live_phonemes() {
  RandomMarkup random(7);
  std::vector<Event> events;
  GstClockTime t = 300 * GST_MSECOND + 123'456;
  bool sentence_start = true;
  int in_sentence = 0;
  for (int i = 0; t < 4300 * GST_MSECOND; ++i) {
    Event e;
    e.phoneme.symbol = static_cast<uint8_t>(i & 0xff);
    e.phoneme.f0 = static_cast<uint8_t>(i >> 8);
    e.phoneme.duration_ms = static_cast<uint16_t>(random.uniform(40, 150));
    e.phoneme.stress = random.chance(0.3);
    e.phoneme.word_begin = random.chance(0.3);
    e.phoneme.end_of_text = ++in_sentence >= random.uniform(6, 14);
    const int n_faps = random.uniform(0, 2);
    for (int k = 0; k < n_faps; ++k) e.faps.push_back(random.fap());
    e.flags = pfap::testing::phoneme_flags(e.phoneme, sentence_start);
    e.pts = t;
    e.duration = e.phoneme.duration_ms * GST_MSECOND;
    t += e.duration;
    sentence_start = e.phoneme.end_of_text;
    if (sentence_start) {
      in_sentence = 0;
      t += static_cast<GstClockTime>(random.uniform(100, 300)) * GST_MSECOND;
    }
    events.push_back(e);
  }
  events.back().phoneme.end_of_text = true;
  events.back().flags |= PFAP_FLAG_END_OF_TEXT;
  return events;
}

TEST(LoopbackUdp, PhonemesKeepLipSyncWithAudio) {
  ASSERT_TRUE(plugin_available(kElements));
  const std::vector<Event> sent = live_phonemes();
  const Event& last = sent.back();
  // What the pipelines' callbacks write to outlives the pipelines.
  SentAudio sent_audio(kAudioRate);
  Received received;
  ReceiverLinks links{nullptr, nullptr, &received};

  Pipeline receiver(
      "rtpbin name=rtpbin buffer-mode=none " +
      rtpbin_receive_session(0, "audio_",
                             "application/x-rtp,media=audio,clock-rate=44100,"
                             "encoding-name=L16,channels=1,payload=96") +
      rtpbin_receive_session(1, "pfap_",
                             "application/x-rtp,media=application,clock-rate=44100,"
                             "encoding-name=PFAP,payload=97,alphabet=(string)x-sampa") +
      "rtpL16depay name=audio_depay ! appsink name=audio_sink sync=false emit-signals=true "
      "rtppfapdepay name=pfap_depay ! appsink name=pfap_sink sync=false emit-signals=true");
  ASSERT_TRUE(receiver.ok()) << receiver.error();
  Pipeline sender(
      "rtpbin name=rtpbin "
      "sdes=\"application/x-rtp-source-sdes,cname=(string)pfap-test-sender\" " +
      rtpbin_send_session(0, "audio_",
                          "audiotestsrc is-live=true wave=white-noise samplesperbuffer=441 "
                          "! audio/x-raw,rate=44100,channels=1 ! audioconvert "
                          "! rtpL16pay name=audio_pay pt=96",
                          /*sync_rtp=*/true) +
      rtpbin_send_session(1, "pfap_",
                          "appsrc name=pfap_src is-live=true format=time "
                          "caps=\"application/x-pfap,alphabet=(string)x-sampa\" "
                          "! rtppfappay pt=97",
                          /*sync_rtp=*/true));
  ASSERT_TRUE(sender.ok()) << sender.error();

  links.audio_depay = receiver.by_name("audio_depay");
  links.pfap_depay = receiver.by_name("pfap_depay");
  GstElement* receiver_rtpbin = receiver.by_name("rtpbin");
  g_signal_connect(receiver_rtpbin, "pad-added", G_CALLBACK(on_rtpbin_pad), &links);
  g_signal_connect(receiver_rtpbin, "new-jitterbuffer", G_CALLBACK(on_new_jitterbuffer), &received);
  g_signal_connect(receiver.by_name("audio_sink"), "new-sample", G_CALLBACK(on_audio), &received);
  g_signal_connect(receiver.by_name("pfap_sink"), "new-sample", G_CALLBACK(on_phoneme), &received);
  GstPad* pay_sink = gst_element_get_static_pad(sender.by_name("audio_pay"), "sink");
  gst_pad_add_probe(pay_sink, GST_PAD_PROBE_TYPE_BUFFER, record_sent_audio, &sent_audio, nullptr);
  gst_object_unref(pay_sink);

  // Every socket is bound to a free port of 127.0.0.1 (port=0) in READY; each sink is then
  // pointed at the port its peer got.
  ASSERT_EQ(receiver.set_state(GST_STATE_READY), "");
  ASSERT_EQ(sender.set_state(GST_STATE_READY), "");
  for (const char* name : {"audio_rtp", "audio_rtcp", "pfap_rtp", "pfap_rtcp"}) {
    const guint port = bound_port(receiver.by_name(name));
    ASSERT_NE(port, 0u) << name;
    g_object_set(sender.by_name(name), "port", port, nullptr);
  }
  for (const char* name : {"audio_rr", "pfap_rr"}) {
    const guint port = bound_port(sender.by_name(name));
    ASSERT_NE(port, 0u) << name;
    g_object_set(receiver.by_name(name), "port", port, nullptr);
  }
  fast_rtcp(sender.by_name("rtpbin"));
  fast_rtcp(receiver_rtpbin);

  ASSERT_EQ(receiver.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(sender.set_state(GST_STATE_PLAYING), "");
  // A live pipeline has its clock and base time once it is PLAYING.
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
  std::thread pusher(push_live, sender.by_name("pfap_src"), clock.get(), base_time, std::cref(sent),
                     std::cref(stop));

  // Until every phoneme is out and the audio reaches past the last one (or a deadline).
  const GstClockTime audio_needed = last.pts + last.duration + 100 * GST_MSECOND;
  const auto deadline =
      Clock::now() + std::chrono::nanoseconds(audio_needed) + std::chrono::seconds(15);
  std::string failure;
  {
    std::unique_lock lock(received.mutex);
    for (;;) {
      const bool all_phonemes =
          !received.phonemes.empty() &&
          number_of(received.phonemes.back().event.phoneme) == number_of(last.phoneme);
      bool enough_audio = false;
      if (!received.audio.empty()) {
        // The sender's audio starts at running time 0, so the audio received so far reaches
        // sender time (samples / rate): enough once that is past the last phoneme.
        size_t samples = 0;
        for (const Received::Audio& a : received.audio) samples += a.bytes.size() / 2;
        enough_audio = gst_util_uint64_scale(samples, GST_SECOND, kAudioRate) > audio_needed;
      }
      if (all_phonemes && enough_audio) break;
      if (!received.link_errors.empty()) {
        failure = received.link_errors.front();
        break;
      }
      lock.unlock();
      failure = sender.poll_error();
      if (failure.empty()) failure = receiver.poll_error();
      lock.lock();
      if (!failure.empty()) break;
      if (Clock::now() > deadline) {
        std::ostringstream s;
        s << "timed out: " << received.phonemes.size() << " of " << sent.size() << " phonemes and "
          << received.audio.size() << " audio buffers received; sync counts audio "
          << received.syncs[0] << ", PFAP " << received.syncs[1];
        failure = s.str();
        break;
      }
      received.changed.wait_for(lock, std::chrono::milliseconds(50));
    }
  }
  stop = true;
  pusher.join();
  sender.set_state(GST_STATE_NULL);
  receiver.set_state(GST_STATE_NULL);
  ASSERT_EQ(failure, "");

  // Every phoneme arrives once, in order, with its fields (times are the receiver's).
  ASSERT_EQ(received.phonemes.size(), sent.size());
  for (size_t i = 0; i < sent.size(); ++i) {
    Event got = received.phonemes[i].event;
    got.discont = false;
    got.pts = sent[i].pts;
    ASSERT_EQ(got, sent[i]) << "phoneme " << i << "\n  sent " << describe(sent[i]) << "\n  got  "
                            << describe(received.phonemes[i].event);
  }

  // Where each received audio buffer was in the sent audio, by its bytes.
  size_t unmatched = 0;
  const std::vector<AudioOffset> audio_offsets =
      pfap::testing::audio_offsets(sent_audio, received, unmatched);
  ASSERT_GT(audio_offsets.size(), received.audio.size() / 2)
      << unmatched << " of " << received.audio.size()
      << " received audio buffers not found in the sent audio";

  std::vector<GstClockTime> sent_times;
  for (const Event& e : sent) sent_times.push_back(e.pts);
  const pfap::testing::LipSync sync =
      pfap::testing::compare_offsets(audio_offsets, sent_times, received.phonemes, kTolerance);
  SCOPED_TRACE("per phoneme (syncs < 2: before RTCP sync, not counted):\n" + sync.table);
  EXPECT_GE(sync.compared, 10) << "too few phonemes after RTCP sync";
  EXPECT_EQ(sync.out_of_tolerance, 0)
      << "worst |R_p - R_a| " << sync.worst / 1000 << " us over " << sync.compared << " phonemes";
  if (const char* verbose = g_getenv("PFAP_TEST_VERBOSE"); verbose != nullptr) {
    std::cout << sync.table << "worst " << sync.worst << " ns over " << sync.compared << "\n";
  }
}

}  // namespace

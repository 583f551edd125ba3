// SPDX-License-Identifier: LGPL-2.1-or-later
// libgstpfap's C API (gst/pfap/pfap.h), as an application calls it: events from and to
// buffers, refusals as GErrors (never a CRITICAL: main() makes criticals and warnings fatal),
// alphabets, bookmarks, and the FAP state against libpfap's own.
#include <gst/gst.h>
#include <gst/pfap/pfap.h>
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

#include "pfap/fap_state.h"

namespace {

struct ErrorFree {
  void operator()(GError* e) const { g_error_free(e); }
};
using Error = std::unique_ptr<GError, ErrorFree>;

TEST(GstPfapEvent, PhonemeRoundTripsThroughABufferWithItsDuration) {
  g_autoptr(GstPfapEvent) event = gst_pfap_event_new(GST_PFAP_EVENT_KIND_PHONEME);
  gst_pfap_event_set_symbol(event, 42);
  gst_pfap_event_set_duration_ms(event, 100);
  gst_pfap_event_set_f0(event, 60);
  gst_pfap_event_set_flags(event, static_cast<GstPfapEventFlags>(
                                      GST_PFAP_EVENT_FLAG_STRESS | GST_PFAP_EVENT_FLAG_WORD_BEGIN |
                                      GST_PFAP_EVENT_FLAG_SENTENCE_START));
  g_autoptr(GstPfapFap) joy = gst_pfap_fap_new(69, 40, 2000, GST_PFAP_CURVE_SPLINE);
  g_autoptr(GstPfapFap) lip = gst_pfap_fap_new(48, -20000, 0, GST_PFAP_CURVE_LINEAR);
  gst_pfap_event_add_fap(event, joy);
  gst_pfap_event_add_fap(event, lip);

  GError* error = nullptr;
  GstBuffer* buffer = gst_pfap_event_to_buffer(event, &error);
  ASSERT_NE(buffer, nullptr) << error->message;
  EXPECT_EQ(GST_BUFFER_DURATION(buffer), 100 * GST_MSECOND);
  // The bytes of docs/markup.md, as tests/lib/test_markup.cc writes them by hand.
  const guint8 expected[] = {0x01, 0x0B, 0x2A, 0x3C, 0x00, 0x64, 0x00, 0x02,
                             0x45, 0x03, 0x07, 0xD0, 0x00, 0x00, 0x00, 0x28,
                             0x30, 0x01, 0x00, 0x00, 0xFF, 0xFF, 0xB1, 0xE0};
  ASSERT_EQ(gst_buffer_get_size(buffer), sizeof expected);
  EXPECT_EQ(gst_buffer_memcmp(buffer, 0, expected, sizeof expected), 0);

  g_autoptr(GstPfapEvent) back = gst_pfap_event_new_from_buffer(buffer, &error);
  gst_buffer_unref(buffer);
  ASSERT_NE(back, nullptr) << error->message;
  EXPECT_EQ(gst_pfap_event_get_kind(back), GST_PFAP_EVENT_KIND_PHONEME);
  EXPECT_EQ(gst_pfap_event_get_symbol(back), 42);
  EXPECT_EQ(gst_pfap_event_get_duration_ms(back), 100);
  EXPECT_EQ(gst_pfap_event_get_f0(back), 60);
  EXPECT_EQ(gst_pfap_event_get_flags(back), gst_pfap_event_get_flags(event));
  ASSERT_EQ(gst_pfap_event_get_n_faps(back), 2u);
  g_autolist(GstPfapFap) faps = gst_pfap_event_get_faps(back);
  ASSERT_EQ(g_list_length(faps), 2u);
  const auto* first = static_cast<GstPfapFap*>(faps->data);
  EXPECT_EQ(first->index, 69);
  EXPECT_EQ(first->amplitude, 40);
  EXPECT_EQ(first->transition_ms, 2000);
  EXPECT_EQ(first->curve, GST_PFAP_CURVE_SPLINE);
  g_autoptr(GstPfapFap) second = gst_pfap_event_get_fap(back, 1);
  EXPECT_EQ(second->index, 48);
  EXPECT_EQ(second->amplitude, -20000);
  EXPECT_EQ(second->transition_ms, 0);
  EXPECT_EQ(second->curve, GST_PFAP_CURVE_LINEAR);
  EXPECT_EQ(gst_pfap_event_get_fap(back, 2), nullptr);

  g_autoptr(GstPfapEvent) copy = gst_pfap_event_copy(back);
  gst_pfap_event_clear_faps(back);
  EXPECT_EQ(gst_pfap_event_get_n_faps(back), 0u);
  EXPECT_EQ(gst_pfap_event_get_n_faps(copy), 2u);
}

// A buffer of several memories (an appsrc application may build one) is read as one run of
// bytes, as the plugins read it (markupbuffer.h).
TEST(GstPfapEvent, EventSplitOverTwoMemoriesIsReadWhole) {
  g_autoptr(GstPfapEvent) event = gst_pfap_event_new(GST_PFAP_EVENT_KIND_RECOVERED);
  g_autoptr(GstPfapFap) joy = gst_pfap_fap_new(69, -40, 300, GST_PFAP_CURVE_TRIANGLE);
  gst_pfap_event_add_fap(event, joy);
  GstBuffer* whole = gst_pfap_event_to_buffer(event, nullptr);
  ASSERT_NE(whole, nullptr);
  const gsize size = gst_buffer_get_size(whole);
  // Split inside the FAP record, so neither memory holds a valid event.
  GstBuffer* split =
      gst_buffer_append(gst_buffer_copy_region(whole, GST_BUFFER_COPY_MEMORY, 0, 11),
                        gst_buffer_copy_region(whole, GST_BUFFER_COPY_MEMORY, 11, size - 11));
  gst_buffer_unref(whole);
  ASSERT_EQ(gst_buffer_n_memory(split), 2u);

  GError* raw = nullptr;
  g_autoptr(GstPfapEvent) back = gst_pfap_event_new_from_buffer(split, &raw);
  gst_buffer_unref(split);
  Error error(raw);
  ASSERT_NE(back, nullptr) << error->message;
  EXPECT_EQ(gst_pfap_event_get_kind(back), GST_PFAP_EVENT_KIND_RECOVERED);
  g_autoptr(GstPfapFap) fap = gst_pfap_event_get_fap(back, 0);
  ASSERT_NE(fap, nullptr);
  EXPECT_EQ(fap->index, 69);
  EXPECT_EQ(fap->amplitude, -40);
  EXPECT_EQ(fap->transition_ms, 300);
  EXPECT_EQ(fap->curve, GST_PFAP_CURVE_TRIANGLE);
}

TEST(GstPfapEvent, StateEventsCarryNoPhoneme) {
  g_autoptr(GstPfapEvent) event = gst_pfap_event_new(GST_PFAP_EVENT_KIND_COMPLETE);
  gst_pfap_event_set_symbol(event, 9);
  gst_pfap_event_set_flags(event, GST_PFAP_EVENT_FLAG_UNCERTAIN);
  GstBuffer* buffer = gst_pfap_event_to_buffer(event, nullptr);
  ASSERT_NE(buffer, nullptr);
  EXPECT_FALSE(GST_BUFFER_DURATION_IS_VALID(buffer));
  g_autoptr(GstPfapEvent) back = gst_pfap_event_new_from_buffer(buffer, nullptr);
  gst_buffer_unref(buffer);
  ASSERT_NE(back, nullptr);
  EXPECT_EQ(gst_pfap_event_get_kind(back), GST_PFAP_EVENT_KIND_COMPLETE);
  EXPECT_EQ(gst_pfap_event_get_symbol(back), 0);
  EXPECT_EQ(gst_pfap_event_get_flags(back), GST_PFAP_EVENT_FLAG_UNCERTAIN);
}

TEST(GstPfapEvent, MalformedBytesGiveAMalformedError) {
  const std::vector<std::vector<guint8>> bad = {
      {},                                                  // empty
      {0x01, 0x00, 0x00, 0x00},                            // shorter than a header
      {0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},    // unknown kind
      {0x01, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},    // unknown flag
      {0x01, 0x00, 0x00, 0x00, 0x10, 0x00, 0x00, 0x00},    // duration 4096
      {0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01},    // one FAP announced, none there
      {0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01,     // FAP index 2
       0x02, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},
      {0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01,     // curve 4
       0x03, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},
  };
  for (const auto& bytes : bad) {
    GstBuffer* buffer = gst_buffer_new_allocate(nullptr, bytes.size(), nullptr);
    gst_buffer_fill(buffer, 0, bytes.data(), bytes.size());
    GError* raw = nullptr;
    EXPECT_EQ(gst_pfap_event_new_from_buffer(buffer, &raw), nullptr);
    gst_buffer_unref(buffer);
    Error error(raw);
    ASSERT_NE(error, nullptr);
    EXPECT_TRUE(g_error_matches(error.get(), GST_PFAP_EVENT_ERROR, GST_PFAP_EVENT_ERROR_MALFORMED));
    EXPECT_NE(strstr(error->message, "not a valid application/x-pfap event"), nullptr)
        << error->message;
    // Without a GError the refusal is the NULL alone.
    EXPECT_EQ(gst_pfap_event_new_from_data(bytes.data(), bytes.size(), nullptr), nullptr);
  }
}

TEST(GstPfapEvent, OutOfRangeValuesAreNamedAndNothingIsWritten) {
  g_autoptr(GstPfapEvent) event = gst_pfap_event_new(GST_PFAP_EVENT_KIND_PHONEME);
  gst_pfap_event_set_duration_ms(event, 4096);
  GError* raw = nullptr;
  EXPECT_EQ(gst_pfap_event_to_buffer(event, &raw), nullptr);
  Error error(raw);
  ASSERT_NE(error, nullptr);
  EXPECT_TRUE(
      g_error_matches(error.get(), GST_PFAP_EVENT_ERROR, GST_PFAP_EVENT_ERROR_OUT_OF_RANGE));
  EXPECT_NE(strstr(error->message, "duration 4096"), nullptr) << error->message;

  gst_pfap_event_set_duration_ms(event, 10);
  g_autoptr(GstPfapFap) good = gst_pfap_fap_new(3, 1, 0, GST_PFAP_CURVE_LINEAR);
  g_autoptr(GstPfapFap) bad = gst_pfap_fap_new(3, GST_PFAP_MAX_AMPLITUDE + 1, 0,
                                               GST_PFAP_CURVE_LINEAR);
  gst_pfap_event_add_fap(event, good);
  gst_pfap_event_add_fap(event, bad);
  raw = nullptr;
  EXPECT_EQ(gst_pfap_event_to_buffer(event, &raw), nullptr);
  error.reset(raw);
  ASSERT_NE(error, nullptr);
  EXPECT_NE(strstr(error->message, "FAP 1: index 3, amplitude 2529601"), nullptr)
      << error->message;
}

TEST(GstPfapAlphabet, ArpabetMapsSymbolsToNamesAndVisemes) {
  EXPECT_EQ(gst_pfap_alphabet_find("x-sampa"), nullptr);
  const GstPfapAlphabet* arpabet = gst_pfap_alphabet_find(GST_PFAP_ALPHABET_ARPABET);
  ASSERT_NE(arpabet, nullptr);
  EXPECT_STREQ(gst_pfap_alphabet_get_name(arpabet), "x-pfap-arpabet");
  EXPECT_EQ(gst_pfap_alphabet_get_n_symbols(arpabet), 40u);
  EXPECT_STREQ(gst_pfap_alphabet_get_phoneme_name(arpabet, 0), "pause");
  EXPECT_STREQ(gst_pfap_alphabet_get_phoneme_name(arpabet, 1), "AA");
  EXPECT_STREQ(gst_pfap_alphabet_get_phoneme_name(arpabet, 39), "ZH");
  EXPECT_EQ(gst_pfap_alphabet_get_phoneme_name(arpabet, 40), nullptr);
  EXPECT_EQ(gst_pfap_alphabet_get_viseme(arpabet, 1), GST_PFAP_VISEME_A);
  EXPECT_EQ(gst_pfap_alphabet_get_viseme(arpabet, 200), GST_PFAP_VISEME_NONE);
  guint8 symbol = 0;
  EXPECT_TRUE(gst_pfap_alphabet_lookup_symbol(arpabet, "M", &symbol));
  EXPECT_EQ(gst_pfap_alphabet_get_viseme(arpabet, symbol), GST_PFAP_VISEME_PBM);
  EXPECT_FALSE(gst_pfap_alphabet_lookup_symbol(arpabet, "QQ", &symbol));
}

// pfapalign recognizer=visemes's alphabet: symbol k is MPEG-4 viseme k.
TEST(GstPfapAlphabet, TheVisemeDetectorsAlphabetIsKnown) {
  const GstPfapAlphabet* oculus = gst_pfap_alphabet_find("x-pfap-oculus-viseme");
  ASSERT_NE(oculus, nullptr);
  EXPECT_EQ(gst_pfap_alphabet_get_n_symbols(oculus), 15u);
  EXPECT_STREQ(gst_pfap_alphabet_get_phoneme_name(oculus, 1), "PP");
  for (guint8 k = 0; k < 15; ++k) EXPECT_EQ(gst_pfap_alphabet_get_viseme(oculus, k), k);
}

TEST(GstPfapBookmark, ParsesExpressionsAndFormatsTheTransformedForm) {
  GError* raw = nullptr;
  g_autolist(GstPfapFap) faps = gst_pfap_bookmarks_parse(
      " <FAP 2 1 40 2 30 2000 3> <FAP 48 -7 0 1>", GST_PFAP_MAX_BOOKMARKS, &raw);
  ASSERT_EQ(raw, nullptr) << raw->message;
  ASSERT_EQ(g_list_length(faps), 3u);
  EXPECT_EQ(static_cast<GstPfapFap*>(g_list_nth_data(faps, 1))->index, 70);
  g_autofree gchar* text = gst_pfap_bookmarks_format(faps);
  EXPECT_STREQ(text, "<FAP 69 40 2000 3><FAP 70 30 2000 3><FAP 48 -7 0 1>");
  // White space alone is a valid run of no bookmarks.
  EXPECT_EQ(gst_pfap_bookmarks_parse(" \t", GST_PFAP_MAX_BOOKMARKS, &raw), nullptr);
  EXPECT_EQ(raw, nullptr);
  g_autofree gchar* none = gst_pfap_bookmarks_format(nullptr);
  EXPECT_STREQ(none, "");
}

TEST(GstPfapBookmark, ErrorsCarryTheirCodeAndPosition) {
  struct Case {
    const char* text;
    GstPfapBookmarkError code;
    const char* position;
  };
  const Case cases[] = {
      {"<FAP 48 1 0 1> x", GST_PFAP_BOOKMARK_ERROR_UNEXPECTED_TEXT, "at byte 15:"},
      {"<FAP 48 1 16384 1>", GST_PFAP_BOOKMARK_ERROR_TRANSITION_OUT_OF_RANGE, "at byte 10:"},
      {"<FAP 75 1 0 1>", GST_PFAP_BOOKMARK_ERROR_UNKNOWN_FAP, "at byte 5:"},
      {"  <FAP 48 1 0 1", GST_PFAP_BOOKMARK_ERROR_UNTERMINATED, "at byte 2:"},
  };
  for (const Case& c : cases) {
    GError* raw = nullptr;
    EXPECT_EQ(gst_pfap_bookmarks_parse(c.text, GST_PFAP_MAX_BOOKMARKS, &raw), nullptr) << c.text;
    Error error(raw);
    ASSERT_NE(error, nullptr) << c.text;
    EXPECT_TRUE(g_error_matches(error.get(), GST_PFAP_BOOKMARK_ERROR, c.code))
        << c.text << ": " << error->message;
    EXPECT_TRUE(g_str_has_prefix(error->message, c.position)) << c.text << ": " << error->message;
  }
  GError* raw = nullptr;
  EXPECT_EQ(gst_pfap_bookmarks_parse("<FAP 3 1 0 1><FAP 4 1 0 1>", 1, &raw), nullptr);
  Error error(raw);
  EXPECT_TRUE(g_error_matches(error.get(), GST_PFAP_BOOKMARK_ERROR,
                              GST_PFAP_BOOKMARK_ERROR_TOO_MANY_BOOKMARKS));
}

TEST(GstPfapFapState, FollowsLibpfapsStateThroughEveryKindOfEvent) {
  g_autoptr(GstPfapFapState) state = gst_pfap_fap_state_new();
  pfap::FapState expected;
  const GstClockTime t0 = GST_SECOND;

  g_autoptr(GstPfapEvent) phoneme = gst_pfap_event_new(GST_PFAP_EVENT_KIND_PHONEME);
  g_autoptr(GstPfapFap) spline = gst_pfap_fap_new(3, 1000, 400, GST_PFAP_CURVE_SPLINE);
  g_autoptr(GstPfapFap) triangle = gst_pfap_fap_new(4, -600, 300, GST_PFAP_CURVE_TRIANGLE);
  gst_pfap_event_add_fap(phoneme, spline);
  gst_pfap_event_add_fap(phoneme, triangle);
  ASSERT_TRUE(gst_pfap_fap_state_apply_event(state, phoneme, t0, nullptr));
  expected.apply({3, 1000, 400, pfap::Curve::kSpline}, t0);
  expected.apply({4, -600, 300, pfap::Curve::kTriangle}, t0);
  for (GstClockTime t = t0; t < t0 + 500 * GST_MSECOND; t += 7 * GST_MSECOND) {
    EXPECT_EQ(gst_pfap_fap_state_get_amplitude(state, 3, t), expected.amplitude(3, t));
    EXPECT_EQ(gst_pfap_fap_state_get_amplitude(state, 4, t), expected.amplitude(4, t));
    EXPECT_EQ(gst_pfap_fap_state_is_at_rest(state, 4, t), expected.at_rest(4, t));
  }
  EXPECT_EQ(gst_pfap_fap_state_get_settled(state, 3), 1000);
  EXPECT_EQ(gst_pfap_fap_state_get_settled(state, 4), 0);

  g_autoptr(GstPfapEvent) complete = gst_pfap_event_new(GST_PFAP_EVENT_KIND_COMPLETE);
  g_autoptr(GstPfapFap) held = gst_pfap_fap_new(5, 77, 0, GST_PFAP_CURVE_LINEAR);
  gst_pfap_event_add_fap(complete, held);
  ASSERT_TRUE(gst_pfap_fap_state_apply_event(state, complete, 2 * GST_SECOND, nullptr));
  EXPECT_EQ(gst_pfap_fap_state_get_settled(state, 3), 0);
  EXPECT_EQ(gst_pfap_fap_state_get_settled(state, 5), 77);

  gst_pfap_fap_state_reset(state);
  EXPECT_EQ(gst_pfap_fap_state_get_settled(state, 5), 0);
}

TEST(GstPfapFapState, AnOutOfRangeFapChangesNothing) {
  g_autoptr(GstPfapFapState) state = gst_pfap_fap_state_new();
  g_autoptr(GstPfapEvent) event = gst_pfap_event_new(GST_PFAP_EVENT_KIND_PHONEME);
  g_autoptr(GstPfapFap) good = gst_pfap_fap_new(3, 10, 0, GST_PFAP_CURVE_LINEAR);
  g_autoptr(GstPfapFap) bad = gst_pfap_fap_new(200, 10, 0, GST_PFAP_CURVE_LINEAR);
  gst_pfap_event_add_fap(event, good);
  gst_pfap_event_add_fap(event, bad);
  GError* raw = nullptr;
  EXPECT_FALSE(gst_pfap_fap_state_apply_event(state, event, 0, &raw));
  Error error(raw);
  EXPECT_TRUE(
      g_error_matches(error.get(), GST_PFAP_EVENT_ERROR, GST_PFAP_EVENT_ERROR_OUT_OF_RANGE));
  EXPECT_EQ(gst_pfap_fap_state_get_settled(state, 3), 0);
  raw = nullptr;
  EXPECT_FALSE(gst_pfap_fap_state_apply_fap(state, bad, 0, &raw));
  error.reset(raw);
  EXPECT_NE(error, nullptr);
}

TEST(GstPfapTypes, AreRegisteredForBindings) {
  EXPECT_TRUE(G_TYPE_IS_BOXED(GST_TYPE_PFAP_EVENT));
  EXPECT_TRUE(G_TYPE_IS_BOXED(GST_TYPE_PFAP_FAP));
  EXPECT_TRUE(G_TYPE_IS_BOXED(GST_TYPE_PFAP_ALPHABET));
  EXPECT_TRUE(G_TYPE_IS_OBJECT(GST_TYPE_PFAP_FAP_STATE));
  EXPECT_TRUE(G_TYPE_IS_FLAGS(gst_pfap_event_flags_get_type()));
  EXPECT_TRUE(G_TYPE_IS_ENUM(gst_pfap_event_kind_get_type()));
  EXPECT_STREQ(GST_PFAP_CAPS, "application/x-pfap");
}

}  // namespace

int main(int argc, char** argv) {
  gst_init(&argc, &argv);
  // Bad input must come back as a GError, never as a GLib critical or warning.
  g_log_set_always_fatal(static_cast<GLogLevelFlags>(G_LOG_LEVEL_CRITICAL | G_LOG_LEVEL_WARNING));
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

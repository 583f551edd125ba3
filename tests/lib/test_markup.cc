// SPDX-License-Identifier: LGPL-2.1-or-later
// The application/x-pfap event layout (pfap/markup.h): bytes written by hand, round trips and
// refusal of bad events.
#include <gtest/gtest.h>

#include <vector>

#include "pfap/markup.h"
#include "pfap/markup_event.h"
#include "random_markup.h"

namespace {

using Bytes = std::vector<uint8_t>;

// kind 1, flags S|W|sentence start = 0x0B, symbol 42, f0 60, duration 100 = 00 64, 2 FAPs;
// FAP 69 curve 3 T 2000 = 07 D0 a 40 = 00 00 00 28; FAP 48 curve 1 T 0 a -20000 = FF FF B1 E0.
const Bytes kPhonemeEvent = {0x01, 0x0B, 0x2A, 0x3C, 0x00, 0x64, 0x00, 0x02,
                             0x45, 0x03, 0x07, 0xD0, 0x00, 0x00, 0x00, 0x28,
                             0x30, 0x01, 0x00, 0x00, 0xFF, 0xFF, 0xB1, 0xE0};
const PfapEventHeader kHeader{PFAP_EVENT_PHONEME,
                              PFAP_FLAG_STRESS | PFAP_FLAG_WORD_BEGIN | PFAP_FLAG_SENTENCE_START,
                              42,
                              60,
                              100,
                              2};
const PfapFap kFaps[] = {{69, 3, 2000, 40}, {48, 1, 0, -20000}};

TEST(Markup, WriteGivesTheDocumentedBytes) {
  Bytes out(pfap_markup_size(2));
  ASSERT_EQ(out.size(), kPhonemeEvent.size());
  ASSERT_EQ(pfap_markup_write(&kHeader, kFaps, out.data(), out.size()), 0);
  EXPECT_EQ(out, kPhonemeEvent);
}

TEST(Markup, ReadGivesTheEventBack) {
  PfapEventHeader h{};
  ASSERT_EQ(pfap_markup_read_header(kPhonemeEvent.data(), kPhonemeEvent.size(), &h), 0);
  EXPECT_EQ(h.kind, PFAP_EVENT_PHONEME);
  EXPECT_EQ(h.flags, kHeader.flags);
  EXPECT_EQ(h.symbol, 42);
  EXPECT_EQ(h.f0, 60);
  EXPECT_EQ(h.duration_ms, 100);
  ASSERT_EQ(h.n_faps, 2);
  for (unsigned i = 0; i < 2; ++i) {
    PfapFap f;
    pfap_markup_read_fap(kPhonemeEvent.data(), i, &f);
    EXPECT_EQ(f.index, kFaps[i].index);
    EXPECT_EQ(f.curve, kFaps[i].curve);
    EXPECT_EQ(f.transition_ms, kFaps[i].transition_ms);
    EXPECT_EQ(f.amplitude, kFaps[i].amplitude);
  }
}

TEST(Markup, StateEventWithNoFapsIsEightBytes) {
  const PfapEventHeader complete{PFAP_EVENT_COMPLETE, 0, 0, 0, 0, 0};
  Bytes out(pfap_markup_size(0));
  ASSERT_EQ(out.size(), 8u);
  ASSERT_EQ(pfap_markup_write(&complete, nullptr, out.data(), out.size()), 0);
  EXPECT_EQ(out, (Bytes{0x03, 0, 0, 0, 0, 0, 0, 0}));
}

TEST(Markup, BadEventsAreRefused) {
  const auto with = [](size_t at, uint8_t value) {
    Bytes b = kPhonemeEvent;
    b[at] = value;
    return b;
  };
  const struct {
    const char* name;
    Bytes bytes;
  } cases[] = {
      {"empty", {}},
      {"header_only_cut", Bytes(kPhonemeEvent.begin(), kPhonemeEvent.begin() + 7)},
      {"fap_cut", Bytes(kPhonemeEvent.begin(), kPhonemeEvent.end() - 1)},
      {"byte_too_many",
       [] {
         Bytes b = kPhonemeEvent;
         b.push_back(0);
         return b;
       }()},
      {"kind_0", with(0, 0)},
      {"kind_4", with(0, 4)},
      {"unknown_flag", with(1, 0x20)},
      {"duration_4096",
       [&] {
         Bytes b = with(4, 0x10);
         b[5] = 0x00;
         return b;
       }()},
      {"fap_index_2", with(8, 2)},
      {"fap_index_75", with(8, 75)},
      {"curve_0", with(9, 0)},
      {"curve_4", with(9, 4)},
      {"transition_16384",
       [&] {
         Bytes b = with(10, 0x40);
         b[11] = 0x00;
         return b;
       }()},
      {"amplitude_2529601",
       [&] {  // 0x00269941
         Bytes b = with(12, 0x00);
         b[13] = 0x26, b[14] = 0x99, b[15] = 0x41;
         return b;
       }()},
  };
  for (const auto& c : cases) {
    PfapEventHeader h{};
    EXPECT_EQ(pfap_markup_read_header(c.bytes.data(), c.bytes.size(), &h), -1) << c.name;
  }
}

TEST(Markup, WriteRefusesOutOfRangeValuesAndWrongSize) {
  Bytes out(pfap_markup_size(2));
  EXPECT_EQ(pfap_markup_write(&kHeader, kFaps, out.data(), out.size() - 1), -1);
  PfapFap bad[] = {kFaps[0], {48, 1, 0, 2529601}};
  EXPECT_EQ(pfap_markup_write(&kHeader, bad, out.data(), out.size()), -1);
  PfapEventHeader long_phoneme = kHeader;
  long_phoneme.duration_ms = 4096;
  EXPECT_EQ(pfap_markup_write(&long_phoneme, kFaps, out.data(), out.size()), -1);
}

}  // namespace

namespace pfap {
namespace {

TEST(MarkupEvent, WritesTheSameBytesAsTheCApi) {
  MarkupEvent event;
  event.phoneme = {42, 100, 60, true, true, false};
  event.sentence_start = true;
  event.faps = {{69, 40, 2000, Curve::kSpline}, {48, -20000, 0, Curve::kLinear}};
  Bytes out(markup_size(event));
  ASSERT_TRUE(write_markup(event, out));
  EXPECT_EQ(out, kPhonemeEvent);
  MarkupEvent back;
  ASSERT_TRUE(read_markup(out, back));
  EXPECT_EQ(back, event);
}

TEST(MarkupEvent, RandomEventsOfEveryKindRoundTrip) {
  pfap::testing::RandomMarkup random(7);
  for (int n = 0; n < 2000; ++n) {
    MarkupEvent event;
    event.kind = static_cast<PfapEventKind>(random.uniform(1, 3));
    if (event.kind == PFAP_EVENT_PHONEME) {
      event.phoneme = random.phoneme();
      event.phoneme.end_of_text = random.chance(0.2);
      event.sentence_start = random.chance(0.2);
    }
    event.uncertain = random.chance(0.2);
    for (int i = random.uniform(0, 80); i > 0; --i) event.faps.push_back(random.fap());
    Bytes out(markup_size(event));
    ASSERT_TRUE(write_markup(event, out)) << n;
    MarkupEvent back;
    ASSERT_TRUE(read_markup(out, back)) << n;
    ASSERT_EQ(back, event) << n;
  }
}

TEST(MarkupEvent, InvalidEventsAndWrongSizesAreRefused) {
  MarkupEvent event;
  event.faps = {{2, 0, 0, Curve::kLinear}};
  Bytes out(markup_size(event));
  EXPECT_FALSE(write_markup(event, out));
  event.faps = {};
  event.phoneme.duration_ms = 4096;
  out.resize(markup_size(event));
  EXPECT_FALSE(write_markup(event, out));
  event.phoneme.duration_ms = 1;
  Bytes wrong(markup_size(event) + 1);
  EXPECT_FALSE(write_markup(event, wrong));
  MarkupEvent back;
  EXPECT_FALSE(read_markup(Bytes{0x01, 0, 0, 0}, back));
}

TEST(MarkupEvent, ApplyStartsEachFapAndACompleteStateResetsTheRest) {
  FapState state;
  MarkupEvent phoneme;
  phoneme.faps = {{3, 100, 10, Curve::kLinear}, {4, -50, 0, Curve::kLinear}};
  apply_markup(phoneme, 1'000'000'000, state);
  EXPECT_EQ(state.amplitude(3, 1'005'000'000), 50);
  EXPECT_EQ(state.settled(4), -50);

  MarkupEvent complete;
  complete.kind = PFAP_EVENT_COMPLETE;
  complete.faps = {{3, 7, 0, Curve::kLinear}};
  apply_markup(complete, 2'000'000'000, state);
  EXPECT_EQ(state.settled(3), 7);
  EXPECT_EQ(state.settled(4), 0);

  MarkupEvent recovered;
  recovered.kind = PFAP_EVENT_RECOVERED;
  recovered.faps = {{5, 9, 0, Curve::kLinear}};
  apply_markup(recovered, 3'000'000'000, state);
  EXPECT_EQ(state.settled(3), 7);
  EXPECT_EQ(state.settled(5), 9);
}

}  // namespace
}  // namespace pfap

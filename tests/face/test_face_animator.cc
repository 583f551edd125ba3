// SPDX-License-Identifier: LGPL-2.1-or-later
// The face over time: FAP state, mouth shapes from phonemes, state events, expressions.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "face/animator.h"
#include "pfap/fap_state.h"
#include "pfap/phoneme_table.h"

namespace pfap::face {
namespace {

constexpr int64_t kMs = 1'000'000;

const pfap::PhonemeAlphabet& arpabet() { return *pfap::find_alphabet(pfap::kArpabetAlphabet); }

pfap::MarkupEvent phoneme(const char* name, uint16_t duration_ms,
                          std::vector<pfap::Fap> faps = {}) {
  pfap::MarkupEvent event;
  event.phoneme.symbol = *pfap::find_symbol(arpabet(), name);
  event.phoneme.duration_ms = duration_ms;
  event.faps = std::move(faps);
  return event;
}

pfap::MarkupEvent state(PfapEventKind kind, std::vector<pfap::Fap> faps) {
  pfap::MarkupEvent event;
  event.kind = kind;
  event.faps = std::move(faps);
  return event;
}

pfap::Fap fap(int index, int32_t amplitude, uint16_t transition_ms,
              pfap::Curve curve = pfap::Curve::kLinear) {
  return {static_cast<uint8_t>(index), amplitude, transition_ms, curve};
}

Animator arpabet_animator() {
  Animator animator;
  animator.set_alphabet(&arpabet());
  return animator;
}

TEST(Animator, OpenVowelOpensTheJawMoreThanLipsClosed) {
  Animator aa = arpabet_animator(), m = arpabet_animator();
  EXPECT_TRUE(aa.apply(phoneme("AA", 200), 0));
  EXPECT_TRUE(m.apply(phoneme("M", 200), 0));
  const FacePose open = aa.pose(100 * kMs), closed = m.pose(100 * kMs);
  EXPECT_GT(open.jaw_open, 0.05);
  EXPECT_DOUBLE_EQ(closed.jaw_open, 0);
  EXPECT_GT(open.inner_lips[6].y - open.inner_lips[2].y, 0.05);
  EXPECT_DOUBLE_EQ(closed.inner_lips[6].y - closed.inner_lips[2].y, 0);
}

TEST(Animator, EveryVisemeOfTheAlphabetHasItsShape) {
  for (size_t symbol = 1; symbol < arpabet().symbols.size(); ++symbol) {
    Animator animator = arpabet_animator();
    pfap::MarkupEvent event;
    event.phoneme.symbol = static_cast<uint8_t>(symbol);
    event.phoneme.duration_ms = 300;
    ASSERT_TRUE(animator.apply(event, 0));
    const MouthShape expected = pfap::viseme_mouth(arpabet().symbols[symbol].viseme);
    EXPECT_DOUBLE_EQ(animator.faps(200 * kMs)[3], expected.open_jaw)
        << arpabet().symbols[symbol].name;
  }
}

TEST(Animator, BookmarksFollowTheLibraryStateModel) {
  Animator animator = arpabet_animator();
  pfap::FapState reference;
  const std::vector<pfap::Fap> first{fap(31, 300, 200, pfap::Curve::kSpline),
                                     fap(19, 1024, 300, pfap::Curve::kTriangle)};
  const std::vector<pfap::Fap> second{fap(31, -100, 400, pfap::Curve::kLinear)};
  animator.apply(phoneme("AA", 100, first), 0);
  for (const pfap::Fap& f : first) reference.apply(f, 0);
  animator.apply(phoneme("M", 100, second), 100 * kMs);
  for (const pfap::Fap& f : second) reference.apply(f, 100 * kMs);
  for (int64_t t = 100 * kMs; t <= 700 * kMs; t += 25 * kMs) {
    const FapValues f = animator.faps(t);
    EXPECT_DOUBLE_EQ(f[31], reference.amplitude(31, t)) << t;
    EXPECT_DOUBLE_EQ(f[19], reference.amplitude(19, t)) << t;
  }
}

TEST(Animator, MouthMovesSmoothlyBetweenPhonemesAndClosesInPauses) {
  Animator animator = arpabet_animator();
  animator.apply(phoneme("AA", 120), 0);
  animator.apply(phoneme("M", 100), 120 * kMs);
  animator.apply(phoneme("IY", 150), 220 * kMs);
  double previous = animator.faps(0)[3];
  double largest_step = 0;
  for (int64_t t = 0; t <= 600 * kMs; t += kMs) {
    const double jaw = animator.faps(t)[3];
    largest_step = std::max(largest_step, std::abs(jaw - previous));
    previous = jaw;
  }
  // The widest change, AA (430) to M (0) in 50 ms eased, moves under 20 units per ms.
  EXPECT_LT(largest_step, 20);
  EXPECT_GT(largest_step, 1);
  // After the last phoneme (ends at 370 ms) and the ease, the mouth is closed.
  EXPECT_DOUBLE_EQ(animator.faps(370 * kMs + kMouthEaseNs)[3], 0);
  EXPECT_EQ(animator.describe(500 * kMs), "pause");
  EXPECT_EQ(animator.describe(300 * kMs), "IY");
}

TEST(Animator, PauseSymbolClosesTheMouth) {
  Animator animator = arpabet_animator();
  animator.apply(phoneme("AA", 200), 0);
  animator.apply(phoneme("pause", 400), 200 * kMs);
  EXPECT_DOUBLE_EQ(animator.faps(200 * kMs + kMouthEaseNs)[3], 0);
}

TEST(Animator, UnknownAlphabetOpensAGenericMouthOverEachPhoneme) {
  Animator animator;  // no alphabet
  pfap::MarkupEvent event;
  event.phoneme.symbol = 5;
  event.phoneme.duration_ms = 200;
  EXPECT_FALSE(animator.apply(event, 0));
  EXPECT_DOUBLE_EQ(animator.faps(0)[3], 0);
  EXPECT_NEAR(animator.faps(100 * kMs)[3], generic_mouth().open_jaw, 1e-9);
  EXPECT_NEAR(animator.faps(200 * kMs)[3], 0, 1e-9);
  EXPECT_EQ(animator.describe(50 * kMs), "#5");
}

TEST(Animator, UnknownSymbolIsReported) {
  Animator animator = arpabet_animator();
  pfap::MarkupEvent event;
  event.phoneme.symbol = 200;
  event.phoneme.duration_ms = 100;
  EXPECT_FALSE(animator.apply(event, 0));
}

TEST(Animator, CompleteStateSetsEveryFap) {
  Animator animator = arpabet_animator();
  animator.apply(phoneme("M", 100, {fap(31, 300, 0), fap(49, 8000, 0)}), 0);
  animator.apply(state(PFAP_EVENT_COMPLETE, {fap(33, 100, 0)}), 50 * kMs);
  const FapValues f = animator.faps(60 * kMs);
  EXPECT_DOUBLE_EQ(f[31], 0);
  EXPECT_DOUBLE_EQ(f[49], 0);
  EXPECT_DOUBLE_EQ(f[33], 100);
}

TEST(Animator, RecoveredEntriesRunTheirRemainingTransitionFromTheirTime) {
  Animator animator = arpabet_animator();
  animator.apply(phoneme("M", 100, {fap(33, 100, 0)}), 0);
  animator.apply(state(PFAP_EVENT_RECOVERED, {fap(31, 400, 200)}), 1000 * kMs);
  const FapValues f = animator.faps(1100 * kMs);
  EXPECT_DOUBLE_EQ(f[31], 200);
  EXPECT_DOUBLE_EQ(f[33], 100) << "a recovered state leaves other FAPs";
  EXPECT_DOUBLE_EQ(animator.faps(1300 * kMs)[31], 400);
}

TEST(Animator, TimeNeverGoesBack) {
  Animator animator = arpabet_animator();
  animator.apply(phoneme("M", 100, {fap(31, 400, 200)}), 1000 * kMs);
  animator.apply(phoneme("M", 100, {fap(31, 0, 200)}), 500 * kMs);  // taken at 1000 ms
  // Had it started at 500 ms, FAP 31 would be on its way to 400 at 1100 ms.
  EXPECT_DOUBLE_EQ(animator.faps(1100 * kMs)[31], 0);
  EXPECT_EQ(animator.describe(1050 * kMs), "M");
}

TEST(Animator, EndIsTheLastPhonemeOrTransition) {
  Animator animator = arpabet_animator();
  animator.apply(phoneme("M", 100, {fap(69, 40, 800)}), 0);
  EXPECT_EQ(animator.end_ns(), 800 * kMs);
  animator.apply(phoneme("AA", 1000), 100 * kMs);
  EXPECT_EQ(animator.end_ns(), 1100 * kMs);
}

TEST(Animator, ExpressionsAndOverlayText) {
  Animator animator = arpabet_animator();
  animator.apply(phoneme("M", 100, {fap(69, 63, 0), fap(31, -20, 0)}), 0);
  EXPECT_DOUBLE_EQ(animator.pose(50 * kMs).expressions[0], 1);
  EXPECT_GT(animator.faps(50 * kMs)[12], 100) << "joy lifts the corners";
  EXPECT_EQ(animator.describe(50 * kMs), "M 31:-20 69:63");
}

TEST(Animator, ResetGivesTheNeutralFace) {
  Animator animator = arpabet_animator();
  animator.apply(phoneme("AA", 100, {fap(49, 8000, 0)}), 1000 * kMs);
  animator.reset();
  const FapValues f = animator.faps(0);
  for (double amplitude : f) EXPECT_DOUBLE_EQ(amplitude, 0);
  EXPECT_EQ(animator.end_ns(), 0);
  EXPECT_TRUE(animator.apply(phoneme("AA", 100), 0)) << "the alphabet stays";
}

}  // namespace
}  // namespace pfap::face

// SPDX-License-Identifier: LGPL-2.1-or-later
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <ostream>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "pfap/fap_state.h"

namespace pfap {
namespace {

constexpr int64_t kMs = 1'000'000;  // ns
constexpr int64_t kStart = 5'000 * kMs;

Fap make_fap(int index, int32_t amplitude, uint16_t transition_ms, Curve curve) {
  return Fap{.index = static_cast<uint8_t>(index),
             .amplitude = amplitude,
             .transition_ms = transition_ms,
             .curve = curve};
}

// Brings FAP `index` to `amplitude` at once, so that the next bookmark starts there.
void jump_to(FapState& state, int index, int32_t amplitude, int64_t at_ns) {
  state.apply(make_fap(index, amplitude, 0, Curve::kLinear), at_ns);
}

// ---- Curve values ----

struct CurveCase {
  const char* name;
  Curve curve;
  int32_t from;
  int32_t target;
  uint16_t transition_ms;
  // At start, T/4, T/2, 3T/4, T and 2T.
  std::array<double, 6> expected;
};

void PrintTo(const CurveCase& c, std::ostream* os) { *os << c.name; }

constexpr int32_t kMax = kMaxAmplitude;
constexpr uint16_t kLongest = kMaxTransitionMs;

const CurveCase kCurveCases[] = {
    {"LinearUp", Curve::kLinear, 0, 1000, 1000, {0, 250, 500, 750, 1000, 1000}},
    {"LinearDown", Curve::kLinear, 200, -1000, 1000, {200, -100, -400, -700, -1000, -1000}},
    {"LinearFullRange",
     Curve::kLinear,
     -kMax,
     kMax,
     kLongest,
     {-kMax, -1264800, 0, 1264800, kMax, kMax}},
    {"TriangleUp", Curve::kTriangle, 0, 1000, 1000, {0, 500, 1000, 500, 0, 0}},
    {"TriangleDown", Curve::kTriangle, 200, -1000, 1000, {200, -400, -1000, -400, 200, 200}},
    {"TriangleFullRange", Curve::kTriangle, kMax, -kMax, kLongest, {kMax, 0, -kMax, 0, kMax, kMax}},
    {"SplineUp", Curve::kSpline, 0, 1000, 1000, {0, 156.25, 500, 843.75, 1000, 1000}},
    {"SplineDown", Curve::kSpline, 200, -1000, 1000, {200, 12.5, -400, -812.5, -1000, -1000}},
    {"SplineFullRange",
     Curve::kSpline,
     -kMax,
     kMax,
     kLongest,
     {-kMax, -1739100, 0, 1739100, kMax, kMax}},
};

class CurveValues : public ::testing::TestWithParam<CurveCase> {};

TEST_P(CurveValues, MatchTheCurveAtQuarterSteps) {
  const CurveCase& c = GetParam();
  FapState state;
  jump_to(state, 3, c.from, 0);
  state.apply(make_fap(3, c.target, c.transition_ms, c.curve), kStart);
  const int64_t duration_ns = c.transition_ms * kMs;  // divisible by 4: quarters are exact
  const std::array<int64_t, 6> times = {kStart,
                                        kStart + duration_ns / 4,
                                        kStart + duration_ns / 2,
                                        kStart + 3 * duration_ns / 4,
                                        kStart + duration_ns,
                                        kStart + 2 * duration_ns};
  for (size_t i = 0; i < times.size(); ++i) {
    EXPECT_DOUBLE_EQ(state.amplitude(3, times[i]), c.expected[i]) << "point " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(FapState, CurveValues, ::testing::ValuesIn(kCurveCases),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(FapState, BeforeItsStartABookmarkGivesItsStartingAmplitude) {
  FapState state;
  jump_to(state, 3, 300, 0);
  state.apply(make_fap(3, 1000, 1000, Curve::kLinear), kStart);
  EXPECT_EQ(state.amplitude(3, kStart - 1), 300);
}

// ---- Starting amplitude ----

TEST(FapState, NeverBookmarkedFapStartsFromZero) {
  FapState state;
  EXPECT_EQ(state.amplitude(3, kStart), 0);
  EXPECT_EQ(state.settled(3), 0);
  state.apply(make_fap(3, 1000, 1000, Curve::kLinear), kStart);
  EXPECT_EQ(state.amplitude(3, kStart), 0);
  EXPECT_EQ(state.amplitude(3, kStart + 500 * kMs), 500);
}

TEST(FapState, AfterATransitionIsOverTheNextStartsFromItsTarget) {
  FapState state;
  state.apply(make_fap(3, 1000, 100, Curve::kLinear), 0);
  state.apply(make_fap(3, -500, 1000, Curve::kLinear), kStart);
  EXPECT_EQ(state.amplitude(3, kStart), 1000);
  EXPECT_EQ(state.amplitude(3, kStart + 500 * kMs), 250);
  EXPECT_EQ(state.settled(3), -500);
}

TEST(FapState, AfterASplineIsOverTheNextStartsFromItsTarget) {
  FapState state;
  state.apply(make_fap(3, 777, 100, Curve::kSpline), 0);
  state.apply(make_fap(3, 0, 1000, Curve::kLinear), 100 * kMs);
  EXPECT_EQ(state.amplitude(3, 100 * kMs), 777);
}

TEST(FapState, InterruptedTransitionStartsFromTheReachedRoundedValue) {
  FapState state;
  state.apply(make_fap(3, 1000, 3, Curve::kLinear), 0);  // 333.33 after 1 ms
  state.apply(make_fap(3, 0, 1000, Curve::kLinear), 1 * kMs);
  EXPECT_EQ(state.amplitude(3, 1 * kMs), 333);
  EXPECT_EQ(state.amplitude(3, 1 * kMs + 500 * kMs), 166.5);
}

TEST(FapState, InterruptedSplineStartsFromTheReachedValue) {
  FapState state;
  state.apply(make_fap(3, 1000, 1000, Curve::kSpline), 0);  // 156.25 at T/4
  state.apply(make_fap(3, 2000, 1000, Curve::kLinear), 250 * kMs);
  EXPECT_EQ(state.amplitude(3, 250 * kMs), 156);
}

TEST(FapState, ReachedValueRoundsHalvesAwayFromZero) {
  FapState state;
  state.apply(make_fap(3, 1001, 2, Curve::kLinear), 0);   // 500.5 after 1 ms
  state.apply(make_fap(4, -1001, 2, Curve::kLinear), 0);  // -500.5 after 1 ms
  state.apply(make_fap(3, 0, 1000, Curve::kLinear), 1 * kMs);
  state.apply(make_fap(4, 0, 1000, Curve::kLinear), 1 * kMs);
  EXPECT_EQ(state.amplitude(3, 1 * kMs), 501);
  EXPECT_EQ(state.amplitude(4, 1 * kMs), -501);
}

TEST(FapState, InterruptedTriangleOnItsWayBackStartsFromTheReachedValue) {
  FapState state;
  state.apply(make_fap(3, 1000, 1000, Curve::kTriangle), 0);  // 500 at 3T/4, going down
  state.apply(make_fap(3, 2000, 1000, Curve::kLinear), 750 * kMs);
  EXPECT_EQ(state.amplitude(3, 750 * kMs), 500);
  EXPECT_EQ(state.amplitude(3, 1250 * kMs), 1250);
  EXPECT_EQ(state.settled(3), 2000);
}

TEST(FapState, BookmarksAtTheSameStartChainFromTheSameValue) {
  FapState state;
  jump_to(state, 3, 100, 0);
  state.apply(make_fap(3, 1000, 1000, Curve::kLinear), kStart);
  state.apply(make_fap(3, -1000, 1000, Curve::kLinear), kStart);  // replaces it, from 100
  EXPECT_EQ(state.amplitude(3, kStart), 100);
  EXPECT_EQ(state.amplitude(3, kStart + 500 * kMs), -450);
}

// ---- Triangle ----

TEST(FapState, TriangleHoldsItsStartAmplitudeAfterwards) {
  FapState state;
  jump_to(state, 3, 200, 0);
  state.apply(make_fap(3, 1000, 1000, Curve::kTriangle), kStart);
  EXPECT_EQ(state.amplitude(3, kStart + 500 * kMs), 1000);
  EXPECT_EQ(state.amplitude(3, kStart + 1000 * kMs), 200);
  EXPECT_EQ(state.amplitude(3, kStart + 60'000 * kMs), 200);
  EXPECT_EQ(state.settled(3), 200);
}

TEST(FapState, BookmarkAfterATriangleStartsFromTheTrianglesStart) {
  FapState state;
  jump_to(state, 3, 200, 0);
  state.apply(make_fap(3, 1000, 1000, Curve::kTriangle), kStart);
  state.apply(make_fap(3, 0, 1000, Curve::kLinear), kStart + 2000 * kMs);
  EXPECT_EQ(state.amplitude(3, kStart + 2000 * kMs), 200);
}

// ---- T = 0 ----

TEST(FapState, ZeroTransitionJumpsAtItsStart) {
  for (Curve curve : {Curve::kLinear, Curve::kSpline}) {
    FapState state;
    jump_to(state, 3, 100, 0);
    state.apply(make_fap(3, -700, 0, curve), kStart);
    EXPECT_EQ(state.amplitude(3, kStart - 1), 100);
    EXPECT_EQ(state.amplitude(3, kStart), -700);
    EXPECT_EQ(state.amplitude(3, kStart + 1), -700);
    EXPECT_EQ(state.settled(3), -700);
  }
}

// A triangle interrupting a transition goes back to what the FAP held, the previous
// target, not to the value it happened to reach: settled values depend only on the order of
// bookmarks, which is what makes recovery exact.
TEST(FapState, TriangleInterruptingATransitionReturnsToThePreviousTarget) {
  FapState state;
  state.apply(make_fap(3, 1000, 1000, Curve::kLinear), kStart);  // 500 at T/2
  state.apply(make_fap(3, 2000, 400, Curve::kTriangle), kStart + 500 * kMs);
  EXPECT_DOUBLE_EQ(state.amplitude(3, kStart + 500 * kMs), 500);   // starts where it is
  EXPECT_DOUBLE_EQ(state.amplitude(3, kStart + 700 * kMs), 2000);  // the peak at T/2
  EXPECT_DOUBLE_EQ(state.amplitude(3, kStart + 800 * kMs), 1500);  // halfway back
  EXPECT_DOUBLE_EQ(state.amplitude(3, kStart + 900 * kMs), 1000);  // back at the target
  EXPECT_DOUBLE_EQ(state.amplitude(3, kStart + 5000 * kMs), 1000);
  EXPECT_EQ(state.settled(3), 1000);
}

TEST(FapState, TriangleOnARunningTriangleKeepsTheHeldValue) {
  FapState state;
  jump_to(state, 3, 100, 0);
  state.apply(make_fap(3, 900, 1000, Curve::kTriangle), kStart);
  state.apply(make_fap(3, -500, 1000, Curve::kTriangle), kStart + 300 * kMs);
  EXPECT_EQ(state.settled(3), 100);
  EXPECT_DOUBLE_EQ(state.amplitude(3, kStart + 1300 * kMs), 100);
}

TEST(FapState, AtRestOnceTheTransitionIsOver) {
  FapState state;
  EXPECT_TRUE(state.at_rest(3, 0));
  state.apply(make_fap(3, 100, 200, Curve::kSpline), kStart);
  EXPECT_FALSE(state.at_rest(3, kStart));
  EXPECT_FALSE(state.at_rest(3, kStart + 199 * kMs));
  EXPECT_TRUE(state.at_rest(3, kStart + 200 * kMs));
}

TEST(FapState, RecoveryEntryRestoresTheSettledValue) {
  FapState state;
  state.apply(make_fap(3, 100, 1000, Curve::kSpline), kStart);
  // Running: the target and the time left, rounded up to whole ms.
  EXPECT_EQ(state.recovery_entry(3, kStart + 400 * kMs + 1), make_fap(3, 100, 600, Curve::kSpline));
  // Not started yet: all of it.
  EXPECT_EQ(state.recovery_entry(3, kStart - kMs), make_fap(3, 100, 1000, Curve::kSpline));
  // Over: the settled value at once.
  EXPECT_EQ(state.recovery_entry(3, kStart + 1000 * kMs), make_fap(3, 100, 0, Curve::kLinear));
  // A running triangle: the held value at once, its excursion left out.
  state.apply(make_fap(3, 900, 1000, Curve::kTriangle), kStart + 2000 * kMs);
  EXPECT_EQ(state.recovery_entry(3, kStart + 2100 * kMs), make_fap(3, 100, 0, Curve::kLinear));
  // A FAP never bookmarked: 0.
  EXPECT_EQ(state.recovery_entry(4, kStart), make_fap(4, 0, 0, Curve::kLinear));
}

TEST(FapState, ZeroTransitionTriangleLeavesNoTrace) {
  FapState state;
  jump_to(state, 3, 100, 0);
  state.apply(make_fap(3, 900, 0, Curve::kTriangle), kStart);
  EXPECT_EQ(state.amplitude(3, kStart), 100);
  EXPECT_EQ(state.amplitude(3, kStart + 1), 100);
  EXPECT_EQ(state.settled(3), 100);
}

// ---- Reset ----

TEST(FapState, ZeroAmplitudeResetsTheFapOverItsTransition) {
  FapState state;
  jump_to(state, 3, 1000, 0);
  state.apply(make_fap(3, 0, 1000, Curve::kLinear), kStart);
  EXPECT_EQ(state.amplitude(3, kStart + 500 * kMs), 500);
  EXPECT_EQ(state.amplitude(3, kStart + 1000 * kMs), 0);
  EXPECT_EQ(state.settled(3), 0);
}

TEST(FapState, ResetBringsEveryFapBackToZero) {
  FapState state;
  for (int index = kMinFapIndex; index <= kMaxFapIndex; ++index) {
    state.apply(make_fap(index, 1000 + index, 1000, Curve::kSpline), kStart);
  }
  state.reset();
  for (int index = kMinFapIndex; index <= kMaxFapIndex; ++index) {
    EXPECT_EQ(state.amplitude(index, kStart + 500 * kMs), 0) << "FAP " << index;
    EXPECT_EQ(state.settled(index), 0) << "FAP " << index;
  }
  state.apply(make_fap(3, 1000, 1000, Curve::kLinear), kStart + 500 * kMs);
  EXPECT_EQ(state.amplitude(3, kStart + 500 * kMs), 0);
}

// ---- Complete states ----

// What apply_complete must do, written the plain way: the settled values before, a reset,
// each entry applied as a bookmark, and whether any settled value moved.
bool apply_complete_by_reset(FapState& state, std::span<const Fap> entries, int64_t time_ns) {
  std::array<int32_t, kFapCount> before{};
  for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) before[f] = state.settled(f);
  state.reset();
  for (const Fap& entry : entries) state.apply(entry, time_ns);
  bool changed = false;
  for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) changed |= state.settled(f) != before[f];
  return changed;
}

void expect_same_state(const FapState& a, const FapState& b, int64_t from_ns) {
  for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) {
    EXPECT_EQ(a.settled(f), b.settled(f)) << "FAP " << f;
    for (int64_t t = from_ns; t <= from_ns + 2'000 * kMs; t += 250 * kMs) {
      EXPECT_EQ(a.amplitude(f, t), b.amplitude(f, t)) << "FAP " << f << " at " << t;
    }
  }
}

// apply_complete takes entries in index order, as senders list them, in one pass, and any
// other order or a FAP given twice the plain way: both must end where the plain way ends,
// from any state, with any entries (some left out, some 0, some still moving, triangles).
TEST(FapState, CompleteStateEndsWhereResetAndApplyEnd) {
  std::mt19937 random(15);
  const auto uniform = [&](int lo, int hi) {
    return std::uniform_int_distribution(lo, hi)(random);
  };
  const auto random_fap = [&](int index) {
    return make_fap(index, uniform(-3, 3) * 1000, static_cast<uint16_t>(uniform(0, 2) * 400),
                    static_cast<Curve>(uniform(1, 3)));
  };
  for (int round = 0; round < 300; ++round) {
    SCOPED_TRACE(round);
    FapState state;
    int64_t t = kStart;
    for (int i = uniform(0, 40); i > 0; --i) {
      t += uniform(0, 300) * kMs;
      state.apply(random_fap(uniform(kMinFapIndex, kMaxFapIndex)), t);
    }
    t += uniform(-100, 300) * kMs;  // the complete state may come before a running start
    std::vector<Fap> entries;
    for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) {
      if (uniform(0, 2) != 0) entries.push_back(random_fap(f));
    }
    if (round % 3 == 1 && entries.size() > 1) std::shuffle(entries.begin(), entries.end(), random);
    if (round % 3 == 2 && !entries.empty()) entries.push_back(random_fap(entries[0].index));

    FapState expected = state;
    const bool expected_changed = apply_complete_by_reset(expected, entries, t);
    EXPECT_EQ(state.apply_complete(entries, t), expected_changed);
    expect_same_state(state, expected, t - 200 * kMs);
  }
}

TEST(FapState, CompleteStateThatChangesNothingSaysSo) {
  FapState state;
  state.apply(make_fap(5, 300, 0, Curve::kLinear), kStart);
  state.apply(make_fap(9, -20, 0, Curve::kSpline), kStart);
  const std::vector<Fap> same = {make_fap(5, 300, 0, Curve::kLinear),
                                 make_fap(9, -20, 0, Curve::kLinear)};
  EXPECT_FALSE(state.apply_complete(same, kStart + 1'000 * kMs));
  const std::vector<Fap> without_9 = {make_fap(5, 300, 0, Curve::kLinear)};
  EXPECT_TRUE(state.apply_complete(without_9, kStart + 2'000 * kMs));
  EXPECT_EQ(state.settled(9), 0);
}

// ---- Indexes ----

TEST(FapState, FapIndexesAreIndependent) {
  FapState state;
  for (int index = kMinFapIndex; index <= kMaxFapIndex; ++index) {
    state.apply(make_fap(index, index * 100, 1000, Curve::kLinear), kStart);
  }
  state.apply(make_fap(10, -5, 0, Curve::kLinear), kStart + 500 * kMs);
  for (int index = kMinFapIndex; index <= kMaxFapIndex; ++index) {
    if (index == 10) continue;
    EXPECT_EQ(state.amplitude(index, kStart + 500 * kMs), index * 50) << "FAP " << index;
    EXPECT_EQ(state.settled(index), index * 100) << "FAP " << index;
  }
  EXPECT_EQ(state.amplitude(10, kStart + 500 * kMs), -5);
}

TEST(FapState, ExpressionFapsBehaveLikeOtherFaps) {
  const auto run = [](int index) {
    FapState state;
    state.apply(make_fap(index, 40, 2000, Curve::kSpline), kStart);
    state.apply(make_fap(index, -30, 1000, Curve::kTriangle), kStart + 700 * kMs);
    std::array<double, 4> seen = {};
    for (size_t i = 0; i < seen.size(); ++i) {
      seen[i] = state.amplitude(index, kStart + 700 * kMs + static_cast<int64_t>(i) * 300 * kMs);
    }
    return std::pair{seen, state.settled(index)};
  };
  const auto reference = run(kMinFapIndex);
  for (int index = kFirstExpressionIndex; index <= kMaxFapIndex; ++index) {
    EXPECT_EQ(run(index), reference) << "FAP " << index;
  }
}

// ---- Spline shape ----

TEST(FapState, SplineHasZeroSlopeAtBothEnds) {
  FapState state;
  state.apply(make_fap(3, 1000, 1000, Curve::kSpline), kStart);
  const double mean_slope = 1000.0 / (1000 * kMs);  // per ns
  const int64_t step = 1000;                        // 1 us, 1e-6 of T
  const auto slope_after = [&](int64_t t) {
    return (state.amplitude(3, t + step) - state.amplitude(3, t)) / step;
  };
  const double start_slope = slope_after(kStart);
  const double end_slope = slope_after(kStart + 1000 * kMs - step);
  const double mid_slope = slope_after(kStart + 500 * kMs);
  EXPECT_NEAR(start_slope, 0, 1e-4 * mean_slope);
  EXPECT_NEAR(end_slope, 0, 1e-4 * mean_slope);
  EXPECT_NEAR(mid_slope, 1.5 * mean_slope, 1e-3 * mean_slope);  // 6u(1-u) at u = 1/2
}

TEST(FapState, SplineIsMonotone) {
  for (int32_t target : {kMaxAmplitude, -kMaxAmplitude}) {
    FapState state;
    state.apply(make_fap(3, target, kMaxTransitionMs, Curve::kSpline), kStart);
    const int64_t duration_ns = kMaxTransitionMs * kMs;
    double previous = state.amplitude(3, kStart);
    for (int i = 1; i <= 1000; ++i) {
      const double value = state.amplitude(3, kStart + duration_ns * i / 1000);
      if (target > 0) {
        EXPECT_GE(value, previous) << "step " << i;
      } else {
        EXPECT_LE(value, previous) << "step " << i;
      }
      previous = value;
    }
    EXPECT_EQ(previous, target);
  }
}

}  // namespace
}  // namespace pfap

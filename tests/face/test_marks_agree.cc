// libpfap's blendshapes (pfap/blendshapes.h) agree with what pfapface draws: a viseme's mouth
// is the one pfapface's animator gives it, and each expression's blendshape combination moves
// the features pfapface's own FAP displacements for it move.
#include <gtest/gtest.h>

#include <string>

#include "face/animator.h"
#include "face/model.h"
#include "pfap/blendshapes.h"
#include "pfap/phoneme_table.h"

namespace {

using pfap::Blendshape;
using pfap::Viseme;

pfap::FapAmplitudes amplitudes(const face::FapValues& f) {
  pfap::FapAmplitudes a{};
  for (size_t i = 0; i < a.size(); ++i) a[i] = f[i];
  return a;
}

// For every MPEG-4 viseme: the blendshapes of the FAPs pfapface's animator gives a phoneme of
// that viseme in mid-phoneme equal libpfap's for the viseme on a neutral face.
TEST(MarksAgree, VisemeMouthsAreThoseOfTheAnimator) {
  const pfap::PhonemeAlphabet& arpabet = *pfap::find_alphabet(pfap::kArpabetAlphabet);
  for (int v = 0; v <= 14; ++v) {
    const Viseme viseme = static_cast<Viseme>(v);
    SCOPED_TRACE("viseme " + std::to_string(v));
    std::optional<uint8_t> symbol;
    for (size_t s = 0; s < arpabet.symbols.size() && !symbol; ++s) {
      if (arpabet.symbols[s].viseme == viseme) symbol = static_cast<uint8_t>(s);
    }
    ASSERT_TRUE(symbol.has_value());
    face::Animator animator;
    animator.set_alphabet(&arpabet);
    pfap::MarkupEvent event;
    event.phoneme.symbol = *symbol;
    event.phoneme.duration_ms = 1000;
    animator.apply(event, 0);
    const pfap::BlendshapeWeights drawn =
        pfap::blendshape_weights(amplitudes(animator.faps(500 * pfap::kNsPerMs)), Viseme::kNone);
    const pfap::BlendshapeWeights ours = pfap::blendshape_weights(pfap::FapAmplitudes{}, viseme);
    for (int b = 0; b < pfap::kBlendshapeCount; ++b) {
      if (static_cast<Blendshape>(b) == Blendshape::tongueOut) continue;  // not in FAPs
      EXPECT_NEAR(drawn[b], ours[b], 1e-9) << pfap::blendshape_names()[b];
    }
  }
}

TEST(MarksAgree, ExpressionsMoveWhatPfapfaceMoves) {
  for (int e = 1; e <= 6; ++e) {
    SCOPED_TRACE("expression " + std::to_string(e));
    const int index = pfap::kFirstExpressionIndex - 1 + e;
    face::FapValues displaced{};
    displaced[index] = 63;
    face::add_expressions(displaced);
    displaced[index] = 0;
    const pfap::BlendshapeWeights drawn =
        pfap::blendshape_weights(amplitudes(displaced), Viseme::kNone);
    pfap::FapAmplitudes expression{};
    expression[index] = 63;
    const pfap::BlendshapeWeights ours = pfap::blendshape_weights(expression, Viseme::kNone);
    int checked = 0;
    for (int b = 0; b < pfap::kBlendshapeCount; ++b) {
      const std::string name(pfap::blendshape_names()[b]);
      if (ours[b] < 0.5 || name.starts_with("nose")) continue;  // pfapface has no nose FAPs
      EXPECT_GT(drawn[b], 0.1) << name;
      ++checked;
    }
    EXPECT_GE(checked, 2);
  }
}

}  // namespace

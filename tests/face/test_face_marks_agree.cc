// SPDX-License-Identifier: LGPL-2.1-or-later
// libpfap's blendshapes (pfap/blendshapes.h) agree with what pfapface draws: each expression's
// blendshape combination moves the features pfapface's own FAP displacements for it move. (A
// viseme's mouth is one table, pfap::viseme_mouth, that both use.)
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "face/animator.h"
#include "face/model.h"
#include "pfap/blendshapes.h"
#include "pfap/phoneme_table.h"
#include "pfap/speech_marks.h"
#include "pfap/text.h"

namespace {

using pfap::Blendshape;
using pfap::Viseme;

pfap::FapAmplitudes amplitudes(const pfap::face::FapValues& f) {
  pfap::FapAmplitudes a{};
  for (size_t i = 0; i < a.size(); ++i) a[i] = f[i];
  return a;
}

TEST(MarksAgree, ExpressionsMoveWhatPfapfaceMoves) {
  for (int e = 1; e <= 6; ++e) {
    SCOPED_TRACE("expression " + std::to_string(e));
    const int index = pfap::kFirstExpressionIndex - 1 + e;
    pfap::face::FapValues displaced{};
    displaced[index] = 63;
    pfap::face::add_expressions(displaced);
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

// pfapmarksenc's ARKit frames of a whole session are the blendshapes of the FAPs pfapface's
// animator draws at the same times: the same FAP state, the same mouths eased the same way.
// face.pfap has no expressions, which the two add differently (FAP displacements there,
// blendshape combinations here: ExpressionsMoveWhatPfapfaceMoves).
TEST(MarksAgree, ArkitFramesAreWhatTheAnimatorDraws) {
  std::ifstream file(std::string(PFAP_SOURCE_DIR) + "/docs/examples/face.pfap");
  ASSERT_TRUE(file.good());
  pfap::TextReader reader;
  std::vector<pfap::TextEvent> events;
  std::string line;
  while (std::getline(file, line)) {
    pfap::TextEvent event;
    bool has_event = false;
    ASSERT_TRUE(reader.read_line(line, event, has_event).ok()) << line;
    if (has_event) events.push_back(event);
  }
  ASSERT_GT(events.size(), 10u);

  const pfap::PhonemeAlphabet& arpabet = *pfap::find_alphabet(pfap::kArpabetAlphabet);
  pfap::MarksWriter writer(pfap::MarksFormat::kArkitCsv, 100);
  writer.set_alphabet(&arpabet);
  std::string csv;
  const pfap::MarksWriter::Sink sink = [&csv](std::string_view text) {
    csv += text;
    return true;
  };
  for (const pfap::TextEvent& e : events) {
    ASSERT_TRUE(writer.add(e.event, e.time_ms * pfap::kNsPerMs, sink));
  }
  ASSERT_TRUE(writer.finish(sink));

  std::istringstream rows(csv);
  std::getline(rows, line);  // the header
  pfap::face::Animator animator;
  animator.set_alphabet(&arpabet);
  size_t next = 0;
  int frames = 0;
  while (std::getline(rows, line)) {
    std::istringstream fields(line);
    std::string field;
    std::getline(fields, field, ',');
    const int64_t time_ns = std::llround(std::stod(field) * 1e6);
    // The events before the frame, applied as pfapface applies them.
    while (next < events.size() && events[next].time_ms * pfap::kNsPerMs <= time_ns) {
      animator.apply(events[next].event, events[next].time_ms * pfap::kNsPerMs);
      ++next;
    }
    const pfap::BlendshapeWeights drawn =
        pfap::blendshape_weights(amplitudes(animator.faps(time_ns)), Viseme::kNone);
    for (int b = 0; b < pfap::kBlendshapeCount; ++b) {
      std::getline(fields, field, ',');
      if (static_cast<Blendshape>(b) == Blendshape::tongueOut) continue;  // not in FAPs
      ASSERT_NEAR(std::stod(field), drawn[b], 6e-5)
          << pfap::blendshape_names()[b] << " at " << time_ns / 1e6 << " ms";
    }
    ++frames;
  }
  EXPECT_GT(frames, 300);
}

}  // namespace

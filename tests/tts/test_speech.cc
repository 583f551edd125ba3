// SPDX-License-Identifier: LGPL-2.1-or-later
// speak(): espeak-ng's speech as x-pfap phonemes, checked against the audio and against
// espeak-ng's own transcription.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "corpus.h"
#include "pfap/phoneme_table.h"
#include "speech.h"

namespace pfap::tts {
namespace {

Speech say(const std::string& input, VoiceSettings settings = {}) {
  std::vector<BadBookmark> bad;
  const Utterance u = parse_utterance(input, bad);
  EXPECT_TRUE(bad.empty());
  Speech speech;
  std::string error;
  EXPECT_TRUE(speak(u, settings, speech, error)) << error;
  return speech;
}

std::string name(const SpokenPhoneme& p) {
  return std::string(find_phoneme(*find_alphabet(kArpabetAlphabet), p.event.phoneme.symbol)->name);
}

// The phonemes as "HH AH L 'OW" with ' for stress and | before a word begin; pauses as _.
std::string describe(const Speech& s) {
  std::string out;
  for (const SpokenPhoneme& p : s.phonemes) {
    if (!out.empty()) out += ' ';
    if (p.event.phoneme.word_begin) out += '|';
    if (p.event.phoneme.stress) out += '\'';
    out += p.event.phoneme.symbol == 0 ? "_" : name(p);
  }
  return out;
}

TEST(Speech, PhonemesCoverTheAudio) {
  // At the highest rate espeak-ng's positions step back now and then.
  for (const int rate : {175, 450}) {
    for (const char* voice : {"en", "en-us"}) {
      for (const char* sentence : kCorpus) {
        SCOPED_TRACE(std::string(voice) + " at " + std::to_string(rate) + ": " + sentence);
        const Speech s = say(sentence, {voice, rate, 50, 100});
        ASSERT_EQ(s.sample_rate, 22050u);
        ASSERT_FALSE(s.phonemes.empty());
        uint64_t sum_ms = 0;
        size_t expected_start = 0;
        for (size_t i = 0; i < s.phonemes.size(); ++i) {
          const SpokenPhoneme& p = s.phonemes[i];
          EXPECT_EQ(p.start, expected_start) << "phoneme " << i;
          EXPECT_GT(p.n_samples, 0u) << "phoneme " << i;  // so starts strictly increase
          expected_start = p.start + p.n_samples;
          sum_ms += p.event.phoneme.duration_ms;
        }
        EXPECT_EQ(expected_start, s.samples.size());
        const double audio_ms = 1000.0 * static_cast<double>(s.samples.size()) / s.sample_rate;
        EXPECT_NEAR(static_cast<double>(sum_ms), audio_ms, 20.0);
      }
    }
  }
}

// espeak-ng -x: "h@l'oU w'3:ld", "D@ kw'Ik br'aUn f'0ks dZ'Vmps ,oUv3 D@ l'eIzi d'0g".
TEST(Speech, StressAndWordBeginWhereEspeakTranscribesThem) {
  EXPECT_EQ(describe(say("Hello world.")), "_ |HH AH L 'OW |W 'ER L D _");
  EXPECT_EQ(describe(say("The quick brown fox jumps over the lazy dog.", {"en-us"})),
            "_ |DH AH |K W 'IH K |B R 'AW N |F 'AA K S |JH 'AH M P S |OW V ER |DH AH |L 'EY Z "
            "IY |D 'AA G _");
}

TEST(Speech, SentencesStartAndEndText) {
  const Speech s = say("Hello world. How are you? Fine.");
  std::vector<size_t> starts, ends;
  for (size_t i = 0; i < s.phonemes.size(); ++i) {
    if (s.phonemes[i].event.sentence_start) starts.push_back(i);
    if (s.phonemes[i].event.phoneme.end_of_text) ends.push_back(i);
  }
  ASSERT_EQ(starts.size(), 3u) << describe(s);
  ASSERT_EQ(ends.size(), 3u) << describe(s);
  EXPECT_EQ(starts[0], 0u);
  EXPECT_EQ(ends.back(), s.phonemes.size() - 1);
  for (size_t k = 0; k + 1 < starts.size(); ++k) EXPECT_EQ(ends[k] + 1, starts[k + 1]);
}

// The FAP index of each bookmark names the phoneme it should land on.
TEST(Speech, BookmarksFollowTheMpegRule) {
  const Speech s =
      say("<FAP 3 1 0 1>Hello <FAP 4 1 0 1> world <FAP 5 1 0 1>. <FAP 6 1 0 1> How are you "
          "<FAP 7 1 0 1>?<FAP 8 1 0 1>");
  const std::string d = describe(s);
  SCOPED_TRACE(d);
  auto index_of_fap = [&](int fap) -> int {
    for (size_t i = 0; i < s.phonemes.size(); ++i) {
      for (const Fap& f : s.phonemes[i].event.faps) {
        if (f.index == fap) return static_cast<int>(i);
      }
    }
    return -1;
  };
  auto word_begins = [&] {
    std::vector<int> w;
    for (size_t i = 0; i < s.phonemes.size(); ++i) {
      if (s.phonemes[i].event.phoneme.word_begin) w.push_back(static_cast<int>(i));
    }
    return w;
  }();
  ASSERT_EQ(word_begins.size(), 5u);  // Hello world How are you
  const int hello = word_begins[0], world = word_begins[1], how = word_begins[2],
            you = word_begins[4];
  EXPECT_EQ(index_of_fap(3), hello) << "before the first word";
  EXPECT_EQ(index_of_fap(4), world) << "between words: the next word's first phoneme";
  EXPECT_EQ(index_of_fap(5), how - 3) << "before the full stop: world's last phoneme (D)";
  ASSERT_GE(index_of_fap(5), 0);
  EXPECT_EQ(name(s.phonemes[index_of_fap(5)]), "D");
  EXPECT_EQ(index_of_fap(6), how) << "after the full stop: the next sentence's first word";
  EXPECT_EQ(index_of_fap(7), you + 1) << "before the question mark: you's last phoneme";
  ASSERT_GE(index_of_fap(7), 0);
  EXPECT_EQ(name(s.phonemes[index_of_fap(7)]), "UW");
  EXPECT_EQ(index_of_fap(8), you + 1) << "at the end of the text: you's last phoneme";
}

// espeak-ng 1.51 drops an SSML mark that follows a sentence-final full stop and more text;
// bookmarks here never go through SSML, so such a bookmark is placed like any other.
TEST(Speech, BookmarkAfterAFullStopBeforeMoreText) {
  const Speech s = say("Stop. <FAP 19 1 0 1>Go on.");
  int with_fap = -1, second_sentence = -1;
  for (size_t i = 0; i < s.phonemes.size(); ++i) {
    if (!s.phonemes[i].event.faps.empty()) with_fap = static_cast<int>(i);
    if (i > 0 && s.phonemes[i].event.sentence_start && second_sentence < 0) {
      second_sentence = static_cast<int>(i);
    }
  }
  EXPECT_EQ(with_fap, second_sentence) << describe(s);
  ASSERT_GE(with_fap, 0) << describe(s);
  EXPECT_EQ(name(s.phonemes[with_fap]), "G");
}

TEST(Speech, OnlyBookmarksGiveOnePause) {
  const Speech s = say("<FAP 3 1 0 1>");
  ASSERT_FALSE(s.phonemes.empty());
  EXPECT_EQ(s.phonemes[0].event.faps.size(), 1u);
}

double mean_voiced_f0(const Speech& s) {
  double sum = 0;
  int n = 0;
  for (const SpokenPhoneme& p : s.phonemes) {
    if (p.event.phoneme.f0 == 0) continue;
    sum += p.event.phoneme.f0_hz();
    ++n;
  }
  return n > 0 ? sum / n : 0;
}

TEST(Speech, F0FollowsThePitchSetting) {
  const std::string text = "The birch canoe slid on the smooth planks.";
  const Speech low = say(text, {"en", 175, 20, 100});
  const Speech high = say(text, {"en", 175, 80, 100});
  const double f_low = mean_voiced_f0(low), f_high = mean_voiced_f0(high);
  std::printf("mean f0 of voiced phonemes: pitch 20 %.1f Hz, pitch 80 %.1f Hz\n", f_low, f_high);
  EXPECT_GT(f_low, 60.0);
  EXPECT_GT(f_high, f_low * 1.15);
  // Vowels are voiced; the pauses around the sentence are not.
  int vowels = 0, voiced_vowels = 0;
  for (const SpokenPhoneme& p : low.phonemes) {
    const std::string n = p.event.phoneme.symbol == 0 ? "_" : name(p);
    if (std::string("AEIOU").find(n[0]) == std::string::npos) continue;
    ++vowels;
    voiced_vowels += p.event.phoneme.f0 > 0;
  }
  EXPECT_GE(voiced_vowels * 10, vowels * 9) << voiced_vowels << " of " << vowels;
  EXPECT_EQ(low.phonemes.front().event.phoneme.f0, 0);
}

// A phoneme of 10 s (from 1 s into the utterance) goes as 4095 + 4095 + 1810 ms, contiguous.
TEST(Speech, LongPhonemesAreSplit) {
  MarkupEvent e;
  e.phoneme = {22, 0, 60, true, true, true};
  e.sentence_start = true;
  e.faps = {{69, 40, 500, Curve::kLinear}};
  std::vector<SpokenPhoneme> out;
  add_phoneme(e, 22050, 11 * 22050, 22050, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].event.phoneme.duration_ms, 4095);
  EXPECT_EQ(out[1].event.phoneme.duration_ms, 4095);
  EXPECT_EQ(out[2].event.phoneme.duration_ms, 1810);
  size_t at = 22050;
  for (const SpokenPhoneme& p : out) {
    EXPECT_EQ(p.start, at);
    at += p.n_samples;
    // Each piece's start is on the ms grid of its duration.
    EXPECT_NEAR(static_cast<double>(p.n_samples) * 1000 / 22050, p.event.phoneme.duration_ms, 0.5);
  }
  EXPECT_EQ(at, 11u * 22050);
  EXPECT_EQ(out[0].event.faps.size(), 1u);
  EXPECT_TRUE(out[0].event.sentence_start && out[0].event.phoneme.word_begin);
  EXPECT_TRUE(out[1].event.faps.empty() && !out[1].event.sentence_start);
  EXPECT_FALSE(out[1].event.phoneme.end_of_text);
  EXPECT_TRUE(out[2].event.phoneme.end_of_text && !out[2].event.phoneme.stress);
}

// A short one: from 0.41 ms to 80.59 ms is from 0 to 81 on the utterance's ms grid.
TEST(Speech, DurationsOnTheUtterancesMsGrid) {
  MarkupEvent e;
  std::vector<SpokenPhoneme> out;
  add_phoneme(e, 9, 1777, 22050, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].event.phoneme.duration_ms, 81);
  EXPECT_EQ(out[0].n_samples, 1768u);
}

// espeak-ng keeps its wave generator's pitch flutter and roughness from one synthesis to the
// next (issue 31): each synthesis must give the same audio and phonemes whatever was spoken
// before it, in another voice or at another rate.
TEST(Speech, SameTextGivesTheSameSpeechWhateverWasSpokenBefore) {
  const std::string text = "Always remember the open ocean.";
  const Speech first = say(text);
  for (const VoiceSettings& before :
       {VoiceSettings{}, VoiceSettings{"en-us", 140, 60, 100}, VoiceSettings{"de", 300, 20, 150}}) {
    SCOPED_TRACE(before.voice + " at " + std::to_string(before.rate));
    say("The quick brown fox jumps over the lazy dog near the river bank.", before);
    const Speech again = say(text);
    EXPECT_EQ(again.samples, first.samples);
    ASSERT_EQ(again.phonemes.size(), first.phonemes.size());
    for (size_t i = 0; i < first.phonemes.size(); ++i) {
      EXPECT_EQ(again.phonemes[i].start, first.phonemes[i].start) << "phoneme " << i;
      EXPECT_EQ(again.phonemes[i].n_samples, first.phonemes[i].n_samples) << "phoneme " << i;
      EXPECT_EQ(again.phonemes[i].event.phoneme.f0, first.phonemes[i].event.phoneme.f0);
    }
  }
}

TEST(Speech, UnknownVoiceIsAnError) {
  Speech s;
  std::string error;
  EXPECT_FALSE(speak({}, {"no-such-voice"}, s, error));
  EXPECT_NE(error.find("no-such-voice"), std::string::npos) << error;
}

}  // namespace
}  // namespace pfap::tts

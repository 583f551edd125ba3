// SPDX-License-Identifier: LGPL-2.1-or-later
// pfapalign's cutting of the audio into utterances (align/utterances.h), offline and live,
// its reading of S16LE, the audio it keeps offline and the text pad's queue.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "recognizer.h"
#include "speech_fixtures.h"
#include "utterances.h"

namespace {

using pfap::align::TimedText;
using pfap::align::UtteranceSpan;
namespace tts = pfap::tts;

struct Expected {
  size_t from;
  size_t to;
  std::string text;
  bool is_text;
};

void expect_spans(const std::vector<UtteranceSpan>& got, const std::vector<Expected>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(got[i].from, want[i].from);
    EXPECT_EQ(got[i].to, want[i].to);
    EXPECT_EQ(got[i].text, want[i].text);
    EXPECT_EQ(got[i].is_text, want[i].is_text);
  }
}

TEST(Utterances, TextsComeFirstThenTheRecognizerThenAPause) {
  using pfap::align::PhonemeSource;
  EXPECT_EQ(pfap::align::phoneme_source(true), PhonemeSource::kTexts);
  EXPECT_EQ(pfap::align::phoneme_source(false), pfap::align::recognition_available()
                                                    ? PhonemeSource::kRecognition
                                                    : PhonemeSource::kPause);
  // recognizer=visemes: the detector, in any build, and only without a text.
  EXPECT_EQ(pfap::align::phoneme_source(false, pfap::align::Recognizer::kVisemes),
            PhonemeSource::kVisemes);
  EXPECT_EQ(pfap::align::phoneme_source(true, pfap::align::Recognizer::kVisemes),
            PhonemeSource::kTexts);
}

// The detector's phonemes are its visemes; the rest x-pfap-arpabet. Live, each source
// declares its own latency: a pause is aligned as a text is.
TEST(Utterances, EachSourceHasItsAlphabetAndLiveLatency) {
  using pfap::align::PhonemeSource;
  EXPECT_EQ(pfap::align::alphabet_of(PhonemeSource::kVisemes), "x-pfap-oculus-viseme");
  for (const PhonemeSource source :
       {PhonemeSource::kTexts, PhonemeSource::kRecognition, PhonemeSource::kPause}) {
    EXPECT_EQ(pfap::align::alphabet_of(source), "x-pfap-arpabet");
  }
  EXPECT_EQ(pfap::align::live_latency_ms(PhonemeSource::kTexts), 400u);
  EXPECT_EQ(pfap::align::live_latency_ms(PhonemeSource::kPause), 400u);
  EXPECT_EQ(pfap::align::live_latency_ms(PhonemeSource::kRecognition), 700u);
  EXPECT_EQ(pfap::align::live_latency_ms(PhonemeSource::kVisemes), 95u);
}

// The aligner takes 16 to 48 kHz; the viseme detector, where it has the stream, 8 to 192.
TEST(Utterances, RatesOutsideWhatHearsTheAudioAreAProblem) {
  using pfap::align::RateProblem;
  using pfap::align::Recognizer;
  EXPECT_EQ(pfap::align::rate_problem(15999, Recognizer::kPhonemes), RateProblem::kCannotAlign);
  EXPECT_EQ(pfap::align::rate_problem(16000, Recognizer::kPhonemes), RateProblem::kNone);
  EXPECT_EQ(pfap::align::rate_problem(48000, Recognizer::kPhonemes), RateProblem::kNone);
  EXPECT_EQ(pfap::align::rate_problem(48001, Recognizer::kPhonemes), RateProblem::kCannotAlign);
  EXPECT_EQ(pfap::align::rate_problem(7999, Recognizer::kVisemes),
            RateProblem::kCannotDetectVisemes);
  EXPECT_EQ(pfap::align::rate_problem(8000, Recognizer::kVisemes), RateProblem::kNone);
  EXPECT_EQ(pfap::align::rate_problem(192000, Recognizer::kVisemes), RateProblem::kNone);
  EXPECT_EQ(pfap::align::rate_problem(192001, Recognizer::kVisemes),
            RateProblem::kCannotDetectVisemes);
}

// Without a text, silence is heard as pauses by each source; a build without pocketsphinx
// says it cannot recognize (kPause) or cannot load the model (kRecognition).
TEST(Utterances, WithoutATextTheAudioIsHeardOrAPause) {
  using pfap::align::PhonemeSource;
  const unsigned rate = 16000;
  const std::vector<int16_t> silence(rate, 0);
  const bool available = pfap::align::recognition_available();
  pfap::align::Heard heard;
  std::string error;

  ASSERT_TRUE(pfap::align::hear(silence, rate, PhonemeSource::kVisemes, heard, error));
  pfap::align::testing::expect_tiles(heard.phonemes, silence.size(), rate);
  EXPECT_FALSE(heard.cannot_recognize);

  ASSERT_TRUE(pfap::align::hear(silence, rate, PhonemeSource::kPause, heard, error));
  pfap::align::testing::expect_tiles(heard.phonemes, silence.size(), rate);
  EXPECT_EQ(heard.cannot_recognize, !available);

  EXPECT_EQ(pfap::align::hear(silence, rate, PhonemeSource::kRecognition, heard, error), available);
  if (available) {
    pfap::align::testing::expect_tiles(heard.phonemes, silence.size(), rate);
    EXPECT_EQ(heard.problem, pfap::align::RecognitionProblem::kNoSpeech);
    EXPECT_FALSE(heard.cannot_recognize);
  } else {
    EXPECT_FALSE(error.empty());
  }
}

TEST(Utterances, NoTextAtAllIsToBeRecognized) {
  std::vector<TimedText> texts;
  std::vector<size_t> later;
  EXPECT_TRUE(pfap::align::utterances_of(texts, std::nullopt, 1000, true, later).empty());
  EXPECT_TRUE(later.empty());
}

TEST(Utterances, TheWholeTextCoversTheAudio) {
  std::vector<TimedText> texts;
  std::vector<size_t> later;
  expect_spans(pfap::align::utterances_of(texts, std::string("Hello."), 1000, true, later),
               {{0, 1000, "Hello.", true}});
}

TEST(Utterances, TextsWithoutATimeContinueTheOneBefore) {
  // A file read in blocks: the first block starts at 0, the others continue it.
  std::vector<TimedText> texts = {
      {std::nullopt, "Hel"}, {std::nullopt, "lo."}, {500, "Bye."}, {std::nullopt, " Now."}};
  std::vector<size_t> later;
  expect_spans(pfap::align::utterances_of(texts, std::nullopt, 1000, false, later),
               {{0, 500, "Hello.", true}, {500, 1000, "Bye. Now.", true}});
}

TEST(Utterances, TheAudioBeforeTheFirstTextIsAPauseAndTextsAreSorted) {
  std::vector<TimedText> texts = {{700, "Two."}, {300, "One."}};
  std::vector<size_t> later;
  expect_spans(pfap::align::utterances_of(texts, std::nullopt, 1000, false, later),
               {{0, 300, "", false}, {300, 700, "One.", true}, {700, 1000, "Two.", true}});
}

TEST(Utterances, TextsBeyondTheAudioWaitUntilTheEnd) {
  std::vector<TimedText> texts = {{100, "Now."}, {1000, "Later."}, {5000, "Much later."}};
  std::vector<size_t> later;
  const auto spans = pfap::align::utterances_of(texts, std::nullopt, 1000, false, later);
  expect_spans(spans, {{0, 100, "", false}, {100, 1000, "Now.", true}});
  EXPECT_EQ(later, (std::vector<size_t>{1, 2}));
  EXPECT_EQ(texts[1].bytes, "Later.");  // left for the caller to keep
  EXPECT_EQ(texts[2].bytes, "Much later.");

  // At the end of the stream they start at the audio's end, empty.
  std::vector<TimedText> at_end = {{100, "Now."}, {5000, "Much later."}};
  later.clear();
  expect_spans(pfap::align::utterances_of(at_end, std::nullopt, 1000, true, later),
               {{0, 100, "", false}, {100, 1000, "Now.", true}, {1000, 1000, "Much later.", true}});
  EXPECT_TRUE(later.empty());
}

TEST(Utterances, LiveTextsStartNoEarlierThanTheAudioSoFar) {
  std::vector<TimedText> texts = {{900, "Late in the block."},
                                  {std::nullopt, "No time."},
                                  {100, "Came late."},
                                  {2000, "Next."}};
  std::vector<size_t> later;
  expect_spans(pfap::align::live_utterances_before(texts, 500, 1000, later),
               {{500, 1000, "No time.", true},
                {500, 1000, "Came late.", true},
                {900, 1000, "Late in the block.", true}});
  EXPECT_EQ(later, (std::vector<size_t>{3}));
  EXPECT_EQ(texts[3].bytes, "Next.");
}

TEST(Utterances, S16leIsLittleEndianSignedAndCapped) {
  const std::vector<uint8_t> bytes = {0x01, 0x00, 0xff, 0xff, 0x00, 0x80, 0xff, 0x7f, 0x42};
  std::vector<int16_t> samples = {7};
  pfap::align::append_s16le(bytes, 100, samples);
  EXPECT_EQ(samples, (std::vector<int16_t>{7, 1, -1, -32768, 32767}));  // the odd byte left out
  pfap::align::append_s16le(bytes, 2, samples);
  EXPECT_EQ(samples, (std::vector<int16_t>{7, 1, -1, -32768, 32767, 1, -1}));
}

TEST(Utterances, KeptAudioStopsAtTheLimitAndSaysSoOnce) {
  pfap::align::KeptAudio kept;
  constexpr unsigned kRate = 100;  // the limit: kMaxAudioSeconds * 100 samples
  const size_t limit = size_t{pfap::align::kMaxAudioSeconds} * kRate;
  const std::vector<uint8_t> second(2 * kRate, 0x01);  // 0x0101 each
  for (size_t i = 0; i + 1 < pfap::align::kMaxAudioSeconds; ++i) {
    EXPECT_FALSE(kept.append(second, kRate));
  }
  const std::vector<uint8_t> more(2 * kRate + 3, 0x02);  // one second, a sample and a byte
  EXPECT_TRUE(kept.append(more, kRate));
  EXPECT_FALSE(kept.append(more, kRate));  // said once
  ASSERT_EQ(kept.samples().size(), limit);
  EXPECT_EQ(kept.samples().front(), 0x0101);
  EXPECT_EQ(kept.samples().back(), 0x0202);
  kept.reset();
  EXPECT_TRUE(kept.samples().empty());
  EXPECT_FALSE(kept.append(second, kRate));
  EXPECT_EQ(kept.samples().size(), kRate);
}

TEST(Utterances, TextQueueKeepsOrderAndWaitsForTheEndOrAFlush) {
  using pfap::align::PadText;
  pfap::align::TextQueue queue;
  EXPECT_TRUE(queue.ready(false));
  queue.add({std::nullopt, "a"});
  queue.add({7, "b"});
  std::vector<PadText> taken = queue.take();
  ASSERT_EQ(taken.size(), 2u);
  queue.add({9, "c"});
  queue.put_back({std::move(taken[1])});  // "b" before "c", added since
  taken = queue.take();
  ASSERT_EQ(taken.size(), 2u);
  EXPECT_EQ(taken[0].bytes, "b");
  EXPECT_EQ(taken[0].running_time, 7u);
  EXPECT_EQ(taken[1].bytes, "c");
  EXPECT_TRUE(queue.take().empty());

  // The wait ends at the text pad's end, from another thread.
  std::thread ender([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    queue.add({std::nullopt, "last"});
    queue.end();
  });
  EXPECT_TRUE(queue.ready(true));
  ender.join();
  EXPECT_EQ(queue.take().size(), 1u);
  // The text pad's flush: not ended any more, its texts gone.
  queue.add({std::nullopt, "dropped"});
  queue.clear();
  EXPECT_TRUE(queue.take().empty());

  // A flush ends the wait, false, until reset().
  std::thread flusher([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    queue.flush();
  });
  EXPECT_FALSE(queue.ready(true));
  flusher.join();
  EXPECT_FALSE(queue.ready(false));
  queue.reset();
  EXPECT_TRUE(queue.ready(false));
}

// The queue cuts its texts as utterances_of() and live_utterances_before() do, at the samples
// the element's timeline gives, and keeps those for audio still to come, in order.
TEST(Utterances, TextQueueCutsItsTextsAndKeepsThoseStillToCome) {
  pfap::align::TextQueue queue;
  const auto to_sample = [](std::optional<uint64_t> t) -> std::optional<size_t> {
    if (!t) return std::nullopt;
    return static_cast<size_t>(*t / 10);
  };
  queue.add({1000, "first"});
  queue.add({std::nullopt, " more"});
  queue.add({5000, "later"});
  queue.add({7000, "last"});
  expect_spans(queue.take_utterances(to_sample, std::nullopt, 300, false),
               {{0, 100, "", false}, {100, 300, "first more", true}});
  // Live: from the audio so far (400), those starting before 600.
  expect_spans(queue.take_live_utterances(to_sample, 400, 600), {{500, 600, "later", true}});
  expect_spans(queue.take_utterances(to_sample, std::nullopt, 800, true),
               {{0, 700, "", false}, {700, 800, "last", true}});
  EXPECT_TRUE(queue.take().empty());
}

TEST(Utterances, LivePhonemesCountFromTheStreamsStartAndTileIt) {
  const tts::Speech one = pfap::align::testing::say("Hello world.", {});
  const tts::Speech two = pfap::align::testing::say("Good morning.", {});
  const unsigned rate = one.sample_rate;
  pfap::align::LiveUtterances live;
  std::vector<tts::SpokenPhoneme> out;
  std::string error;
  EXPECT_FALSE(live.is_open());
  ASSERT_TRUE(live.start_text(pfap::align::testing::utterance("Hello world."), {}, rate, error))
      << error;
  EXPECT_TRUE(live.is_open());
  EXPECT_FALSE(live.is_recognizing());
  const size_t block = rate / 50;
  for (size_t i = 0; i < one.samples.size(); i += block) {
    live.push(std::span(one.samples).subspan(i, std::min(block, one.samples.size() - i)), out);
  }
  live.end(out);
  EXPECT_FALSE(live.is_open());
  const size_t first_count = out.size();
  ASSERT_TRUE(live.start_text(pfap::align::testing::utterance("Good morning."), {}, rate, error))
      << error;
  EXPECT_EQ(live.utterance_start(), one.samples.size());
  for (size_t i = 0; i < two.samples.size(); i += block) {
    live.push(std::span(two.samples).subspan(i, std::min(block, two.samples.size() - i)), out);
  }
  live.end(out);
  live.end(out);  // nothing open: nothing more
  EXPECT_EQ(live.samples(), one.samples.size() + two.samples.size());

  ASSERT_GT(out.size(), first_count);
  EXPECT_EQ(out[first_count].start, one.samples.size());  // the second from its first sample
  size_t next = 0;
  for (const tts::SpokenPhoneme& p : out) {
    EXPECT_EQ(p.start, next);
    next = p.start + p.n_samples;
  }
  EXPECT_EQ(next, live.samples());

  live.reset();
  EXPECT_EQ(live.samples(), 0u);
  EXPECT_FALSE(live.is_open());
}

// Without a text, the live utterance is heard to the stream's end: by the viseme detector, or
// by pocketsphinx where the build has it.
TEST(Utterances, LiveUtterancesHeardWithoutATextAreTheRecognizersOrTheDetectors) {
  const unsigned rate = 16000;
  const std::vector<int16_t> silence(rate, 0);
  std::vector<tts::SpokenPhoneme> out;
  std::string error;
  pfap::align::LiveUtterances visemes;
  ASSERT_TRUE(visemes.start_heard(pfap::align::Recognizer::kVisemes, rate, error)) << error;
  EXPECT_TRUE(visemes.is_open());
  EXPECT_FALSE(visemes.is_recognizing());
  visemes.push(silence, out);
  visemes.end(out);
  EXPECT_FALSE(visemes.is_open());
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.front().start, 0u);
  EXPECT_EQ(out.back().start + out.back().n_samples, silence.size());

  pfap::align::LiveUtterances phonemes;
  const bool available = pfap::align::recognition_available();
  EXPECT_EQ(phonemes.start_heard(pfap::align::Recognizer::kPhonemes, rate, error), available);
  EXPECT_EQ(phonemes.is_recognizing(), available);
  EXPECT_EQ(error.empty(), available);
}

}  // namespace

// SPDX-License-Identifier: LGPL-2.1-or-later
// The frame-level viseme detector (align/viseme_detector.h): agreement with espeak-ng's own
// phoneme times on sentences in a voice it was not trained on, the runs tiling the audio
// whatever the blocks, the lookahead it declares, and bad input (silence, noise, clipping,
// other rates, a broken model) giving a clear result in bounded work; and its runs as
// pfapalign's phonemes (align/viseme_phonemes.h), with the live bound they keep.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "boundaries.h"
#include "speech_fixtures.h"
#include "viseme_detector.h"
#include "viseme_frames.h"
#include "viseme_phonemes.h"

namespace pfap::align {
namespace {

// Three Harvard sentences (tools/align-sentences.txt, the held-out texts) in espeak-ng's
// en-us+f2, a variant held out of the training (tools/viseme-corpus).
const char* const kSentences[] = {
    "The birch canoe slid on the smooth planks.",
    "Glue the sheet to the dark blue background.",
    "It's easy to tell the depth of a well.",
};

struct Spoken {
  std::vector<int16_t> samples;
  unsigned rate = 0;
  std::vector<Viseme> truth;  // each 10 ms frame's, from the phonemes in phonetic convention
};

Spoken spoken(const char* text) {
  tts::VoiceSettings voice;
  voice.voice = "en-us+f2";
  voice.rate = 165;
  voice.pitch = 55;
  tts::Speech speech = testing::say(text, voice);
  to_phonetic_boundaries(speech);
  std::vector<TimedSymbol> phonemes;
  for (const tts::SpokenPhoneme& p : speech.phonemes) {
    phonemes.push_back({static_cast<double>(p.start) / speech.sample_rate, p.event.phoneme.symbol});
  }
  const double seconds = static_cast<double>(speech.samples.size()) / speech.sample_rate;
  return {speech.samples, speech.sample_rate, viseme_frames(phonemes, seconds)};
}

std::vector<VisemeRun> detect(std::span<const int16_t> samples, unsigned rate, size_t block,
                              size_t max_run_frames = 0) {
  VisemeDetector detector(rate, max_run_frames);
  std::vector<VisemeRun> runs;
  for (size_t i = 0; i < samples.size(); i += block) {
    detector.push(samples.subspan(i, std::min(block, samples.size() - i)), runs);
  }
  detector.finish(runs);
  return runs;
}

std::vector<Viseme> frames_of(const std::vector<VisemeRun>& runs) {
  std::vector<Viseme> out;
  for (const VisemeRun& r : runs) out.insert(out.end(), r.frames, r.viseme);
  return out;
}

// The runs are contiguous from frame 0 and cover every 10 ms frame of `seconds` (the last
// partly), none empty.
void expect_tiles(const std::vector<VisemeRun>& runs, double seconds) {
  uint64_t next = 0;
  for (const VisemeRun& r : runs) {
    EXPECT_EQ(r.start, next);
    EXPECT_GT(r.frames, 0u);
    next = r.start + r.frames;
  }
  EXPECT_EQ(next, static_cast<uint64_t>(std::ceil(seconds * 100 - 1e-9)));
}

TEST(VisemeDetector, HeldOutVoiceAgreesWithItsPhonemesWellAboveTheBaseline) {
  size_t same = 0, frames = 0, pauses = 0, runs_total = 0;
  double seconds = 0;
  for (const char* text : kSentences) {
    const Spoken s = spoken(text);
    const std::vector<VisemeRun> runs = detect(s.samples, s.rate, s.rate / 50);
    expect_tiles(runs, static_cast<double>(s.samples.size()) / s.rate);
    const std::vector<Viseme> got = frames_of(runs);
    for (size_t f = 0; f < std::min(got.size(), s.truth.size()); ++f) {
      same += got[f] == s.truth[f];
      pauses += s.truth[f] == Viseme::kNone;
      ++frames;
    }
    runs_total += runs.size();
    seconds += static_cast<double>(s.samples.size()) / s.rate;
  }
  const double agreement = static_cast<double>(same) / static_cast<double>(frames);
  std::printf("agreement %.1f %% of %zu frames (pauses %.1f %%), %.1f runs a second\n",
              100 * agreement, frames, 100.0 * static_cast<double>(pauses) / frames,
              static_cast<double>(runs_total) / seconds);
  // Measured 73.5 % on these (docs/align.md); the baseline of one viseme is under 20 %.
  EXPECT_GT(agreement, 0.50);
  // Smoothed: about 10 runs a second, not a flicker every frame or two.
  EXPECT_LT(static_cast<double>(runs_total) / seconds, 20);
}

TEST(VisemeDetector, BlocksOfAnySizeGiveTheSameRuns) {
  const Spoken s = spoken(kSentences[0]);
  const std::vector<VisemeRun> whole = detect(s.samples, s.rate, s.samples.size());
  for (size_t block : {size_t{1}, size_t{7}, size_t{441}, size_t{4096}}) {
    const std::vector<VisemeRun> runs = detect(s.samples, s.rate, block);
    ASSERT_EQ(runs.size(), whole.size()) << block;
    for (size_t k = 0; k < runs.size(); ++k) {
      EXPECT_EQ(runs[k].start, whole[k].start);
      EXPECT_EQ(runs[k].frames, whole[k].frames);
      EXPECT_EQ(runs[k].viseme, whole[k].viseme);
    }
  }
}

TEST(VisemeDetector, SettlesEachFrameWithinTheDeclaredLookahead) {
  EXPECT_LE(kVisemeLookaheadMs, 60);
  for (unsigned rate : {8000u, 16000u, 22050u, 44100u, 48000u}) {
    const Spoken s = spoken(kSentences[1]);
    const std::vector<int16_t> audio = testing::resample(s.samples, s.rate, rate);
    VisemeDetector detector(rate);
    std::vector<VisemeRun> runs;
    const size_t block = rate / 100;  // 10 ms
    for (size_t i = 0; i < audio.size(); i += block) {
      detector.push(std::span(audio).subspan(i, std::min(block, audio.size() - i)), runs);
      const double ms = static_cast<double>(std::min(i + block, audio.size())) * 1000 / rate;
      // Every frame ending kVisemeLookaheadMs or more before the newest sample is settled.
      const auto due = static_cast<uint64_t>(std::max(0.0, (ms - kVisemeLookaheadMs) / 10));
      ASSERT_GE(detector.frames(), due) << rate << " Hz at " << ms << " ms";
    }
  }
}

TEST(VisemeDetector, PiecesKeepEveryRunWithinTheLimit) {
  std::vector<int16_t> audio(16000 * 2, 0);  // two seconds of silence, then speech
  const Spoken s = spoken(kSentences[2]);
  const std::vector<int16_t> speech = testing::resample(s.samples, s.rate, 16000);
  audio.insert(audio.end(), speech.begin(), speech.end());
  const std::vector<VisemeRun> whole = detect(audio, 16000, 320);
  const std::vector<VisemeRun> pieces = detect(audio, 16000, 320, 5);
  EXPECT_TRUE(std::all_of(pieces.begin(), pieces.end(),
                          [](const VisemeRun& r) { return r.frames <= 5; }));
  EXPECT_EQ(frames_of(pieces), frames_of(whole));
  EXPECT_GT(pieces.size(), whole.size());
}

TEST(VisemeDetector, SilenceIsOnePause) {
  for (unsigned rate : {16000u, 48000u}) {
    const std::vector<int16_t> silence(rate * 3, 0);
    const std::vector<VisemeRun> runs = detect(silence, rate, rate / 50);
    ASSERT_EQ(runs.size(), 1u);
    EXPECT_EQ(runs[0].viseme, Viseme::kNone);
    expect_tiles(runs, 3);
  }
  EXPECT_TRUE(detect(std::vector<int16_t>{}, 16000, 320).empty());
}

TEST(VisemeDetector, NoiseTilesTheAudioInFewRuns) {
  // White noise at about -20 dBFS and a low hiss at about -60 dBFS: no speech to follow, so
  // the runs must be few (no flicker), whatever visemes they show.
  std::mt19937 rng(30);
  for (double level : {3000.0, 30.0}) {
    std::normal_distribution<double> noise(0, level);
    std::vector<int16_t> audio(16000 * 3);
    for (int16_t& x : audio) x = static_cast<int16_t>(std::clamp(noise(rng), -32768.0, 32767.0));
    const std::vector<VisemeRun> runs = detect(audio, 16000, 320);
    expect_tiles(runs, 3);
    std::printf("noise of sd %.0f: %zu runs in 3 s, first viseme %d\n", level, runs.size(),
                static_cast<int>(runs[0].viseme));
    EXPECT_LT(runs.size(), 30u) << level;
  }
}

TEST(VisemeDetector, ClippedAndResampledSpeechStillAgrees) {
  const Spoken s = spoken(kSentences[0]);
  auto agreement = [&](const std::vector<VisemeRun>& runs) {
    return viseme_agreement(frames_of(runs), s.truth);
  };
  const double plain = agreement(detect(s.samples, s.rate, 441));
  // Clipped: 12 dB louder, the peaks cut at full scale.
  std::vector<int16_t> clipped(s.samples.size());
  std::transform(s.samples.begin(), s.samples.end(), clipped.begin(), [](int16_t x) {
    return static_cast<int16_t>(std::clamp(x * 4, -32768, 32767));
  });
  const double clip = agreement(detect(clipped, s.rate, 441));
  std::printf("agreement: as spoken (%u Hz) %.2f, clipped %.2f", s.rate, plain, clip);
  EXPECT_GT(clip, plain - 0.2);
  for (unsigned rate : {8000u, 16000u, 44100u, 48000u}) {
    const std::vector<int16_t> audio = testing::resample(s.samples, s.rate, rate);
    const std::vector<VisemeRun> runs = detect(audio, rate, rate / 50);
    expect_tiles(runs, static_cast<double>(audio.size()) / rate);
    const double a = agreement(runs);
    std::printf(", %u Hz %.2f", rate, a);
    // 8 kHz audio has nothing above 4 kHz, where the mel bands up to 7.6 kHz look; the
    // training has telephone copies at 8 kHz (measured 0.63 against 0.72; 0.05 before them).
    EXPECT_GT(a, plain - (rate == 8000 ? 0.25 : 0.15)) << rate;
  }
  std::printf("\n");
}

// A thin microphone's tilt (a first difference, 0.95: high frequencies 20 dB over the low)
// moves c1..c12 alike in every frame; the running cepstral mean takes it out as the stream
// goes (here the three sentences in one stream, 7 s). Measured: plain 74 %, tilted 73 %;
// without the mean (the model before it), 63 % and 36 %.
TEST(VisemeDetector, AMicrophonesTiltCostsLittle) {
  std::vector<int16_t> stream;
  std::vector<Viseme> truth;
  unsigned rate = 0;
  for (const char* text : kSentences) {
    // Each sentence padded with silence to whole 20 ms, so that its frames stay its own.
    Spoken s = spoken(text);
    const size_t block = s.rate / 50;
    s.samples.resize((s.samples.size() + block - 1) / block * block, 0);
    s.truth.resize(s.samples.size() / block * 2, Viseme::kNone);
    stream.insert(stream.end(), s.samples.begin(), s.samples.end());
    truth.insert(truth.end(), s.truth.begin(), s.truth.end());
    rate = s.rate;
  }
  std::vector<int16_t> tilted(stream.size());
  for (size_t i = 0; i < stream.size(); ++i) {
    const double previous = i > 0 ? stream[i - 1] : 0;
    tilted[i] = static_cast<int16_t>(std::clamp(stream[i] - 0.95 * previous, -32768.0, 32767.0));
  }
  const double plain = viseme_agreement(frames_of(detect(stream, rate, rate / 50)), truth);
  const double tilt = viseme_agreement(frames_of(detect(tilted, rate, rate / 50)), truth);
  std::printf("agreement: plain %.2f, tilted %.2f\n", plain, tilt);
  EXPECT_GT(tilt, plain - 0.1);
}

TEST(VisemeDetector, CepstralMeanFollowsTheFramesOfSound) {
  std::vector<float> prior(kVisemeMfccs - 1, 1.0f);
  CepstralMean mean(prior);
  // A frame of sound whose c1..c12 are 3 over the prior: its first copy moves the mean 1 /
  // kCepstralPriorFrames of the way, and after half a minute of it the frame reads as the prior.
  std::vector<float> sound(kVisemeMfccs, 4.0f);
  sound[0] = 0;
  std::vector<float> frame = sound;
  mean.apply(frame);
  EXPECT_EQ(frame[0], 0.0f);
  EXPECT_NEAR(frame[1], 4.0 - 3.0 / kCepstralPriorFrames, 1e-5);
  for (int k = 0; k < 3000; ++k) frame = sound, mean.apply(frame);
  for (size_t i = 1; i < kVisemeMfccs; ++i) EXPECT_NEAR(frame[i], 1.0, 0.01) << i;
  // Quiet frames leave the mean where it is: a pause does not pull it.
  std::vector<float> quiet(kVisemeMfccs, -20.0f);
  quiet[0] = static_cast<float>(kCepstralSoundC0) - 1;
  for (int k = 0; k < 1000; ++k) frame = quiet, mean.apply(frame);
  frame = sound;
  mean.apply(frame);
  EXPECT_NEAR(frame[1], 1.0, 0.01);
}

// The phonemes of `samples` by VisemePhonemes, pushed in blocks of `block` samples; with
// `pushed_at`, for each phoneme the samples pushed when it came out.
std::vector<tts::SpokenPhoneme> viseme_phonemes(std::span<const int16_t> samples, unsigned rate,
                                                size_t block, size_t max_run_frames,
                                                std::vector<size_t>* pushed_at = nullptr) {
  VisemePhonemes visemes(rate, max_run_frames);
  std::vector<tts::SpokenPhoneme> out;
  for (size_t i = 0; i < samples.size(); i += block) {
    const size_t n = std::min(block, samples.size() - i);
    visemes.push(samples.subspan(i, n), out);
    if (pushed_at != nullptr) pushed_at->resize(out.size(), i + n);
  }
  visemes.finish(out);
  if (pushed_at != nullptr) pushed_at->resize(out.size(), samples.size());
  return out;
}

// Each 10 ms frame's viseme, by the phoneme holding the frame's middle.
std::vector<Viseme> frames_of(const std::vector<tts::SpokenPhoneme>& phonemes, unsigned rate) {
  std::vector<Viseme> out;
  for (const tts::SpokenPhoneme& p : phonemes) {
    while ((out.size() * rate + rate / 200) / 100 < p.start + p.n_samples) {
      out.push_back(static_cast<Viseme>(p.event.phoneme.symbol));
    }
  }
  return out;
}

TEST(VisemePhonemes, TheRunsAsPhonemesTilingTheAudioOfflineAndLive) {
  const Spoken s = spoken(kSentences[0]);
  const std::vector<Viseme> runs = frames_of(detect(s.samples, s.rate, s.samples.size()));
  // Offline: one phoneme a run; live: pieces of at most kLiveVisemeRunFrames, the same frames.
  for (const size_t max_run : {size_t{0}, kLiveVisemeRunFrames}) {
    SCOPED_TRACE(max_run);
    const std::vector<tts::SpokenPhoneme> phonemes =
        viseme_phonemes(s.samples, s.rate, s.rate / 50, max_run);
    testing::expect_tiles(phonemes, s.samples.size(), s.rate);
    const std::vector<Viseme> frames = frames_of(phonemes, s.rate);
    ASSERT_EQ(frames.size(), runs.size());
    EXPECT_EQ(frames, runs);
    for (size_t k = 0; k < phonemes.size(); ++k) {
      const tts::SpokenPhoneme& p = phonemes[k];
      EXPECT_LT(p.event.phoneme.symbol, kVisemeCount);
      const bool after_pause = k == 0 || phonemes[k - 1].event.phoneme.symbol == 0;
      EXPECT_EQ(p.event.phoneme.word_begin, p.event.phoneme.symbol != 0 && after_pause) << k;
      if (max_run > 0 && k + 1 < phonemes.size()) {
        EXPECT_LE(p.n_samples, max_run * s.rate / 100 + 1) << k;
      }
    }
  }
}

// Every phoneme comes out once kLiveVisemeBoundMs of audio has come after its start, whatever
// the block (plus the block: the push that completes that audio); at 16 kHz and through the
// resampler.
TEST(VisemePhonemes, LiveEachPhonemeWithinTheBoundAfterItsStart) {
  const Spoken s = spoken(kSentences[1]);
  for (const unsigned rate : {16000u, 22050u}) {
    const std::vector<int16_t> audio = testing::resample(s.samples, s.rate, rate);
    for (const size_t block_ms : {1u, 10u, 20u}) {
      SCOPED_TRACE(std::to_string(rate) + " Hz, " + std::to_string(block_ms) + " ms blocks");
      std::vector<size_t> pushed_at;
      const std::vector<tts::SpokenPhoneme> phonemes =
          viseme_phonemes(audio, rate, rate * block_ms / 1000, kLiveVisemeRunFrames, &pushed_at);
      double most = 0;
      for (size_t k = 0; k + 1 < phonemes.size(); ++k) {  // the last comes at the end
        const double ms = 1000.0 * static_cast<double>(pushed_at[k] - phonemes[k].start) / rate;
        most = std::max(most, ms);
      }
      std::printf("%u Hz, %zu ms blocks: %zu phonemes, out at most %.2f ms after their start\n",
                  rate, block_ms, phonemes.size(), most);
      EXPECT_LE(most, kLiveVisemeBoundMs + static_cast<double>(block_ms) + 0.1);
    }
  }
}

TEST(VisemePhonemes, ARateTheDetectorCannotTakeIsPausesAsTheAudioComes) {
  EXPECT_FALSE(visemes_take_rate(4000));
  EXPECT_TRUE(visemes_take_rate(8000));
  const std::vector<int16_t> audio(4000, 1000);  // 1 s at 4 kHz
  std::vector<size_t> pushed_at;
  const std::vector<tts::SpokenPhoneme> phonemes =
      viseme_phonemes(audio, 4000, 80, kLiveVisemeRunFrames, &pushed_at);
  testing::expect_tiles(phonemes, audio.size(), 4000);
  for (size_t k = 0; k < phonemes.size(); ++k) {
    EXPECT_EQ(phonemes[k].event.phoneme.symbol, 0);
    EXPECT_EQ(pushed_at[k], phonemes[k].start + phonemes[k].n_samples);  // at once
  }
}

TEST(VisemeDetector, RatesOutsideTheRangeAreTakenAsTheNearest) {
  // 4 kHz is read as 8 kHz and 400 kHz as 192 kHz: a clear (if wrong-speed) result, no crash.
  for (unsigned rate : {4000u, 400000u, 0u}) {
    const std::vector<int16_t> audio(8000, 1000);
    const std::vector<VisemeRun> runs = detect(audio, rate, 100);
    EXPECT_FALSE(runs.empty()) << rate;
  }
}

TEST(VisemeDetector, ModelNumbersAreChecked) {
  EXPECT_GT(VisemeModel::builtin().weights(), 10000u);
  // A small network: 48,949 weights take 0.6 % of a core (docs/align.md), the aim 2 %.
  EXPECT_LT(VisemeModel::builtin().weights(), 100000u);
  EXPECT_EQ(VisemeModel::from_numbers(std::vector<float>{}), nullptr);
  EXPECT_EQ(VisemeModel::from_numbers(std::vector<float>{2, 13, 8, 4, 2, 2, 15}), nullptr);
  // Kind 2: the means and scales of 13 coefficients, the cepstral prior of 12, the layers.
  const size_t size = 7 + 26 + 12 + 2 * 170 + 2 * 3 + 15 * 3;
  std::vector<float> wrong_shape{2, 13, 8, 5, 2, 2, 15};
  wrong_shape.resize(size);
  EXPECT_EQ(VisemeModel::from_numbers(wrong_shape), nullptr);
  std::vector<float> kind_1{1, 13, 8, 4, 2, 2, 15};  // before the cepstral mean
  kind_1.resize(size);
  EXPECT_EQ(VisemeModel::from_numbers(kind_1), nullptr);
  std::vector<float> right{2, 13, 8, 4, 2, 2, 15};
  right.resize(size);
  EXPECT_NE(VisemeModel::from_numbers(right), nullptr);
  // The past context is the file's, whole frames up to kMaxVisemePastFrames; the frames
  // ahead are the lookahead's, fixed.
  for (float past : {0.0f, 24.0f, 8.5f, static_cast<float>(kMaxVisemePastFrames + 1), -1.0f}) {
    const bool whole = past >= 0 && past <= kMaxVisemePastFrames && past == std::floor(past);
    std::vector<float> other{2, 13, past, 4, 2, 2, 15};
    other.resize(7 + 26 + 12 + 2 * (13 * (static_cast<size_t>(std::max(past, 0.0f)) + 5) + 1) +
                 2 * 3 + 15 * 3);
    EXPECT_EQ(VisemeModel::from_numbers(other) != nullptr, whole) << past;
  }
}

constexpr float kBuiltinNumbers[] = {
#include "viseme_model.txt"
};

// The built-in model with `extra` more frames of past whose weights are 0: the same network,
// so the same probabilities, if the detector feeds the context oldest first as the file says.
std::vector<float> with_more_past(size_t extra) {
  std::vector<float> n(std::begin(kBuiltinNumbers), std::end(kBuiltinNumbers));
  const auto past = static_cast<size_t>(n[2]), hidden1 = static_cast<size_t>(n[4]);
  const size_t inputs = (past + 1 + kVisemeAheadFrames) * kVisemeMfccs;
  const size_t layer1 = 7 + 2 * kVisemeMfccs + (kVisemeMfccs - 1);
  n[2] = static_cast<float>(past + extra);
  for (size_t r = hidden1; r-- > 0;) {
    n.insert(n.begin() + static_cast<std::ptrdiff_t>(layer1 + r * inputs), extra * kVisemeMfccs,
             0.0f);
  }
  return n;
}

TEST(VisemeDetector, ThePastContextIsTheModelsOwn) {
  const Spoken s = spoken(kSentences[0]);
  auto trace = [&](const VisemeModel& model) {
    VisemeDetector detector(s.rate, 0, {}, model);
    std::vector<float> probabilities;
    detector.trace(&probabilities);
    std::vector<VisemeRun> runs;
    detector.push(std::span<const int16_t>(s.samples), runs);
    detector.finish(runs);
    return probabilities;
  };
  const std::vector<float> builtin = trace(VisemeModel::builtin());
  const auto longer = VisemeModel::from_numbers(with_more_past(16));
  ASSERT_NE(longer, nullptr);
  EXPECT_EQ(longer->past_frames(), VisemeModel::builtin().past_frames() + 16);
  EXPECT_EQ(trace(*longer), builtin);
}

}  // namespace
}  // namespace pfap::align

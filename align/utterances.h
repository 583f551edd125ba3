// SPDX-License-Identifier: LGPL-2.1-or-later
// pfapalign's logic beside the aligner and the recognizer, without GStreamer: where a stream's
// phonemes come from (its texts, the recognizer or a pause), which stretch of the recording
// each text is the utterance of (the texts come with the sample they start at: the element
// turns their running time into it), the live mode's open utterance, and the audio's bytes
// (S16LE) as samples. docs/align.md, "Timeline and utterances".
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "aligner.h"  // kMaxAudioSeconds
#include "live.h"
#include "recognizer.h"
#include "viseme_phonemes.h"

namespace pfap::align {

// Where a stream's phonemes come from, offline and live: its texts, when it has any; else the
// audio alone: by `recognizer`, pocketsphinx's phonemes (recognizer.h; in a build without it,
// one pause, which the element warns about) or the viseme detector's (viseme_phonemes.h).
enum class Recognizer { kPhonemes, kVisemes };
enum class PhonemeSource { kTexts, kRecognition, kPause, kVisemes };
PhonemeSource phoneme_source(bool has_text, Recognizer recognizer = Recognizer::kPhonemes);

// The alphabet of phonemes from `source`: the viseme detector's, else x-pfap-arpabet.
std::string_view alphabet_of(PhonemeSource source);

// The latency the live mode declares for phonemes from `source`, in ms: the aligner's
// (kLiveLatencyMs; a pause is aligned as a text), pocketsphinx's or the viseme detector's.
unsigned live_latency_ms(PhonemeSource source);

// What audio at `rate` Hz cannot be: aligned (kMinRate..kMaxRate), or heard by the viseme
// detector where it has the stream (`recognizer` kVisemes). Either way its phonemes are pauses.
enum class RateProblem { kNone, kCannotAlign, kCannotDetectVisemes };
RateProblem rate_problem(unsigned rate, Recognizer recognizer);

// Offline, without a text: the phonemes of audio heard by a PhonemeSource other than kTexts,
// contiguous from sample 0 to the audio's end.
struct Heard {
  std::vector<tts::SpokenPhoneme> phonemes;
  RecognitionProblem problem = RecognitionProblem::kNone;  // what the recognizer met
  bool cannot_recognize = false;  // kPause: the build has no recognizer, the audio is a pause
};
// False with `error` where kRecognition's model cannot be loaded.
bool hear(std::span<const int16_t> audio, unsigned rate, PhonemeSource source, Heard& out,
          std::string& error);

// One text: the sample it starts at, counted from the first sample kept (none: it has no
// time, and continues the text before it offline or starts at the audio so far live), and its
// bytes (any, UTF-8 is checked later).
struct TimedText {
  std::optional<size_t> from;
  std::string bytes;
};

// The utterance of `text` over samples [from, to). `is_text`: false for the audio before the
// first text, a pause whose empty text is no problem.
struct UtteranceSpan {
  size_t from = 0;
  size_t to = 0;
  std::string text;
  bool is_text = true;
};

// Offline: the utterances of the `n` samples kept, in order, tiling [0, n). `whole` is the
// text of the whole stream (the text property, when no text pad is linked), an utterance from
// 0 before `texts`. A text without a start continues the one before (the first starts at 0);
// a text from beyond the audio starts at its end at `end_of_stream`, and else waits: its index
// in `texts` goes to `later` (in order) and it is left as it is; the bytes of the others are
// moved out. The audio before the first
// utterance is one that is not a text. Empty when there is no text at all: the audio is to be
// recognized.
std::vector<UtteranceSpan> utterances_of(std::vector<TimedText>& texts,
                                         const std::optional<std::string>& whole, size_t n,
                                         bool end_of_stream, std::vector<size_t>& later);

// Live: of `texts`, those that start before sample `end`, as utterance starts in order
// (UtteranceSpan::to is `end`), none before `now` (the audio so far; a text without a start,
// or a late one, starts there). The others' indices go to `later`, in order, and they are left
// as they are; the bytes of those taken are moved out.
std::vector<UtteranceSpan> live_utterances_before(std::vector<TimedText>& texts, size_t now,
                                                  size_t end, std::vector<size_t>& later);

// Appends the S16LE samples in `bytes` (an odd last byte left out) to `samples`, at most
// `max_count` of them.
void append_s16le(std::span<const uint8_t> bytes, size_t max_count, std::vector<int16_t>& samples);

// Offline: the audio kept for one alignment, at most kMaxAudioSeconds of it (aligner.h); the
// rest is left out, and the element warns once.
class KeptAudio {
 public:
  // Forgets the audio and the overflow.
  void reset();
  // Appends the S16LE `bytes` of audio at `rate` Hz, as much as the limit lets in. True the
  // first time some of them are left out.
  bool append(std::span<const uint8_t> bytes, unsigned rate);
  const std::vector<int16_t>& samples() const { return samples_; }

 private:
  std::vector<int16_t> samples_;
  bool overflowed_ = false;
};

// One buffer of the text pad: its start, a running time in ns (none: it continues the one
// before), and its bytes.
struct PadText {
  std::optional<uint64_t> running_time;
  std::string bytes;
};

// The text pad's buffers, from its thread to the audio's: offline, the alignment at the
// audio's end waits for the text pad's end (its EOS) unless the stream flushes or stops.
class TextQueue {
 public:
  // A new stream: no texts, not ended, not flushing.
  void reset();
  void add(PadText text);
  // The text pad's EOS: every text is here.
  void end();
  // The text pad's flush: its texts dropped, and it has not ended.
  void clear();
  // The audio flushes or the element stops: waiting stops, until reset().
  void flush();
  // With `wait_for_end`, waits for end() or flush() first. False when flushing.
  bool ready(bool wait_for_end);
  // Takes the texts, in order.
  std::vector<PadText> take();
  // Puts `texts` (taken, for audio still to come) back before those added since.
  void put_back(std::vector<PadText> texts);

  // The sample a text's running time falls on (the element's timeline; none for none).
  using ToSample = std::function<std::optional<size_t>(std::optional<uint64_t> running_time)>;
  // Offline: utterances_of() over the texts taken; those for audio still to come stay.
  std::vector<UtteranceSpan> take_utterances(const ToSample& to_sample,
                                             const std::optional<std::string>& whole, size_t n,
                                             bool end_of_stream);
  // Live: live_utterances_before() over the texts taken; the others stay.
  std::vector<UtteranceSpan> take_live_utterances(const ToSample& to_sample, size_t now,
                                                  size_t end);

 private:
  // Takes the texts, cuts them with `cut` (which says which are `later`), puts those back.
  template <typename Cut>
  std::vector<UtteranceSpan> take_cut(const ToSample& to_sample, Cut cut);

  std::mutex lock_;
  std::condition_variable changed_;
  std::vector<PadText> texts_;
  bool ended_ = false;
  bool flushing_ = false;
};

// Live: a stream's utterances, one open at a time, as its audio comes: each aligned to its
// text (LiveAligner) or, without a text, recognized to the stream's end (LiveRecognizer, or
// the viseme detector: VisemePhonemes). Phoneme starts count from the stream's first sample.
class LiveUtterances {
 public:
  // A new stream: nothing open, no audio yet.
  void reset();
  bool is_open() const { return open_; }
  // The open utterance is pocketsphinx's (start_heard() with Recognizer::kPhonemes).
  bool is_recognizing() const { return open_ && kind_ == Kind::kRecognition; }
  size_t samples() const { return samples_; }       // the audio so far
  size_t utterance_start() const { return from_; }  // the open utterance's first sample

  // Opens the utterance of `utterance` at the audio so far (end() the open one first). False
  // with `error` where espeak-ng cannot speak; problem() and inexact() then say what of it
  // cannot be aligned exactly.
  bool start_text(const tts::Utterance& utterance, const tts::VoiceSettings& voice, unsigned rate,
                  std::string& error);
  // Opens the utterance heard by `recognizer` at the audio so far, to the stream's end (end()
  // the open one first): pocketsphinx's, or the viseme detector's with its runs in pieces of
  // kLiveVisemeRunFrames. False with `error` where pocketsphinx's model cannot be loaded.
  bool start_heard(Recognizer recognizer, unsigned rate, std::string& error);
  // Gives `samples` to the open utterance; the phonemes now settled to `out`.
  void push(std::span<const int16_t> samples, std::vector<tts::SpokenPhoneme>& out);
  // Ends the open utterance, if any, at the audio so far: its last phonemes to `out`.
  void end(std::vector<tts::SpokenPhoneme>& out);

  Problem problem() const { return aligner_.problem(); }
  const std::vector<tts::Speech::Inexact>& inexact() const { return aligner_.inexact(); }
  RecognitionProblem recognition_problem() const { return recognizer_.problem(); }

 private:
  void count_from_stream_start(std::vector<tts::SpokenPhoneme>& out, size_t first) const;

  enum class Kind { kText, kRecognition, kVisemes };
  LiveAligner aligner_;
  LiveRecognizer recognizer_;
  std::optional<VisemePhonemes> visemes_;
  bool open_ = false;
  Kind kind_ = Kind::kText;
  size_t from_ = 0;
  size_t samples_ = 0;
};

}  // namespace pfap::align

// SPDX-License-Identifier: LGPL-2.1-or-later
#include "utterances.h"

#include <algorithm>
#include <utility>

#include "pfap/phoneme_table.h"

namespace pfap::align {

namespace {

void sort_by_start(std::vector<UtteranceSpan>& utterances) {
  std::stable_sort(utterances.begin(), utterances.end(),
                   [](const UtteranceSpan& a, const UtteranceSpan& b) { return a.from < b.from; });
}

}  // namespace

PhonemeSource phoneme_source(bool has_text, Recognizer recognizer) {
  if (has_text) return PhonemeSource::kTexts;
  if (recognizer == Recognizer::kVisemes) return PhonemeSource::kVisemes;
  return recognition_available() ? PhonemeSource::kRecognition : PhonemeSource::kPause;
}

std::string_view alphabet_of(PhonemeSource source) {
  return source == PhonemeSource::kVisemes ? kOculusVisemeAlphabet : kArpabetAlphabet;
}

unsigned live_latency_ms(PhonemeSource source) {
  switch (source) {
    case PhonemeSource::kRecognition:
      return kLiveRecognitionLatencyMs;
    case PhonemeSource::kVisemes:
      return kLiveVisemeLatencyMs;
    default:
      return kLiveLatencyMs;
  }
}

RateProblem rate_problem(unsigned rate, Recognizer recognizer) {
  if (recognizer == Recognizer::kVisemes) {
    return visemes_take_rate(rate) ? RateProblem::kNone : RateProblem::kCannotDetectVisemes;
  }
  return rate < kMinRate || rate > kMaxRate ? RateProblem::kCannotAlign : RateProblem::kNone;
}

bool hear(std::span<const int16_t> audio, unsigned rate, PhonemeSource source, Heard& out,
          std::string& error) {
  out = Heard{};
  if (source == PhonemeSource::kVisemes) {
    VisemePhonemes visemes(rate, 0);
    visemes.push(audio, out.phonemes);
    visemes.finish(out.phonemes);
    return true;
  }
  Recognition recognition;
  if (!recognize(audio, rate, recognition, error)) {
    if (source == PhonemeSource::kRecognition) return false;
    out.cannot_recognize = true;  // recognition is one pause
  } else {
    out.problem = recognition.problem;
  }
  out.phonemes = std::move(recognition.phonemes);
  return true;
}

std::vector<UtteranceSpan> utterances_of(std::vector<TimedText>& texts,
                                         const std::optional<std::string>& whole, size_t n,
                                         bool end_of_stream, std::vector<size_t>& later) {
  std::vector<UtteranceSpan> utterances;
  if (whole.has_value()) utterances.push_back({0, n, *whole, true});
  for (size_t i = 0; i < texts.size(); ++i) {
    TimedText& t = texts[i];
    if (!t.from.has_value()) {
      if (utterances.empty()) {
        utterances.push_back({0, n, std::move(t.bytes), true});
      } else {
        utterances.back().text += t.bytes;
      }
      continue;
    }
    if (*t.from >= n && !end_of_stream) {
      later.push_back(i);
      continue;
    }
    utterances.push_back({std::min(*t.from, n), n, std::move(t.bytes), true});
  }
  if (utterances.empty()) return utterances;
  sort_by_start(utterances);
  for (size_t i = 0; i + 1 < utterances.size(); ++i) utterances[i].to = utterances[i + 1].from;
  utterances.back().to = n;
  if (utterances.front().from > 0) {
    utterances.insert(utterances.begin(), {0, utterances.front().from, std::string(), false});
  }
  return utterances;
}

std::vector<UtteranceSpan> live_utterances_before(std::vector<TimedText>& texts, size_t now,
                                                  size_t end, std::vector<size_t>& later) {
  std::vector<UtteranceSpan> starting;
  for (size_t i = 0; i < texts.size(); ++i) {
    const size_t from = std::max(texts[i].from.value_or(now), now);
    if (from < end) {
      starting.push_back({from, end, std::move(texts[i].bytes), true});
    } else {
      later.push_back(i);
    }
  }
  sort_by_start(starting);
  return starting;
}

void append_s16le(std::span<const uint8_t> bytes, size_t max_count, std::vector<int16_t>& samples) {
  const size_t taken = std::min(bytes.size() / sizeof(int16_t), max_count);
  samples.reserve(samples.size() + taken);
  for (size_t i = 0; i < taken; ++i) {
    samples.push_back(static_cast<int16_t>(bytes[2 * i] | (bytes[2 * i + 1] << 8)));
  }
}

void KeptAudio::reset() {
  samples_.clear();
  overflowed_ = false;
}

bool KeptAudio::append(std::span<const uint8_t> bytes, unsigned rate) {
  const size_t limit = size_t{kMaxAudioSeconds} * rate;
  const size_t room = limit - std::min(samples_.size(), limit);
  append_s16le(bytes, room, samples_);
  if (bytes.size() / sizeof(int16_t) <= room || overflowed_) return false;
  overflowed_ = true;
  return true;
}

void TextQueue::reset() {
  std::lock_guard guard(lock_);
  texts_.clear();
  ended_ = false;
  flushing_ = false;
}

void TextQueue::add(PadText text) {
  std::lock_guard guard(lock_);
  texts_.push_back(std::move(text));
}

void TextQueue::end() {
  {
    std::lock_guard guard(lock_);
    ended_ = true;
  }
  changed_.notify_all();
}

void TextQueue::clear() {
  std::lock_guard guard(lock_);
  texts_.clear();
  ended_ = false;
}

void TextQueue::flush() {
  {
    std::lock_guard guard(lock_);
    flushing_ = true;
  }
  changed_.notify_all();
}

bool TextQueue::ready(bool wait_for_end) {
  std::unique_lock guard(lock_);
  if (wait_for_end) changed_.wait(guard, [&] { return ended_ || flushing_; });
  return !flushing_;
}

std::vector<PadText> TextQueue::take() {
  std::lock_guard guard(lock_);
  std::vector<PadText> taken;
  taken.swap(texts_);
  return taken;
}

void TextQueue::put_back(std::vector<PadText> texts) {
  std::lock_guard guard(lock_);
  texts_.insert(texts_.begin(), std::make_move_iterator(texts.begin()),
                std::make_move_iterator(texts.end()));
}

template <typename Cut>
std::vector<UtteranceSpan> TextQueue::take_cut(const ToSample& to_sample, Cut cut) {
  std::vector<PadText> texts = take();
  std::vector<TimedText> timed;
  for (PadText& t : texts) timed.push_back({to_sample(t.running_time), std::move(t.bytes)});
  std::vector<size_t> later;
  std::vector<UtteranceSpan> utterances = cut(timed, later);
  std::vector<PadText> waiting;
  for (size_t i : later) waiting.push_back({texts[i].running_time, std::move(timed[i].bytes)});
  put_back(std::move(waiting));
  return utterances;
}

std::vector<UtteranceSpan> TextQueue::take_utterances(const ToSample& to_sample,
                                                      const std::optional<std::string>& whole,
                                                      size_t n, bool end_of_stream) {
  return take_cut(to_sample, [&](std::vector<TimedText>& timed, std::vector<size_t>& later) {
    return utterances_of(timed, whole, n, end_of_stream, later);
  });
}

std::vector<UtteranceSpan> TextQueue::take_live_utterances(const ToSample& to_sample, size_t now,
                                                           size_t end) {
  return take_cut(to_sample, [&](std::vector<TimedText>& timed, std::vector<size_t>& later) {
    return live_utterances_before(timed, now, end, later);
  });
}

void LiveUtterances::reset() {
  open_ = false;
  samples_ = 0;
}

bool LiveUtterances::start_text(const tts::Utterance& utterance, const tts::VoiceSettings& voice,
                                unsigned rate, std::string& error) {
  if (!aligner_.start(utterance, voice, rate, error)) return false;
  open_ = true;
  kind_ = Kind::kText;
  from_ = samples_;
  return true;
}

bool LiveUtterances::start_heard(Recognizer recognizer, unsigned rate, std::string& error) {
  if (recognizer == Recognizer::kVisemes) {
    visemes_.emplace(rate, kLiveVisemeRunFrames);
    kind_ = Kind::kVisemes;
  } else {
    if (!recognizer_.start(rate, error)) return false;
    kind_ = Kind::kRecognition;
  }
  open_ = true;
  from_ = samples_;
  return true;
}

void LiveUtterances::push(std::span<const int16_t> samples, std::vector<tts::SpokenPhoneme>& out) {
  const size_t first = out.size();
  switch (kind_) {
    case Kind::kText:
      aligner_.push(samples, out);
      break;
    case Kind::kRecognition:
      recognizer_.push(samples, out);
      break;
    case Kind::kVisemes:
      visemes_->push(samples, out);
      break;
  }
  samples_ += samples.size();
  count_from_stream_start(out, first);
}

void LiveUtterances::end(std::vector<tts::SpokenPhoneme>& out) {
  if (!open_) return;
  open_ = false;
  const size_t first = out.size();
  switch (kind_) {
    case Kind::kText:
      aligner_.finish(out);
      break;
    case Kind::kRecognition:
      recognizer_.finish(out);
      break;
    case Kind::kVisemes:
      visemes_->finish(out);
      break;
  }
  count_from_stream_start(out, first);
}

void LiveUtterances::count_from_stream_start(std::vector<tts::SpokenPhoneme>& out,
                                             size_t first) const {
  for (size_t i = first; i < out.size(); ++i) out[i].start += from_;
}

}  // namespace pfap::align

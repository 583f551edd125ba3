// SPDX-License-Identifier: LGPL-2.1-or-later
#include "recognizer.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include "aligner.h"  // kSpeechLevelDb
#include "f0.h"
#include "mfcc.h"
#include "pfap/phoneme_table.h"

#if PFAP_HAVE_POCKETSPHINX
#include <pocketsphinx.h>
#include <sphinxbase/err.h>
#include <sphinxbase/feat.h>
#endif

namespace pfap::align {
namespace {

// The whole audio as one pause.
void pause_over(size_t n_samples, unsigned rate, Recognition& out) {
  MarkupEvent e;
  e.kind = PFAP_EVENT_PHONEME;
  e.sentence_start = true;
  e.phoneme.end_of_text = true;
  tts::add_phoneme(e, 0, n_samples, rate, out.phonemes);
}

#if PFAP_HAVE_POCKETSPHINX
// A recognized phone: its symbol and first and last 10 ms frame.
struct Phone {
  uint8_t symbol;
  int first_frame, last_frame;
};

// The decoder's acoustic front end: 10 ms frames of a 25.625 ms window (the model's
// feat.params), whatever the rate; the FFT must hold the window.
constexpr unsigned kFramesPerSecond = 100;
constexpr double kWindowSeconds = 0.025625;

// A phone whose first frame is `frame` starts half a hop before that frame's window centre,
// where the frame before it ends: the window is 25.6 ms, the hop 10 ms.
double frame_start(int frame, unsigned rate) {
  return static_cast<double>(frame) * rate / kFramesPerSecond +
         (kWindowSeconds - 1.0 / kFramesPerSecond) / 2 * rate;
}

int fft_size(unsigned rate) {
  int n = 512;
  while (n < kWindowSeconds * rate) n *= 2;
  return n;
}

// CMU's settings for phoneme recognition (the all-phone search of cmusphinx.github.io's
// "Phoneme recognition" page: language weight 2, backtrace) but beams of 1e-15, not 1e-20:
// 60 % of the time, the same phones on the Festival sentences we tried; at 1e-10 the search
// lost its way in some (one W held for 2 s of "Mesh wire keeps chicks inside.").
// -remove_silence no: pocketsphinx 5prealpha's voice activity detector otherwise drops the
// frames it takes for silence, and every time after them moves.
// Live, beams of 1e-10: a third of the processor time (real-time factor 0.27 against 0.85),
// for 3.5 points of viseme agreement on the Festival corpus; at 1e-15 the search took most of
// a core and fell behind the clock, and the phonemes behind the declared latency.
constexpr const char* kBeam = "1e-15";
constexpr const char* kLiveBeam = "1e-10";
ps_decoder_t* new_decoder(unsigned rate, std::string& error, const char* beam) {
  const std::string model = PFAP_POCKETSPHINX_MODELDIR "/en-us";
  const std::string hmm = model + "/en-us";
  const std::string phone_lm = model + "/en-us-phone.lm.bin";
  const std::string samprate = std::to_string(rate);
  const std::string nfft = std::to_string(fft_size(rate));
  cmd_ln_t* config =
      cmd_ln_init(nullptr, ps_args(), TRUE, "-hmm", hmm.c_str(), "-allphone", phone_lm.c_str(),
                  "-backtrace", "yes", "-beam", beam, "-pbeam", beam, "-lw", "2.0", "-samprate",
                  samprate.c_str(), "-nfft", nfft.c_str(), "-remove_silence", "no", nullptr);
  ps_decoder_t* ps = config != nullptr ? ps_init(config) : nullptr;
  if (config != nullptr) cmd_ln_free_r(config);  // the decoder keeps its own reference
  if (ps == nullptr) {
    error = "pocketsphinx cannot load its US English model from " + model +
            " (Debian: pocketsphinx-en-us)";
  }
  return ps;
}

// The phones of the best path so far (at the utterance's end, the final one), SIL and fillers
// as pauses, consecutive pauses merged. Mid-utterance the all-phone search traces back from the
// best phone ending in the latest frame where one ends (allphone_search.c), so the phone still
// going on is not in it. Frames count from the utterance's start: the path's first phone
// starts there, but pocketsphinx 5prealpha numbers a decoder's second utterance fed in blocks
// on from the first's frames (seen: its first phone at frame 293).
std::vector<Phone> best_path(ps_decoder_t* ps) {
  std::vector<Phone> phones;
  int offset = -1;
  for (ps_seg_t* seg = ps_seg_iter(ps); seg != nullptr; seg = ps_seg_next(seg)) {
    int first = 0, last = 0;
    ps_seg_frames(seg, &first, &last);
    if (offset < 0) offset = first;
    first -= offset;
    last -= offset;
    const uint8_t symbol = arpabet_symbol(ps_seg_word(seg));
    if (!phones.empty() && symbol == 0 && phones.back().symbol == 0) {
      phones.back().last_frame = last;
      continue;
    }
    phones.push_back({symbol, first, last});
  }
  return phones;
}

// The phones of the best path, SIL and fillers as pauses, consecutive pauses merged.
std::vector<Phone> decode(ps_decoder_t* ps, std::span<const int16_t> audio) {
  ps_start_utt(ps);
  ps_process_raw(ps, audio.data(), audio.size(), FALSE, TRUE);  // whole: CMN over it all
  ps_end_utt(ps);
  return best_path(ps);
}

// The process's decoder for one rate, and the lock of its turns.
struct SharedDecoder {
  std::mutex lock;
  ps_decoder_t* ps = nullptr;
};

// The decoder for `rate`, made at the first call for it and kept for the process (never
// freed, so never destroyed under a thread still using it at exit); nullptr with `error`
// when the model cannot be loaded.
SharedDecoder* shared_decoder(unsigned rate, std::string& error) {
  static std::mutex lock;
  static auto& decoders = *new std::map<unsigned, std::unique_ptr<SharedDecoder>>;
  std::lock_guard<std::mutex> guard(lock);
  std::unique_ptr<SharedDecoder>& decoder = decoders[rate];
  if (decoder != nullptr) return decoder.get();
  // pocketsphinx logs every setting and result to stderr; its log is one per process.
  err_set_logfp(nullptr);
  ps_decoder_t* ps = new_decoder(rate, error, kBeam);
  if (ps == nullptr) {
    decoders.erase(rate);
    return nullptr;
  }
  decoder = std::make_unique<SharedDecoder>();
  decoder->ps = ps;
  return decoder.get();
}
#endif

}  // namespace

#if PFAP_HAVE_POCKETSPHINX
// A decoder for live recognition, one LiveRecognizer's at a time: its utterance lasts
// over many calls, so it cannot take turns with others as the shared decoders do. Returned to
// a pool per rate, never freed (as the shared ones). Fed in blocks, pocketsphinx normalizes
// the cepstra by a running mean (its live CMN) that each use would carry into the next: the
// mean it had when made is set again at each start, so that a stream's phones do not depend
// on the streams before it.
struct LiveDecoder {
  ps_decoder_t* ps = nullptr;
  unsigned rate = 0;
  std::vector<mfcc_t> initial_mean;
};

namespace {

std::mutex live_pool_lock;
std::vector<LiveDecoder*>& live_pool() {
  static auto& pool = *new std::vector<LiveDecoder*>;
  return pool;
}

LiveDecoder* take_live_decoder(unsigned rate, std::string& error) {
  {
    std::lock_guard<std::mutex> guard(live_pool_lock);
    auto& pool = live_pool();
    auto it =
        std::find_if(pool.begin(), pool.end(), [&](LiveDecoder* d) { return d->rate == rate; });
    if (it != pool.end()) {
      LiveDecoder* d = *it;
      pool.erase(it);
      cmn_live_set(ps_get_feat(d->ps)->cmn_struct, d->initial_mean.data());
      return d;
    }
    err_set_logfp(nullptr);
  }
  ps_decoder_t* ps = new_decoder(rate, error, kLiveBeam);
  if (ps == nullptr) return nullptr;
  auto* d = new LiveDecoder{ps, rate, {}};
  cmn_t* cmn = ps_get_feat(ps)->cmn_struct;
  d->initial_mean.resize(static_cast<size_t>(cmn->veclen));
  cmn_live_get(cmn, d->initial_mean.data());
  return d;
}

void give_back(LiveDecoder* d) {
  std::lock_guard<std::mutex> guard(live_pool_lock);
  live_pool().push_back(d);
}

}  // namespace
#endif

uint8_t arpabet_symbol(std::string_view cmu_phone) {
  static const PhonemeAlphabet& arpabet = *find_alphabet(kArpabetAlphabet);
  // "pause" is x-pfap-arpabet's name for 0, never a CMU phone.
  if (cmu_phone == "pause") return 0;
  return find_symbol(arpabet, cmu_phone).value_or(0);
}

const char* problem_text(RecognitionProblem p) {
  switch (p) {
    case RecognitionProblem::kNone:
      return "recognized";
    case RecognitionProblem::kNoSpeech:
      return "the audio is silent: it is one pause";
    case RecognitionProblem::kBadRate:
      return "the sample rate is outside 16000..48000 Hz: the audio is one pause";
    case RecognitionProblem::kNothingHeard:
      return "no speech was recognized in the audio (noise?): it is one pause";
  }
  return "?";
}

std::vector<size_t> recognition_windows(const Features& level, size_t n_samples) {
  std::vector<size_t> starts = {0};
  const auto samples = [&](double seconds) { return static_cast<size_t>(seconds * level.rate); };
  while (n_samples - starts.back() > samples(kMaxWindowSeconds)) {
    const size_t from = starts.back() + samples(kMinWindowSeconds);
    const size_t to = starts.back() + samples(kMaxWindowSeconds);
    size_t quietest = level.frame_at(from);
    for (size_t k = quietest; k < level.n_frames && level.centre(k) < to; ++k) {
      if (level.level_db[k] < level.level_db[quietest]) quietest = k;
    }
    starts.push_back(std::clamp(level.centre(quietest), from, to));
  }
  return starts;
}

#if PFAP_HAVE_POCKETSPHINX
bool recognition_available() { return true; }

bool recognize(std::span<const int16_t> audio, unsigned rate, Recognition& out,
               std::string& error) {
  out = Recognition{};
  if (rate < kMinRate || rate > kMaxRate) {
    out.problem = RecognitionProblem::kBadRate;
    pause_over(audio.size(), rate, out);
    return true;
  }
  const Features level = mfcc(audio, rate);
  if (audio.empty() ||
      *std::max_element(level.level_db.begin(), level.level_db.end()) < kSpeechLevelDb) {
    out.problem = RecognitionProblem::kNoSpeech;
    pause_over(audio.size(), rate, out);
    return true;
  }
  SharedDecoder* decoder = shared_decoder(rate, error);
  if (decoder == nullptr) {
    pause_over(audio.size(), rate, out);
    return false;
  }
  // Each window's phones, as (symbol, first sample), consecutive pauses merged.
  std::vector<std::pair<uint8_t, size_t>> phones;
  const std::vector<size_t> windows = recognition_windows(level, audio.size());
  for (size_t w = 0; w < windows.size(); ++w) {
    const size_t from = windows[w];
    const size_t to = w + 1 < windows.size() ? windows[w + 1] : audio.size();
    std::vector<Phone> heard;
    {
      std::lock_guard<std::mutex> turn(decoder->lock);
      heard = decode(decoder->ps, audio.subspan(from, to - from));
    }
    for (size_t k = 0; k < heard.size(); ++k) {
      if (!phones.empty() && heard[k].symbol == 0 && phones.back().first == 0) continue;
      const size_t start =
          k == 0 ? from
                 : from + std::min(static_cast<size_t>(frame_start(heard[k].first_frame, rate)),
                                   to - from);
      phones.emplace_back(heard[k].symbol, start);
    }
  }
  if (std::none_of(phones.begin(), phones.end(), [](const auto& p) { return p.first != 0; })) {
    out.problem = RecognitionProblem::kNothingHeard;
    pause_over(audio.size(), rate, out);
    return true;
  }

  std::vector<size_t> bounds;
  bounds.push_back(0);
  for (size_t k = 1; k < phones.size(); ++k)
    bounds.push_back(std::max(phones[k].second, bounds.back()));
  bounds.push_back(audio.size());

  const std::vector<double> f0 = tts::segment_f0(audio, rate, bounds);
  for (size_t k = 0; k < phones.size(); ++k) {
    MarkupEvent e;
    e.kind = PFAP_EVENT_PHONEME;
    e.phoneme.symbol = phones[k].first;
    e.phoneme.f0 = f0_code(static_cast<unsigned>(std::lround(f0[k])));
    e.phoneme.word_begin = phones[k].first != 0 && (k == 0 || phones[k - 1].first == 0);
    e.sentence_start = k == 0;
    e.phoneme.end_of_text = k + 1 == phones.size();
    tts::add_phoneme(e, bounds[k], bounds[k + 1], rate, out.phonemes);
  }
  return true;
}
#else
bool recognition_available() { return false; }

bool recognize(std::span<const int16_t> audio, unsigned rate, Recognition& out,
               std::string& error) {
  out = Recognition{};
  pause_over(audio.size(), rate, out);
  error = "this build has no phoneme recognizer (pocketsphinx; meson feature `recognition`)";
  return false;
}
#endif

}  // namespace pfap::align

// Live (LiveRecognizer).

namespace pfap::align {
namespace {

size_t samples_of(unsigned ms, unsigned rate) { return size_t{ms} * rate / 1000; }

// pocketsphinx's utterance restarts at a pause once it is this long, or at any point once it
// is kForceRestartMs long: its history of phone exits, traced back at each step, grows with it.
constexpr unsigned kRestartMs = 5000;
constexpr unsigned kForceRestartMs = 20000;
// YIN's half window, the audio kept before a piece for its f0.
constexpr size_t kHalfF0Window = 512;

}  // namespace

LiveRecognizer::~LiveRecognizer() { release(); }

void LiveRecognizer::release() {
#if PFAP_HAVE_POCKETSPHINX
  if (decoder_ == nullptr) return;
  if (in_utterance_) ps_end_utt(decoder_->ps);
  give_back(decoder_);
  decoder_ = nullptr;
#endif
  in_utterance_ = false;
}

bool LiveRecognizer::start(unsigned rate, std::string& error) {
  release();
  rate_ = rate;
  problem_ = RecognitionProblem::kNone;
  audio_.clear();
  first_ = utterance_from_ = settled_ = last_step_ = 0;
  loudest_db_ = -100;
  last_symbol_ = 0;
  piece_open_ = any_speech_ = any_out_ = false;
  if (rate < kMinRate || rate > kMaxRate) {
    problem_ = RecognitionProblem::kBadRate;
    return true;
  }
#if PFAP_HAVE_POCKETSPHINX
  decoder_ = take_live_decoder(rate, error);
  if (decoder_ == nullptr) return false;
  ps_start_utt(decoder_->ps);
  in_utterance_ = true;
  return true;
#else
  error = "this build has no phoneme recognizer (pocketsphinx; meson feature `recognition`)";
  return false;
#endif
}

std::vector<LiveRecognizer::Segment> LiveRecognizer::best_path() const {
  std::vector<Segment> out;
#if PFAP_HAVE_POCKETSPHINX
  const size_t n = samples();
  auto at = [&](int frame) {
    return std::min(n, utterance_from_ + static_cast<size_t>(frame_start(frame, rate_)));
  };
  for (const Phone& p : pfap::align::best_path(decoder_->ps)) {
    out.push_back({p.symbol, at(p.first_frame), at(p.last_frame + 1)});
  }
#endif
  return out;
}

void LiveRecognizer::push(std::span<const int16_t> samples,
                               std::vector<tts::SpokenPhoneme>& out) {
  audio_.insert(audio_.end(), samples.begin(), samples.end());
#if PFAP_HAVE_POCKETSPHINX
  if (decoder_ != nullptr && !samples.empty()) {
    ps_process_raw(decoder_->ps, samples.data(), samples.size(), FALSE, FALSE);
  }
#endif
  if (this->samples() - last_step_ < samples_of(kStepMs, rate_)) return;
  step(false, out);
}

void LiveRecognizer::finish(std::vector<tts::SpokenPhoneme>& out) {
  step(true, out);
  if (!any_speech_ && problem_ == RecognitionProblem::kNone) {
    problem_ = loudest_db_ < kSpeechLevelDb ? RecognitionProblem::kNoSpeech
                                            : RecognitionProblem::kNothingHeard;
  }
}

void LiveRecognizer::step(bool at_end, std::vector<tts::SpokenPhoneme>& out) {
  const size_t n = samples();
  // The level of the audio since the last step (and a window before), for "silent".
  if (n > last_step_ && problem_ != RecognitionProblem::kBadRate) {
    const size_t from = last_step_ - std::min(last_step_, kHalfF0Window * 2);
    const Features f = mfcc(std::span(audio_).subspan(from - first_), rate_);
    for (float db : f.level_db) loudest_db_ = std::max(loudest_db_, db);
  }
  last_step_ = n;
  const size_t horizon = n - std::min(n, samples_of(kLookaheadMs, rate_));
  if (decoder_ == nullptr) {  // the rate: a pause, in pieces
    if (at_end) {
      if (n > settled_) emit(0, n, true, true, out);
    } else if (horizon > settled_ + samples_of(kHoldMs, rate_)) {
      emit(0, horizon, false, false, out);
    }
  } else if (at_end) {
    end_utterance(true, out);
  } else {
    const std::vector<Segment> path = best_path();
    for (const Segment& seg : path) {
      if (seg.end <= settled_) continue;
      if (seg.end > horizon) break;
      emit(seg.symbol, seg.end, true, false, out);
    }
    if (horizon > settled_ + samples_of(kHoldMs, rate_)) {
      // A phone going on past the hold: a piece of what the path has there, or of the phone
      // given out last where the path does not yet reach.
      uint8_t symbol = last_symbol_;
      for (const Segment& seg : path) {
        if (seg.start <= settled_ && settled_ < seg.end) symbol = seg.symbol;
      }
      emit(symbol, horizon, false, false, out);
    }
    const size_t length = n - utterance_from_;
    const bool pausing = !path.empty() && path.back().symbol == 0;
    if (length >= samples_of(kForceRestartMs, rate_) ||
        (length >= samples_of(kRestartMs, rate_) && pausing)) {
      end_utterance(false, out);
    }
  }
  // The audio the next pieces' f0 and the next step's level need.
  const size_t keep_from =
      std::min(settled_, last_step_) - std::min(std::min(settled_, last_step_), kHalfF0Window * 2);
  if (keep_from > first_ + rate_) {
    audio_.erase(audio_.begin(), audio_.begin() + static_cast<std::ptrdiff_t>(keep_from - first_));
    first_ = keep_from;
  }
}

void LiveRecognizer::end_utterance(bool at_end, std::vector<tts::SpokenPhoneme>& out) {
  const size_t n = samples();
#if PFAP_HAVE_POCKETSPHINX
  ps_end_utt(decoder_->ps);
  in_utterance_ = false;
#endif
  std::vector<Segment> path = best_path();
  // The final path ends at the last frame, which ends before the last sample: its last phone
  // takes the rest.
  while (!path.empty() && path.back().start >= n && path.size() > 1) path.pop_back();
  bool any = false;
  for (size_t k = 0; k < path.size(); ++k) {
    const bool last = k + 1 == path.size();
    const size_t to = last ? n : path[k].end;
    if (to <= settled_) continue;
    emit(path[k].symbol, to, true, at_end && last, out);
    any = true;
  }
  if (!any && n > settled_) emit(last_symbol_, n, true, at_end, out);
#if PFAP_HAVE_POCKETSPHINX
  if (!at_end) {
    ps_start_utt(decoder_->ps);
    in_utterance_ = true;
    utterance_from_ = n;
  }
#endif
}

void LiveRecognizer::emit(uint8_t symbol, size_t to, bool whole, bool end_of_text,
                               std::vector<tts::SpokenPhoneme>& out) {
  if (to <= settled_) return;
  MarkupEvent e;
  e.kind = PFAP_EVENT_PHONEME;
  e.phoneme.symbol = symbol;
  // The rest of a phoneme given out in pieces carries nothing of its start (as
  // pfap::split_long_phoneme's pieces); a word begins after a pause (no words are known).
  if (!(piece_open_ && symbol == last_symbol_)) {
    e.sentence_start = !any_out_;
    e.phoneme.word_begin = symbol != 0 && (!any_out_ || last_symbol_ == 0);
  }
  e.phoneme.end_of_text = end_of_text;
  const size_t a = settled_ - std::min(settled_, kHalfF0Window);
  const size_t b = std::min(samples(), to + kHalfF0Window);
  const size_t bounds[] = {settled_ - a, to - a};
  const double hz = tts::segment_f0(std::span(audio_).subspan(a - first_, b - a), rate_, bounds)[0];
  e.phoneme.f0 = f0_code(static_cast<unsigned>(std::lround(hz)));
  tts::add_phoneme(e, settled_, to, rate_, out);
  settled_ = to;
  last_symbol_ = symbol;
  piece_open_ = !whole;
  any_out_ = true;
  any_speech_ = any_speech_ || symbol != 0;
}

}  // namespace pfap::align

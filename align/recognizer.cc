// SPDX-License-Identifier: LGPL-2.1-or-later
#include "recognizer.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include "aligner.h"  // kSpeechLevelDb
#include "f0.h"
#include "mfcc.h"
#include "pfap/phoneme_table.h"

#if PFAP_HAVE_POCKETSPHINX
#include <pocketsphinx.h>
#include <sphinxbase/err.h>
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
// A recognized phone: its symbol and first 10 ms frame.
struct Phone {
  uint8_t symbol;
  int first_frame;
};

// The decoder's acoustic front end: 10 ms frames of a 25.625 ms window (the model's
// feat.params), whatever the rate; the FFT must hold the window.
constexpr unsigned kFramesPerSecond = 100;
constexpr double kWindowSeconds = 0.025625;

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
ps_decoder_t* new_decoder(unsigned rate, std::string& error) {
  const std::string model = PFAP_POCKETSPHINX_MODELDIR "/en-us";
  const std::string hmm = model + "/en-us";
  const std::string phone_lm = model + "/en-us-phone.lm.bin";
  const std::string samprate = std::to_string(rate);
  const std::string nfft = std::to_string(fft_size(rate));
  cmd_ln_t* config = cmd_ln_init(nullptr, ps_args(), TRUE, "-hmm", hmm.c_str(), "-allphone",
                                 phone_lm.c_str(), "-backtrace", "yes", "-beam", "1e-15", "-pbeam",
                                 "1e-15", "-lw", "2.0", "-samprate", samprate.c_str(), "-nfft",
                                 nfft.c_str(), "-remove_silence", "no", nullptr);
  ps_decoder_t* ps = config != nullptr ? ps_init(config) : nullptr;
  if (config != nullptr) cmd_ln_free_r(config);  // the decoder keeps its own reference
  if (ps == nullptr) {
    error = "pocketsphinx cannot load its US English model from " + model +
            " (Debian: pocketsphinx-en-us)";
  }
  return ps;
}

// The phones of the best path, SIL and fillers as pauses, consecutive pauses merged.
std::vector<Phone> decode(ps_decoder_t* ps, std::span<const int16_t> audio) {
  std::vector<Phone> phones;
  ps_start_utt(ps);
  ps_process_raw(ps, audio.data(), audio.size(), FALSE, TRUE);  // whole: CMN over it all
  ps_end_utt(ps);
  for (ps_seg_t* seg = ps_seg_iter(ps); seg != nullptr; seg = ps_seg_next(seg)) {
    int first = 0, last = 0;
    ps_seg_frames(seg, &first, &last);
    const uint8_t symbol = arpabet_symbol(ps_seg_word(seg));
    if (!phones.empty() && symbol == 0 && phones.back().symbol == 0) continue;
    phones.push_back({symbol, first});
  }
  return phones;
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
  ps_decoder_t* ps = new_decoder(rate, error);
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
  std::vector<Phone> phones;
  {
    std::lock_guard<std::mutex> turn(decoder->lock);
    phones = decode(decoder->ps, audio);
  }
  if (std::none_of(phones.begin(), phones.end(), [](const Phone& p) { return p.symbol != 0; })) {
    out.problem = RecognitionProblem::kNothingHeard;
    pause_over(audio.size(), rate, out);
    return true;
  }

  // A phone's first frame starts half a hop before that frame's window centre, where the
  // frame before it ends: the window is 25.6 ms, the hop 10 ms.
  const double offset = (kWindowSeconds - 1.0 / kFramesPerSecond) / 2 * rate;
  std::vector<size_t> bounds;
  bounds.push_back(0);
  for (size_t k = 1; k < phones.size(); ++k) {
    const double at = static_cast<double>(phones[k].first_frame) * rate / kFramesPerSecond + offset;
    const size_t s = std::min(static_cast<size_t>(at), audio.size());
    bounds.push_back(std::max(s, bounds.back()));
  }
  bounds.push_back(audio.size());

  const std::vector<double> f0 = tts::segment_f0(audio, rate, bounds);
  for (size_t k = 0; k < phones.size(); ++k) {
    MarkupEvent e;
    e.kind = PFAP_EVENT_PHONEME;
    e.phoneme.symbol = phones[k].symbol;
    e.phoneme.f0 = f0_code(static_cast<unsigned>(std::lround(f0[k])));
    e.phoneme.word_begin = phones[k].symbol != 0 && (k == 0 || phones[k - 1].symbol == 0);
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

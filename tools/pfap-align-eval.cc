// SPDX-License-Identifier: LGPL-2.1-or-later
// Measures pfapalign's alignment (align/) against phoneme times known from another
// synthesizer: for each `name` in a corpus directory, name.wav (16-bit mono PCM), name.txt
// (its text) and name.segs (Festival's segment file: "end_time 100 phone" lines after "#").
// The phoneme sequences of the two synthesizers are matched by edit distance, and the
// boundary error is measured at the start of each phoneme both have in the same place.
// Prints each sentence and then the median and 90th percentile error of the alignment and of
// two baselines, the share of phonemes matched and the real-time factor. Then, where the build
// has the recognizer (align/recognizer.h), the text-free mode: the share of 10 ms frames whose
// viseme is Festival's, beside the alignment's with the text and the baseline of one viseme
// throughout (the commonest, chosen knowing the truth), and its real-time factor.
// docs/align.md.
//
//   pfap-align-eval DIR NAME...      (tools/align-eval-festival makes DIR and runs this)
// With PFAP_ALIGN_EVAL_VERBOSE set it prints both phoneme sequences with their starts in ms;
// PFAP_ALIGN_EVAL_VOICE picks the espeak-ng voice (default "en"); with PFAP_ALIGN_EVAL_LIVE
// set it aligns as pfapalign live=true does (align/live.h, the audio in 20 ms blocks) and
// recognizes live too (LiveRecognizer), beside the offline recognition; with
// PFAP_ALIGN_EVAL_TEXT_ONLY set it leaves out the text-free modes (minutes of recognition);
// PFAP_ALIGN_EVAL_LEAD_IN=S puts S seconds of silence before each recording (its truth moved
// with it) and PFAP_ALIGN_EVAL_LEAD_OUT=S after it, for the first sound's start error and the
// last sound's end error (issue 31), printed beside the median and p90.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "aligner.h"
#include "command_line.h"
#include "live.h"
#include "pfap/phoneme_table.h"
#include "recognizer.h"
#include "viseme_detector.h"
#include "viseme_frames.h"
#include "wav_file.h"

namespace {

struct Phone {
  std::string name;
  double start;  // seconds
};

std::vector<Phone> read_segs(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && line != "#") {
  }
  std::vector<Phone> out;
  double start = 0, end = 0;
  int colour = 0;
  std::string name;
  while (in >> end >> colour >> name) {
    out.push_back({name, start});
    start = end;
  }
  return out;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out == "pause" ? "pau" : out;
}

// The start-time errors (seconds) of the phonemes `got` and `want` have in the same place of
// an edit-distance alignment of their names, the first (which starts at 0 in both) left out.
std::vector<double> matched_errors(const std::vector<Phone>& got, const std::vector<Phone>& want,
                                   size_t& matched) {
  const size_t n = got.size(), m = want.size();
  std::vector<std::vector<int>> d(n + 1, std::vector<int>(m + 1));
  for (size_t i = 0; i <= n; ++i) d[i][0] = static_cast<int>(i);
  for (size_t j = 0; j <= m; ++j) d[0][j] = static_cast<int>(j);
  for (size_t i = 1; i <= n; ++i) {
    for (size_t j = 1; j <= m; ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1,
                          d[i - 1][j - 1] + (got[i - 1].name == want[j - 1].name ? 0 : 1)});
    }
  }
  std::vector<double> errors;
  matched = 0;
  for (size_t i = n, j = m; i > 0 && j > 0;) {
    const bool same = got[i - 1].name == want[j - 1].name;
    if (d[i][j] == d[i - 1][j - 1] + (same ? 0 : 1)) {
      if (same) {
        ++matched;
        if (i > 1 && j > 1) errors.push_back(std::abs(got[i - 1].start - want[j - 1].start));
      }
      --i, --j;
    } else if (d[i][j] == d[i - 1][j] + 1) {
      --i;
    } else {
      --j;
    }
  }
  return errors;
}

// Festival's phone (its radio phone set, lower case) as an x-pfap-arpabet symbol: the same
// names but "ax" (schwa, ARPAbet's unstressed AH) and "pau".
uint8_t festival_symbol(const std::string& name) {
  if (name == "pau" || name == "h#" || name == "brth") return 0;
  std::string upper = name == "ax" ? "AH" : name;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const std::optional<uint8_t> symbol =
      pfap::find_symbol(*pfap::find_alphabet(pfap::kArpabetAlphabet), upper);
  if (!symbol)
    std::fprintf(stderr, "Festival phone %s: not in x-pfap-arpabet, a pause\n", name.c_str());
  return symbol.value_or(0);
}

std::vector<pfap::align::TimedSymbol> timed(const std::vector<pfap::tts::SpokenPhoneme>& phonemes,
                                            unsigned rate) {
  std::vector<pfap::align::TimedSymbol> out;
  for (const pfap::tts::SpokenPhoneme& p : phonemes) {
    out.push_back({static_cast<double>(p.start) / rate, p.event.phoneme.symbol});
  }
  return out;
}

// Frames on which `got` shows `truth`'s viseme, added to `same`, over all (`frames`) and over
// those where the truth is not a pause (`speech_same` of `speech_frames`).
struct Agreement {
  size_t same = 0, frames = 0, speech_same = 0, speech_frames = 0;
  void add(const std::vector<pfap::Viseme>& got, const std::vector<pfap::Viseme>& truth) {
    for (size_t f = 0; f < std::min(got.size(), truth.size()); ++f) {
      const bool agree = got[f] == truth[f];
      same += agree;
      ++frames;
      if (truth[f] != pfap::Viseme::kNone) {
        speech_same += agree;
        ++speech_frames;
      }
    }
  }
  void print(const char* what) const {
    std::printf("%-36s %5.1f %% of frames, %5.1f %% of speech frames\n", what,
                100.0 * static_cast<double>(same) / std::max<size_t>(frames, 1),
                100.0 * static_cast<double>(speech_same) / std::max<size_t>(speech_frames, 1));
  }
};

double seconds_from_env(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr ? std::max(0.0, std::atof(value)) : 0;
}

// PFAP_ALIGN_EVAL_LEAD_IN seconds of digital silence put before `samples` and
// PFAP_ALIGN_EVAL_LEAD_OUT seconds after (as `sox in.wav out.wav pad IN OUT`), the truth's
// starts after its first moved by the lead-in.
void add_silence(std::vector<int16_t>& samples, unsigned rate, std::vector<Phone>& truth) {
  const double lead_in = seconds_from_env("PFAP_ALIGN_EVAL_LEAD_IN");
  samples.insert(samples.begin(), static_cast<size_t>(lead_in * rate), 0);
  samples.resize(
      samples.size() + static_cast<size_t>(seconds_from_env("PFAP_ALIGN_EVAL_LEAD_OUT") * rate), 0);
  for (size_t k = 1; k < truth.size(); ++k) truth[k].start += lead_in;
}

bool is_sound(const Phone& p) { return p.name != "pau" && p.name != "h#" && p.name != "brth"; }

// The error of the first sound's start (the first phoneme that is not a pause) in seconds.
double first_sound_error(const std::vector<Phone>& got, const std::vector<Phone>& truth) {
  auto first = [](const std::vector<Phone>& ps) {
    const auto p = std::find_if(ps.begin(), ps.end(), is_sound);
    return p != ps.end() ? p->start : 0.0;
  };
  return std::abs(first(got) - first(truth));
}

// The error of the last sound's end (the start of the pause after it, else the recording's
// `end`) in seconds.
double last_sound_error(const std::vector<Phone>& got, const std::vector<Phone>& truth,
                        double end) {
  auto last_end = [end](const std::vector<Phone>& ps) {
    const auto p = std::find_if(ps.rbegin(), ps.rend(), is_sound);
    return p != ps.rbegin() && p != ps.rend() ? (p - 1)->start : end;
  };
  return std::abs(last_end(got) - last_end(truth));
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

// As align(), but by the live aligner, the audio given in 20 ms blocks as a microphone gives
// it; a phoneme sent in pieces is one phoneme.
bool align_live(const pfap::tts::Utterance& utterance, const pfap::tts::VoiceSettings& voice,
                const std::vector<int16_t>& samples, unsigned rate, pfap::align::Alignment& out,
                std::string& error) {
  pfap::align::LiveAligner aligner;
  if (!aligner.start(utterance, voice, rate, error)) return false;
  std::vector<pfap::tts::SpokenPhoneme> phonemes;
  const size_t block = rate / 50;
  for (size_t i = 0; i < samples.size(); i += block) {
    aligner.push(std::span(samples).subspan(i, std::min(block, samples.size() - i)), phonemes);
  }
  aligner.finish(phonemes);
  out = pfap::align::Alignment{};
  for (const pfap::tts::SpokenPhoneme& p : phonemes) {
    if (!out.phonemes.empty() &&
        out.phonemes.back().event.phoneme.symbol == p.event.phoneme.symbol) {
      continue;
    }
    out.phonemes.push_back(p);
  }
  return true;
}

// As recognize(), but by the live recognizer, the audio given in 20 ms blocks; `lag` is the
// most audio that had come past what was given out, after any block.
bool recognize_live(const std::vector<int16_t>& samples, unsigned rate,
                    pfap::align::Recognition& out, size_t& lag, std::string& error) {
  pfap::align::LiveRecognizer recognizer;
  if (!recognizer.start(rate, error)) return false;
  out = pfap::align::Recognition{};
  const size_t block = rate / 50;
  for (size_t i = 0; i < samples.size(); i += block) {
    recognizer.push(std::span(samples).subspan(i, std::min(block, samples.size() - i)),
                    out.phonemes);
    lag = std::max(lag, recognizer.samples() - recognizer.settled());
  }
  recognizer.finish(out.phonemes);
  out.problem = recognizer.problem();
  return true;
}

// The frame-level viseme detector (align/viseme_detector.h) over the recording in 20 ms
// blocks: each 10 ms frame's viseme.
std::vector<pfap::Viseme> detect_visemes(const std::vector<int16_t>& samples, unsigned rate) {
  pfap::align::VisemeDetector detector(rate);
  std::vector<pfap::align::VisemeRun> runs;
  const size_t block = std::max(1u, rate / 50);
  for (size_t i = 0; i < samples.size(); i += block) {
    detector.push(std::span(samples).subspan(i, std::min(block, samples.size() - i)), runs);
  }
  detector.finish(runs);
  std::vector<pfap::Viseme> out;
  for (const pfap::align::VisemeRun& r : runs) out.insert(out.end(), r.frames, r.viseme);
  return out;
}

// How this run measures, from the environment (the file's comment says how).
struct Settings {
  pfap::tts::VoiceSettings voice;  // PFAP_ALIGN_EVAL_VOICE, pfapalign's voice property
  bool recognize = false;          // the text-free modes: built, and not TEXT_ONLY
  bool live = false;
  bool verbose = false;
  int wrong_text_shift = 0;  // PFAP_ALIGN_EVAL_WRONG_TEXT: each recording with the text k on
};

// What is measured over every sentence.
struct Totals {
  std::vector<double> aligned_errors, first_errors, last_errors, equal_errors, scaled_errors,
      costs;
  size_t matched = 0, truth_phonemes = 0, poor = 0;
  double audio_seconds = 0, align_seconds = 0;
  std::vector<pfap::Viseme> truth_frames;  // every sentence's, for the baseline
  Agreement aligned_agreement;
  Agreement detector_agreement;  // the frame-level viseme detector's
  double detector_cpu_seconds = 0;
  // Without the text, offline and live.
  Agreement recognized_agreement, live_agreement, live_offline_agreement;
  double recognize_seconds = 0, recognize_cpu_seconds = 0, live_seconds = 0, live_cpu_seconds = 0;
  size_t live_lag_ms = 0;  // the most audio not yet given out
};

// One recording, its text and its truth.
struct Sentence {
  std::vector<int16_t> samples;
  unsigned rate = 0;
  std::string text;
  std::vector<Phone> truth;
  double duration = 0;  // seconds
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double cpu_seconds_since(std::clock_t c0) {
  return static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
}

std::string arpabet_name(uint8_t symbol) {
  return std::string(
      pfap::find_phoneme(*pfap::find_alphabet(pfap::kArpabetAlphabet), symbol)->name);
}

// PFAP_ALIGN_EVAL_VERBOSE: a phoneme sequence with its starts in ms.
void print_phones(const std::vector<Phone>& phones) {
  for (const Phone& p : phones) std::printf(" %s@%.0f", p.name.c_str(), p.start * 1000);
  std::printf("\n");
}

void print_phonemes(const std::vector<pfap::tts::SpokenPhoneme>& phonemes, unsigned rate) {
  for (const pfap::tts::SpokenPhoneme& p : phonemes) {
    std::printf(" %s@%zu", arpabet_name(p.event.phoneme.symbol).c_str(), p.start * 1000 / rate);
  }
  std::printf("\n");
}

// DIR/NAME.wav and .segs, with the lead-in, and the text of DIR/TEXT_NAME.txt.
bool read_sentence(const std::string& dir, const char* name, const char* text_name, Sentence& out) {
  const std::string base = dir + "/" + name;
  if (!pfap::tools::read_wav(base + ".wav", out.samples, out.rate)) {
    std::fprintf(stderr, "%s.wav: not 16-bit mono PCM\n", base.c_str());
    return false;
  }
  std::ifstream text_in(dir + "/" + text_name + ".txt");
  std::stringstream text;
  text << text_in.rdbuf();
  out.text = text.str();
  out.truth = read_segs(base + ".segs");
  add_silence(out.samples, out.rate, out.truth);
  out.duration = static_cast<double>(out.samples.size()) / out.rate;
  return true;
}

// The alignment's boundary errors beside the two baselines': equal-length phonemes, and
// espeak-ng's own times stretched to the recording's length (what the warp adds to that).
// Returns the alignment's errors.
std::vector<double> measure_boundaries(const Settings& settings, const Sentence& s,
                                       const pfap::tts::Utterance& utterance,
                                       const pfap::align::Alignment& alignment, Totals& totals,
                                       size_t& matched) {
  std::vector<Phone> got, equal, scaled;
  for (const pfap::tts::SpokenPhoneme& p : alignment.phonemes) {
    got.push_back(
        {lower(arpabet_name(p.event.phoneme.symbol)), static_cast<double>(p.start) / s.rate});
  }
  pfap::tts::Speech syn;
  std::string error;
  pfap::tts::speak(utterance, settings.voice, syn, error);
  const double syn_duration = static_cast<double>(syn.samples.size()) / syn.sample_rate;
  for (size_t k = 0; k < syn.phonemes.size(); ++k) {
    const std::string name = lower(arpabet_name(syn.phonemes[k].event.phoneme.symbol));
    equal.push_back(
        {name, s.duration * static_cast<double>(k) / static_cast<double>(syn.phonemes.size())});
    scaled.push_back({name, static_cast<double>(syn.phonemes[k].start) / syn.sample_rate *
                                s.duration / syn_duration});
  }
  if (settings.verbose) {
    print_phones(got);
    print_phones(s.truth);
  }
  size_t unused = 0;
  const std::vector<double> e = matched_errors(got, s.truth, matched);
  totals.aligned_errors.insert(totals.aligned_errors.end(), e.begin(), e.end());
  totals.first_errors.push_back(first_sound_error(got, s.truth));
  totals.last_errors.push_back(last_sound_error(got, s.truth, s.duration));
  const std::vector<double> b1 = matched_errors(equal, s.truth, unused);
  totals.equal_errors.insert(totals.equal_errors.end(), b1.begin(), b1.end());
  const std::vector<double> b2 = matched_errors(scaled, s.truth, unused);
  totals.scaled_errors.insert(totals.scaled_errors.end(), b2.begin(), b2.end());
  totals.matched += matched;
  totals.truth_phonemes += s.truth.size();
  totals.costs.push_back(alignment.relative_cost);
  return e;
}

// The text-free modes' viseme agreement with the truth, offline and (settings.live) live;
// `share` is the offline one's for this sentence.
bool measure_recognition(const Settings& settings, const Sentence& s,
                         const std::vector<pfap::Viseme>& truth_visemes, Totals& totals,
                         double& share, std::string& error) {
  pfap::align::Recognition recognition;
  const auto r0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  if (!pfap::align::recognize(s.samples, s.rate, recognition, error)) return false;
  totals.recognize_seconds += seconds_since(r0);
  totals.recognize_cpu_seconds += cpu_seconds_since(c0);
  const std::vector<pfap::Viseme> visemes =
      pfap::align::viseme_frames(timed(recognition.phonemes, s.rate), s.duration);
  totals.recognized_agreement.add(visemes, truth_visemes);
  share = pfap::align::viseme_agreement(visemes, truth_visemes);
  if (settings.live) {
    pfap::align::Recognition live_recognition;
    size_t lag = 0;
    const auto l0 = std::chrono::steady_clock::now();
    const std::clock_t lc0 = std::clock();
    if (!recognize_live(s.samples, s.rate, live_recognition, lag, error)) return false;
    totals.live_seconds += seconds_since(l0);
    totals.live_cpu_seconds += cpu_seconds_since(lc0);
    totals.live_lag_ms = std::max(totals.live_lag_ms, lag * 1000 / s.rate);
    const std::vector<pfap::Viseme> live_visemes =
        pfap::align::viseme_frames(timed(live_recognition.phonemes, s.rate), s.duration);
    totals.live_agreement.add(live_visemes, truth_visemes);
    totals.live_offline_agreement.add(live_visemes, visemes);
    if (settings.verbose) print_phonemes(live_recognition.phonemes, s.rate);
  }
  if (settings.verbose) print_phonemes(recognition.phonemes, s.rate);
  return true;
}

// Aligns one sentence (and recognizes it without its text), adds what it measures to
// `totals` and prints its line.
bool evaluate(const Settings& settings, const char* name, const Sentence& s, Totals& totals) {
  std::vector<pfap::tts::BadBookmark> bad;
  const pfap::tts::Utterance utterance = pfap::tts::parse_utterance(s.text, bad);
  pfap::align::Alignment alignment;
  std::string error;
  const auto t0 = std::chrono::steady_clock::now();
  if (!(settings.live
            ? align_live(utterance, settings.voice, s.samples, s.rate, alignment, error)
            : pfap::align::align(utterance, settings.voice, s.samples, s.rate, alignment, error))) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return false;
  }
  totals.align_seconds += seconds_since(t0);
  totals.audio_seconds += s.duration;

  size_t matched = 0;
  const std::vector<double> e =
      measure_boundaries(settings, s, utterance, alignment, totals, matched);

  std::vector<pfap::align::TimedSymbol> truth_symbols;
  for (const Phone& p : s.truth) truth_symbols.push_back({p.start, festival_symbol(p.name)});
  const std::vector<pfap::Viseme> truth_visemes =
      pfap::align::viseme_frames(truth_symbols, s.duration);
  totals.truth_frames.insert(totals.truth_frames.end(), truth_visemes.begin(), truth_visemes.end());
  totals.aligned_agreement.add(
      pfap::align::viseme_frames(timed(alignment.phonemes, s.rate), s.duration), truth_visemes);
  const std::clock_t d0 = std::clock();
  totals.detector_agreement.add(detect_visemes(s.samples, s.rate), truth_visemes);
  totals.detector_cpu_seconds += cpu_seconds_since(d0);
  double recognized_share = 0;
  if (settings.recognize &&
      !measure_recognition(settings, s, truth_visemes, totals, recognized_share, error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return false;
  }
  std::printf(
      "%s: %.2f s, %zu of %zu phonemes matched, median %.1f ms, p90 %.1f ms, cost %.2f, "
      "heard %.2f%s; without text %.0f %% of viseme frames\n",
      name, s.duration, matched, s.truth.size(), percentile(e, 0.5) * 1000,
      percentile(e, 0.9) * 1000, alignment.relative_cost, alignment.heard_agreement,
      alignment.problem == pfap::align::Problem::kNone ? "" : " (poor)", recognized_share * 100);
  totals.poor += alignment.problem != pfap::align::Problem::kNone;
  return true;
}

void print_boundary_summary(const Totals& t, int sentences) {
  std::printf("\n%d sentences, %.1f s of audio, %zu boundaries (%zu of %zu phonemes matched)\n",
              sentences, t.audio_seconds, t.aligned_errors.size(), t.matched, t.truth_phonemes);
  std::printf("%-36s median %6.1f ms   p90 %6.1f ms\n", "aligned (pfapalign)",
              percentile(t.aligned_errors, 0.5) * 1000, percentile(t.aligned_errors, 0.9) * 1000);
  std::printf("%-36s median %6.1f ms   p90 %6.1f ms   max %6.1f ms\n", "first sound's start",
              percentile(t.first_errors, 0.5) * 1000, percentile(t.first_errors, 0.9) * 1000,
              percentile(t.first_errors, 1) * 1000);
  std::printf("%-36s median %6.1f ms   p90 %6.1f ms   max %6.1f ms\n", "last sound's end",
              percentile(t.last_errors, 0.5) * 1000, percentile(t.last_errors, 0.9) * 1000,
              percentile(t.last_errors, 1) * 1000);
  std::printf("%-36s median %6.1f ms   p90 %6.1f ms\n", "baseline: equal-length phonemes",
              percentile(t.equal_errors, 0.5) * 1000, percentile(t.equal_errors, 0.9) * 1000);
  std::printf("%-36s median %6.1f ms   p90 %6.1f ms\n", "baseline: espeak-ng times stretched",
              percentile(t.scaled_errors, 0.5) * 1000, percentile(t.scaled_errors, 0.9) * 1000);
  std::printf("relative warp cost: min %.2f, median %.2f, max %.2f; %zu of %d flagged poor\n",
              percentile(t.costs, 0), percentile(t.costs, 0.5), percentile(t.costs, 1), t.poor,
              sentences);
  std::printf("real-time factor: %.3f (%.2f s to align %.1f s, with espeak-ng's synthesis)\n",
              t.align_seconds / t.audio_seconds, t.align_seconds, t.audio_seconds);
}

void print_viseme_summary(const Settings& settings, const Totals& t) {
  // The baseline: the viseme most frames show, throughout, over all frames and over speech.
  std::array<size_t, 15> count{}, speech_count{};
  for (pfap::Viseme v : t.truth_frames) {
    ++count[static_cast<size_t>(v)];
    if (v != pfap::Viseme::kNone) ++speech_count[static_cast<size_t>(v)];
  }
  const size_t speech_total = t.truth_frames.size() - count[0];
  std::printf("\nviseme agreement per 10 ms frame (%zu frames, %zu of them speech):\n",
              t.truth_frames.size(), speech_total);
  if (settings.recognize) t.recognized_agreement.print("without text (pocketsphinx phones)");
  if (settings.recognize && settings.live) {
    t.live_agreement.print("without text, live");
    t.live_offline_agreement.print("live against offline (not Festival)");
  }
  t.aligned_agreement.print("with text (pfapalign)");
  t.detector_agreement.print("frame-level viseme detector, live");
  const auto commonest = std::max_element(count.begin(), count.end());
  const auto commonest_speech = std::max_element(speech_count.begin(), speech_count.end());
  std::printf("%-36s %5.1f %% of frames (viseme %zu), %5.1f %% of speech frames (viseme %zu)\n",
              "baseline: one viseme throughout",
              100.0 * static_cast<double>(*commonest) / std::max<size_t>(t.truth_frames.size(), 1),
              static_cast<size_t>(commonest - count.begin()),
              100.0 * static_cast<double>(*commonest_speech) / std::max<size_t>(speech_total, 1),
              static_cast<size_t>(commonest_speech - speech_count.begin()));
  std::printf("viseme detector: %.2f s of processor time for %.1f s, %.2f %% of a core\n",
              t.detector_cpu_seconds, t.audio_seconds,
              100 * t.detector_cpu_seconds / t.audio_seconds);
  if (!settings.recognize) {
    std::printf("without text: not measured (PFAP_ALIGN_EVAL_TEXT_ONLY, or no -Drecognition)\n");
    return;
  }
  // The processor time too: on a shared machine the wall clock measures the others' load.
  std::printf(
      "real-time factor without text: %.3f (%.2f s to recognize %.1f s; %.2f s of "
      "processor time, %.3f)\n",
      t.recognize_seconds / t.audio_seconds, t.recognize_seconds, t.audio_seconds,
      t.recognize_cpu_seconds, t.recognize_cpu_seconds / t.audio_seconds);
  if (settings.live) {
    std::printf(
        "real-time factor without text, live: %.3f (%.2f s; %.2f s of processor time, %.3f); "
        "at most %zu ms of audio not yet given out\n",
        t.live_seconds / t.audio_seconds, t.live_seconds, t.live_cpu_seconds,
        t.live_cpu_seconds / t.audio_seconds, t.live_lag_ms);
  }
}

}  // namespace

int main(int argc, char** argv) {
  // It runs no GStreamer, so it takes none of GStreamer's options.
  const GOptionEntry entries[] = {{}};
  if (const int status = parse_command_line(
          &argc, &argv, "DIR NAME...",
          "Measures the forced alignment (and, where built, the text-free recognition) against\n"
          "the phoneme times of DIR/NAME.segs for DIR/NAME.wav and DIR/NAME.txt\n"
          "(tools/align-eval-festival makes DIR and runs this; docs/align.md). The environment:\n"
          "PFAP_ALIGN_EVAL_VOICE the espeak-ng voice (default en); PFAP_ALIGN_EVAL_LIVE set:\n"
          "align and recognize live too; PFAP_ALIGN_EVAL_TEXT_ONLY set: no text-free modes;\n"
          "PFAP_ALIGN_EVAL_WRONG_TEXT=K: each recording with the text K places on;\n"
          "PFAP_ALIGN_EVAL_VERBOSE set: every phoneme sequence with its starts in ms.",
          entries, nullptr);
      status != 0) {
    return status;
  }
  if (argc < 3) return usage_error("wants a DIR and at least one NAME");
  const std::string dir = argv[1];
  Settings settings;
  if (const char* v = std::getenv("PFAP_ALIGN_EVAL_VOICE")) settings.voice.voice = v;
  settings.recognize =
      pfap::align::recognition_available() && std::getenv("PFAP_ALIGN_EVAL_TEXT_ONLY") == nullptr;
  settings.live = std::getenv("PFAP_ALIGN_EVAL_LIVE") != nullptr;
  settings.verbose = std::getenv("PFAP_ALIGN_EVAL_VERBOSE") != nullptr;
  // PFAP_ALIGN_EVAL_WRONG_TEXT=k: each recording with the text k places on (default 1), to
  // see the poor-match statistics of a text that does not match.
  if (const char* wrong = std::getenv("PFAP_ALIGN_EVAL_WRONG_TEXT")) {
    settings.wrong_text_shift = std::max(1, std::atoi(wrong));
  }
  const int sentences = argc - 2;
  Totals totals;
  for (int a = 2; a < argc; ++a) {
    Sentence s;
    const char* text_name = argv[2 + (a - 2 + settings.wrong_text_shift) % sentences];
    if (!read_sentence(dir, argv[a], text_name, s) || !evaluate(settings, argv[a], s, totals)) {
      return 1;
    }
  }
  print_boundary_summary(totals, sentences);
  print_viseme_summary(settings, totals);
  return 0;
}

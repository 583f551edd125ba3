// SPDX-License-Identifier: LGPL-2.1-or-later
// Measures pfapalign's alignment (align/) against phoneme times known from another
// synthesizer: for each `name` in a corpus directory, name.wav (16-bit mono PCM), name.txt
// (its text) and name.segs (Festival's segment file: "end_time 100 phone" lines after "#").
// The phoneme sequences of the two synthesizers are matched by edit distance, and the
// boundary error is measured at the start of each phoneme both have in the same place.
// Prints each sentence and then the median and 90th percentile error of the alignment and of
// two baselines, the share of phonemes matched and the real-time factor. docs/align.md.
//
//   pfap-align-eval DIR NAME...      (tools/align-eval-festival makes DIR and runs this)
// With PFAP_ALIGN_EVAL_VERBOSE set it prints both phoneme sequences with their starts in ms;
// PFAP_ALIGN_EVAL_VOICE picks the espeak-ng voice (default "en"); with PFAP_ALIGN_EVAL_LIVE
// set it aligns as pfapalign live=true does (align/streaming.h, the audio in 20 ms blocks).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "aligner.h"
#include "pfap/phoneme_table.h"
#include "streaming.h"

namespace {

struct Phone {
  std::string name;
  double start;  // seconds
};

bool read_wav(const std::string& path, std::vector<int16_t>& samples, unsigned& rate) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 12 || bytes.compare(0, 4, "RIFF") != 0) return false;
  auto u32 = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  auto u16 = [&](size_t at) {
    uint16_t v;
    std::memcpy(&v, bytes.data() + at, 2);
    return v;
  };
  bool format_ok = false;
  for (size_t at = 12; at + 8 <= bytes.size();) {
    const std::string id = bytes.substr(at, 4);
    const uint32_t size = u32(at + 4);
    if (id == "fmt ") {
      format_ok = u16(at + 8) == 1 && u16(at + 10) == 1 && u16(at + 22) == 16;
      rate = u32(at + 12);
    } else if (id == "data" && format_ok) {
      const size_t n = std::min<size_t>(size, bytes.size() - at - 8) / 2;
      samples.resize(n);
      std::memcpy(samples.data(), bytes.data() + at + 8, n * 2);
      return true;
    }
    at += 8 + size + (size & 1);
  }
  return false;
}

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
  pfap::align::StreamingAligner aligner;
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

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s DIR NAME...\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  // PFAP_ALIGN_EVAL_VOICE: the espeak-ng voice to align with (pfapalign's voice property).
  pfap::tts::VoiceSettings voice;
  if (const char* v = std::getenv("PFAP_ALIGN_EVAL_VOICE")) voice.voice = v;
  const pfap::PhonemeAlphabet& arpabet = *pfap::find_alphabet(pfap::kArpabetAlphabet);
  std::vector<double> aligned_errors, equal_errors, scaled_errors, costs;
  size_t matched_total = 0, truth_total = 0;
  double audio_seconds = 0, align_seconds = 0;
  for (int a = 2; a < argc; ++a) {
    const std::string base = dir + "/" + argv[a];
    std::vector<int16_t> samples;
    unsigned rate = 0;
    if (!read_wav(base + ".wav", samples, rate)) {
      std::fprintf(stderr, "%s.wav: not 16-bit mono PCM\n", base.c_str());
      return 1;
    }
    // PFAP_ALIGN_EVAL_WRONG_TEXT: each recording with the next one's text, to see the cost
    // of a text that does not match.
    const bool wrong = std::getenv("PFAP_ALIGN_EVAL_WRONG_TEXT") != nullptr;
    std::ifstream text_in(dir + "/" + argv[wrong ? 2 + (a - 1) % (argc - 2) : a] + ".txt");
    std::stringstream text;
    text << text_in.rdbuf();
    const std::vector<Phone> truth = read_segs(base + ".segs");

    std::vector<pfap::tts::BadBookmark> bad;
    const pfap::tts::Utterance utterance = pfap::tts::parse_utterance(text.str(), bad);
    pfap::align::Alignment alignment;
    std::string error;
    const auto t0 = std::chrono::steady_clock::now();
    const bool live = std::getenv("PFAP_ALIGN_EVAL_LIVE") != nullptr;
    if (!(live ? align_live(utterance, voice, samples, rate, alignment, error)
               : pfap::align::align(utterance, voice, samples, rate, alignment, error))) {
      std::fprintf(stderr, "%s\n", error.c_str());
      return 1;
    }
    align_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double duration = static_cast<double>(samples.size()) / rate;
    audio_seconds += duration;

    // Ours; the baseline of equal-length phonemes; espeak-ng's own times stretched to the
    // recording's length (what the warp adds to that).
    std::vector<Phone> got, equal, scaled;
    for (const pfap::tts::SpokenPhoneme& p : alignment.phonemes) {
      got.push_back({lower(pfap::find_phoneme(arpabet, p.event.phoneme.symbol)->name),
                     static_cast<double>(p.start) / rate});
    }
    pfap::tts::Speech syn;
    pfap::tts::speak(utterance, voice, syn, error);
    const double syn_duration = static_cast<double>(syn.samples.size()) / syn.sample_rate;
    for (size_t k = 0; k < syn.phonemes.size(); ++k) {
      const std::string name =
          lower(pfap::find_phoneme(arpabet, syn.phonemes[k].event.phoneme.symbol)->name);
      equal.push_back(
          {name, duration * static_cast<double>(k) / static_cast<double>(syn.phonemes.size())});
      scaled.push_back({name, static_cast<double>(syn.phonemes[k].start) / syn.sample_rate *
                                  duration / syn_duration});
    }
    if (std::getenv("PFAP_ALIGN_EVAL_VERBOSE") != nullptr) {
      for (const Phone& p : got) std::printf(" %s@%.0f", p.name.c_str(), p.start * 1000);
      std::printf("\n");
      for (const Phone& p : truth) std::printf(" %s@%.0f", p.name.c_str(), p.start * 1000);
      std::printf("\n");
    }
    size_t matched = 0, unused = 0;
    const std::vector<double> e = matched_errors(got, truth, matched);
    aligned_errors.insert(aligned_errors.end(), e.begin(), e.end());
    const std::vector<double> b1 = matched_errors(equal, truth, unused);
    equal_errors.insert(equal_errors.end(), b1.begin(), b1.end());
    const std::vector<double> b2 = matched_errors(scaled, truth, unused);
    scaled_errors.insert(scaled_errors.end(), b2.begin(), b2.end());
    matched_total += matched;
    truth_total += truth.size();
    costs.push_back(alignment.relative_cost);
    std::printf(
        "%s: %.2f s, %zu of %zu phonemes matched, median %.1f ms, p90 %.1f ms, cost %.2f%s\n",
        argv[a], duration, matched, truth.size(), percentile(e, 0.5) * 1000,
        percentile(e, 0.9) * 1000, alignment.relative_cost,
        alignment.problem == pfap::align::Problem::kNone ? "" : " (poor)");
  }
  std::printf("\n%d sentences, %.1f s of audio, %zu boundaries (%zu of %zu phonemes matched)\n",
              argc - 2, audio_seconds, aligned_errors.size(), matched_total, truth_total);
  std::printf("%-36s median %6.1f ms   p90 %6.1f ms\n", "aligned (pfapalign)",
              percentile(aligned_errors, 0.5) * 1000, percentile(aligned_errors, 0.9) * 1000);
  std::printf("%-36s median %6.1f ms   p90 %6.1f ms\n", "baseline: equal-length phonemes",
              percentile(equal_errors, 0.5) * 1000, percentile(equal_errors, 0.9) * 1000);
  std::printf("%-36s median %6.1f ms   p90 %6.1f ms\n", "baseline: espeak-ng times stretched",
              percentile(scaled_errors, 0.5) * 1000, percentile(scaled_errors, 0.9) * 1000);
  std::printf("relative warp cost: min %.2f, median %.2f, max %.2f\n", percentile(costs, 0),
              percentile(costs, 0.5), percentile(costs, 1));
  std::printf("real-time factor: %.3f (%.2f s to align %.1f s, with espeak-ng's synthesis)\n",
              align_seconds / audio_seconds, align_seconds, audio_seconds);
  return 0;
}

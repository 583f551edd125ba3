// SPDX-License-Identifier: LGPL-2.1-or-later
// The viseme detector's corpus and measurement (docs/align.md, "A viseme detector"), run by
// tools/viseme-corpus, tools/viseme-train and tools/viseme-eval. A corpus directory holds
// NAME.wav (16-bit mono PCM, any rate) and NAME.segs (Festival's segment file: "end_time 100
// phone" lines after "#", phones in lower case as Festival's radio set: x-pfap-arpabet's
// names, "ax" for AH, "pau").
//
//   pfap-viseme-data speak VOICE RATE PITCH DIR PREFIX < SENTENCES
//       espeak-ng (as pfaptts speaks, tts/) says each line: DIR/PREFIX-NNN.wav and .segs, the
//       phoneme starts in phonetic convention (align/boundaries.h)
//   pfap-viseme-data label WAV TEXT SEGS
//       pfapalign's alignment of the recording WAV with the text in file TEXT, as SEGS
//   pfap-viseme-data features DIR NAME...
//       DIR/NAME.mfcc (the detector's features, float32, 13 a frame) and DIR/NAME.vis (each
//       10 ms frame's viseme in the segments, one byte a frame)
//   pfap-viseme-data eval DIR NAME...
//       the detector on each recording in 20 ms blocks: its visemes' agreement with the
//       segments', the baseline of one viseme, phonemes (runs) a second, processor time
//   pfap-viseme-data trace WAV OUT.json
//       the detector's probabilities and runs for WAV, in 20 ms blocks, as JSON: the
//       fixture tests/web compares web/src/viseme_detector.js with
// eval and trace use the model of the file PFAP_VISEME_MODEL if set, else the built-in one.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "aligner.h"
#include "boundaries.h"
#include "pfap/phoneme_table.h"
#include "viseme_detector.h"
#include "viseme_frames.h"
#include "wav_file.h"

namespace {

using pfap::align::TimedSymbol;

const pfap::PhonemeAlphabet& arpabet() { return *pfap::find_alphabet(pfap::kArpabetAlphabet); }

// `path` as 16-bit mono PCM, or false with a message.
bool load(const std::string& path, std::vector<int16_t>& samples, unsigned& rate) {
  if (pfap::tools::read_wav(path, samples, rate)) return true;
  std::fprintf(stderr, "%s: not 16-bit mono PCM\n", path.c_str());
  return false;
}

void write_wav(const std::string& path, const std::vector<int16_t>& samples, unsigned rate) {
  std::ofstream out(path, std::ios::binary);
  auto u32 = [&](uint32_t v) { out.write(reinterpret_cast<const char*>(&v), 4); };
  auto u16 = [&](uint16_t v) { out.write(reinterpret_cast<const char*>(&v), 2); };
  const auto bytes = static_cast<uint32_t>(samples.size() * 2);
  out.write("RIFF", 4), u32(36 + bytes), out.write("WAVEfmt ", 8), u32(16), u16(1), u16(1);
  u32(rate), u32(rate * 2), u16(2), u16(16), out.write("data", 4), u32(bytes);
  out.write(reinterpret_cast<const char*>(samples.data()), bytes);
}

// Festival's name of an x-pfap-arpabet symbol, and back ("ax" is AH, as Festival's schwa).
std::string segs_name(uint8_t symbol) {
  if (symbol == 0) return "pau";
  std::string name(pfap::find_phoneme(arpabet(), symbol)->name);
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return name;
}

uint8_t segs_symbol(const std::string& name) {
  if (name == "pau" || name == "h#" || name == "brth") return 0;
  std::string upper = name == "ax" ? "AH" : name;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return pfap::find_symbol(arpabet(), upper).value_or(0);
}

// Phonemes by start (seconds) as a segment file: each one's end, the last at `seconds`.
void write_segs(const std::string& path, const std::vector<TimedSymbol>& phonemes,
                double seconds) {
  std::ofstream out(path);
  out << "#\n";
  for (size_t k = 0; k < phonemes.size(); ++k) {
    const double end = k + 1 < phonemes.size() ? phonemes[k + 1].start : seconds;
    out << end << " 100 " << segs_name(phonemes[k].symbol) << "\n";
  }
}

std::vector<TimedSymbol> read_segs(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && line != "#") {
  }
  std::vector<TimedSymbol> out;
  double start = 0, end = 0;
  int colour = 0;
  std::string name;
  while (in >> end >> colour >> name) {
    out.push_back({start, segs_symbol(name)});
    start = end;
  }
  return out;
}

std::vector<TimedSymbol> timed(const std::vector<pfap::tts::SpokenPhoneme>& phonemes,
                               unsigned rate) {
  std::vector<TimedSymbol> out;
  for (const pfap::tts::SpokenPhoneme& p : phonemes) {
    if (!out.empty() && out.back().symbol == p.event.phoneme.symbol) continue;  // a piece
    out.push_back({static_cast<double>(p.start) / rate, p.event.phoneme.symbol});
  }
  return out;
}

int speak(int argc, char** argv) {
  if (argc != 7) return 2;
  pfap::tts::VoiceSettings voice;
  voice.voice = argv[2];
  voice.rate = std::atoi(argv[3]);
  voice.pitch = std::atoi(argv[4]);
  std::string line;
  for (int n = 1; std::getline(std::cin, line); ++n) {
    std::vector<pfap::tts::BadBookmark> bad;
    pfap::tts::Speech speech;
    std::string error;
    if (!pfap::tts::speak(pfap::tts::parse_utterance(line, bad), voice, speech, error)) {
      std::fprintf(stderr, "%s\n", error.c_str());
      return 1;
    }
    pfap::align::to_phonetic_boundaries(speech);
    char name[64];
    std::snprintf(name, sizeof name, "%s-%03d", argv[6], n);
    const std::string base = std::string(argv[5]) + "/" + name;
    write_wav(base + ".wav", speech.samples, speech.sample_rate);
    write_segs(base + ".segs", timed(speech.phonemes, speech.sample_rate),
               static_cast<double>(speech.samples.size()) / speech.sample_rate);
  }
  return 0;
}

int label(int argc, char** argv) {
  if (argc != 5) return 2;
  std::vector<int16_t> samples;
  unsigned rate = 0;
  if (!load(argv[2], samples, rate)) return 1;
  std::ifstream text_in(argv[3]);
  std::stringstream text;
  text << text_in.rdbuf();
  std::vector<pfap::tts::BadBookmark> bad;
  pfap::align::Alignment alignment;
  std::string error;
  if (!pfap::align::align(pfap::tts::parse_utterance(text.str(), bad), {}, samples, rate,
                          alignment, error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 1;
  }
  write_segs(argv[4], timed(alignment.phonemes, rate),
             static_cast<double>(samples.size()) / rate);
  return 0;
}

int features(int argc, char** argv) {
  for (int a = 3; a < argc; ++a) {
    const std::string base = std::string(argv[2]) + "/" + argv[a];
    std::vector<int16_t> samples;
    unsigned rate = 0;
    if (!load(base + ".wav", samples, rate)) return 1;
    const std::vector<float> f = pfap::align::viseme_features(samples, rate);
    const size_t frames = f.size() / pfap::align::kVisemeMfccs;
    std::vector<pfap::Viseme> truth = pfap::align::viseme_frames(
        read_segs(base + ".segs"), static_cast<double>(frames) * pfap::align::kVisemeFrameSeconds);
    std::ofstream(base + ".mfcc", std::ios::binary)
        .write(reinterpret_cast<const char*>(f.data()),
               static_cast<std::streamsize>(f.size() * sizeof(float)));
    std::ofstream(base + ".vis", std::ios::binary)
        .write(reinterpret_cast<const char*>(truth.data()),
               static_cast<std::streamsize>(truth.size()));
  }
  return 0;
}

// The model of PFAP_VISEME_MODEL (a file as align/viseme_model.txt; to compare models without
// building each in), else the built-in one. Exits if the file holds no model.
const pfap::align::VisemeModel& model() {
  static const std::unique_ptr<pfap::align::VisemeModel> from_file =
      []() -> std::unique_ptr<pfap::align::VisemeModel> {
    const char* path = std::getenv("PFAP_VISEME_MODEL");
    if (path == nullptr) return nullptr;
    std::ifstream in(path);
    std::vector<float> numbers;
    std::string line;
    while (std::getline(in, line)) {
      std::stringstream fields(line.substr(0, line.find("//")));
      std::string field;
      while (std::getline(fields, field, ',')) {
        if (field.find_first_not_of(" \t") != std::string::npos)
          numbers.push_back(
              std::strtof(field.c_str(), nullptr));  // as the compiler reads a denormal
      }
    }
    auto model = pfap::align::VisemeModel::from_numbers(numbers);
    if (model == nullptr) {
      std::fprintf(stderr, "%s: not a viseme model of this version\n", path);
      std::exit(1);
    }
    return model;
  }();
  return from_file != nullptr ? *from_file : pfap::align::VisemeModel::builtin();
}

// The detector over `samples` in 20 ms blocks, as a live source gives them.
std::vector<pfap::align::VisemeRun> detect(const std::vector<int16_t>& samples, unsigned rate,
                                           std::vector<float>* trace = nullptr) {
  // PFAP_VISEME_MARGIN and PFAP_VISEME_MIN_RUN: other smoothing, to choose it on the
  // validation set.
  pfap::align::VisemeSmoothing smoothing;
  if (const char* m = std::getenv("PFAP_VISEME_MARGIN")) smoothing.switch_margin = std::stof(m);
  if (const char* m = std::getenv("PFAP_VISEME_MIN_RUN")) smoothing.min_run_frames = std::stoul(m);
  pfap::align::VisemeDetector detector(rate, 0, smoothing, model());
  detector.trace(trace);
  std::vector<pfap::align::VisemeRun> runs;
  const size_t block = std::max(1u, rate / 50);
  for (size_t i = 0; i < samples.size(); i += block) {
    detector.push(std::span(samples).subspan(i, std::min(block, samples.size() - i)), runs);
  }
  detector.finish(runs);
  return runs;
}

std::vector<pfap::Viseme> run_frames(const std::vector<pfap::align::VisemeRun>& runs) {
  std::vector<pfap::Viseme> out;
  for (const pfap::align::VisemeRun& r : runs) out.insert(out.end(), r.frames, r.viseme);
  return out;
}

int eval(int argc, char** argv) {
  size_t same = 0, frames = 0, speech_same = 0, speech_frames = 0, runs_total = 0;
  std::array<size_t, pfap::align::kVisemeCount> count{}, speech_count{};
  std::array<std::array<size_t, pfap::align::kVisemeCount>, pfap::align::kVisemeCount> confusion{};
  double seconds = 0, cpu = 0;
  for (int a = 3; a < argc; ++a) {
    const std::string base = std::string(argv[2]) + "/" + argv[a];
    std::vector<int16_t> samples;
    unsigned rate = 0;
    if (!load(base + ".wav", samples, rate)) return 1;
    const double duration = static_cast<double>(samples.size()) / rate;
    seconds += duration;
    const std::clock_t c0 = std::clock();
    const std::vector<pfap::align::VisemeRun> runs = detect(samples, rate);
    cpu += static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    runs_total += runs.size();
    const std::vector<pfap::Viseme> got = run_frames(runs);
    const std::vector<pfap::Viseme> truth =
        pfap::align::viseme_frames(read_segs(base + ".segs"), duration);
    for (size_t f = 0; f < std::min(got.size(), truth.size()); ++f) {
      const auto t = static_cast<size_t>(truth[f]);
      const bool agree = got[f] == truth[f];
      same += agree, ++frames, ++count[t];
      ++confusion[t][static_cast<size_t>(got[f])];
      if (t != 0) speech_same += agree, ++speech_frames, ++speech_count[t];
    }
  }
  const size_t commonest = *std::max_element(count.begin(), count.end());
  const size_t commonest_speech = *std::max_element(speech_count.begin(), speech_count.end());
  std::printf("%d recordings, %.1f s, %zu frames (%zu speech)\n", argc - 3, seconds, frames,
              speech_frames);
  std::printf("%-36s %5.1f %% of frames, %5.1f %% of speech frames\n", "viseme detector",
              100.0 * static_cast<double>(same) / std::max<size_t>(frames, 1),
              100.0 * static_cast<double>(speech_same) / std::max<size_t>(speech_frames, 1));
  std::printf("%-36s %5.1f %% of frames, %5.1f %% of speech frames\n",
              "baseline: one viseme throughout",
              100.0 * static_cast<double>(commonest) / std::max<size_t>(frames, 1),
              100.0 * static_cast<double>(commonest_speech) / std::max<size_t>(speech_frames, 1));
  std::printf("runs (phonemes) a second: %.1f; processor time %.3f s, %.2f %% of a core\n",
              static_cast<double>(runs_total) / std::max(seconds, 1e-9), cpu,
              100 * cpu / std::max(seconds, 1e-9));
  if (std::getenv("PFAP_VISEME_CONFUSION") != nullptr) {
    std::printf("confusion (rows truth, columns detected, %% of the row):\n");
    for (size_t t = 0; t < pfap::align::kVisemeCount; ++t) {
      std::printf("%2zu:", t);
      for (size_t g = 0; g < pfap::align::kVisemeCount; ++g) {
        std::printf(" %3.0f", 100.0 * static_cast<double>(confusion[t][g]) /
                                  std::max<size_t>(count[t], 1));
      }
      std::printf("\n");
    }
  }
  return 0;
}

int trace(int argc, char** argv) {
  if (argc != 4) return 2;
  std::vector<int16_t> samples;
  unsigned rate = 0;
  if (!load(argv[2], samples, rate)) return 1;
  std::vector<float> probabilities;
  const std::vector<pfap::align::VisemeRun> runs = detect(samples, rate, &probabilities);
  std::ofstream out(argv[3]);
  out << "{\"rate\":" << rate << ",\"probabilities\":[";
  char number[32];
  for (size_t i = 0; i < probabilities.size(); ++i) {
    std::snprintf(number, sizeof number, "%s%.7g", i > 0 ? "," : "",
                  static_cast<double>(probabilities[i]));
    out << number;
  }
  out << "],\"runs\":[";
  for (size_t i = 0; i < runs.size(); ++i) {
    out << (i > 0 ? "," : "") << "[" << runs[i].start << "," << runs[i].frames << ","
        << static_cast<int>(runs[i].viseme) << "]";
  }
  out << "]}\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  int status = 2;
  if (mode == "speak") status = speak(argc, argv);
  if (mode == "label") status = label(argc, argv);
  if (mode == "features" && argc > 3) status = features(argc, argv);
  if (mode == "eval" && argc > 3) status = eval(argc, argv);
  if (mode == "trace") status = trace(argc, argv);
  if (status == 2) {
    std::fprintf(stderr,
                 "usage: %s speak VOICE RATE PITCH DIR PREFIX < SENTENCES | label WAV TEXT SEGS "
                 "| features DIR NAME... | eval DIR NAME... | trace WAV OUT.json\n",
                 argv[0]);
  }
  return status;
}

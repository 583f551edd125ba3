// SPDX-License-Identifier: LGPL-2.1-or-later
// MPEG-4 FAP files (pfap/fap_file.h, pfap/fap_animation.h; docs/fap-files.md):
//  - SharedFapFiles.*: every file in ../shared/fap parses; its events, applied to a FapState
//    and sampled at the frame times, give back every frame's values exactly; FapRecorder
//    writes a file that reads back the same.
//  - FapFileRead.*, FapFileErrors.*: what the reader accepts, and a table of bad files each
//    with its status, line, field and FAP.
//  - FapFileMarkup.*, FapRecorder.*: the mapping's rules (expressions, 40 bookmarks per
//    phoneme, the mask the writer sets).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pfap/fap_animation.h"
#include "pfap/fap_file.h"
#include "pfap/fap_state.h"

namespace pfap {
namespace {

namespace fs = std::filesystem;

// ../shared/fap beside the source tree, or $PFAP_FAP_DIR (for a worktree elsewhere).
fs::path shared_dir() {
  const char* env = std::getenv("PFAP_FAP_DIR");
  return env != nullptr && *env != '\0' ? fs::path(env) : fs::path(PFAP_SHARED_FAP_DIR);
}

std::vector<fs::path> shared_files() {
  std::vector<fs::path> files;
  const fs::path dir = shared_dir();
  if (!fs::is_directory(dir)) return files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".fap") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

#define SKIP_WITHOUT_SHARED_FILES(files)              \
  if ((files).empty())                                \
  GTEST_SKIP() << "no .fap files in " << shared_dir() \
               << ": the real MPEG-4 FAP files live beside the project in ../shared/fap"

// Each frame's amplitudes, as the mapping reads them.
std::vector<FapAmplitudes> amplitudes_of(const FapFile& file) {
  std::vector<FapAmplitudes> out;
  NotCarried ignored;
  for (const FapFrame& frame : file.frames) out.push_back(amplitudes_of(frame, ignored));
  return out;
}

// A receiver's FapState fed the events, sampled at each frame's time.
std::vector<FapAmplitudes> sampled(const std::vector<TextEvent>& events,
                                   const FapFileHeader& header) {
  std::vector<FapAmplitudes> out;
  FapState state;
  size_t next = 0;
  for (uint32_t k = 0; k < header.frame_count; ++k) {
    const int64_t at = frame_time_ms(k, header.frame_rate) * kNsPerMs;
    for (; next < events.size() && events[next].time_ms * kNsPerMs <= at; ++next) {
      for (const Fap& f : events[next].event.faps) state.apply(f, events[next].time_ms * kNsPerMs);
    }
    FapAmplitudes& frame = out.emplace_back();
    for (int i = kMinFapIndex; i <= kMaxFapIndex; ++i) {
      const double a = state.amplitude(i, at);
      frame[i] = static_cast<int32_t>(a);
      EXPECT_EQ(a, frame[i]) << "frame " << k << " FAP " << i << " not a whole value";
    }
  }
  return out;
}

std::string first_difference(const std::vector<FapAmplitudes>& got,
                             const std::vector<FapAmplitudes>& want) {
  if (got.size() != want.size()) {
    return std::to_string(got.size()) + " frames, want " + std::to_string(want.size());
  }
  for (size_t k = 0; k < got.size(); ++k) {
    for (int i = kMinFapIndex; i <= kMaxFapIndex; ++i) {
      if (got[k][i] != want[k][i]) {
        return "frame " + std::to_string(k) + " FAP " + std::to_string(i) + ": " +
               std::to_string(got[k][i]) + ", want " + std::to_string(want[k][i]);
      }
    }
  }
  return "";
}

TEST(SharedFapFiles, EveryFileParses) {
  const auto files = shared_files();
  SKIP_WITHOUT_SHARED_FILES(files);
  EXPECT_EQ(files.size(), 8u);
  for (const fs::path& path : files) {
    SCOPED_TRACE(path.filename().string());
    FapFile file;
    const FapFileResult result = read_fap_file(read_all(path), file);
    ASSERT_TRUE(result.ok()) << describe(result);
    EXPECT_EQ(file.header.version, "2.1");
    EXPECT_EQ(file.header.frame_rate, 25.0);
    EXPECT_EQ(file.frames.size(), file.header.frame_count);
    EXPECT_GE(file.frames.size(), 107u);
    // Faces move: some frame sets some FAP to something other than 0.
    const auto amplitudes = amplitudes_of(file);
    EXPECT_TRUE(std::any_of(amplitudes.begin(), amplitudes.end(), [](const FapAmplitudes& a) {
      return std::any_of(a.begin(), a.end(), [](int32_t v) { return v != 0; });
    }));
  }
}

TEST(SharedFapFiles, EventsSampledAtFrameTimesGiveBackEveryValue) {
  const auto files = shared_files();
  SKIP_WITHOUT_SHARED_FILES(files);
  for (const fs::path& path : files) {
    SCOPED_TRACE(path.filename().string());
    FapFile file;
    ASSERT_TRUE(read_fap_file(read_all(path), file).ok());
    NotCarried not_carried;
    const std::vector<TextEvent> events = markup_of(file, &not_carried);
    EXPECT_FALSE(not_carried.any());  // these files set neither FAP 1 nor FAP 2
    EXPECT_EQ(first_difference(sampled(events, file.header), amplitudes_of(file)), "");
    // Phonemes tile the file's time: contiguous, ending at the last frame's end.
    int64_t at = 0;
    for (const TextEvent& e : events) {
      EXPECT_EQ(e.time_ms, at);
      EXPECT_LE(e.event.faps.size(), size_t{kMaxBookmarksPerPhoneme});
      at += e.event.phoneme.duration_ms;
    }
    EXPECT_EQ(at, frame_time_ms(file.header.frame_count, 25.0));
    EXPECT_TRUE(events.back().event.phoneme.end_of_text);
  }
}

TEST(SharedFapFiles, RecorderWritesAFileThatReadsBackTheSame) {
  const auto files = shared_files();
  SKIP_WITHOUT_SHARED_FILES(files);
  for (const fs::path& path : files) {
    SCOPED_TRACE(path.filename().string());
    FapFile file;
    ASSERT_TRUE(read_fap_file(read_all(path), file).ok());
    const std::vector<TextEvent> events = markup_of(file);
    FapRecorder recorder(file.header.frame_rate);
    for (const TextEvent& e : events) ASSERT_TRUE(recorder.apply(e.event, e.time_ms * kNsPerMs));
    const TextEvent& last = events.back();
    ASSERT_TRUE(recorder.finish((last.time_ms + last.event.phoneme.duration_ms) * kNsPerMs));
    EXPECT_EQ(first_difference(recorder.amplitudes(), amplitudes_of(file)), "");

    const std::string written = write_fap_file(recorder.file("joy"));
    FapFile back;
    const FapFileResult result = read_fap_file(written, back);
    ASSERT_TRUE(result.ok()) << describe(result);
    EXPECT_EQ(back.header.frame_count, file.header.frame_count);
    EXPECT_EQ(first_difference(amplitudes_of(back), amplitudes_of(file)), "");
  }
}

// ---------------------------------------------------------------------------------------------
// Reading

// A file of `frames` frames setting FAPs 3 and 4 to k and -k in frame k.
std::string small_file(int frames, const std::string& header = "2.1 test 25") {
  std::string mask = "0 0 1 1";
  for (int i = 5; i <= 68; ++i) mask += " 0";
  std::string text = header + " " + std::to_string(frames) + "\n";
  for (int k = 0; k < frames; ++k) {
    text +=
        mask + "\n" + std::to_string(k) + " " + std::to_string(k) + " " + std::to_string(-k) + "\n";
  }
  return text;
}

std::string mask_setting(std::initializer_list<int> faps) {
  std::string mask;
  for (int i = 1; i <= 68; ++i) {
    if (i > 1) mask += ' ';
    mask += std::find(faps.begin(), faps.end(), i) != faps.end() ? '1' : '0';
  }
  return mask;
}

TEST(FapFileRead, CommentsBlankLinesCrlfAndANameWithSpaces) {
  const std::string text = "# made by hand\r\n\r\n2.1 C:\\My Faces\\a b 12.5 1\r\n  # mask\r\n" +
                           mask_setting({3, 68}) + " \r\n\t0 7 -8 \r\n# end";
  FapFile file;
  const FapFileResult result = read_fap_file(text, file);
  ASSERT_TRUE(result.ok()) << describe(result);
  EXPECT_EQ(file.header.name, "C:\\My Faces\\a b");
  EXPECT_EQ(file.header.frame_rate, 12.5);
  ASSERT_EQ(file.frames.size(), 1u);
  EXPECT_EQ(file.frames[0].value[3], 7);
  EXPECT_EQ(file.frames[0].value[68], -8);
  EXPECT_TRUE(file.frames[0].set[68]);
  EXPECT_FALSE(file.frames[0].set[4]);
}

TEST(FapFileRead, FractionsRoundToTheNearestHalvesAwayFromZero) {
  struct Case {
    const char* text;
    int32_t value;
    uint32_t rounded;
  };
  const Case cases[] = {{"12", 12, 0},     {"12.0", 12, 0}, {"12.49", 12, 1}, {"12.5", 13, 1},
                        {"-12.5", -13, 1}, {"-0.4", 0, 1},  {".5", 1, 1},     {"-.5", -1, 1},
                        {"+3", 3, 0},      {"007", 7, 0}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    FapFile file;
    const FapFileResult result =
        read_fap_file("2.0 t 25 1\n" + mask_setting({5}) + "\n0 " + c.text + "\n", file);
    ASSERT_TRUE(result.ok()) << describe(result);
    EXPECT_EQ(file.frames[0].value[5], c.value);
    EXPECT_EQ(file.frames[0].rounded, c.rounded);
  }
}

TEST(FapFileRead, VisemeAndExpressionFields) {
  FapFile file;
  const FapFileResult result = read_fap_file(
      "2.1 t 25 1\n" + mask_setting({1, 2, 3}) + "\n0 3 4 50 1  1 40 3 20 1 0  -6\n", file);
  ASSERT_TRUE(result.ok()) << describe(result);
  const FapFrame& f = file.frames[0];
  EXPECT_EQ(f.viseme, (std::array<int32_t, 4>{3, 4, 50, 1}));
  EXPECT_EQ(f.expression, (std::array<int32_t, 6>{1, 40, 3, 20, 1, 0}));
  EXPECT_EQ(f.value[3], -6);
}

TEST(FapFileRead, WritingAndReadingAgain) {
  FapFile file;
  ASSERT_TRUE(read_fap_file(small_file(3, "2.1 my name 29.97"), file).ok());
  const std::string written = write_fap_file(file);
  EXPECT_EQ(written.substr(0, written.find('\n')), "2.1 my_name 29.97 3");
  FapFile back;
  ASSERT_TRUE(read_fap_file(written, back).ok());
  EXPECT_EQ(back.frames, file.frames);
  EXPECT_EQ(write_fap_file(back), written);
}

struct BadFile {
  const char* what;
  std::string text;
  FapFileStatus status;
  uint64_t line;
  uint32_t field;
  int fap;
};

std::vector<BadFile> bad_files() {
  const std::string mask = mask_setting({3, 4});
  const std::string head = "2.1 t 25 2\n";
  const std::string frame0 = mask + "\n0 1 2\n";
  return {
      {"empty", "", FapFileStatus::kTruncated, 1, 0, 0},
      {"only comments", "# nothing\n", FapFileStatus::kTruncated, 2, 0, 0},
      {"version 3", "3.0 t 25 1\n", FapFileStatus::kBadVersion, 1, 1, 0},
      {"no version", "t 25 1\n", FapFileStatus::kBadVersion, 1, 1, 0},
      {"no count", "2.1 t 25\n", FapFileStatus::kMissingField, 1, 4, 0},
      {"rate 0", "2.1 t 0 1\n", FapFileStatus::kBadFrameRate, 1, 3, 0},
      {"rate 0.5", "2.1 t 0.5 1\n", FapFileStatus::kBadFrameRate, 1, 3, 0},
      {"rate 1001", "2.1 t 1001 1\n", FapFileStatus::kBadFrameRate, 1, 3, 0},
      {"rate negative", "2.1 t -25 1\n", FapFileStatus::kBadFrameRate, 1, 3, 0},
      {"rate inf", "2.1 t inf 1\n", FapFileStatus::kBadFrameRate, 1, 3, 0},
      {"rate nan", "2.1 t nan 1\n", FapFileStatus::kBadFrameRate, 1, 3, 0},
      {"rate 1e3", "2.1 t 1e3 1\n", FapFileStatus::kBadFrameRate, 1, 3, 0},
      {"count 0", "2.1 t 25 0\n", FapFileStatus::kBadFrameCount, 1, 4, 0},
      {"count absurd", "2.1 t 25 99999999999999999999999\n", FapFileStatus::kBadFrameCount, 1, 4,
       0},
      {"count over the limit", "2.1 t 25 360001\n", FapFileStatus::kBadFrameCount, 1, 4, 0},
      {"count not a number", "2.1 t 25 1x\n", FapFileStatus::kBadFrameCount, 1, 4, 0},
      {"name too long", "2.1 " + std::string(2000, 'n') + " 25 1\n", FapFileStatus::kBadName, 1, 2,
       0},
      {"mask of 67", head + mask.substr(0, mask.size() - 2) + "\n", FapFileStatus::kWrongMaskLength,
       2, 68, 0},
      {"mask of 69", head + mask + " 0\n", FapFileStatus::kWrongMaskLength, 2, 69, 0},
      {"mask flag 2", head + "2" + mask.substr(1) + "\n", FapFileStatus::kBadMaskFlag, 2, 1, 1},
      {"frame number 1 first", head + mask + "\n1 1 2\n", FapFileStatus::kBadFrameNumber, 3, 1, 0},
      {"frame number repeated", head + frame0 + mask + "\n0 1 2\n", FapFileStatus::kBadFrameNumber,
       5, 1, 0},
      {"value not a number", head + mask + "\n0 1 x\n", FapFileStatus::kBadValue, 3, 3, 4},
      {"value 5.", head + mask + "\n0 5. 1\n", FapFileStatus::kBadValue, 3, 2, 3},
      {"value -inf", head + mask + "\n0 -inf 1\n", FapFileStatus::kBadValue, 3, 2, 3},
      {"value past the draft", head + mask + "\n0 1 2529601\n", FapFileStatus::kValueOutOfRange, 3,
       3, 4},
      {"value far past", head + mask + "\n0 -99999999999999999999 1\n",
       FapFileStatus::kValueOutOfRange, 3, 2, 3},
      {"value rounds past", head + mask + "\n0 2529600.5 1\n", FapFileStatus::kValueOutOfRange, 3,
       2, 3},
      {"expression 7", "2.1 t 25 1\n" + mask_setting({2}) + "\n0 7 40 0 0 0 0\n",
       FapFileStatus::kValueOutOfRange, 3, 2, 2},
      {"intensity 64", "2.1 t 25 1\n" + mask_setting({2}) + "\n0 1 64 0 0 0 0\n",
       FapFileStatus::kValueOutOfRange, 3, 3, 2},
      {"viseme 15", "2.1 t 25 1\n" + mask_setting({1}) + "\n0 15 0 0 0\n",
       FapFileStatus::kValueOutOfRange, 3, 2, 1},
      {"missing value", head + mask + "\n0 1\n", FapFileStatus::kMissingValues, 3, 3, 4},
      {"missing expression fields", "2.1 t 25 1\n" + mask_setting({2}) + "\n0 1 40 0 0\n",
       FapFileStatus::kMissingValues, 3, 6, 2},
      {"extra value", head + mask + "\n0 1 2 3\n", FapFileStatus::kExtraValues, 3, 4, 0},
      {"truncated: mask only", head + frame0 + mask + "\n", FapFileStatus::kTruncated, 5, 0, 0},
      {"truncated: a frame short", head + frame0, FapFileStatus::kTruncated, 4, 0, 0},
      {"too many frames", "2.1 t 25 1\n" + frame0 + mask + "\n1 1 2\n",
       FapFileStatus::kTooManyFrames, 4, 1, 0},
      {"line too long", head + std::string(70000, ' ') + "\n", FapFileStatus::kLineTooLong, 2, 0,
       0},
  };
}

TEST(FapFileErrors, EachBadFileNamesItsLineFieldAndFap) {
  for (const BadFile& bad : bad_files()) {
    SCOPED_TRACE(bad.what);
    FapFile file;
    file.header.name = "untouched";
    const FapFileResult result = read_fap_file(bad.text, file);
    EXPECT_EQ(result.status, bad.status) << describe(result);
    EXPECT_EQ(result.line, bad.line) << describe(result);
    EXPECT_EQ(result.field, bad.field) << describe(result);
    EXPECT_EQ(result.fap, bad.fap) << describe(result);
    EXPECT_EQ(file.header.name, "untouched");  // nothing kept from a bad file
    EXPECT_EQ(describe(result).find("line " + std::to_string(bad.line)), 0u);
  }
}

TEST(FapFileErrors, DescribeSaysWhereAndWhat) {
  EXPECT_EQ(describe({FapFileStatus::kValueOutOfRange, 6, 13, 14}),
            "line 6, field 13 (FAP 14): value out of range");
  EXPECT_EQ(describe({FapFileStatus::kTruncated, 9, 0, 0}),
            "line 9: the file ends before the header's count of frames");
}

TEST(FapFileErrors, ALineReaderStaysWhereItWasAfterABadLine) {
  FapFileReader reader;
  FapFrame frame;
  bool has_frame = false;
  ASSERT_TRUE(reader.read_line("2.1 t 25 1", frame, has_frame).ok());
  EXPECT_FALSE(reader.read_line("0 1", frame, has_frame).ok());
  EXPECT_FALSE(has_frame);
  ASSERT_TRUE(reader.read_line(mask_setting({3}), frame, has_frame).ok());
  ASSERT_TRUE(reader.read_line("0 12", frame, has_frame).ok());
  EXPECT_TRUE(has_frame);
  EXPECT_EQ(frame.value[3], 12);
  EXPECT_TRUE(reader.finish().ok());
}

// ---------------------------------------------------------------------------------------------
// The mapping

TEST(FapFileMarkup, ExpressionsBecomeFaps69To74AndVisemesAreCounted) {
  FapFile file;
  ASSERT_TRUE(read_fap_file("2.1 t 25 2\n" + mask_setting({1, 2}) + "\n0 3 0 0 0 1 40 3 20 1 0\n" +
                                mask_setting({2}) + "\n1 0 0 6 10 0 0\n",
                            file)
                  .ok());
  NotCarried not_carried;
  const std::vector<TextEvent> events = markup_of(file, &not_carried);
  EXPECT_EQ(not_carried.visemes, 1u);
  EXPECT_EQ(not_carried.expression_flags, 1u);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].event.faps,
            (std::vector<Fap>{{69, 40, 0, Curve::kLinear}, {71, 20, 0, Curve::kLinear}}));
  // Joy and anger end; surprise starts.
  EXPECT_EQ(events[1].event.faps, (std::vector<Fap>{{69, 0, 0, Curve::kLinear},
                                                    {71, 0, 0, Curve::kLinear},
                                                    {74, 10, 0, Curve::kLinear}}));
  EXPECT_EQ(events[1].time_ms, 40);
  EXPECT_TRUE(events[0].event.sentence_start);
  EXPECT_TRUE(events[1].event.phoneme.end_of_text);
}

TEST(FapFileMarkup, MoreThan40ChangesGoOnZeroLengthPhonemesFirst) {
  std::string values = "0";
  for (int i = 3; i <= 68; ++i) values += " " + std::to_string(i);
  std::string mask;
  for (int i = 1; i <= 68; ++i) mask += i < 3 ? "0 " : "1 ";
  FapFile file;
  ASSERT_TRUE(read_fap_file("2.1 t 10 1\n" + mask + "\n" + values + "\n", file).ok());
  const std::vector<TextEvent> events = markup_of(file);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].event.faps.size(), 40u);
  EXPECT_EQ(events[0].event.phoneme.duration_ms, 0);
  EXPECT_FALSE(events[0].event.phoneme.end_of_text);
  EXPECT_EQ(events[1].event.faps.size(), 26u);
  EXPECT_EQ(events[1].event.phoneme.duration_ms, 100);
  EXPECT_EQ(events[1].time_ms, 0);
  EXPECT_TRUE(events[1].event.phoneme.end_of_text);
  EXPECT_FALSE(events[1].event.sentence_start);
}

TEST(FapFileMarkup, FrameTimesAreRoundedToWholeMs) {
  EXPECT_EQ(frame_time_ms(1, 30.0), 33);
  EXPECT_EQ(frame_time_ms(2, 30.0), 67);
  EXPECT_EQ(frame_time_ms(3, 30.0), 100);
  EXPECT_EQ(frame_time_ms(359999, 1000.0), 359999);
  // And sampling at those times gives back every frame, at a rate that is not whole ms.
  FapFile file;
  ASSERT_TRUE(read_fap_file(small_file(31, "2.1 t 29.97"), file).ok());
  EXPECT_EQ(first_difference(sampled(markup_of(file), file.header), amplitudes_of(file)), "");
}

TextEvent speech_phoneme(int64_t start_ms, uint16_t duration_ms, uint8_t symbol, bool end = false,
                         std::vector<Fap> faps = {}) {
  TextEvent e;
  e.time_ms = start_ms;
  e.event.kind = PFAP_EVENT_PHONEME;
  e.event.phoneme = {.symbol = symbol,
                     .duration_ms = duration_ms,
                     .f0 = 60,
                     .stress = true,
                     .word_begin = true,
                     .end_of_text = end};
  e.event.sentence_start = start_ms == 0;
  e.event.faps = std::move(faps);
  return e;
}

TEST(FapFileMarkup, MergedWithSpeechTheFileKeepsItsValuesAndTheSpeechItsPhonemes) {
  FapFile file;
  ASSERT_TRUE(read_fap_file(small_file(20), file).ok());  // 0..800 ms, a change each frame
  // Speech: 0..100 (split at 40 and 80), 100..250 (end of text; split at 120 ... 240), a gap
  // with frames from 280, 400..500, then frames after the speech to 800.
  const std::vector<TextEvent> speech = {speech_phoneme(0, 100, 7),
                                         speech_phoneme(100, 150, 8, true),
                                         speech_phoneme(400, 100, 9, true)};
  const std::vector<TextEvent> merged = merge_with_speech(speech, markup_of(file), 0);
  EXPECT_EQ(first_difference(sampled(merged, file.header), amplitudes_of(file)), "");

  // Each speech phoneme is still there, in pieces that tile it; silence only where no speech.
  for (const TextEvent& s : speech) {
    int64_t covered = 0;
    for (const TextEvent& m : merged) {
      if (m.time_ms < s.time_ms || m.time_ms >= s.time_ms + s.event.phoneme.duration_ms) continue;
      EXPECT_EQ(m.event.phoneme.symbol, s.event.phoneme.symbol) << m.time_ms;
      EXPECT_EQ(m.event.phoneme.f0, 60);
      EXPECT_EQ(m.event.phoneme.word_begin, m.time_ms == s.time_ms);
      covered += m.event.phoneme.duration_ms;
    }
    EXPECT_EQ(covered, s.event.phoneme.duration_ms);
  }
  int64_t at = 0;
  for (const TextEvent& m : merged) {
    if (m.time_ms != at) {  // gaps: from each end of speech to the next frame
      EXPECT_TRUE((at == 250 && m.time_ms == 280) || (at == 500 && m.time_ms == 520))
          << at << " to " << m.time_ms;
    }
    at = m.time_ms + m.event.phoneme.duration_ms;
    const bool in_speech = m.time_ms < 250 || (m.time_ms >= 400 && m.time_ms < 500);
    EXPECT_EQ(m.event.phoneme.symbol == 0, !in_speech) << m.time_ms;
    EXPECT_EQ(m.event.phoneme.end_of_text, m.time_ms == 240 || m.time_ms == 480 || m.time_ms == 760)
        << m.time_ms;
    EXPECT_EQ(m.event.sentence_start, m.time_ms == 0 || m.time_ms == 280 || m.time_ms == 520)
        << m.time_ms;
  }
  EXPECT_EQ(at, 800);
}

TEST(FapFileMarkup, MergedTheFileWinsOverTheSpeechAtItsFrames) {
  FapFile file;
  ASSERT_TRUE(read_fap_file(small_file(3), file).ok());  // FAP 3: 0, 1, 2
  const std::vector<TextEvent> speech = {
      speech_phoneme(0, 50, 7, false, {{3, 99, 0, Curve::kLinear}}),
      speech_phoneme(50, 70, 8, true, {{3, 77, 0, Curve::kLinear}})};
  const std::vector<TextEvent> merged = merge_with_speech(speech, markup_of(file), 0);
  // 99 at 0 is overridden by frame 0's 0... frame 0 has no change of FAP 3 (0 -> 0), so the
  // speech's 99 holds at 0 ms; frames 1 and 2 (40, 80 ms) set 1 and 2 after the speech's.
  const std::vector<FapAmplitudes> got = sampled(merged, file.header);
  EXPECT_EQ(got[0][3], 99);
  EXPECT_EQ(got[1][3], 1);
  EXPECT_EQ(got[2][3], 2);
  ASSERT_EQ(merged.size(), 4u);  // 0..40, 40..50, 50..80, 80..120
  EXPECT_EQ(merged[1].time_ms, 40);
  EXPECT_EQ(merged[1].event.phoneme.symbol, 7);
  EXPECT_EQ(merged[3].event.phoneme.duration_ms, 40);
  EXPECT_TRUE(merged[3].event.phoneme.end_of_text);
}

TEST(FapRecorder, SetsEveryFapEverUsedInEveryFrameAndTheTwoStrongestExpressions) {
  FapRecorder recorder(25.0);
  MarkupEvent e;
  e.kind = PFAP_EVENT_PHONEME;
  e.faps = {{69, 40, 0, Curve::kLinear}, {72, 100, 0, Curve::kLinear}, {74, 5, 0, Curve::kLinear}};
  ASSERT_TRUE(recorder.apply(e, 40 * kNsPerMs));
  e.faps = {{10, -30, 80, Curve::kLinear}};
  ASSERT_TRUE(recorder.apply(e, 80 * kNsPerMs));
  ASSERT_TRUE(recorder.finish(200 * kNsPerMs));
  ASSERT_EQ(recorder.frames(), 5u);  // 0, 40, 80, 120, 160 ms
  NotWritten not_written;
  const FapFile file = recorder.file("x", &not_written);
  EXPECT_EQ(not_written.expressions_dropped, 4u);  // surprise in frames 1..4
  EXPECT_EQ(not_written.intensities_clamped, 4u);  // fear at 100
  std::array<bool, 69> fap2_and_10{};
  fap2_and_10[2] = fap2_and_10[10] = true;
  for (const FapFrame& f : file.frames) EXPECT_EQ(f.set, fap2_and_10);
  EXPECT_EQ(file.frames[0].expression, (std::array<int32_t, 6>{}));
  EXPECT_EQ(file.frames[1].expression, (std::array<int32_t, 6>{4, 63, 1, 40, 0, 0}));
  EXPECT_EQ(file.frames[2].value[10], 0);    // the transition starts at 80 ms
  EXPECT_EQ(file.frames[3].value[10], -15);  // halfway
  EXPECT_EQ(file.frames[4].value[10], -30);
}

TEST(FapRecorder, EndsOnTheSettledStateAndHasAtLeastOneFrame) {
  FapRecorder recorder(25.0);
  MarkupEvent e;
  e.kind = PFAP_EVENT_PHONEME;
  e.faps = {{69, 40, 500, Curve::kLinear}};
  ASSERT_TRUE(recorder.apply(e, 300 * kNsPerMs));
  // The transition ends at 800 ms, the stream at 810 ms: frames 0..20, the last settled.
  ASSERT_TRUE(recorder.finish(810 * kNsPerMs));
  ASSERT_EQ(recorder.frames(), 21u);
  EXPECT_EQ(recorder.amplitudes()[20][69], 40);
  FapRecorder running(25.0);
  e.faps = {{69, 40, 500, Curve::kLinear}};
  ASSERT_TRUE(running.apply(e, 400 * kNsPerMs));
  ASSERT_TRUE(running.finish(820 * kNsPerMs));  // frames 0..20; 20 (800 ms) at 32
  ASSERT_EQ(running.frames(), 24u);             // then on while the transition runs (to 900 ms)
  EXPECT_EQ(running.amplitudes()[20][69], 32);
  EXPECT_EQ(running.amplitudes()[22][69], 38);  // 880 ms
  EXPECT_EQ(running.amplitudes()[23][69], 40);  // 920 ms: settled
  FapRecorder empty(25.0);
  ASSERT_TRUE(empty.finish(0));
  EXPECT_EQ(empty.frames(), 1u);
}

TEST(FapRecorder, StopsAtItsFrameLimitAndCompleteStatesReset) {
  FapRecorder recorder(100.0, 10);
  MarkupEvent e;
  e.kind = PFAP_EVENT_PHONEME;
  e.faps = {{3, 7, 0, Curve::kLinear}};
  ASSERT_TRUE(recorder.apply(e, 0));
  MarkupEvent complete;
  complete.kind = PFAP_EVENT_COMPLETE;
  complete.faps = {{4, 9, 0, Curve::kLinear}};
  ASSERT_TRUE(recorder.apply(complete, 50 * kNsPerMs));
  EXPECT_FALSE(recorder.finish(1000 * kNsPerMs));
  ASSERT_EQ(recorder.frames(), 10u);
  EXPECT_EQ(recorder.amplitudes()[4][3], 7);
  EXPECT_EQ(recorder.amplitudes()[5][3], 0);
  EXPECT_EQ(recorder.amplitudes()[5][4], 9);
}

}  // namespace
}  // namespace pfap

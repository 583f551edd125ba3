// SPDX-License-Identifier: LGPL-2.1-or-later
// The x-pfap writers (pfaptextenc, pfapfapenc, pfapmarksenc in every format) as users run
// them: beside an audio branch into files (they let it preroll), file to file (they keep the
// times), and from speech whose phoneme times fall between milliseconds (no zero-length marks).
#include <gst/check/gstharness.h>
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "documented_commands.h"
#include "element_harness.h"
#include "pfap/markup.h"
#include "pfap/markup_event.h"
#include "pfap_buffers.h"
#include "pipeline.h"
#include "temp_dir.h"

namespace {

using namespace std::chrono_literals;
using pfap::testing::Pipeline;
using pfap::testing::read_file;
using pfap::testing::source_path;
using pfap::testing::TempDir;

constexpr std::array<const char*, 6> kElements{"pfaptts",      "pfaptextenc",    "pfapfapenc",
                                               "pfapmarksenc", "pfapmarksparse", "pfaptextparse"};

// Every writer, and pfapmarksenc in every format.
constexpr std::array<const char*, 9> kWriters{
    "pfaptextenc",
    "pfapfapenc",
    "pfapmarksenc format=polly",
    "pfapmarksenc format=rhubarb-tsv",
    "pfapmarksenc format=rhubarb-json",
    "pfapmarksenc format=talkinghead",
    "pfapmarksenc format=azure",
    "pfapmarksenc format=arkit-json",
    "pfapmarksenc format=arkit-csv",
};

// The README's "Into files" line with each writer where pfaptextenc is. A writer that holds
// its output (a FAP file, a Rhubarb JSON document, an utterance's marks) left the markup's
// filesink without preroll: the audio queue filled, pfaptts blocked, and nothing ended. The
// first sentence lasts longer than the queue holds (1 s), so that the writers that hold an
// utterance's marks hold them past that too.
TEST(WritersIntoFiles, EveryWriterLetsTheAudioBranchRunAndBothFilesAreWritten) {
  ASSERT_TRUE(pfap::testing::plugin_available(kElements));
  for (const char* writer : kWriters) {
    SCOPED_TRACE(writer);
    TempDir dir;
    Pipeline p(std::string("pfaptts name=t text=\"Hello <FAP 2 1 40 0 0 500 1> world, this first "
                           "sentence goes on for well over a second of speech before it ends. "
                           "How are you?\" t.audio ! queue ! audioconvert ! wavenc ! filesink "
                           "location=") +
               dir.file("speech.wav") + " t.pfap ! queue ! " + writer +
               " ! filesink location=" + dir.file("speech.out"));
    ASSERT_TRUE(p.ok()) << p.error();
    ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
    EXPECT_EQ(p.wait_eos(10s), "");
    EXPECT_GT(read_file(dir.file("speech.wav")).size(), 44u * 1000);  // header and speech
    EXPECT_FALSE(read_file(dir.file("speech.out")).empty());
  }
}

// `text` with every number that `pattern`'s first group matches moved by `by` (in the
// format's unit), the numbers written as `write` writes them.
template <typename Write>
std::string shift(const std::string& text, const std::regex& pattern, Write write) {
  std::string out;
  auto last = text.cbegin();
  for (std::sregex_iterator it(text.begin(), text.end(), pattern), end; it != end; ++it) {
    const std::ssub_match& number = (*it)[1];
    out.append(last, number.first);
    out += write(number.str());
    last = number.second;
  }
  out.append(last, text.cend());
  return out;
}

// Each format, its file of hello.pfap's marks (times from 0), how to move its times by
// 500 ms, and the reader and writer of that format.
struct Conversion {
  const char* file;
  const char* reader;
  const char* writer;
  std::string (*later)(const std::string& text);
};

std::string integers_later(const std::string& text, const char* pattern, long by) {
  return shift(text, std::regex(pattern),
               [by](const std::string& n) { return std::to_string(std::stol(n) + by); });
}

// Seconds with three decimals (Rhubarb's), 0.5 s later.
std::string seconds_later(const std::string& text, const char* pattern) {
  return shift(text, std::regex(pattern), [](const std::string& n) {
    const long ms = std::lround(std::stod(n) * 1000) + 500;
    char buffer[32];
    g_snprintf(buffer, sizeof buffer, "%ld.%03ld", ms / 1000, ms % 1000);
    return std::string(buffer);
  });
}

const std::array<Conversion, 5> kConversions{{
    {"hello.pfap", "pfaptextparse", "pfaptextenc",
     [](const std::string& t) { return integers_later(t, "(?:^|\n)(\\d+) ", 500); }},
    {"marks/hello.polly.jsonl", "pfapmarksparse format=polly", "pfapmarksenc format=polly",
     [](const std::string& t) { return integers_later(t, "\"time\":(\\d+)", 500); }},
    {"marks/hello.azure.jsonl", "pfapmarksparse format=azure", "pfapmarksenc format=azure",
     [](const std::string& t) { return integers_later(t, "\"audioOffset\":(\\d+)", 5'000'000); }},
    {"marks/hello.rhubarb.tsv", "pfapmarksparse format=rhubarb", "pfapmarksenc format=rhubarb-tsv",
     [](const std::string& t) { return seconds_later(t, "(?:^|\n)(\\d+\\.\\d+)\t"); }},
    {"marks/hello.rhubarb.json", "pfapmarksparse format=rhubarb",
     "pfapmarksenc format=rhubarb-json",
     [](const std::string& t) {
       return seconds_later(t, "\"(?:start|end|duration)\":(\\d+\\.\\d+)");
     }},
}};

// What `reader ! writer` makes of `text`.
std::string convert(const std::string& text, const Conversion& c) {
  TempDir dir;
  const std::string in = dir.file("in");
  g_file_set_contents(in.c_str(), text.data(), static_cast<gssize>(text.size()), nullptr);
  Pipeline p("filesrc location=" + in + " ! " + c.reader + " ! " + c.writer +
             " ! filesink location=" + dir.file("out"));
  EXPECT_TRUE(p.ok()) << p.error();
  if (!p.ok()) return "";
  EXPECT_EQ(p.set_state(GST_STATE_PLAYING), "");
  EXPECT_EQ(p.wait_eos(10s, true), "");
  return read_file(dir.file("out"));
}

// A file whose first mark is 500 ms into the audio comes out with it at 500 ms: the writers
// write stream time, which the readers take from the file. Before, every time came out 500 ms
// early (the first event at 0).
TEST(WritersKeepTimes, FileToFileConversionsKeepEveryTimeInEveryFormat) {
  ASSERT_TRUE(pfap::testing::plugin_available(kElements));
  for (const Conversion& c : kConversions) {
    SCOPED_TRACE(std::string(c.reader) + " ! " + c.writer);
    const std::string from_zero = read_file(source_path(std::string("docs/examples/") + c.file));
    ASSERT_FALSE(from_zero.empty());
    const std::string at_zero = convert(from_zero, c);
    ASSERT_FALSE(at_zero.empty());
    // The shift moves every time: the example's marks start at 0.
    ASSERT_NE(c.later(at_zero), at_zero);
    EXPECT_EQ(convert(c.later(from_zero), c), c.later(at_zero));
  }
}

// Phonemes whose times fall between milliseconds, as pfaptts's come from audio samples: the
// gaps between them are fractions of a ms. Each format writes whole ms, and none writes a mark
// of no length or two marks at one time.
class ZeroLengthMarks : public ::testing::TestWithParam<const char*> {};

// The numbers `pattern`'s first group matches in `text`, in order, in ms: seconds when its
// second group (the decimal point) matched.
std::vector<long> numbers(const std::string& text, const char* pattern) {
  std::vector<long> out;
  const std::regex re(pattern);
  for (std::sregex_iterator it(text.begin(), text.end(), re), end; it != end; ++it) {
    out.push_back(std::lround(std::stod((*it)[1].str()) * ((*it)[2].matched ? 1000 : 1)));
  }
  return out;
}

TEST_P(ZeroLengthMarks, NoMarkOfNoLengthFromSubMillisecondGaps) {
  const std::string format = GetParam();
  GstHarness* h = gst_harness_new_parse(("pfapmarksenc format=" + format).c_str());
  gst_harness_set_src_caps_str(h, PFAP_MARKUP_CAPS ",alphabet=x-pfap-arpabet");
  // HH 0..60, AH 60.3..150.3, M 150.7..230.7 (end of text): gaps of 0.3 and 0.4 ms.
  const std::array<std::pair<uint8_t, GstClockTime>, 3> phonemes{
      {{16, 0}, {3, 60'300'000}, {22, 150'700'000}}};
  const std::array<uint16_t, 3> durations{60, 90, 80};
  for (size_t i = 0; i < phonemes.size(); ++i) {
    pfap::Phoneme p{phonemes[i].first, durations[i], 60};
    p.word_begin = i == 0;
    p.end_of_text = i == phonemes.size() - 1;
    gst_harness_push(h, pfap::testing::phoneme_buffer(p, {}, phonemes[i].second, i == 0));
  }
  gst_harness_push_event(h, gst_event_new_eos());
  const std::string text = pfap::testing::pull_text(h);
  gst_harness_teardown(h);
  SCOPED_TRACE(text);

  if (format == "rhubarb-json" || format == "talkinghead") {
    // Starts and ends (TalkingHead: vtimes then vdurations): every cue lasts.
    std::vector<long> starts, lengths;
    if (format == "rhubarb-json") {
      const std::vector<long> both = numbers(text, "\"(?:start|end)\":(\\d+(\\.)\\d+)");
      for (size_t i = 0; i + 1 < both.size(); i += 2) {
        starts.push_back(both[i]);
        lengths.push_back(both[i + 1] - both[i]);
      }
    } else {
      const std::regex array("\"(vtimes|vdurations)\":\\[([0-9,]*)\\]");
      for (std::sregex_iterator it(text.begin(), text.end(), array), end; it != end; ++it) {
        std::vector<long>& into = (*it)[1] == "vtimes" ? starts : lengths;
        for (long n : numbers((*it)[2].str(), "(\\d+)")) into.push_back(n);
      }
    }
    ASSERT_EQ(starts.size(), 3u);
    ASSERT_EQ(lengths.size(), 3u);
    for (long length : lengths) EXPECT_GT(length, 0);
    EXPECT_EQ(starts, (std::vector<long>{0, 60, 151}));
    return;
  }
  // The formats of instants: one mark per phoneme and the silence where speech ends, at
  // times that always go forward.
  std::vector<long> times = numbers(text, format == "polly" ? "\"time\":(\\d+),\"type\":\"viseme\""
                                          : format == "azure" ? "\"audioOffset\":(\\d+)"
                                                              : "(?:^|\n)(\\d+(\\.)\\d+)\t");
  if (format == "azure") {
    for (long& t : times) t /= 10'000;  // 100 ns ticks
  }
  EXPECT_EQ(times, (std::vector<long>{0, 60, 151, 231}));
}

INSTANTIATE_TEST_SUITE_P(EveryFormatWithTimes, ZeroLengthMarks,
                         ::testing::Values("polly", "rhubarb-tsv", "rhubarb-json", "talkinghead",
                                           "azure"));

}  // namespace

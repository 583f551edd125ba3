// SPDX-License-Identifier: LGPL-2.1-or-later
// Speech-mark formats: exact output for a known utterance, round trips from .pfap through
// each format back to x-pfap keeping every viseme's time to the ms, and readers' errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pfap/speech_marks.h"
#include "pfap/text.h"

namespace pfap {
namespace {

const PhonemeAlphabet& arpabet() { return *find_alphabet(kArpabetAlphabet); }

std::vector<TextEvent> read_pfap(const std::string& name) {
  std::ifstream file(std::string(PFAP_EXAMPLES_DIR) + "/" + name);
  EXPECT_TRUE(file.good()) << name;
  TextReader reader;
  std::vector<TextEvent> events;
  std::string line;
  while (std::getline(file, line)) {
    TextEvent event;
    bool has_event = false;
    EXPECT_TRUE(reader.read_line(line, event, has_event).ok()) << line;
    if (has_event) events.push_back(event);
  }
  return events;
}

std::string write(MarksFormat format, const std::vector<TextEvent>& events, int fps = 30,
                  int fps_den = 1) {
  MarksWriter writer(format, fps, fps_den);
  writer.set_alphabet(&arpabet());
  std::string out;
  const MarksWriter::Sink sink = [&out](std::string_view text) {
    out += text;
    return true;
  };
  for (const TextEvent& e : events) EXPECT_TRUE(writer.add(e.event, e.time_ms * kNsPerMs, sink));
  EXPECT_TRUE(writer.finish(sink));
  EXPECT_EQ(writer.unknown_phonemes(), 0u);
  return out;
}

std::vector<TextEvent> read_lines(MarksInput input, const std::string& text) {
  MarksReader reader(input);
  std::vector<TextEvent> events;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    const MarksResult result = reader.read_line(line, events);
    EXPECT_TRUE(result.ok()) << "line " << number << ": " << to_string(result.status) << " "
                             << result.what << " at " << result.column << ": " << line;
  }
  reader.finish(events);
  return events;
}

Phoneme phoneme(uint8_t symbol, uint16_t duration_ms, bool word_begin = false,
                bool end_of_text = false) {
  Phoneme p{symbol, duration_ms, 60};
  p.word_begin = word_begin;
  p.end_of_text = end_of_text;
  return p;
}

TextEvent event(int64_t time_ms, Phoneme p, bool sentence_start = false) {
  TextEvent e;
  e.time_ms = time_ms;
  e.event.phoneme = p;
  e.event.sentence_start = sentence_start;
  return e;
}

// "HH AH" then a gap, "M" ending the text: symbols 16 3 22.
std::vector<TextEvent> small_utterance() {
  return {event(0, phoneme(16, 60, true), true), event(60, phoneme(3, 90)),
          event(200, phoneme(22, 80, true, true))};
}

TEST(SpeechMarks, PollyLines) {
  EXPECT_EQ(write(MarksFormat::kPolly, small_utterance()),
            "{\"time\":0,\"type\":\"sentence\",\"value\":\"HH-AH M\"}\n"
            "{\"time\":0,\"type\":\"word\",\"value\":\"HH-AH\"}\n"
            "{\"time\":0,\"type\":\"viseme\",\"value\":\"k\"}\n"
            "{\"time\":60,\"type\":\"viseme\",\"value\":\"@\"}\n"
            "{\"time\":150,\"type\":\"viseme\",\"value\":\"sil\"}\n"
            "{\"time\":200,\"type\":\"word\",\"value\":\"M\"}\n"
            "{\"time\":200,\"type\":\"viseme\",\"value\":\"p\"}\n"
            "{\"time\":280,\"type\":\"viseme\",\"value\":\"sil\"}\n");
}

TEST(SpeechMarks, RhubarbAzureAndTalkingHead) {
  EXPECT_EQ(write(MarksFormat::kRhubarbTsv, small_utterance()),
            "0.000\tB\n0.060\tC\n0.150\tX\n0.200\tA\n0.280\tX\n");
  EXPECT_EQ(write(MarksFormat::kRhubarbJson, small_utterance()),
            "{\"metadata\":{\"soundFile\":\"\",\"duration\":0.280},\"mouthCues\":[\n"
            "{\"start\":0.000,\"end\":0.060,\"value\":\"B\"},\n"
            "{\"start\":0.060,\"end\":0.150,\"value\":\"C\"},\n"
            "{\"start\":0.150,\"end\":0.200,\"value\":\"X\"},\n"
            "{\"start\":0.200,\"end\":0.280,\"value\":\"A\"}\n]}\n");
  EXPECT_EQ(write(MarksFormat::kAzure, small_utterance()),
            "{\"audioOffset\":0,\"visemeId\":12}\n"
            "{\"audioOffset\":600000,\"visemeId\":1}\n"
            "{\"audioOffset\":1500000,\"visemeId\":0}\n"
            "{\"audioOffset\":2000000,\"visemeId\":21}\n"
            "{\"audioOffset\":2800000,\"visemeId\":0}\n");
  EXPECT_EQ(write(MarksFormat::kTalkingHead, small_utterance()),
            "{\"visemes\":[\"kk\",\"aa\",\"sil\",\"PP\"],\"vtimes\":[0,60,150,200],"
            "\"vdurations\":[60,90,50,80],\"words\":[\"HH-AH\",\"M\"],\"wtimes\":[0,200],"
            "\"wdurations\":[150,80]}\n");
}

// Every phoneme of the file comes back at its time, to the ms, with its duration and as the
// viseme of the format that stands for it.
void expect_round_trip(MarksInput input, MarksFormat format, const std::string& file) {
  SCOPED_TRACE(file + " as " + std::string(to_string(format)));
  const std::vector<TextEvent> original = read_pfap(file);
  const std::string text = write(format, original);
  std::vector<TextEvent> back;
  MarksReader reader(input);
  if (format == MarksFormat::kRhubarbJson) {
    const MarksResult result = reader.read_document(text, back);
    ASSERT_TRUE(result.ok()) << to_string(result.status) << " " << result.what;
  } else {
    back = read_lines(input, text);
  }
  const PhonemeAlphabet& alphabet = *find_alphabet(reader.alphabet());
  size_t checked = 0;
  size_t j = 0;
  for (const TextEvent& e : original) {
    if (e.event.kind != PFAP_EVENT_PHONEME) continue;
    const VisemeSet visemes = *find_visemes(arpabet(), e.event.phoneme.symbol);
    // A pause may merge with the silence around it; every sound has its own viseme.
    if (visemes.mpeg4 == Viseme::kNone) continue;
    while (j < back.size() && back[j].time_ms < e.time_ms) ++j;
    ASSERT_LT(j, back.size()) << "nothing at " << e.time_ms;
    EXPECT_EQ(back[j].time_ms, e.time_ms);
    EXPECT_EQ(back[j].event.phoneme.duration_ms, e.event.phoneme.duration_ms) << e.time_ms;
    const std::optional<VisemeSet> read = find_visemes(alphabet, back[j].event.phoneme.symbol);
    ASSERT_TRUE(read.has_value());
    EXPECT_EQ(read->mpeg4, alphabet.symbols[back[j].event.phoneme.symbol].viseme);
    switch (input) {
      case MarksInput::kPolly:
        EXPECT_EQ(back[j].event.phoneme.symbol, visemes.polly) << e.time_ms;
        break;
      case MarksInput::kAzure:
        EXPECT_EQ(back[j].event.phoneme.symbol, visemes.azure) << e.time_ms;
        break;
      case MarksInput::kRhubarb:
        EXPECT_EQ(back[j].event.phoneme.symbol, visemes.rhubarb) << e.time_ms;
        break;
    }
    ++checked;
    ++j;
  }
  EXPECT_GE(checked, 5u);
}

TEST(SpeechMarks, RoundTripsKeepEveryVisemesTime) {
  for (const char* file : {"hello.pfap", "expressions.pfap", "long.pfap", "face.pfap"}) {
    expect_round_trip(MarksInput::kPolly, MarksFormat::kPolly, file);
    expect_round_trip(MarksInput::kAzure, MarksFormat::kAzure, file);
    expect_round_trip(MarksInput::kRhubarb, MarksFormat::kRhubarbTsv, file);
    expect_round_trip(MarksInput::kRhubarb, MarksFormat::kRhubarbJson, file);
  }
}

TEST(SpeechMarks, PollyWordsAndSentencesBecomeFlags) {
  const std::vector<TextEvent> events = read_lines(MarksInput::kPolly, R"({"time":0,"type":"sentence","start":0,"end":23,"value":"Mary had a little lamb."}
{"time":6,"type":"word","start":0,"end":4,"value":"Mary"}
{"time":6,"type":"viseme","value":"p"}
{"time":73,"type":"viseme","value":"E"}
{"time":180,"type":"viseme","value":"r"}
{"time":292,"type":"viseme","value":"i"}
{"time":373,"type":"word","start":5,"end":8,"value":"had"}
{"time":373,"type":"viseme","value":"k"}
{"time":460,"type":"ssml","value":"here"}
{"time":460,"type":"viseme","value":"a"}
{"time":600,"type":"sentence","value":"Yes."}
{"time":600,"type":"viseme","value":"sil"}
{"time":700,"type":"word","value":"Yes"}
{"time":700,"type":"viseme","value":"i"}
)");
  ASSERT_EQ(events.size(), 8u);
  const PhonemeAlphabet& polly = *find_alphabet(kPollyVisemeAlphabet);
  EXPECT_EQ(events[0].time_ms, 6);
  EXPECT_EQ(polly.symbols[events[0].event.phoneme.symbol].name, "p");
  EXPECT_EQ(events[0].event.phoneme.duration_ms, 67);
  EXPECT_TRUE(events[0].event.sentence_start);
  EXPECT_TRUE(events[0].event.phoneme.word_begin);
  EXPECT_FALSE(events[1].event.phoneme.word_begin);
  EXPECT_TRUE(events[4].event.phoneme.word_begin);  // "had"
  EXPECT_EQ(events[5].event.phoneme.duration_ms, 140);
  EXPECT_TRUE(events[5].event.phoneme.end_of_text);  // the last viseme of the sentence
  EXPECT_EQ(events[6].event.phoneme.symbol, 0);      // sil
  EXPECT_TRUE(events[6].event.sentence_start);
  EXPECT_TRUE(events[7].event.phoneme.word_begin);
  EXPECT_EQ(events[7].event.phoneme.duration_ms, MarksReader::kLastVisemeMs);
  EXPECT_TRUE(events[7].event.phoneme.end_of_text);
}

TEST(SpeechMarks, AzureTicksAndSdkSpellings) {
  const std::vector<TextEvent> events = read_lines(MarksInput::kAzure,
                                                   "{\"AudioOffset\":500000,\"VisemeId\":0}\n"
                                                   "{\"audio_offset\":1004999,\"viseme_id\":21}\n"
                                                   "{\"audioOffset\":1505000,\"visemeId\":2}\n");
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].time_ms, 50);
  EXPECT_EQ(events[1].time_ms, 100);  // ticks rounded to the nearest ms
  EXPECT_EQ(events[2].time_ms, 151);
  EXPECT_EQ(events[1].event.phoneme.symbol, 21);
  EXPECT_EQ(events[1].event.phoneme.duration_ms, 51);
}

TEST(SpeechMarks, LongVisemesAreSplitAsTheWireNeeds) {
  const std::vector<TextEvent> events =
      read_lines(MarksInput::kRhubarb, "0.00\tD\n9.5\tX\n");
  ASSERT_EQ(events.size(), 4u);  // 9500 ms = 4095 + 4095 + 1310, then the rest
  EXPECT_EQ(events[0].event.phoneme.duration_ms, 4095);
  EXPECT_EQ(events[1].time_ms, 4095);
  EXPECT_EQ(events[2].time_ms, 8190);
  EXPECT_EQ(events[2].event.phoneme.duration_ms, 1310);
  EXPECT_EQ(events[3].time_ms, 9500);
}

TEST(SpeechMarks, AVisemeFarAheadCostsNoMoreThanItsCap) {
  const std::vector<TextEvent> events =
      read_lines(MarksInput::kRhubarb, "0.0\tX\n9000000000.0\tA\n");
  ASSERT_EQ(events.size(), 17u);  // X cut at 16 pieces of 4095 ms, then A far ahead
  EXPECT_EQ(events[15].time_ms, 15 * 4095);
  EXPECT_EQ(events[16].time_ms, 9'000'000'000'000);
}

// A fractional rate (NTSC's 30000/1001) puts frame k at k * 1001 / 30000 s, to the ns rounded
// down, also after a rest cut 11.6 days long, where the first frame is found from the time.
TEST(SpeechMarks, ArkitFramesAtAFractionalRateAreExact) {
  const std::string csv =
      write(MarksFormat::kArkitCsv,
            {event(0, phoneme(1, 100), true), event(1'000'000'000, phoneme(1, 100))}, 30000, 1001);
  std::istringstream lines(csv);
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(lines, line)) rows.push_back(line.substr(0, line.find(',')));
  ASSERT_GE(rows.size(), 5u);
  EXPECT_EQ(rows[1], "0.000");
  EXPECT_EQ(rows[2], "33.367");  // 33,366,666 ns
  EXPECT_EQ(rows[3], "66.733");
  EXPECT_EQ(rows[4], "100.100");
  // Frame 29,970,030 is the first at or after 1e9 ms: 30,000,000,030 / 30,000 s.
  const auto far = std::find(rows.begin(), rows.end(), "1000000001.000");
  ASSERT_NE(far, rows.end());
  EXPECT_LT(std::stod(*(far - 1)), 2000.0);  // the frame before it is the rest's last
}

TEST(SpeechMarks, ArkitFramesOfALongRestAreLeftOut) {
  const std::string csv = write(MarksFormat::kArkitCsv,
                                {event(0, phoneme(1, 100), true), event(60'000, phoneme(1, 100))},
                                10);
  std::istringstream lines(csv);
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(lines, line)) rows.push_back(line);
  // Header; 0 up to 1 s after the mouth has closed at 0.18 s (12 frames), then 60 to
  // 60.18 s.
  ASSERT_EQ(rows.size(), 1u + 12 + 2);
  EXPECT_TRUE(rows[12].starts_with("1100.000,"));
  EXPECT_TRUE(rows[13].starts_with("60000.000,"));
  EXPECT_TRUE(rows[14].starts_with("60100.000,"));
}

// Issue 27: 2,000 phonemes 11.6 days apart made 8.9 GB of arkit-json at 240 frames/s, 10 s of
// rest frames for each. An event makes the frames of what it moves, then at most
// kMaxRestNs of rest.
TEST(SpeechMarks, ArkitFramesPerEventAreBoundedWhateverTheGaps) {
  constexpr int kFps = 240;
  constexpr int64_t kEvents = 200;
  constexpr int64_t kGapMs = 1'000'000'000;  // 11.6 days
  std::vector<TextEvent> events;
  for (int64_t i = 0; i < kEvents; ++i) events.push_back(event(i * kGapMs, phoneme(1, 100)));
  MarksWriter writer(MarksFormat::kArkitJson, kFps);
  writer.set_alphabet(&arpabet());
  size_t frames = 0, bytes = 0;
  const MarksWriter::Sink sink = [&](std::string_view text) {
    frames += static_cast<size_t>(std::count(text.begin(), text.end(), '\n'));
    bytes += text.size();
    return true;
  };
  for (const TextEvent& e : events) ASSERT_TRUE(writer.add(e.event, e.time_ms * kNsPerMs, sink));
  ASSERT_TRUE(writer.finish(sink));
  // The phoneme, its 80 ms closing and 1 s of rest: frames from 0 to 1.18 s, 284 of them;
  // the last event's end at 0.18 s, 44.
  EXPECT_EQ(frames, (kEvents - 1) * 284 + 44) << bytes << " bytes";
  EXPECT_EQ(writer.cut_rests(), static_cast<uint64_t>(kEvents - 1));
}

TEST(SpeechMarks, BadLinesSayWhatAndWhere) {
  const struct {
    MarksInput input;
    const char* line;
    MarksStatus status;
    size_t column;
  } rows[] = {
      {MarksInput::kPolly, R"({"time":5,"type":"viseme","value":"p")", MarksStatus::kBadJson, 37},
      {MarksInput::kPolly, R"([1,2])", MarksStatus::kNotAnObject, 0},
      {MarksInput::kPolly, R"({"type":"viseme","value":"p"})", MarksStatus::kMissingField, 0},
      {MarksInput::kPolly, R"({"time":-5,"type":"viseme","value":"p"})", MarksStatus::kBadTime, 8},
      {MarksInput::kPolly, R"({"time":"5","type":"viseme","value":"p"})", MarksStatus::kBadTime,
       8},
      {MarksInput::kPolly, R"({"time":1e30,"type":"viseme","value":"p"})", MarksStatus::kBadTime,
       8},
      {MarksInput::kPolly, R"({"time":5,"type":"phoneme","value":"p"})", MarksStatus::kBadType,
       17},
      {MarksInput::kPolly, R"({"time":5,"type":"viseme","value":"P"})", MarksStatus::kBadViseme,
       34},
      {MarksInput::kAzure, R"({"audioOffset":5,"visemeId":22})", MarksStatus::kBadViseme, 28},
      {MarksInput::kAzure, R"({"audioOffset":5,"visemeId":2.5})", MarksStatus::kBadViseme, 28},
      {MarksInput::kAzure, R"({"visemeId":2})", MarksStatus::kMissingField, 0},
      {MarksInput::kRhubarb, "0.5", MarksStatus::kMissingField, 3},
      {MarksInput::kRhubarb, "x\tA", MarksStatus::kBadTime, 0},
      {MarksInput::kRhubarb, "0.5\tI", MarksStatus::kBadViseme, 4},
  };
  for (const auto& row : rows) {
    MarksReader reader(row.input);
    std::vector<TextEvent> out;
    const MarksResult result = reader.read_line(row.line, out);
    EXPECT_EQ(result.status, row.status) << row.line << ": " << to_string(result.status);
    EXPECT_EQ(result.column, row.column) << row.line;
    EXPECT_TRUE(out.empty());
  }
  // Time going back, then reading goes on.
  MarksReader reader(MarksInput::kRhubarb);
  std::vector<TextEvent> out;
  EXPECT_TRUE(reader.read_line("1.0\tA", out).ok());
  EXPECT_EQ(reader.read_line("0.5\tB", out).status, MarksStatus::kTimeGoesBack);
  EXPECT_TRUE(reader.read_line("1.2\tX", out).ok());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].event.phoneme.duration_ms, 200);
}

TEST(SpeechMarks, RhubarbJsonDocument) {
  MarksReader reader(MarksInput::kRhubarb);
  std::vector<TextEvent> out;
  ASSERT_TRUE(reader
                  .read_document(R"({"metadata":{"soundFile":"a.wav","duration":0.47},
"mouthCues":[{"start":0.00,"end":0.05,"value":"X"},{"start":0.05,"end":0.27,"value":"D"},
{"start":0.30,"end":0.47,"value":"B"}]})",
                                 out)
                  .ok());
  ASSERT_EQ(out.size(), 4u);  // the gap 0.27..0.30 is a rest
  EXPECT_EQ(out[1].time_ms, 50);
  EXPECT_EQ(out[1].event.phoneme.duration_ms, 220);
  EXPECT_EQ(out[2].time_ms, 270);
  EXPECT_EQ(out[2].event.phoneme.symbol, 0);
  EXPECT_EQ(out[3].event.phoneme.duration_ms, 170);
  EXPECT_TRUE(out[3].event.phoneme.end_of_text);

  MarksReader bad(MarksInput::kRhubarb);
  out.clear();
  EXPECT_EQ(bad.read_document(R"({"mouthCues":[{"start":0.1,"end":0.05,"value":"X"}]})", out)
                .status,
            MarksStatus::kTimeGoesBack);
  EXPECT_EQ(bad.read_document(R"({"cues":[]})", out).status, MarksStatus::kMissingField);
  std::string deep(40, '[');
  EXPECT_EQ(bad.read_document(deep, out).status, MarksStatus::kBadJson);
  // A tree's memory is bounded: at most 400,000 values in a document.
  std::string wide = "{\"mouthCues\":[0";
  for (int i = 0; i < 400'000; ++i) wide += ",0";
  wide += "]}";
  const MarksResult too_many = bad.read_document(wide, out);
  EXPECT_EQ(too_many.status, MarksStatus::kBadJson);
  EXPECT_STREQ(too_many.what, "more than 400000 values");
}

// Issue 27: the good cue before a bad one was lost, and every cue after it.
TEST(SpeechMarks, RhubarbJsonBadCueLosesNoGoodOne) {
  std::string doc = R"({"mouthCues":[)";
  for (int i = 0; i < 10; ++i) {
    if (i > 0) doc += ',';
    // Cue 6 (i == 5) has an unknown shape; each cue is 100 ms, the shapes A..H in turn.
    doc += R"({"start":)" + std::to_string(i) + R"(.0,"end":)" + std::to_string(i) +
           R"(.1,"value":")" + (i == 5 ? std::string("Z") : std::string(1, char('A' + i % 8))) +
           R"("})";
  }
  doc += "]}";

  // Stopping at the bad cue: the five before it, each followed by its rest.
  MarksReader stops(MarksInput::kRhubarb);
  std::vector<TextEvent> out;
  const MarksResult result = stops.read_document(doc, out);
  EXPECT_EQ(result.status, MarksStatus::kBadViseme);
  EXPECT_EQ(doc.substr(result.column, 3), "\"Z\"");
  ASSERT_EQ(out.size(), 9u);  // 5 cues and the 4 rests between them
  EXPECT_EQ(out[8].time_ms, 4000);
  EXPECT_EQ(out[8].event.phoneme.symbol, 5);  // E
  EXPECT_EQ(out[8].event.phoneme.duration_ms, 100);
  EXPECT_TRUE(out[8].event.phoneme.end_of_text);

  // Skipping it: the nine good cues.
  MarksReader skips(MarksInput::kRhubarb);
  out.clear();
  std::vector<MarksResult> bad;
  ASSERT_TRUE(skips
                  .read_document(doc, out,
                                 [&](const MarksResult& r) {
                                   bad.push_back(r);
                                   return true;
                                 })
                  .ok());
  ASSERT_EQ(bad.size(), 1u);
  EXPECT_EQ(bad[0].status, MarksStatus::kBadViseme);
  std::vector<int64_t> cue_times;
  for (const TextEvent& e : out) {
    if (e.event.phoneme.symbol != 0) cue_times.push_back(e.time_ms);
  }
  EXPECT_EQ(cue_times, (std::vector<int64_t>{0, 1000, 2000, 3000, 4000, 6000, 7000, 8000, 9000}));
  EXPECT_EQ(out[9].time_ms, 4100);  // the rest from cue 5's end to cue 7
  EXPECT_EQ(out[9].event.phoneme.symbol, 0);
  EXPECT_EQ(out[9].event.phoneme.duration_ms, 1900);
  EXPECT_TRUE(out.back().event.phoneme.end_of_text);
}

TEST(SpeechMarks, ArkitFramesAtTheFrameRate) {
  // FAP 3 to 256 over 100 ms from 0, linear; a 200 ms phoneme AA, whose mouth (jaw 430) eases
  // in over 80 ms as pfapface's does.
  TextEvent e = event(0, phoneme(1, 200, true), true);
  e.event.faps = {Fap{3, 256, 100, Curve::kLinear}};
  const std::string csv = write(MarksFormat::kArkitCsv, {e}, 20);
  std::istringstream lines(csv);
  std::string header, line;
  std::getline(lines, header);
  EXPECT_TRUE(header.starts_with("time_ms,eyeBlinkLeft,eyeLookDownLeft,"));
  EXPECT_TRUE(header.ends_with(",tongueOut,headPitch,headYaw,headRoll"));
  std::vector<std::string> rows;
  while (std::getline(lines, line)) rows.push_back(line);
  // Frames at 0, 50, ..., 250 ms: through the mouth closed 80 ms after the phoneme's end.
  ASSERT_EQ(rows.size(), 6u);
  // jawOpen is column 1 + 17.
  auto column = [](const std::string& row, int n) {
    std::istringstream fields(row);
    std::string field;
    for (int i = 0; i <= n; ++i) std::getline(fields, field, ',');
    return field;
  };
  EXPECT_EQ(column(rows[0], 0), "0.000");
  EXPECT_EQ(column(rows[0], 18), "0.0000");  // the mouth starts closed
  EXPECT_EQ(column(rows[1], 0), "50.000");
  // FAP 3 at 128, the mouth at ease(50 / 80) = 0.68359375 of 430: (128 + 293.95) / 512.
  EXPECT_EQ(column(rows[1], 18), "0.8241");
  EXPECT_EQ(column(rows[2], 18), "1.0000");  // 256 + 430, clamped
  EXPECT_EQ(column(rows[4], 0), "200.000");
  const std::string json = write(MarksFormat::kArkitJson, {e}, 20);
  EXPECT_TRUE(json.starts_with("{\"time\":0.000,\"blendshapes\":{\"eyeBlinkLeft\":0.0000,"));
  const size_t at_100 = json.find("{\"time\":100.000,");
  ASSERT_NE(at_100, std::string::npos);
  EXPECT_EQ(json.find("\"jawOpen\":1.0000", at_100) < json.find('\n', at_100), true);
  EXPECT_NE(json.find("\"head\":{\"pitch\":0.00000,\"yaw\":0.00000,\"roll\":0.00000}}\n"),
            std::string::npos);
}

}  // namespace
}  // namespace pfap

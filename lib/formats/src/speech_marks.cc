// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap/speech_marks.h"

#include <algorithm>
#include <array>
#include <charconv>

#include "json.h"

namespace pfap {
namespace {

using Spoken = MarksWriter::Spoken;

constexpr int64_t kNsPerTick = 100;  // Azure's unit
constexpr int64_t kNsPerSecond = 1'000'000'000;
constexpr int64_t kTicksPerMs = kNsPerMs / kNsPerTick;
// Times must end in ns that fit an int64 (about 292 years), as .pfap text times.
constexpr int64_t kMaxTimeMs = INT64_MAX / kNsPerMs - kMaxPhonemeDurationMs;

int64_t to_ms(int64_t ns) { return (ns + kNsPerMs / 2) / kNsPerMs; }

void append_int(int64_t value, std::string& out) {
  char buffer[24];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  out.append(buffer, end);
}

// `value` with `decimals` digits after the point, whatever the C locale (gst-launch sets the
// user's, which may write a decimal comma).
void append_fixed(double value, int decimals, std::string& out) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value,
                                    std::chars_format::fixed, decimals);
  out.append(buffer, result.ptr);
}

// ms as seconds with 3 decimals: Rhubarb writes 2, which would lose the ms.
void append_seconds(int64_t ms, std::string& out) {
  append_int(ms / 1000, out);
  const int frac = static_cast<int>(ms % 1000);
  out += '.';
  out += static_cast<char>('0' + frac / 100);
  out += static_cast<char>('0' + frac / 10 % 10);
  out += static_cast<char>('0' + frac % 10);
}

std::string_view polly_name(uint8_t symbol) {
  return find_alphabet(kPollyVisemeAlphabet)->symbols[symbol].name;
}
std::string_view rhubarb_name(uint8_t symbol) {
  return find_alphabet(kRhubarbShapeAlphabet)->symbols[symbol].name;
}

constexpr VisemeSet kSilence{Viseme::kNone, OculusViseme::kSil, 0, 0, 0};

bool is_silence(const Spoken& p) { return p.visemes.mpeg4 == Viseme::kNone; }

// The phonemes with every gap between one's end and the next's start filled with silence,
// and for formats whose marks have no duration a last silence where speech ends. Every format
// writes whole ms, and no service writes a mark of no length or two marks at one time: a gap
// shorter than a ms (phoneme times from audio samples leave such gaps) is no silence, the
// phoneme before it lasting to the next one's start, and a phoneme of no length is no mark.
std::vector<Spoken> contiguous(const std::vector<Spoken>& phonemes, bool closing_silence) {
  std::vector<Spoken> items;
  for (const Spoken& p : phonemes) {
    if (p.end_ns <= p.start_ns) continue;
    if (!items.empty() && p.start_ns > items.back().end_ns) {
      if (p.start_ns - items.back().end_ns < kNsPerMs) {
        items.back().end_ns = p.start_ns;
      } else {
        items.push_back({items.back().end_ns, p.start_ns, kSilence, "", false, false});
      }
    }
    items.push_back(p);
  }
  if (closing_silence && !items.empty() && !is_silence(items.back())) {
    items.push_back({items.back().end_ns, items.back().end_ns, kSilence, "", false, false});
  }
  return items;
}

struct Span {
  int64_t start_ns;
  int64_t end_ns;
  std::string text;
};

// Words: from a word begin to the next word begin or silence. The stream has no text, so a
// word is spelled by its phonemes' names joined by '-'; a sentence by its words.
void words_and_sentences(const std::vector<Spoken>& phonemes, std::vector<Span>& words,
                         std::vector<Span>& sentences) {
  bool in_word = false;
  for (size_t i = 0; i < phonemes.size(); ++i) {
    const Spoken& p = phonemes[i];
    if (i == 0 || p.sentence_start) sentences.push_back({p.start_ns, p.end_ns, ""});
    Span& sentence = sentences.back();
    sentence.end_ns = p.end_ns;
    if (is_silence(p)) {
      in_word = false;
      continue;
    }
    const std::string_view name = p.name.empty() ? "?" : p.name;
    const bool begins = p.word_begin || !in_word || p.sentence_start;
    if (begins) {
      words.push_back({p.start_ns, p.end_ns, std::string(name)});
      if (!sentence.text.empty()) sentence.text += ' ';
    } else {
      words.back().text += '-';
      words.back().text += name;
      words.back().end_ns = p.end_ns;
      sentence.text += '-';
    }
    sentence.text += name;
    in_word = true;
  }
}

void polly_line(int64_t time_ns, std::string_view type, std::string_view value, std::string& out) {
  out += "{\"time\":";
  append_int(to_ms(time_ns), out);
  out += ",\"type\":\"";
  out += type;
  out += "\",\"value\":";
  json::append_string(value, out);
  out += "}\n";
}

void write_polly(const std::vector<Spoken>& phonemes, std::string& out) {
  std::vector<Span> words, sentences;
  words_and_sentences(phonemes, words, sentences);
  size_t w = 0, s = 0;
  for (const Spoken& item : contiguous(phonemes, true)) {
    // Polly's order at one time: the sentence, the word, then the viseme.
    while (s < sentences.size() && sentences[s].start_ns <= item.start_ns) {
      polly_line(sentences[s].start_ns, "sentence", sentences[s].text, out);
      ++s;
    }
    while (w < words.size() && words[w].start_ns <= item.start_ns) {
      polly_line(words[w].start_ns, "word", words[w].text, out);
      ++w;
    }
    polly_line(item.start_ns, "viseme", polly_name(item.visemes.polly), out);
  }
}

void write_azure(const std::vector<Spoken>& phonemes, std::string& out) {
  for (const Spoken& item : contiguous(phonemes, true)) {
    out += "{\"audioOffset\":";
    append_int(to_ms(item.start_ns) * kTicksPerMs, out);
    out += ",\"visemeId\":";
    append_int(item.visemes.azure, out);
    out += "}\n";
  }
}

void write_rhubarb_tsv(const std::vector<Spoken>& phonemes, std::string& out) {
  for (const Spoken& item : contiguous(phonemes, true)) {
    append_seconds(to_ms(item.start_ns), out);
    out += '\t';
    out += rhubarb_name(item.visemes.rhubarb);
    out += '\n';
  }
}

void write_rhubarb_json(const std::vector<Spoken>& phonemes, std::string& out) {
  const std::vector<Spoken> items = contiguous(phonemes, false);
  out += "{\"metadata\":{\"soundFile\":\"\",\"duration\":";
  append_seconds(items.empty() ? 0 : to_ms(items.back().end_ns), out);
  out += "},\"mouthCues\":[";
  for (size_t i = 0; i < items.size(); ++i) {
    out += i == 0 ? "\n" : ",\n";
    out += "{\"start\":";
    append_seconds(to_ms(items[i].start_ns), out);
    out += ",\"end\":";
    append_seconds(to_ms(items[i].end_ns), out);
    out += ",\"value\":\"";
    out += rhubarb_name(items[i].visemes.rhubarb);
    out += "\"}";
  }
  out += "\n]}\n";
}

template <typename Get>
void json_array(std::string_view key, size_t count, Get get, std::string& out) {
  out += '"';
  out += key;
  out += "\":[";
  for (size_t i = 0; i < count; ++i) {
    if (i > 0) out += ',';
    get(i, out);
  }
  out += ']';
}

void write_talkinghead(const std::vector<Spoken>& phonemes, std::string& out) {
  const std::vector<Spoken> items = contiguous(phonemes, false);
  std::vector<Span> words, sentences;
  words_and_sentences(phonemes, words, sentences);
  out += '{';
  json_array("visemes", items.size(), [&](size_t i, std::string& o) {
    json::append_string(talkinghead_name(items[i].visemes.oculus), o);
  }, out);
  out += ',';
  json_array("vtimes", items.size(), [&](size_t i, std::string& o) {
    append_int(to_ms(items[i].start_ns), o);
  }, out);
  out += ',';
  json_array("vdurations", items.size(), [&](size_t i, std::string& o) {
    append_int(to_ms(items[i].end_ns) - to_ms(items[i].start_ns), o);
  }, out);
  out += ',';
  json_array("words", words.size(), [&](size_t i, std::string& o) {
    json::append_string(words[i].text, o);
  }, out);
  out += ',';
  json_array("wtimes", words.size(), [&](size_t i, std::string& o) {
    append_int(to_ms(words[i].start_ns), o);
  }, out);
  out += ',';
  json_array("wdurations", words.size(), [&](size_t i, std::string& o) {
    append_int(to_ms(words[i].end_ns) - to_ms(words[i].start_ns), o);
  }, out);
  out += "}\n";
}

void write_frame(MarksFormat format, double time_ms, const BlendshapeWeights& weights,
                 const HeadPose& head, std::string& out) {
  const auto& names = blendshape_names();
  if (format == MarksFormat::kArkitCsv) {
    append_fixed(time_ms, 3, out);
    for (double w : weights) {
      out += ',';
      append_fixed(w, 4, out);
    }
    for (double angle : {head.pitch, head.yaw, head.roll}) {
      out += ',';
      append_fixed(angle, 5, out);
    }
    out += '\n';
    return;
  }
  out += "{\"time\":";
  append_fixed(time_ms, 3, out);
  out += ",\"blendshapes\":{";
  for (size_t i = 0; i < weights.size(); ++i) {
    if (i > 0) out += ',';
    out += '"';
    out += names[i];
    out += "\":";
    append_fixed(weights[i], 4, out);
  }
  out += "},\"head\":{\"pitch\":";
  append_fixed(head.pitch, 5, out);
  out += ",\"yaw\":";
  append_fixed(head.yaw, 5, out);
  out += ",\"roll\":";
  append_fixed(head.roll, 5, out);
  out += "}}\n";
}

bool is_arkit(MarksFormat format) {
  return format == MarksFormat::kArkitJson || format == MarksFormat::kArkitCsv;
}

}  // namespace

std::string_view to_string(MarksFormat format) {
  switch (format) {
    case MarksFormat::kPolly:
      return "polly";
    case MarksFormat::kRhubarbTsv:
      return "rhubarb-tsv";
    case MarksFormat::kRhubarbJson:
      return "rhubarb-json";
    case MarksFormat::kTalkingHead:
      return "talkinghead";
    case MarksFormat::kAzure:
      return "azure";
    case MarksFormat::kArkitJson:
      return "arkit-json";
    case MarksFormat::kArkitCsv:
      return "arkit-csv";
  }
  return "";
}

void write_marks(MarksFormat format, const std::vector<Spoken>& phonemes, std::string& out) {
  switch (format) {
    case MarksFormat::kPolly:
      return write_polly(phonemes, out);
    case MarksFormat::kRhubarbTsv:
      return write_rhubarb_tsv(phonemes, out);
    case MarksFormat::kRhubarbJson:
      return write_rhubarb_json(phonemes, out);
    case MarksFormat::kTalkingHead:
      return write_talkinghead(phonemes, out);
    case MarksFormat::kAzure:
      return write_azure(phonemes, out);
    case MarksFormat::kArkitJson:
    case MarksFormat::kArkitCsv:
      return;
  }
}

MarksWriter::MarksWriter(MarksFormat format, int rate_num, int rate_den)
    : format_(format), rate_num_(std::max(1, rate_num)), rate_den_(std::max(1, rate_den)) {}

void MarksWriter::reset() {
  utterance_.clear();
  overflow_ = false;
  wrote_header_ = false;
  state_.reset();
  next_frame_ = 0;
  end_ns_ = 0;
  current_ = {};
  mouth_from_ = {};
}

bool MarksWriter::flush_utterance(const Sink& sink) {
  if (utterance_.empty()) return true;
  text_.clear();
  write_marks(format_, utterance_, text_);
  utterance_.clear();
  return sink(text_);
}

// The mouth as pfapface's animator moves it (face/src/animator.cc, Animator::mouth): from
// where it was when the phoneme started to the phoneme's viseme, eased (zero slope at both
// ends) over at most kMouthEaseNs and half the phoneme; after its end, closing over
// kMouthEaseNs.
VisemeMouth MarksWriter::mouth(int64_t time_ns) const {
  const auto ease = [](double u) {
    u = std::clamp(u, 0.0, 1.0);
    return u * u * (3 - 2 * u);
  };
  const Spoken& s = current_;
  const VisemeMouth to = viseme_mouth(s.visemes.mpeg4);
  const auto during = [&](int64_t t) {
    const int64_t span = std::min(kMouthEaseNs, (s.end_ns - s.start_ns) / 2);
    const double u = span > 0 ? ease(static_cast<double>(t - s.start_ns) / span) : 1.0;
    return mouth_from_.blend(to, u);
  };
  if (time_ns < s.end_ns) return during(std::max(time_ns, s.start_ns));
  return during(s.end_ns).blend(
      VisemeMouth{}, ease(static_cast<double>(time_ns - s.end_ns) / kMouthEaseNs));
}

// Frame k (k >= 0) is at k * den / num s, rounded down to the ns. Computed in three parts,
// none of which overflows for num and den up to INT_MAX, for any time an int64 of ns holds.
int64_t MarksWriter::frame_time(int64_t k) const {
  const int64_t whole = k / rate_num_ * rate_den_;  // seconds from whole cycles of num frames
  const int64_t part = k % rate_num_ * rate_den_;   // < num * den < 2^62
  return (whole + part / rate_num_) * kNsPerSecond + part % rate_num_ * kNsPerSecond / rate_num_;
}

// The first frame at or after `ns`: an estimate in double, off by a frame at most, then
// corrected with the exact frame_time().
int64_t MarksWriter::first_frame_from(int64_t ns) const {
  const double frames = static_cast<double>(ns) / kNsPerSecond * static_cast<double>(rate_num_) /
                        static_cast<double>(rate_den_);
  int64_t k = std::max<int64_t>(0, static_cast<int64_t>(frames));
  while (k > 0 && frame_time(k - 1) >= ns) --k;
  while (frame_time(k) < ns) ++k;
  return k;
}

bool MarksWriter::frames_until(int64_t end_ns, const Sink& sink) {
  text_.clear();
  if (format_ == MarksFormat::kArkitCsv && !wrote_header_) {
    text_ += "time_ms";
    for (std::string_view name : blendshape_names()) {
      text_ += ',';
      text_ += name;
    }
    text_ += ",headPitch,headYaw,headRoll\n";
    wrote_header_ = true;
  }
  // Frames in batches, so that a long pause costs bounded memory.
  constexpr int kBatch = 64;
  int batch = 0;
  FapAmplitudes faps{};
  for (;;) {
    int64_t t = frame_time(next_frame_);
    // Once everything has settled, frames repeat the same face: a rest longer than
    // kMaxRestNs is written for that long, then the frames go on at the next event.
    if (t >= end_ns_ + kMaxRestNs && end_ns > t) {
      ++cut_rests_;
      next_frame_ = first_frame_from(end_ns);
      t = frame_time(next_frame_);
    }
    if (t >= end_ns) break;
    for (int i = kMinFapIndex; i <= kMaxFapIndex; ++i) faps[i] = state_.amplitude(i, t);
    const Viseme viseme =
        t >= current_.start_ns && t < current_.end_ns ? current_.visemes.mpeg4 : Viseme::kNone;
    write_frame(format_, static_cast<double>(t) / kNsPerMs,
                blendshape_weights(faps, mouth(t), viseme), head_pose(faps), text_);
    ++next_frame_;
    if (++batch == kBatch) {
      if (!sink(text_)) return false;
      text_.clear();
      batch = 0;
    }
  }
  return text_.empty() || sink(text_);
}

bool MarksWriter::add(const MarkupEvent& event, int64_t time_ns, const Sink& sink) {
  // Far past any stream (146 years), and room for the durations added to it.
  time_ns = std::clamp<int64_t>(time_ns, 0, INT64_MAX / 2);
  Spoken spoken{};
  if (event.kind == PFAP_EVENT_PHONEME) {
    const std::optional<VisemeSet> visemes =
        alphabet_ != nullptr ? find_visemes(*alphabet_, event.phoneme.symbol) : std::nullopt;
    if (!visemes) ++unknown_phonemes_;
    const PhonemeInfo* info =
        alphabet_ != nullptr ? find_phoneme(*alphabet_, event.phoneme.symbol) : nullptr;
    spoken = {time_ns,
              time_ns + int64_t{event.phoneme.duration_ms} * kNsPerMs,
              visemes.value_or(kUnknownVisemes),
              info != nullptr ? info->name : std::string_view(),
              event.phoneme.word_begin,
              event.sentence_start};
  }

  if (is_arkit(format_)) {
    if (!frames_until(time_ns, sink)) return false;
    if (event.kind == PFAP_EVENT_COMPLETE) state_.reset();
    for (const Fap& fap : event.faps) {
      state_.apply(fap, time_ns);
      end_ns_ = std::max(end_ns_, time_ns + int64_t{fap.transition_ms} * kNsPerMs);
    }
    if (event.kind == PFAP_EVENT_PHONEME) {
      mouth_from_ = mouth(time_ns);
      current_ = spoken;
      end_ns_ = std::max(end_ns_, spoken.end_ns + kMouthEaseNs);  // and the mouth closed
    }
    return true;
  }

  if (event.kind != PFAP_EVENT_PHONEME) return true;  // the marks carry no FAPs
  if (format_ == MarksFormat::kRhubarbJson) {
    if (utterance_.size() >= kMaxDocumentPhonemes) {
      overflow_ = true;
      return false;
    }
    utterance_.push_back(spoken);
    return true;
  }
  // A new sentence closes the utterance before it if no end of text did.
  if (spoken.sentence_start && !flush_utterance(sink)) return false;
  utterance_.push_back(spoken);
  if (event.phoneme.end_of_text || utterance_.size() >= kMaxUtterancePhonemes) {
    return flush_utterance(sink);
  }
  return true;
}

bool MarksWriter::finish(const Sink& sink) {
  if (is_arkit(format_)) {
    // Through the frame at the end, so that the last shape written is the settled one.
    return frames_until(end_ns_ + 1, sink);
  }
  return flush_utterance(sink);
}

// ---------------------------------------------------------------------------------------------

const char* to_string(MarksStatus status) {
  switch (status) {
    case MarksStatus::kOk:
      return "ok";
    case MarksStatus::kBadJson:
      return "not valid JSON";
    case MarksStatus::kNotAnObject:
      return "not a JSON object";
    case MarksStatus::kMissingField:
      return "a required field is missing";
    case MarksStatus::kBadTime:
      return "bad time (a number >= 0 in the format's unit, under about 292 years)";
    case MarksStatus::kTimeGoesBack:
      return "time goes back";
    case MarksStatus::kBadType:
      return "unknown mark type (sentence, word, viseme or ssml)";
    case MarksStatus::kBadViseme:
      return "not a viseme of this format";
    case MarksStatus::kTooLarge:
      return "larger than the reader's limits";
  }
  return "unknown status";
}

std::string_view MarksReader::alphabet() const {
  switch (input_) {
    case MarksInput::kPolly:
      return kPollyVisemeAlphabet;
    case MarksInput::kRhubarb:
      return kRhubarbShapeAlphabet;
    case MarksInput::kAzure:
      return kAzureVisemeAlphabet;
  }
  return {};
}

void MarksReader::reset() { *this = MarksReader(input_); }

void MarksReader::emit_pending(int64_t end_ms, std::vector<TextEvent>& out) {
  if (!has_pending_) return;
  has_pending_ = false;
  std::vector<Phoneme> pieces;
  // Longer than the wire's 4095 ms is split; past kMaxVisemeMs the rest is left a gap (the
  // next event's PTS says when it comes), so that a time far ahead costs no more.
  const int64_t duration =
      std::clamp<int64_t>(end_ms - pending_.time_ms, 0, MarksReader::kMaxVisemeMs);
  split_long_phoneme(pending_.event.phoneme, static_cast<uint32_t>(std::min<int64_t>(
                                                 duration, UINT32_MAX)),
                     pieces);
  int64_t time = pending_.time_ms;
  for (size_t i = 0; i < pieces.size(); ++i) {
    TextEvent event = pending_;
    event.time_ms = time;
    event.event.phoneme = pieces[i];
    event.event.sentence_start = pending_.event.sentence_start && i == 0;
    out.push_back(event);
    time += pieces[i].duration_ms;
  }
}

void MarksReader::sentence() {
  if (sentence_has_visemes_ && has_pending_) pending_.event.phoneme.end_of_text = true;
  next_sentence_start_ = true;
  sentence_has_visemes_ = false;
}

MarksResult MarksReader::viseme(int64_t time_ms, uint8_t symbol, size_t column,
                                std::vector<TextEvent>& out) {
  if (time_ms < last_time_ms_) return {MarksStatus::kTimeGoesBack, column};
  emit_pending(time_ms, out);
  last_time_ms_ = time_ms;
  pending_ = TextEvent{};
  pending_.time_ms = time_ms;
  pending_.event.kind = PFAP_EVENT_PHONEME;
  pending_.event.phoneme.symbol = symbol;
  pending_.event.phoneme.word_begin = next_word_begin_ && symbol != 0;
  pending_.event.sentence_start = next_sentence_start_;
  if (symbol != 0) next_word_begin_ = false;
  next_sentence_start_ = false;
  sentence_has_visemes_ = true;
  has_pending_ = true;
  return {};
}

void MarksReader::finish(std::vector<TextEvent>& out) {
  if (has_pending_) pending_.event.phoneme.end_of_text = true;
  emit_pending(pending_.time_ms + kLastVisemeMs, out);
}

namespace {

// A time member of `object` as a count of units (`decimals` digits after the point of the
// JSON number); `scale_to_ms` divides it down to ms, rounding to the nearest.
MarksResult time_member(const json::Value& object, std::string_view key, int decimals,
                        int64_t units_per_ms, int64_t& ms) {
  const json::Value* value = object.get(key);
  if (value == nullptr) return {MarksStatus::kMissingField, object.offset};
  if (value->type != json::Value::Type::kNumber) return {MarksStatus::kBadTime, value->offset};
  const std::optional<int64_t> units =
      json::to_fixed(value->text, decimals, kMaxTimeMs * units_per_ms);
  if (!units || *units < 0) return {MarksStatus::kBadTime, value->offset};
  ms = (*units + units_per_ms / 2) / units_per_ms;
  return {};
}

MarksResult parse_object(std::string_view line, json::Value& object) {
  json::Error error;
  if (!json::parse(line, object, error)) return {MarksStatus::kBadJson, error.offset, error.what};
  if (object.type != json::Value::Type::kObject) return {MarksStatus::kNotAnObject, 0};
  return {};
}

const json::Value* first_member(const json::Value& object,
                                std::initializer_list<std::string_view> keys,
                                std::string_view& found) {
  for (std::string_view key : keys) {
    if (const json::Value* value = object.get(key)) {
      found = key;
      return value;
    }
  }
  return nullptr;
}

bool is_blank(std::string_view line) {
  return line.find_first_not_of(" \t\r") == std::string_view::npos;
}

}  // namespace

MarksResult MarksReader::read_line(std::string_view line, std::vector<TextEvent>& out) {
  if (is_blank(line)) return {};
  const PhonemeAlphabet& symbols = *find_alphabet(alphabet());
  if (input_ == MarksInput::kRhubarb) {
    // "<seconds><white space><shape>"
    const size_t start = line.find_first_not_of(" \t");
    const size_t time_end = line.find_first_of(" \t", start);
    if (time_end == std::string_view::npos) return {MarksStatus::kMissingField, line.size()};
    const size_t shape_start = line.find_first_not_of(" \t", time_end);
    if (shape_start == std::string_view::npos) return {MarksStatus::kMissingField, line.size()};
    const size_t shape_end = line.find_last_not_of(" \t\r") + 1;
    const std::optional<int64_t> ms =
        json::to_fixed(line.substr(start, time_end - start), 3, kMaxTimeMs);
    if (!ms || *ms < 0) return {MarksStatus::kBadTime, start};
    const std::optional<uint8_t> symbol =
        find_symbol(symbols, line.substr(shape_start, shape_end - shape_start));
    if (!symbol) return {MarksStatus::kBadViseme, shape_start};
    return viseme(*ms, *symbol, start, out);
  }

  json::Value object;
  if (MarksResult result = parse_object(line, object); !result.ok()) return result;
  if (input_ == MarksInput::kAzure) {
    // The SDKs' property names: JavaScript audioOffset, C# AudioOffset, Python audio_offset.
    std::string_view key;
    const json::Value* offset = first_member(object, {"audioOffset", "AudioOffset",
                                                      "audio_offset"}, key);
    if (offset == nullptr) return {MarksStatus::kMissingField, 0};
    int64_t ms = 0;
    if (MarksResult r = time_member(object, key, 0, kTicksPerMs, ms); !r.ok()) return r;
    const json::Value* id = first_member(object, {"visemeId", "VisemeId", "viseme_id"}, key);
    if (id == nullptr) return {MarksStatus::kMissingField, 0};
    const std::optional<int64_t> number =
        id->type == json::Value::Type::kNumber ? json::to_fixed(id->text, 0, 1000) : std::nullopt;
    if (!number || *number < 0 || *number >= kAzureVisemeCount || id->text.find_first_of(".eE") !=
                                                                       std::string::npos) {
      return {MarksStatus::kBadViseme, id->offset};
    }
    return viseme(ms, static_cast<uint8_t>(*number), offset->offset, out);
  }

  // Polly
  int64_t ms = 0;
  if (MarksResult r = time_member(object, "time", 0, 1, ms); !r.ok()) return r;
  const json::Value* type = object.get("type");
  if (type == nullptr) return {MarksStatus::kMissingField, 0};
  if (type->type != json::Value::Type::kString) return {MarksStatus::kBadType, type->offset};
  if (type->text == "ssml") return {};  // a <mark> of the SSML: nothing to animate
  if (ms < last_time_ms_) return {MarksStatus::kTimeGoesBack, object.get("time")->offset};
  if (type->text == "sentence") {
    sentence();
    return {};
  }
  if (type->text == "word") {
    // A word mark comes before its first viseme, at the same time.
    next_word_begin_ = true;
    return {};
  }
  if (type->text != "viseme") return {MarksStatus::kBadType, type->offset};
  const json::Value* value = object.get("value");
  if (value == nullptr) return {MarksStatus::kMissingField, 0};
  const std::optional<uint8_t> symbol = value->type == json::Value::Type::kString
                                            ? find_symbol(symbols, value->text)
                                            : std::nullopt;
  if (!symbol) return {MarksStatus::kBadViseme, value->offset};
  return viseme(ms, *symbol, object.get("time")->offset, out);
}

namespace {

struct Cue {
  int64_t start_ms = 0;
  int64_t end_ms = 0;
  uint8_t symbol = 0;
  size_t start_offset = 0;
};

MarksResult read_cue(const json::Value& cue, const PhonemeAlphabet& symbols, Cue& out) {
  if (cue.type != json::Value::Type::kObject) return {MarksStatus::kNotAnObject, cue.offset};
  if (MarksResult r = time_member(cue, "start", 3, 1, out.start_ms); !r.ok()) return r;
  if (MarksResult r = time_member(cue, "end", 3, 1, out.end_ms); !r.ok()) return r;
  if (out.end_ms < out.start_ms) return {MarksStatus::kTimeGoesBack, cue.get("end")->offset};
  const json::Value* value = cue.get("value");
  if (value == nullptr) return {MarksStatus::kMissingField, cue.offset};
  const std::optional<uint8_t> symbol =
      value->type == json::Value::Type::kString ? find_symbol(symbols, value->text) : std::nullopt;
  if (!symbol) return {MarksStatus::kBadViseme, value->offset};
  out.symbol = *symbol;
  out.start_offset = cue.get("start")->offset;
  return {};
}

}  // namespace

MarksResult MarksReader::read_document(std::string_view document, std::vector<TextEvent>& out,
                                       const BadCue& bad_cue) {
  if (document.size() > kMaxDocumentBytes) return {MarksStatus::kTooLarge, kMaxDocumentBytes};
  json::Value root;
  if (MarksResult result = parse_object(document, root); !result.ok()) return result;
  const json::Value* cues = root.get("mouthCues");
  if (cues == nullptr || cues->type != json::Value::Type::kArray) {
    return {MarksStatus::kMissingField, root.offset};
  }
  const PhonemeAlphabet& symbols = *find_alphabet(kRhubarbShapeAlphabet);
  MarksResult stopped;
  for (const json::Value& item : cues->items) {
    Cue cue;
    MarksResult result = read_cue(item, symbols, cue);
    if (result.ok() && cue.start_ms < last_time_ms_) {
      result = {MarksStatus::kTimeGoesBack, cue.start_offset};
    }
    if (!result.ok()) {
      if (bad_cue && bad_cue(result)) continue;
      stopped = result;
      break;
    }
    // A gap between one cue's end and the next start is a rest (X). Neither viseme can go
    // back in time: the start was checked.
    if (has_pending_ && cue.start_ms > pending_end_ms_ && pending_end_ms_ >= last_time_ms_) {
      viseme(pending_end_ms_, 0, item.offset, out);
    }
    viseme(cue.start_ms, cue.symbol, cue.start_offset, out);
    pending_end_ms_ = cue.end_ms;
  }
  if (has_pending_) {
    pending_.event.phoneme.end_of_text = true;
    emit_pending(pending_end_ms_, out);
  }
  return stopped;
}

}  // namespace pfap

// SPDX-License-Identifier: LGPL-2.1-or-later
// Speech-mark formats of TTS services and lip-sync tools, out of and into x-pfap events
// (docs/visemes.md): Amazon Polly speech marks, Rhubarb Lip Sync TSV and JSON, TalkingHead's
// streamAudio timing object, Azure viseme events, and ARKit blendshape frames.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "pfap/blendshapes.h"
#include "pfap/fap_state.h"
#include "pfap/markup_event.h"
#include "pfap/phoneme_table.h"
#include "pfap/text.h"
#include "pfap/viseme.h"

namespace pfap {

enum class MarksFormat : uint8_t {
  kPolly,        // JSON lines {"time":ms,"type":"sentence"|"word"|"viseme","value":...}
  kRhubarbTsv,   // lines "<seconds>\t<shape>"
  kRhubarbJson,  // {"metadata":{...},"mouthCues":[{"start":s,"end":s,"value":shape},...]}
  kTalkingHead,  // JSON lines {"visemes":[...],"vtimes":[...],"vdurations":[...],"words":...}
  kAzure,        // JSON lines {"audioOffset":ticks,"visemeId":id}
  kArkitJson,    // JSON lines {"time":ms,"blendshapes":{...52...},"head":{...}}, one per frame
  kArkitCsv,     // a header line, then "time_ms,<52 weights>,headPitch,headYaw,headRoll"
};

// The caps/property nick of each format: polly, rhubarb-tsv, rhubarb-json, talkinghead, azure,
// arkit-json, arkit-csv.
std::string_view to_string(MarksFormat format);

// Writes x-pfap events in one of the formats. Events come in time order; text comes out per
// utterance (up to an end of text, or kMaxUtterancePhonemes phonemes) for the mark formats,
// once at finish() for Rhubarb JSON (one document), per batch of frames for ARKit.
class MarksWriter {
 public:
  // Receives each piece of text once it is written; returns false to stop writing.
  using Sink = std::function<bool(std::string_view)>;

  static constexpr size_t kMaxUtterancePhonemes = 4096;
  static constexpr size_t kMaxDocumentPhonemes = 1'000'000;  // Rhubarb JSON
  // How long the mouth of the frames takes from one viseme to the next (at most half the
  // phoneme), and to close after the last: pfapface's animator's kMouthEaseNs.
  static constexpr int64_t kMouthEaseNs = 80'000'000;
  // ARKit frames of a rest (every phoneme, transition and closing mouth over) longer than
  // this are left out: the frames after it keep their times, so a reader sees the jump. It
  // bounds the frames an event can make: what it keeps moving (a phoneme and its 80 ms ease,
  // up to 4.2 s; a transition, up to 16.4 s), then this rest.
  static constexpr int64_t kMaxRestNs = 1'000'000'000;
  // A phoneme whose viseme is unknown (no alphabet, or a symbol not in it) is written as
  // this half-open mouth, the nearest to pfapface's generic mouth.
  static constexpr VisemeSet kUnknownVisemes{Viseme::kE, OculusViseme::kE, 4, 14, 3};

  // ARKit frames go at `rate_num` / `rate_den` frames a second (GStreamer's fractions, so
  // that 30000/1001 is exact); the other formats have no frames.
  MarksWriter(MarksFormat format, int rate_num, int rate_den = 1);

  // The alphabet of the phoneme symbols; nullptr when not known.
  void set_alphabet(const PhonemeAlphabet* alphabet) { alphabet_ = alphabet; }

  // Takes one event at `time_ns` from the stream's start (non-decreasing). False when the sink
  // stopped, or a Rhubarb JSON document is past kMaxDocumentPhonemes (`overflow()`).
  bool add(const MarkupEvent& event, int64_t time_ns, const Sink& sink);
  // Writes what is held: the last utterance, the Rhubarb JSON document, the last frames up to
  // where every phoneme and transition has ended.
  bool finish(const Sink& sink);
  // Back to an empty stream (the alphabet stays).
  void reset();

  // Phonemes written as kUnknownVisemes since the start.
  uint64_t unknown_phonemes() const { return unknown_phonemes_; }
  // Rests cut at kMaxRestNs since the start.
  uint64_t cut_rests() const { return cut_rests_; }
  bool overflow() const { return overflow_; }

  struct Spoken {
    int64_t start_ns;
    int64_t end_ns;
    VisemeSet visemes;
    std::string_view name;  // the phoneme's name in its alphabet, "" when unknown
    bool word_begin;
    bool sentence_start;
  };

 private:
  bool flush_utterance(const Sink& sink);
  bool frames_until(int64_t end_ns, const Sink& sink);
  int64_t frame_time(int64_t k) const;
  VisemeMouth mouth(int64_t time_ns) const;
  int64_t first_frame_from(int64_t ns) const;

  MarksFormat format_;
  int64_t rate_num_;
  int64_t rate_den_;
  const PhonemeAlphabet* alphabet_ = nullptr;
  std::vector<Spoken> utterance_;
  uint64_t unknown_phonemes_ = 0;
  uint64_t cut_rests_ = 0;
  bool overflow_ = false;
  bool wrote_header_ = false;
  // ARKit frames.
  FapState state_;
  int64_t next_frame_ = 0;  // index of the next frame to write
  int64_t end_ns_ = 0;      // when the last phoneme and transition are over
  Spoken current_{};        // the last phoneme, whose viseme the frames show while it lasts
  VisemeMouth mouth_from_;  // the mouth when it started, from which it eases to its viseme's
  std::string text_;
};

// Writes one utterance's phonemes (time order) in a mark format (not ARKit), appending to
// `out`. Used by MarksWriter; public for tests.
void write_marks(MarksFormat format, const std::vector<MarksWriter::Spoken>& phonemes,
                 std::string& out);

enum class MarksStatus : uint8_t {
  kOk = 0,
  kBadJson,        // not a JSON value: MarksResult::what says why
  kNotAnObject,    // a line that is JSON but not an object
  kMissingField,   // a required member or field is missing
  kBadTime,        // not a number of the format's unit >= 0 that fits (about 292 years)
  kTimeGoesBack,   // earlier than the viseme before
  kBadType,        // a Polly mark type other than sentence, word, viseme, ssml
  kBadViseme,      // not a viseme of the format
  kTooLarge,       // a document past the reader's limits
};

const char* to_string(MarksStatus status);

struct MarksResult {
  MarksStatus status = MarksStatus::kOk;
  size_t column = 0;       // byte offset in the line (or document) of the fault
  const char* what = "";   // for kBadJson

  bool ok() const { return status == MarksStatus::kOk; }
};

// The input formats: a viseme becomes a phoneme of the format's viseme alphabet.
enum class MarksInput : uint8_t {
  kPolly,    // kPollyVisemeAlphabet; sentence and word marks become the flags
  kRhubarb,  // kRhubarbShapeAlphabet; TSV lines, or one JSON document
  kAzure,    // kAzureVisemeAlphabet; JSON lines of audioOffset (ticks) and visemeId
};

// Reads marks into x-pfap phoneme events: each viseme lasts until the next one (a
// Rhubarb cue until its end), so an event comes out when the next viseme is read.
class MarksReader {
 public:
  // A last viseme with no end given lasts this long.
  static constexpr int64_t kLastVisemeMs = 150;
  // A viseme lasting longer (a long silence) is cut here: the time after it is a gap.
  static constexpr int64_t kMaxVisemeMs = 16 * kMaxPhonemeDurationMs;
  static constexpr size_t kMaxDocumentBytes = 16 * 1024 * 1024;  // Rhubarb JSON

  explicit MarksReader(MarksInput input) : input_(input) {}

  // The alphabet of the phonemes this reader makes.
  std::string_view alphabet() const;

  // One line (without its end) of Polly, Azure or Rhubarb TSV. Blank lines give nothing. On
  // error nothing is kept from the line.
  MarksResult read_line(std::string_view line, std::vector<TextEvent>& out);
  // Told of a bad cue of a Rhubarb JSON document; returns true to leave it out and go on.
  using BadCue = std::function<bool(const MarksResult&)>;
  // A whole Rhubarb JSON document; its last cue ends at its end. A bad cue is given to
  // `bad_cue`: left out when it returns true (a gap it leaves is a rest, like any gap between
  // cues), else reading stops there and returns it, every cue before given, the last one
  // ending at its end. Without `bad_cue`, the first bad cue stops. A document that is not
  // JSON, or has no mouthCues array, gives nothing.
  MarksResult read_document(std::string_view document, std::vector<TextEvent>& out,
                            const BadCue& bad_cue = {});
  // The last viseme, at the end of the input.
  void finish(std::vector<TextEvent>& out);
  void reset();

 private:
  MarksResult viseme(int64_t time_ms, uint8_t symbol, size_t column, std::vector<TextEvent>& out);
  void emit_pending(int64_t end_ms, std::vector<TextEvent>& out);
  void sentence();

  MarksInput input_;
  bool has_pending_ = false;
  TextEvent pending_;              // the last viseme read, waiting for its end
  int64_t last_time_ms_ = 0;
  int64_t pending_end_ms_ = 0;     // Rhubarb JSON: where the pending cue ends
  bool next_word_begin_ = false;
  bool next_sentence_start_ = true;
  bool sentence_has_visemes_ = false;
};

}  // namespace pfap

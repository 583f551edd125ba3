// SPDX-License-Identifier: LGPL-2.1-or-later
// The example pipelines stay on one line, to be copied.
// clang-format off
/**
 * SECTION:element-pfapfapparse
 * @title: pfapfapparse
 * @see_also: pfapfapenc, pfaptextparse, rtppfappay, pfapface
 *
 * Reads an MPEG-4 FAP file (.fap, the FBA text format of Xface, Greta and other MPEG-4 face
 * players; docs/fap-files.md) and outputs its animation as application/x-pfap events, which
 * rtppfappay, pfapface and pfaptextenc take as they are. Frame k becomes a silence phoneme
 * (#GstPfapFapParse:silence-symbol) at k / frame rate seconds, rounded to the ms, lasting until
 * the next frame, with a bookmark `<FAP n a 0 1>` (linear, T = 0) for each FAP whose value
 * changed since the frame before: a receiver's FAP state holds each frame's values from its
 * time to the next frame's, as MPEG-4 players show the file. More than 40 changes in a frame
 * go on extra 0 ms silence phonemes at the same time (MPEG-4 allows 40 bookmarks before a
 * phoneme). Expression FAP 2 becomes FAPs 69..74 as the bookmark rule `<FAP 2 e1 a1 e2 a2>`
 * does. The draft has no place for FAP 1 (visemes are phonemes here), nor for FAP 2's
 * init_face and expression_def: each frame that sets them is reported with a warning (at the
 * 1st, 2nd, 4th, ... such frame), and the rest of the frame goes on.
 *
 * The output is a TIME segment from 0 with the first frame at 0; a sink with sync=true plays
 * the animation in real time. The caps carry `alphabet` (#GstPfapFapParse:alphabet).
 *
 * With the request pad `speech` linked to a phoneme stream (pfaptts, pfaptextparse), the file's
 * bookmarks go on the speech's phonemes instead (pfap::merge_with_speech): a phoneme that
 * spans a frame with changes is split there into pieces of the same symbol, and silence
 * phonemes carry only the frames where no one speaks. Both are timed from their segment's
 * start. The two inputs are kept until both have ended (at most 100000 speech events), then
 * the merged stream goes out, merged a window of at least 4096 file events at a time; the caps
 * take the speech's alphabet when it has one.
 *
 * A bad file (an unsupported version, a mask without 68 flags, a value past the draft's
 * amplitude range, frame numbers out of order, an absurd frame count or rate, fewer frames
 * than the header says) is an error naming the file, its line, field and FAP: a FAP file's
 * frames depend on the lines before, so there is nothing to skip to. The limits against
 * hostile files are those of pfap/fap_file.h: lines of at most 64 KiB, 360000 frames, 1 to
 * 1000 frames a second. A UTF-8 byte order mark at the start of the file is skipped.
 *
 * ## Example pipelines
 * |[
 * gst-launch-1.0 filesrc location=joy.fap ! pfapfapparse ! pfapface ! videoconvert ! autovideosink
 * ]| Plays joy.fap on the pfapface face.
 * |[
 * gst-launch-1.0 filesrc location=joy.fap ! pfapfapparse ! rtppfappay ! udpsink host=127.0.0.1 port=5004
 * ]| Sends joy.fap as PFAP RTP packets to port 5004, in real time.
 * |[
 * gst-launch-1.0 pfaptts text="Hello world." name=t t.pfap ! p.speech filesrc location=joy.fap ! pfapfapparse name=p ! pfapface ! videoconvert ! autovideosink
 * ]| Smiles joy.fap's smile on the phonemes of a spoken sentence.
 */
// clang-format on
#include "gstpfapfapparse.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "markupbuffer.h"
#include "pfap/fap_animation.h"
#include "pfap/fap_file.h"
#include "pfap/phoneme_table.h"
#include "ratelimit.h"

GST_DEBUG_CATEGORY_STATIC(fapparse_debug);
#define GST_CAT_DEFAULT fapparse_debug

namespace {

enum { PROP_0, PROP_SILENCE_SYMBOL, PROP_ALPHABET };

constexpr guint kDefaultSilenceSymbol = pfap::kSilenceSymbol;
constexpr const char* kDefaultAlphabet = pfap::kArpabetAlphabet.data();

// What the streaming thread keeps between buffers. GObject runs no C++ constructors, so it
// lives behind a pointer made in init and deleted in finalize.
struct Stream {
  pfap::FapFileReader reader;
  std::optional<pfap::FapFileMarkup> markup;  // once the header is read
  pfap::NotCarried reported;                  // what was already warned about
  std::vector<pfap::TextEvent> events;
};

// With a speech pad: both inputs kept until both have ended, then merged
// (pfap::merge_with_speech). Under GstPfapFapParse::merge_lock: the two pads stream in two threads.
struct Merge {
  Merge() { gst_segment_init(&speech_segment, GST_FORMAT_TIME); }

  std::vector<pfap::TextEvent> file_events;
  std::vector<pfap::TextEvent> speech;
  GstSegment speech_segment;
  int64_t speech_end_ms = 0;  // where the last speech phoneme ends
  std::string alphabet;       // the speech caps' alphabet, if any
  uint64_t dropped = 0;       // malformed or over-limit speech events
  bool file_ended = false;
  bool speech_ended = false;
};

// Far above an hour of speech (about 12 phonemes a second): bounds what the speech pad keeps.
constexpr size_t kMaxSpeechEvents = 100'000;
// The file events merged at a time (at least; up to the next place a window can end).
constexpr size_t kMergeWindowEvents = 4096;

}  // namespace

struct _GstPfapFapParse {
  GstPfapBaseParse parent;
  GstPad* speechpad;     // the request pad, or NULL
  guint silence_symbol;  // under the object lock
  gchar* alphabet;       // under the object lock; NULL when unset
  Stream* stream;
  GMutex merge_lock;
  Merge* merge;
};

static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS,
                            GST_STATIC_CAPS("text/x-raw, format = (string) utf8; text/plain"));

static GstStaticPadTemplate speech_template = GST_STATIC_PAD_TEMPLATE(
    "speech", GST_PAD_SINK, GST_PAD_REQUEST, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

G_DEFINE_TYPE(GstPfapFapParse, gst_pfap_fap_parse, GST_TYPE_PFAP_BASE_PARSE)
GST_ELEMENT_REGISTER_DEFINE(pfapfapparse, "pfapfapparse", GST_RANK_NONE, GST_TYPE_PFAP_FAP_PARSE)

// Back to the start of a file (READY to PAUSED, FLUSH_STOP).
static void gst_pfap_fap_parse_reset(GstPfapBaseParse* parse) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(parse);
  *self->stream = Stream{};
  g_mutex_lock(&self->merge_lock);
  *self->merge = Merge{};
  g_mutex_unlock(&self->merge_lock);
}

static bool merging(GstPfapFapParse* self) {
  GST_OBJECT_LOCK(self);
  const bool speech = self->speechpad != nullptr;
  GST_OBJECT_UNLOCK(self);
  return speech;
}

// The upstream file's name for messages.
static const char* file_name(GstPfapFapParse* self) {
  const std::string& source = gst_pfap_base_parse_source(GST_PFAP_BASE_PARSE(self));
  return source.empty() ? "the FAP file" : source.c_str();
}

static GstCaps* gst_pfap_fap_parse_output_caps(GstPfapBaseParse* parse) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(parse);
  GstCaps* caps = gst_static_pad_template_get_caps(&src_template);
  // Merged, the phonemes are mostly the speech's: its alphabet, when it names one.
  g_mutex_lock(&self->merge_lock);
  std::string alphabet = self->merge->alphabet;
  g_mutex_unlock(&self->merge_lock);
  GST_OBJECT_LOCK(self);
  if (alphabet.empty() && self->alphabet != nullptr) alphabet = self->alphabet;
  GST_OBJECT_UNLOCK(self);
  if (!alphabet.empty()) {
    caps = gst_caps_make_writable(caps);
    gst_caps_set_simple(caps, "alphabet", G_TYPE_STRING, alphabet.c_str(), nullptr);
  }
  return caps;
}

// A FAP file's frames depend on the lines before: there is nothing to skip to.
static GstFlowReturn bad_file(GstPfapFapParse* self, const pfap::FapFileResult& result) {
  GST_ELEMENT_ERROR(self, STREAM, DECODE,
                    ("Bad FAP file %s, %s", file_name(self), pfap::describe(result).c_str()),
                    ("docs/fap-files.md describes what is read"));
  return GST_FLOW_ERROR;
}

// Whether a count that went from `before` to `now` passed the 1st, 2nd, 4th, 8th, ...
// occurrence: pfap_warn_at for counts that may grow by more than one at a time.
static bool passed_warning(uint64_t before, uint64_t now) {
  return std::bit_width(before) < std::bit_width(now);
}

// Warns about what a frame holds that the draft cannot carry, at the 1st, 2nd, 4th, ... one.
static void report_not_carried(GstPfapFapParse* self, const pfap::FapFrame& frame) {
  Stream& s = *self->stream;
  const pfap::NotCarried& now = s.markup->not_carried();
  if (passed_warning(s.reported.visemes, now.visemes)) {
    GST_ELEMENT_WARNING(
        self, STREAM, FORMAT,
        ("%s frame %u sets FAP 1 (viseme), which PFAP does not carry: visemes "
         "are phonemes here",
         file_name(self), frame.number),
        ("%" G_GUINT64_FORMAT " such frames so far (warned at the 1st, 2nd, 4th, ...)",
         now.visemes));
  }
  if (passed_warning(s.reported.expression_flags, now.expression_flags)) {
    GST_ELEMENT_WARNING(self, STREAM, FORMAT,
                        ("%s frame %u sets FAP 2's init_face or expression_def, which PFAP does "
                         "not carry; its expressions are carried",
                         file_name(self), frame.number),
                        ("%" G_GUINT64_FORMAT " such frames so far", now.expression_flags));
  }
  if (passed_warning(s.reported.rounded_values, now.rounded_values)) {
    GST_ELEMENT_WARNING(self, STREAM, FORMAT,
                        ("%s frame %u has values with a fraction, rounded to whole FAP units",
                         file_name(self), frame.number),
                        ("%" G_GUINT64_FORMAT " such values so far", now.rounded_values));
  }
  s.reported = now;
}

// Pushes events; the output starts with the first frame, even one that gives none.
static GstFlowReturn push_events(GstPfapFapParse* self,
                                 const std::vector<pfap::TextEvent>& events) {
  GstPfapBaseParse* parse = GST_PFAP_BASE_PARSE(self);
  gst_pfap_base_parse_start_output(parse);
  for (const pfap::TextEvent& event : events) {
    const GstFlowReturn ret = gst_pfap_base_parse_push(parse, event);
    if (ret != GST_FLOW_OK) return ret;
  }
  return GST_FLOW_OK;
}

static GstFlowReturn push_frame(GstPfapFapParse* self, const pfap::FapFrame& frame) {
  Stream& s = *self->stream;
  if (!s.markup) s.markup.emplace(s.reader.header());
  s.events.clear();
  s.markup->add(frame, s.events);
  report_not_carried(self, frame);
  GST_OBJECT_LOCK(self);
  const auto symbol = static_cast<uint8_t>(self->silence_symbol);
  GST_OBJECT_UNLOCK(self);
  for (pfap::TextEvent& event : s.events) event.event.phoneme.symbol = symbol;
  if (merging(self)) {
    g_mutex_lock(&self->merge_lock);
    self->merge->file_events.insert(self->merge->file_events.end(), s.events.begin(),
                                    s.events.end());
    g_mutex_unlock(&self->merge_lock);
    return GST_FLOW_OK;
  }
  return push_events(self, s.events);
}

// The merge of `file` (consumed) with `speech`, pushed a window at a time so that at most a
// window's events are held twice (pfap::merge_with_speech holds its inputs' FAPs twice more).
// A window ends at a frame with changes that no speech phoneme spans: there the whole merge
// is the windows' merges one after the other, but for two flags that `carry` puts back:
// merge_with_speech ends the text at each window's last phoneme, and starts a sentence with a
// silence that opens a window. `carry` is what the whole merge has there: the end of text of
// the last speech phoneme before the cut, none after a silence, and true before anything.
static GstFlowReturn push_merged(GstPfapFapParse* self, std::vector<pfap::TextEvent>& file,
                                 const std::vector<pfap::TextEvent>& speech, uint8_t symbol) {
  const auto is_phoneme = [](const pfap::TextEvent& e) {
    return e.event.kind == PFAP_EVENT_PHONEME;
  };
  const auto end_of = [](const pfap::TextEvent& e) {
    return e.time_ms + e.event.phoneme.duration_ms;
  };
  size_t f = 0, s = 0;
  bool carry = true;
  GstFlowReturn ret = GST_FLOW_OK;
  while (ret == GST_FLOW_OK && (f < file.size() || s < speech.size())) {
    size_t f_end = file.size(), s_end = speech.size();
    int64_t speech_end = 0;  // where the speech phonemes before the candidate cut end
    size_t scanned = s;
    for (size_t i = f + kMergeWindowEvents; i < file.size(); ++i) {
      const pfap::TextEvent& e = file[i];
      if (e.event.faps.empty() || e.time_ms == file[i - 1].time_ms) continue;  // not a cut
      for (; scanned < speech.size() && speech[scanned].time_ms < e.time_ms; ++scanned) {
        if (is_phoneme(speech[scanned])) speech_end = end_of(speech[scanned]);
      }
      if (speech_end > e.time_ms) continue;  // a speech phoneme spans it
      f_end = i;
      s_end = scanned;
      break;
    }
    GST_DEBUG_OBJECT(self, "merging file events %zu..%zu with speech events %zu..%zu", f, f_end, s,
                     s_end);
    const std::vector<pfap::TextEvent> speech_window(speech.begin() + s, speech.begin() + s_end);
    std::vector<pfap::TextEvent> merged;
    int64_t last_cut = -1;
    {
      const std::vector<pfap::TextEvent> file_window(std::make_move_iterator(file.begin() + f),
                                                     std::make_move_iterator(file.begin() + f_end));
      for (const pfap::TextEvent& e : file_window) {
        if (!e.event.faps.empty()) last_cut = e.time_ms;
      }
      merged = pfap::merge_with_speech(speech_window, file_window, symbol);
    }
    const auto first_speech = std::find_if(speech_window.begin(), speech_window.end(), is_phoneme);
    const auto last_speech = std::find_if(speech_window.rbegin(), speech_window.rend(), is_phoneme);
    const auto first = std::find_if(merged.begin(), merged.end(), is_phoneme);
    const auto last = std::find_if(merged.rbegin(), merged.rend(), is_phoneme);
    // A window after the first opens with its cut's silence unless a speech phoneme starts there.
    if (f > 0 && first != merged.end() &&
        (first_speech == speech_window.end() || first_speech->time_ms != file[f].time_ms)) {
      first->event.sentence_start = carry;
    }
    if (last_speech != speech_window.rend() && (last_cut < 0 || last_cut < end_of(*last_speech))) {
      carry = last_speech->event.phoneme.end_of_text;
    } else if (last_cut >= 0) {
      carry = false;
    }
    const bool final_window = f_end == file.size() && s_end == speech.size();
    if (!final_window && last != merged.rend()) last->event.phoneme.end_of_text = carry;
    ret = push_events(self, merged);
    f = f_end;
    s = s_end;
  }
  return ret;
}

// At the end of the file or of the speech: once both have ended, the merged events and EOS
// go downstream. Returns whether this call sent them (else the other input's end will).
static bool end_of_input(GstPfapFapParse* self, bool file) {
  g_mutex_lock(&self->merge_lock);
  Merge& m = *self->merge;
  (file ? m.file_ended : m.speech_ended) = true;
  if (!m.file_ended || !m.speech_ended) {
    g_mutex_unlock(&self->merge_lock);
    return false;
  }
  std::vector<pfap::TextEvent> file_events = std::move(m.file_events);
  std::vector<pfap::TextEvent> speech = std::move(m.speech);
  g_mutex_unlock(&self->merge_lock);
  GST_OBJECT_LOCK(self);
  const auto symbol = static_cast<uint8_t>(self->silence_symbol);
  GST_OBJECT_UNLOCK(self);
  push_merged(self, file_events, speech, symbol);
  gst_pad_push_event(gst_pfap_base_parse_srcpad(GST_PFAP_BASE_PARSE(self)), gst_event_new_eos());
  return true;
}

static GstFlowReturn gst_pfap_fap_parse_read_line(GstPfapBaseParse* parse, std::string_view line) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(parse);
  pfap::FapFrame frame;
  bool has_frame = false;
  const pfap::FapFileResult result = self->stream->reader.read_line(line, frame, has_frame);
  if (!result.ok()) return bad_file(self, result);
  return has_frame ? push_frame(self, frame) : GST_FLOW_OK;
}

static GstFlowReturn gst_pfap_fap_parse_line_too_long(GstPfapBaseParse* parse) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(parse);
  return bad_file(self, {pfap::FapFileStatus::kLineTooLong, self->stream->reader.line() + 1, 0, 0});
}

// At EOS, after the last line: the file must be whole. Merging, EOS goes once the speech has
// ended too.
static GstFlowReturn gst_pfap_fap_parse_finish(GstPfapBaseParse* parse) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(parse);
  const pfap::FapFileResult result = self->stream->reader.finish();
  if (!result.ok()) return bad_file(self, result);
  if (merging(self)) {
    end_of_input(self, true);
    return GST_PFAP_BASE_PARSE_FLOW_EOS_HELD;
  }
  return GST_FLOW_OK;
}

// Speech events are kept, timed in ms from the speech segment's start, until both inputs end.
static GstFlowReturn gst_pfap_fap_parse_speech_chain(GstPad*, GstObject* parent,
                                                     GstBuffer* buffer) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(parent);
  pfap::TextEvent event;
  const bool ok = pfap_buffer_read(buffer, event.event);
  g_mutex_lock(&self->merge_lock);
  Merge& m = *self->merge;
  const GstClockTime running =
      gst_segment_to_running_time(&m.speech_segment, GST_FORMAT_TIME, GST_BUFFER_PTS(buffer));
  // An event without a time starts where the speech before it ended.
  event.time_ms = GST_CLOCK_TIME_IS_VALID(running)
                      ? static_cast<int64_t>((running + GST_MSECOND / 2) / GST_MSECOND)
                      : m.speech_end_ms;
  if (!m.speech.empty()) event.time_ms = std::max(event.time_ms, m.speech.back().time_ms);
  const bool kept = ok && m.speech.size() < kMaxSpeechEvents;
  if (kept) {
    if (event.event.kind == PFAP_EVENT_PHONEME) {
      // Speech phonemes one after the other: an overlap is cut from the earlier one's end.
      event.time_ms = std::max(event.time_ms, m.speech_end_ms);
      m.speech_end_ms = event.time_ms + event.event.phoneme.duration_ms;
    }
    m.speech.push_back(std::move(event));
  }
  const uint64_t dropped = kept ? 0 : ++m.dropped;
  g_mutex_unlock(&self->merge_lock);
  if (!kept && pfap_warn_at(dropped)) {
    GST_ELEMENT_WARNING(
        self, STREAM, DECODE,
        ("Dropped a speech event: %s.",
         ok ? "too many speech events to merge" : "not a valid x-pfap event"),
        ("%" G_GUINT64_FORMAT " dropped so far; at most %zu are kept", dropped, kMaxSpeechEvents));
  }
  gst_buffer_unref(buffer);
  return GST_FLOW_OK;
}

static gboolean gst_pfap_fap_parse_speech_event(GstPad*, GstObject* parent, GstEvent* event) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(parent);
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_CAPS: {
      GstCaps* caps = nullptr;
      gst_event_parse_caps(event, &caps);
      const gchar* alphabet = gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet");
      g_mutex_lock(&self->merge_lock);
      self->merge->alphabet = alphabet != nullptr ? alphabet : "";
      g_mutex_unlock(&self->merge_lock);
      break;
    }
    case GST_EVENT_SEGMENT: {
      GstSegment segment;
      gst_event_copy_segment(event, &segment);
      if (segment.format == GST_FORMAT_TIME) {
        g_mutex_lock(&self->merge_lock);
        self->merge->speech_segment = segment;
        g_mutex_unlock(&self->merge_lock);
      }
      break;
    }
    case GST_EVENT_EOS:
      end_of_input(self, false);
      break;
    default:
      break;  // the output's stream, caps, segment and flushes are the file's
  }
  gst_event_unref(event);
  return TRUE;
}

static GstPad* gst_pfap_fap_parse_request_new_pad(GstElement* element, GstPadTemplate* templ,
                                                  const gchar*, const GstCaps*) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(element);
  GST_OBJECT_LOCK(self);
  const bool taken = self->speechpad != nullptr;
  GST_OBJECT_UNLOCK(self);
  if (taken) {
    GST_WARNING_OBJECT(self, "one speech pad only");
    return nullptr;
  }
  GstPad* pad = gst_pad_new_from_template(templ, "speech");
  gst_pad_set_chain_function(pad, gst_pfap_fap_parse_speech_chain);
  gst_pad_set_event_function(pad, gst_pfap_fap_parse_speech_event);
  GST_OBJECT_LOCK(self);
  self->speechpad = pad;
  GST_OBJECT_UNLOCK(self);
  gst_element_add_pad(element, pad);
  return pad;
}

static void gst_pfap_fap_parse_release_pad(GstElement* element, GstPad* pad) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(element);
  GST_OBJECT_LOCK(self);
  if (self->speechpad == pad) self->speechpad = nullptr;
  GST_OBJECT_UNLOCK(self);
  gst_element_remove_pad(element, pad);
}

static void gst_pfap_fap_parse_set_property(GObject* object, guint prop_id, const GValue* value,
                                            GParamSpec* pspec) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_SILENCE_SYMBOL:
      self->silence_symbol = g_value_get_uint(value);
      break;
    case PROP_ALPHABET:
      g_free(self->alphabet);
      self->alphabet = g_value_dup_string(value);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_fap_parse_get_property(GObject* object, guint prop_id, GValue* value,
                                            GParamSpec* pspec) {
  GstPfapFapParse* self = GST_PFAP_FAP_PARSE(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_SILENCE_SYMBOL:
      g_value_set_uint(value, self->silence_symbol);
      break;
    case PROP_ALPHABET:
      g_value_set_string(value, self->alphabet);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_fap_parse_finalize(GObject* object) {
  delete GST_PFAP_FAP_PARSE(object)->stream;
  delete GST_PFAP_FAP_PARSE(object)->merge;
  g_mutex_clear(&GST_PFAP_FAP_PARSE(object)->merge_lock);
  g_free(GST_PFAP_FAP_PARSE(object)->alphabet);
  G_OBJECT_CLASS(gst_pfap_fap_parse_parent_class)->finalize(object);
}

static void gst_pfap_fap_parse_class_init(GstPfapFapParseClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstPfapBaseParseClass* parse_class = GST_PFAP_BASE_PARSE_CLASS(klass);

  GST_DEBUG_CATEGORY_INIT(fapparse_debug, "pfapfapparse", 0, "MPEG-4 FAP file parser");

  gobject_class->set_property = gst_pfap_fap_parse_set_property;
  gobject_class->get_property = gst_pfap_fap_parse_get_property;
  gobject_class->finalize = gst_pfap_fap_parse_finalize;

  /**
   * GstPfapFapParse:silence-symbol:
   *
   * The phoneme symbol of the silence phonemes that carry the frames: 0, the pause of
   * x-pfap-arpabet, by default. Set it with #GstPfapFapParse:alphabet for another alphabet.
   */
  g_object_class_install_property(
      gobject_class, PROP_SILENCE_SYMBOL,
      g_param_spec_uint("silence-symbol", "Silence symbol",
                        "Phoneme symbol of the silence phonemes that carry the frames", 0, 255,
                        kDefaultSilenceSymbol,
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_READY)));

  /**
   * GstPfapFapParse:alphabet:
   *
   * The phoneme alphabet of #GstPfapFapParse:silence-symbol, for the `alphabet` field of the
   * output caps (rtppfappay carries it to the SDP). Empty: no alphabet field.
   */
  g_object_class_install_property(
      gobject_class, PROP_ALPHABET,
      g_param_spec_string("alphabet", "Phoneme alphabet",
                          "Name of the phoneme alphabet of the silence symbol, for the caps "
                          "and SDP (empty: none)",
                          kDefaultAlphabet,
                          static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                   GST_PARAM_MUTABLE_READY)));

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &speech_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_set_static_metadata(
      element_class, "MPEG-4 FAP file parser", "Codec/Parser/Text",
      "Reads MPEG-4 facial animation parameter (.fap) files as application/x-pfap events",
      "gst-pfap developers");

  parse_class->max_line_bytes = pfap::kMaxFapFileLineBytes;
  parse_class->read_line = gst_pfap_fap_parse_read_line;
  parse_class->line_too_long = gst_pfap_fap_parse_line_too_long;
  parse_class->finish = gst_pfap_fap_parse_finish;
  parse_class->reset = gst_pfap_fap_parse_reset;
  parse_class->output_caps = gst_pfap_fap_parse_output_caps;
  element_class->request_new_pad = gst_pfap_fap_parse_request_new_pad;
  element_class->release_pad = gst_pfap_fap_parse_release_pad;
}

static void gst_pfap_fap_parse_init(GstPfapFapParse* self) {
  self->silence_symbol = kDefaultSilenceSymbol;
  self->alphabet = g_strdup(kDefaultAlphabet);
  self->stream = new Stream{};
  self->speechpad = nullptr;
  g_mutex_init(&self->merge_lock);
  self->merge = new Merge{};
}

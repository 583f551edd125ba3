// SPDX-License-Identifier: LGPL-2.1-or-later
// What the parsers' base class (GstPfapBaseParse) does for each of its parsers, pfaptextparse,
// pfapmarksparse and pfapfapparse, from one table: the text in any chunks, line ends and a byte
// order mark; the longest line; what an error stops; the source file in messages. Each
// parser's own format is tested in test_pfapparse.cc, test_marks.cc and test_fapfile.cc.
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <string>
#include <vector>

#include "element_harness.h"
#include "pfap_buffers.h"
#include "pipeline.h"
#include "temp_dir.h"

namespace {

using pfap::testing::ElementHarness;
using pfap::testing::Event;
using pfap::testing::Pipeline;
using pfap::testing::TempDir;

constexpr size_t kMaxLineBytes = 64 * 1024;

std::string fap_mask() {
  std::string mask = "0 0 1";
  for (int i = 4; i <= 68; ++i) mask += " 0";
  return mask;
}

// A parser and a good text of its format, line by line, whose lines after the first each give
// events; `bad` is a line it cannot read after the first.
struct Reader {
  const char* launch;
  std::vector<std::string> lines;
  std::string bad;
};

const std::vector<Reader>& readers() {
  static const std::vector<Reader> rows = {
      {"pfaptextparse", {"0 1 20 100 -", "20 2 20 100 -", "40 3 20 100 E"}, "60 x"},
      {"pfapmarksparse format=polly",
       {"{\"time\":0,\"type\":\"viseme\",\"value\":\"p\"}",
        "{\"time\":100,\"type\":\"viseme\",\"value\":\"a\"}",
        "{\"time\":250,\"type\":\"viseme\",\"value\":\"sil\"}"},
       "{\"time\":300"},
      {"pfapfapparse", {"2.1 t 25 2", fap_mask(), "0 5", fap_mask(), "1 7"}, "x"},
  };
  return rows;
}

std::string text_of(const std::vector<std::string>& lines, const std::string& line_end) {
  std::string text;
  for (const std::string& line : lines) text += line + line_end;
  return text;
}

// The events the parser outputs for `text`, given in chunks of `chunk` bytes (0: whole), then
// EOS; "" or the first error.
struct Output {
  std::vector<Event> events;
  std::string error;
  bool eos = false;
};

// The parser in a harness that sends text caps and a segment, as a source does.
GstHarness* harness(const char* launch) {
  GstHarness* h = gst_harness_new_parse(launch);
  gst_harness_set_src_caps_str(h, "text/x-raw, format = (string) utf8");
  return h;
}

Output parse(const char* launch, const std::string& text, size_t chunk = 0) {
  ElementHarness h(harness(launch));
  Output out;
  const size_t step = chunk == 0 ? text.size() : chunk;
  for (size_t at = 0; at < text.size(); at += step) {
    const std::string piece = text.substr(at, step);
    if (gst_harness_push(h.harness(), gst_buffer_new_memdup(piece.data(), piece.size())) !=
        GST_FLOW_OK) {
      break;
    }
  }
  gst_harness_push_event(h.harness(), gst_event_new_eos());
  while (GstBuffer* b = gst_harness_try_pull(h.harness())) {
    out.events.push_back(pfap::testing::read_event(b));
    gst_buffer_unref(b);
  }
  while (GstEvent* e = gst_harness_try_pull_event(h.harness())) {
    out.eos = out.eos || GST_EVENT_TYPE(e) == GST_EVENT_EOS;
    gst_event_unref(e);
  }
  const std::vector<std::string> errors = h.errors();
  if (!errors.empty()) out.error = errors[0];
  return out;
}

// Every chunk size (lines, line ends and the byte order mark split anywhere), "\n" or "\r\n",
// with or without a byte order mark, with or without a last line end: the same events.
TEST(Parsers, AnyChunksLineEndsAndByteOrderMarkGiveTheSameEvents) {
  for (const Reader& r : readers()) {
    SCOPED_TRACE(r.launch);
    const Output reference = parse(r.launch, text_of(r.lines, "\n"));
    ASSERT_EQ(reference.error, "");
    ASSERT_GE(reference.events.size(), 2u);
    for (const char* line_end : {"\n", "\r\n"}) {
      for (const char* bom : {"", "\xEF\xBB\xBF"}) {
        std::string text = bom + text_of(r.lines, line_end);
        for (const std::string& t : {text, text.substr(0, text.size() - strlen(line_end))}) {
          for (size_t chunk : {0, 1, 2, 3, 7}) {
            SCOPED_TRACE(::testing::Message()
                         << "line end " << (line_end[0] == '\r' ? "CRLF" : "LF")
                         << (*bom != '\0' ? ", BOM" : "") << ", " << t.size()
                         << " bytes in chunks of " << chunk);
            const Output out = parse(r.launch, t, chunk);
            EXPECT_EQ(out.error, "");
            EXPECT_EQ(out.events, reference.events);
          }
        }
      }
    }
  }
}

// The limit counts a line's bytes without its line end, "\r\n" as "\n": a blank line of 64 KiB
// is read with either, one byte more is a bad line. (pfaptextparse and pfapmarksparse counted the
// '\r' of a "\r\n".)
TEST(Parsers, TheLongestLineIsTheSameWithEitherLineEnd) {
  for (const Reader& r : readers()) {
    SCOPED_TRACE(r.launch);
    const Output reference = parse(r.launch, text_of(r.lines, "\n"));
    for (const char* line_end : {"\n", "\r\n"}) {
      SCOPED_TRACE(line_end[0] == '\r' ? "CRLF" : "LF");
      for (size_t bytes : {kMaxLineBytes, kMaxLineBytes + 1}) {
        std::vector<std::string> lines = r.lines;
        lines.insert(lines.begin() + 1, std::string(bytes, ' '));
        const Output out = parse(r.launch, text_of(lines, line_end), 4096);
        if (bytes == kMaxLineBytes) {
          EXPECT_EQ(out.error, "");
          EXPECT_EQ(out.events, reference.events);
        } else {
          EXPECT_NE(out.error.find("line 2"), std::string::npos) << out.error;
          EXPECT_NE(out.error.find("longer than 65536 bytes"), std::string::npos) << out.error;
        }
      }
    }
  }
}

// A bad line without skip-bad-lines stops the stream: nothing after it is read, the buffers
// after it are refused, and EOS still goes downstream. (pfaptextparse and pfapmarksparse read on
// from the next buffer.)
TEST(Parsers, AfterAnErrorNothingMoreIsRead) {
  for (const Reader& r : readers()) {
    SCOPED_TRACE(r.launch);
    ElementHarness h(harness(r.launch));
    const std::string first = r.lines[0] + "\n" + r.bad + "\n";
    const std::string rest = text_of({r.lines.begin() + 1, r.lines.end()}, "\n");
    EXPECT_EQ(gst_harness_push(h.harness(), gst_buffer_new_memdup(first.data(), first.size())),
              GST_FLOW_ERROR);
    EXPECT_EQ(gst_harness_push(h.harness(), gst_buffer_new_memdup(rest.data(), rest.size())),
              GST_FLOW_ERROR);
    gst_harness_push_event(h.harness(), gst_event_new_eos());
    guint buffers = 0;
    while (GstBuffer* b = gst_harness_try_pull(h.harness())) {
      ++buffers;
      gst_buffer_unref(b);
    }
    // pfaptextparse's first line is an event; the others' first lines give none alone.
    EXPECT_LE(buffers, 1u);
    bool eos = false;
    while (GstEvent* e = gst_harness_try_pull_event(h.harness())) {
      eos = eos || GST_EVENT_TYPE(e) == GST_EVENT_EOS;
      gst_event_unref(e);
    }
    EXPECT_TRUE(eos);
    const std::vector<std::string> errors = h.errors();
    EXPECT_EQ(errors.size(), 1u);
    if (!errors.empty()) {
      EXPECT_NE(errors[0].find("line 2"), std::string::npos) << errors[0];
    }
  }
}

// Read from a file, a bad line's error names the file. (pfapmarksparse did not.)
TEST(Parsers, ABadLineFromAFileNamesTheFile) {
  TempDir dir;
  const std::string path = dir.file("bad.txt");
  for (const Reader& r : readers()) {
    SCOPED_TRACE(r.launch);
    const std::string text = r.lines[0] + "\n" + r.bad + "\n";
    ASSERT_TRUE(
        g_file_set_contents(path.c_str(), text.data(), static_cast<gssize>(text.size()), nullptr));
    Pipeline p("filesrc location=" + path + " ! " + r.launch + " ! fakesink");
    ASSERT_TRUE(p.ok()) << p.error();
    ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
    const std::string error = p.wait_eos(std::chrono::seconds(10));
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find("line 2"), std::string::npos) << error;
    p.set_state(GST_STATE_NULL);
  }
}

}  // namespace

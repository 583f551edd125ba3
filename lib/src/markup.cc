// SPDX-License-Identifier: LGPL-2.1-or-later
// application/x-pfap events: the byte layout of pfap/markup.h, read and written for the C API
// and for pfap::MarkupEvent alike.
#include "pfap/markup.h"

#include "pfap/markup_event.h"
#include "pfap/model.h"

namespace {

constexpr uint8_t kKnownFlags = PFAP_FLAG_STRESS | PFAP_FLAG_WORD_BEGIN | PFAP_FLAG_END_OF_TEXT |
                                PFAP_FLAG_SENTENCE_START | PFAP_FLAG_UNCERTAIN;

bool valid(const PfapEventHeader& h) {
  return (h.kind == PFAP_EVENT_PHONEME || h.kind == PFAP_EVENT_RECOVERED ||
          h.kind == PFAP_EVENT_COMPLETE) &&
         (h.flags & ~kKnownFlags) == 0 && h.duration_ms <= pfap::kMaxPhonemeDurationMs;
}

pfap::Fap to_fap(const PfapFap& f) {
  return {f.index, f.amplitude, f.transition_ms, static_cast<pfap::Curve>(f.curve)};
}

void put16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v >> 8);
  p[1] = static_cast<uint8_t>(v);
}

uint16_t get16(const uint8_t* p) { return static_cast<uint16_t>(p[0] << 8 | p[1]); }

void write_header(const PfapEventHeader& h, uint8_t* out) {
  out[0] = h.kind;
  out[1] = h.flags;
  out[2] = h.symbol;
  out[3] = h.f0;
  put16(out + 4, h.duration_ms);
  put16(out + 6, h.n_faps);
}

void write_fap(const pfap::Fap& f, uint8_t* out) {
  const auto amplitude = static_cast<uint32_t>(f.amplitude);
  out[0] = f.index;
  out[1] = static_cast<uint8_t>(f.curve);
  put16(out + 2, f.transition_ms);
  put16(out + 4, static_cast<uint16_t>(amplitude >> 16));
  put16(out + 6, static_cast<uint16_t>(amplitude));
}

}  // namespace

extern "C" {

size_t pfap_markup_size(unsigned n_faps) {
  return PFAP_MARKUP_HEADER_SIZE + size_t{PFAP_MARKUP_FAP_SIZE} * n_faps;
}

int pfap_markup_write(const PfapEventHeader* header, const PfapFap* faps, uint8_t* out,
                      size_t size) {
  if (!valid(*header) || size != pfap_markup_size(header->n_faps)) return -1;
  for (unsigned i = 0; i < header->n_faps; ++i) {
    if (!pfap::is_valid(to_fap(faps[i]))) return -1;
  }
  write_header(*header, out);
  for (unsigned i = 0; i < header->n_faps; ++i) {
    write_fap(to_fap(faps[i]), out + pfap_markup_size(i));
  }
  return 0;
}

int pfap_markup_read_header(const uint8_t* data, size_t size, PfapEventHeader* header) {
  if (size < PFAP_MARKUP_HEADER_SIZE) return -1;
  const PfapEventHeader h{data[0], data[1], data[2], data[3], get16(data + 4), get16(data + 6)};
  if (!valid(h) || size != pfap_markup_size(h.n_faps)) return -1;
  for (unsigned i = 0; i < h.n_faps; ++i) {
    PfapFap fap;
    pfap_markup_read_fap(data, i, &fap);
    if (!pfap::is_valid(to_fap(fap))) return -1;
  }
  *header = h;
  return 0;
}

void pfap_markup_read_fap(const uint8_t* data, unsigned i, PfapFap* fap) {
  const uint8_t* p = data + pfap_markup_size(i);
  fap->index = p[0];
  fap->curve = p[1];
  fap->transition_ms = get16(p + 2);
  fap->amplitude = static_cast<int32_t>(uint32_t{get16(p + 4)} << 16 | get16(p + 6));
}

}  // extern "C"

namespace pfap {

size_t markup_size(const MarkupEvent& event) {
  return pfap_markup_size(static_cast<unsigned>(event.faps.size()));
}

bool write_markup(const MarkupEvent& event, std::span<uint8_t> out) {
  if (event.faps.size() > UINT16_MAX || out.size() != markup_size(event)) return false;
  const Phoneme& p = event.phoneme;
  const bool phoneme = event.kind == PFAP_EVENT_PHONEME;
  const PfapEventHeader header{
      static_cast<uint8_t>(event.kind),
      static_cast<uint8_t>((p.stress ? PFAP_FLAG_STRESS : 0) |
                           (p.word_begin ? PFAP_FLAG_WORD_BEGIN : 0) |
                           (p.end_of_text ? PFAP_FLAG_END_OF_TEXT : 0) |
                           (event.sentence_start ? PFAP_FLAG_SENTENCE_START : 0) |
                           (event.uncertain ? PFAP_FLAG_UNCERTAIN : 0)),
      phoneme ? p.symbol : uint8_t{0},
      phoneme ? p.f0 : uint8_t{0},
      phoneme ? p.duration_ms : uint16_t{0},
      static_cast<uint16_t>(event.faps.size())};
  if (!valid(header)) return false;
  for (const Fap& f : event.faps) {
    if (!is_valid(f)) return false;
  }
  write_header(header, out.data());
  for (size_t i = 0; i < event.faps.size(); ++i) {
    write_fap(event.faps[i], out.data() + pfap_markup_size(static_cast<unsigned>(i)));
  }
  return true;
}

bool read_markup(std::span<const uint8_t> bytes, MarkupEvent& out) {
  PfapEventHeader h;
  if (pfap_markup_read_header(bytes.data(), bytes.size(), &h) != 0) return false;
  out.kind = static_cast<PfapEventKind>(h.kind);
  out.phoneme = {h.symbol,
                 h.duration_ms,
                 h.f0,
                 (h.flags & PFAP_FLAG_STRESS) != 0,
                 (h.flags & PFAP_FLAG_WORD_BEGIN) != 0,
                 (h.flags & PFAP_FLAG_END_OF_TEXT) != 0};
  out.sentence_start = (h.flags & PFAP_FLAG_SENTENCE_START) != 0;
  out.uncertain = (h.flags & PFAP_FLAG_UNCERTAIN) != 0;
  out.faps.resize(h.n_faps);
  for (unsigned i = 0; i < h.n_faps; ++i) {
    PfapFap f;
    pfap_markup_read_fap(bytes.data(), i, &f);
    out.faps[i] = to_fap(f);
  }
  return true;
}

void apply_markup(const MarkupEvent& event, int64_t time_ns, FapState& state) {
  if (event.kind == PFAP_EVENT_COMPLETE) {
    state.apply_complete(event.faps, time_ns);
  } else {
    for (const Fap& fap : event.faps) state.apply(fap, time_ns);
  }
}

}  // namespace pfap

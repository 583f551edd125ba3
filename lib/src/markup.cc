#include "pfap/markup.h"

#include "pfap/model.h"

namespace {

constexpr uint8_t kKnownFlags = PFAP_FLAG_STRESS | PFAP_FLAG_WORD_BEGIN | PFAP_FLAG_END_OF_TEXT |
                                PFAP_FLAG_SENTENCE_START | PFAP_FLAG_UNCERTAIN;

bool valid(const PfapEventHeader& h) {
  return (h.kind == PFAP_EVENT_PHONEME || h.kind == PFAP_EVENT_RECOVERED ||
          h.kind == PFAP_EVENT_COMPLETE) &&
         (h.flags & ~kKnownFlags) == 0 && h.duration_ms <= pfap::kMaxPhonemeDurationMs;
}

bool valid(const PfapFap& f) {
  return pfap::is_valid(
      pfap::Fap{f.index, f.amplitude, f.transition_ms, static_cast<pfap::Curve>(f.curve)});
}

void put16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v >> 8);
  p[1] = static_cast<uint8_t>(v);
}

uint16_t get16(const uint8_t* p) { return static_cast<uint16_t>(p[0] << 8 | p[1]); }

}  // namespace

extern "C" {

size_t pfap_markup_size(unsigned n_faps) {
  return PFAP_MARKUP_HEADER_SIZE + size_t{PFAP_MARKUP_FAP_SIZE} * n_faps;
}

int pfap_markup_write(const PfapEventHeader* header, const PfapFap* faps, uint8_t* out,
                      size_t size) {
  if (!valid(*header) || size != pfap_markup_size(header->n_faps)) return -1;
  for (unsigned i = 0; i < header->n_faps; ++i) {
    if (!valid(faps[i])) return -1;
  }
  out[0] = header->kind;
  out[1] = header->flags;
  out[2] = header->symbol;
  out[3] = header->f0;
  put16(out + 4, header->duration_ms);
  put16(out + 6, header->n_faps);
  uint8_t* p = out + PFAP_MARKUP_HEADER_SIZE;
  for (unsigned i = 0; i < header->n_faps; ++i, p += PFAP_MARKUP_FAP_SIZE) {
    const uint32_t amplitude = static_cast<uint32_t>(faps[i].amplitude);
    p[0] = faps[i].index;
    p[1] = faps[i].curve;
    put16(p + 2, faps[i].transition_ms);
    put16(p + 4, static_cast<uint16_t>(amplitude >> 16));
    put16(p + 6, static_cast<uint16_t>(amplitude));
  }
  return 0;
}

int pfap_markup_read_header(const uint8_t* data, size_t size, PfapEventHeader* header) {
  if (size < PFAP_MARKUP_HEADER_SIZE) return -1;
  PfapEventHeader h{data[0], data[1], data[2], data[3], get16(data + 4), get16(data + 6)};
  if (!valid(h) || size != pfap_markup_size(h.n_faps)) return -1;
  for (unsigned i = 0; i < h.n_faps; ++i) {
    PfapFap fap;
    pfap_markup_read_fap(data, i, &fap);
    if (!valid(fap)) return -1;
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

/* SPDX-License-Identifier: LGPL-2.1-or-later */
/* The bytes of one application/x-pfap buffer: one event of the TtsFAPInterface.
 *
 * A C API (usable from C and C++) so that an application can read and write these buffers
 * from appsink and appsrc without knowing the layout: map the GstBuffer, then call these.
 *
 * Three kinds of event:
 *  - PFAP_EVENT_PHONEME: a phoneme and the FAPs (bookmarks) that start with it.
 *  - PFAP_EVENT_RECOVERED: FAP targets restored from recovery information after a loss; each
 *    transition is the time still remaining at the buffer's time.
 *  - PFAP_EVENT_COMPLETE: the whole FAP state; every FAP not listed is 0.
 * The buffer's PTS is the event's time (for a phoneme its start), its duration the phoneme's.
 *
 * Layout (docs/markup.md), all integers big-endian:
 *   0  kind      1 byte    PfapEventKind
 *   1  flags     1 byte    PFAP_FLAG_*
 *   2  symbol    1 byte    phoneme symbol (0 for state events)
 *   3  f0        1 byte    f0 average in units of 2 Hz (0 for state events)
 *   4  duration  2 bytes   phoneme duration in ms, 0..4095 (0 for state events)
 *   6  n_faps    2 bytes   number of FAP records that follow
 *   8  n_faps records of 8 bytes: index 1, curve 1, transition_ms 2, amplitude 4 (signed)
 */
#ifndef PFAP_MARKUP_H
#define PFAP_MARKUP_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define PFAP_MARKUP_CAPS "application/x-pfap"
#define PFAP_MARKUP_HEADER_SIZE 8
#define PFAP_MARKUP_FAP_SIZE 8

typedef enum {
  PFAP_EVENT_PHONEME = 1,
  PFAP_EVENT_RECOVERED = 2,
  PFAP_EVENT_COMPLETE = 3,
} PfapEventKind;

typedef enum {
  PFAP_FLAG_STRESS = 1 << 0,
  PFAP_FLAG_WORD_BEGIN = 1 << 1,
  PFAP_FLAG_END_OF_TEXT = 1 << 2,    /* end of text after this phoneme */
  PFAP_FLAG_SENTENCE_START = 1 << 3, /* first phoneme of a sentence */
  PFAP_FLAG_UNCERTAIN = 1 << 4,      /* the receiver's FAP state may be incomplete (loss) */
} PfapEventFlags;

typedef struct {
  uint8_t kind;  /* PfapEventKind */
  uint8_t flags; /* PfapEventFlags */
  uint8_t symbol;
  uint8_t f0;           /* units of 2 Hz */
  uint16_t duration_ms; /* 0..4095 */
  uint16_t n_faps;
} PfapEventHeader;

typedef struct {
  uint8_t index;          /* 3..74; 69..74 are the expressions 1..6 */
  uint8_t curve;          /* 1 linear, 2 triangle, 3 spline */
  uint16_t transition_ms; /* 0..16383 */
  int32_t amplitude;      /* |amplitude| <= 2529600 */
} PfapFap;

/* The size in bytes of an event with n_faps FAPs. */
size_t pfap_markup_size(unsigned n_faps);

/* Writes an event of header->n_faps FAPs to out, which holds `size` bytes. Returns 0, or -1
 * (writing nothing usable) when a value is out of range or size is not
 * pfap_markup_size(header->n_faps). */
int pfap_markup_write(const PfapEventHeader* header, const PfapFap* faps, uint8_t* out,
                      size_t size);

/* Checks a whole event and reads its header. Returns 0, or -1 when the bytes are not a valid
 * event (unknown kind, a size that does not match n_faps, any value out of range). */
int pfap_markup_read_header(const uint8_t* data, size_t size, PfapEventHeader* header);

/* Reads FAP record i of an event that pfap_markup_read_header accepted. */
void pfap_markup_read_fap(const uint8_t* data, unsigned i, PfapFap* fap);

#ifdef __cplusplus
}
#endif

#endif /* PFAP_MARKUP_H */

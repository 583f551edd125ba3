// SPDX-License-Identifier: LGPL-2.1-or-later
/* pfap/markup.h from C99 (docs/markup.md): compiled as C99 with -pedantic-errors and linked
 * with the shared libpfap, an event written and read back field by field, and a bad one
 * refused. Prints what failed; the exit status is the number of failures. */
#include <pfap/markup.h>
#include <stdio.h>

static int failures = 0;

static void check(int ok, const char* what) {
  if (!ok) {
    printf("FAILED: %s\n", what);
    ++failures;
  }
}

int main(void) {
  const PfapEventHeader header = {PFAP_EVENT_PHONEME, PFAP_FLAG_STRESS | PFAP_FLAG_WORD_BEGIN,
                                  16, 60, 118, 2};
  const PfapFap faps[2] = {{3, 1, 500, -1200}, {69, 2, 0, 2529600}};
  uint8_t bytes[PFAP_MARKUP_HEADER_SIZE + 2 * PFAP_MARKUP_FAP_SIZE];
  PfapEventHeader read;
  PfapFap fap;
  unsigned i;

  check(pfap_markup_size(2) == sizeof bytes, "pfap_markup_size(2)");
  check(pfap_markup_write(&header, faps, bytes, sizeof bytes) == 0, "write");
  check(pfap_markup_read_header(bytes, sizeof bytes, &read) == 0, "read_header");
  check(read.kind == PFAP_EVENT_PHONEME && read.flags == header.flags && read.symbol == 16 &&
            read.f0 == 60 && read.duration_ms == 118 && read.n_faps == 2,
        "header read back");
  for (i = 0; i < 2; ++i) {
    pfap_markup_read_fap(bytes, i, &fap);
    check(fap.index == faps[i].index && fap.curve == faps[i].curve &&
              fap.transition_ms == faps[i].transition_ms && fap.amplitude == faps[i].amplitude,
          "FAP read back");
  }
  check(pfap_markup_read_header(bytes, sizeof bytes - 1, &read) == -1, "short event refused");
  bytes[0] = 9; /* no such kind */
  check(pfap_markup_read_header(bytes, sizeof bytes, &read) == -1, "unknown kind refused");
  if (failures == 0) printf("markup.h from C99: write, read back, refuse: ok\n");
  return failures;
}

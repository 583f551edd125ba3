// SPDX-License-Identifier: LGPL-2.1-or-later
// What the fuzz harnesses share: FUZZ_CHECK, which aborts with a message when a property the
// harness checks does not hold, so that libFuzzer saves the input and the corpus replay fails.
#pragma once

#include <cstdio>
#include <cstdlib>

#define FUZZ_CHECK(condition)                                                      \
  do {                                                                             \
    if (!(condition)) {                                                            \
      std::fprintf(stderr, "%s:%d: FUZZ_CHECK failed: %s\n", __FILE__, __LINE__, \
                   #condition);                                                    \
      std::abort();                                                                \
    }                                                                              \
  } while (false)

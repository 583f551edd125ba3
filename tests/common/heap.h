// SPDX-License-Identifier: LGPL-2.1-or-later
// What a process holds in memory now, for benchmarks and tests that show memory does not
// grow: the heap in use (malloc's own count; under AddressSanitizer, its allocator's) and the
// resident set size.
#pragma once

#include <malloc.h>
#include <unistd.h>

#include <cstddef>
#include <cstdio>

#if defined(__SANITIZE_ADDRESS__)
#define PFAP_HEAP_FROM_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PFAP_HEAP_FROM_ASAN 1
#endif
#endif
#ifdef PFAP_HEAP_FROM_ASAN
// From <sanitizer/allocator_interface.h>, which gcc does not install.
extern "C" size_t __sanitizer_get_current_allocated_bytes();
#endif

namespace pfap::testing {

// Bytes of heap allocated and not freed. GLib 2.74's GSlice keeps freed blocks in its own
// caches unless G_SLICE=always-malloc, which the programs using this set.
inline size_t heap_bytes() {
#ifdef PFAP_HEAP_FROM_ASAN
  return __sanitizer_get_current_allocated_bytes();
#else
  return mallinfo2().uordblks;
#endif
}

// Resident set size in bytes (0 if /proc cannot say).
inline size_t rss_bytes() {
  size_t pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%zu %zu", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return resident * static_cast<size_t>(sysconf(_SC_PAGESIZE));
}

}  // namespace pfap::testing

// SPDX-License-Identifier: LGPL-2.1-or-later
// CPU and wall-clock time in seconds, and the median of repeated runs, for benchmarks that
// print what they measure.
#pragma once

#include <time.h>

#include <algorithm>
#include <vector>

namespace pfap::testing {

inline double seconds_of(clockid_t clock) {
  timespec ts;
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// CPU time of the whole process: every thread of a pipeline.
inline double cpu_seconds() { return seconds_of(CLOCK_PROCESS_CPUTIME_ID); }
// CPU time of the calling thread only.
inline double thread_cpu_seconds() { return seconds_of(CLOCK_THREAD_CPUTIME_ID); }
inline double wall_seconds() { return seconds_of(CLOCK_MONOTONIC); }

// The median of `v`, which must not be empty.
inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

}  // namespace pfap::testing

// SPDX-License-Identifier: LGPL-2.1-or-later
// The C++ side of test_gstpfap.py's FAP state comparison: libpfap's pfap::FapState, driven by
// lines on stdin, prints the amplitudes asked for, exactly (%.17g), one per line:
//   E kind time_ns n_faps (index amplitude transition_ms curve){n_faps}   applies an event
//   Q time_ns index                                                     prints the amplitude
//   S index                                                             prints the settled value
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <string>

#include "pfap/fap_state.h"
#include "pfap/markup_event.h"

int main() {
  pfap::FapState state;
  std::string op;
  while (std::cin >> op) {
    if (op == "E") {
      int kind = 0;
      int64_t time_ns = 0;
      size_t n = 0;
      std::cin >> kind >> time_ns >> n;
      pfap::MarkupEvent event;
      event.kind = static_cast<PfapEventKind>(kind);
      for (size_t i = 0; i < n; ++i) {
        int index = 0, amplitude = 0, transition_ms = 0, curve = 0;
        std::cin >> index >> amplitude >> transition_ms >> curve;
        event.faps.push_back({static_cast<uint8_t>(index), amplitude,
                              static_cast<uint16_t>(transition_ms),
                              static_cast<pfap::Curve>(curve)});
        if (!pfap::is_valid(event.faps.back())) {
          std::cerr << "fap_state_values: FAP out of range\n";
          return 2;
        }
      }
      pfap::apply_markup(event, time_ns, state);
    } else if (op == "Q") {
      int64_t time_ns = 0;
      int index = 0;
      std::cin >> time_ns >> index;
      std::printf("%.17g\n", state.amplitude(index, time_ns));
    } else if (op == "S") {
      int index = 0;
      std::cin >> index;
      std::printf("%d\n", state.settled(index));
    } else {
      std::cerr << "fap_state_values: unknown operation " << op << "\n";
      return 2;
    }
  }
  return std::cin.eof() ? 0 : 2;
}

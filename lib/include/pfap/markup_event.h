// SPDX-License-Identifier: LGPL-2.1-or-later
// One application/x-pfap event as library types: the C++ side of pfap/markup.h, used by the
// elements so that the byte layout and its flags are read and written in one place.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pfap/fap_state.h"
#include "pfap/markup.h"
#include "pfap/model.h"

namespace pfap {

struct MarkupEvent {
  PfapEventKind kind = PFAP_EVENT_PHONEME;
  Phoneme phoneme;  // phoneme events only; end_of_text is the END_OF_TEXT flag
  bool sentence_start = false;
  bool uncertain = false;
  std::vector<Fap> faps;

  bool operator==(const MarkupEvent&) const = default;
};

// The event's size in bytes.
size_t markup_size(const MarkupEvent& event);

// Writes exactly markup_size(event) bytes to `out`; false (nothing usable written) when a
// value is out of range, there are more than 65535 FAPs, or `out` has another size.
bool write_markup(const MarkupEvent& event, std::span<uint8_t> out);

// Reads a whole event; false when the bytes are not a valid event.
bool read_markup(std::span<const uint8_t> bytes, MarkupEvent& out);

// Applies `event` at `time_ns` (its buffer's time) to a receiver's `state`: a complete state
// first returns every FAP to 0, then each of the event's FAPs starts at `time_ns`.
void apply_markup(const MarkupEvent& event, int64_t time_ns, FapState& state);

}  // namespace pfap

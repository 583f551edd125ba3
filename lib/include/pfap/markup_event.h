// One application/x-pfap event as library types: the C++ side of pfap/markup.h, used by the
// elements so that the byte layout and its flags are read and written in one place.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

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

}  // namespace pfap

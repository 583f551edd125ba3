// SPDX-License-Identifier: LGPL-2.1-or-later
// The warning of pfaptts and pfapalign, which speak with the same espeak-ng voices, for a
// phoneme of a voice that x-pfap-arpabet lacks: once per mnemonic a stream. A macro, as
// warning.h's, so that each element's own debug category logs it.
#pragma once

#include <gst/gst.h>

#include <set>
#include <string>
#include <vector>

#include "speech.h"

// `inexact`: pfap::tts::Speech::inexact of voice `voice` (a std::string); `warned`: the
// std::set<std::string> of mnemonics already warned about in this stream.
#define PFAP_WARN_INEXACT_PHONEMES(element, inexact, voice, warned)                             \
  G_STMT_START {                                                                                \
    for (const pfap::tts::Speech::Inexact& i_ : (inexact)) {                                    \
      if (!(warned).insert(i_.mnemonic).second) continue;                                       \
      const std::string sent_as_(i_.sent_as);                                                   \
      GST_ELEMENT_WARNING(element, STREAM, FORMAT,                                              \
                          ("espeak-ng phoneme \"%s\" of voice \"%s\" is not in x-pfap-arpabet", \
                           i_.mnemonic.c_str(), (voice).c_str()),                               \
                          ("sent as %s", sent_as_.c_str()));                                    \
    }                                                                                           \
  }                                                                                             \
  G_STMT_END

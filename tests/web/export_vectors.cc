// SPDX-License-Identifier: LGPL-2.1-or-later
// What libpfap, libface and GStreamer's RTP library make of seeded inputs, as JSON on stdout,
// for the differential tests of the JavaScript package (web/test, docs/web.md). Each mode is
// one part of the package:
//   export_vectors payloads CORPUS_DIR  every file of the payload fuzz corpus, then seeded
//                                       random valid, mutated and arbitrary payloads, each
//                                       with pfap::decode_payload's status, offset and packet
//   export_vectors decode               payloads on stdin (4-byte big-endian length, bytes),
//                                       the same records for each
//   export_vectors rtp                  seeded RTP packets and what gst_rtp_buffer_map reads
//   export_vectors curves               pfap::FapState amplitudes, settled values and
//                                       recovery entries after seeded bookmarks
//   export_vectors animator             pfap::face::Animator's FAP values after seeded events
//   export_vectors alphabet             x-pfap-arpabet: each symbol 0..255's name and viseme
//   export_vectors recovery             the seeded speech sessions sent with recovery, lost
//                                       at seeded places, and what RecoveryReceiver holds
//   export_vectors render DIR           face states, their poses, and their frames drawn by
//                                       pfap::face::render as raw BGRx files in DIR
//   export_vectors expressions          pfap::expression_weight of amplitudes in, at the edges
//                                       of and beyond 0..63
// The JSON shapes are the package's own (web/src/index.d.ts): the tests compare them whole.
#include <gst/rtp/gstrtpbuffer.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "face/animator.h"
#include "face/model.h"
#include "face/renderer.h"
#include "pfap/blendshapes.h"
#include "pfap/fap_state.h"
#include "pfap/model.h"
#include "pfap/packetizer.h"
#include "pfap/payload.h"
#include "pfap/phoneme_table.h"
#include "pfap/recovery.h"
#include "random_markup.h"
#include "speech_session.h"

namespace {

using pfap::Fap;
using pfap::Packet;
using Bytes = std::vector<uint8_t>;

// The names of docs/format.md's table, by DecodeStatus value.
constexpr const char* kStatusNames[] = {"kOk",
                                        "kTruncated",
                                        "kReservedRecoveryType",
                                        "kReservedInfoBits",
                                        "kMissingCoverage",
                                        "kFapIndexOutOfRange",
                                        "kAmplitudeOutOfRange",
                                        "kCurveZero",
                                        "kMissingFinalPhoneme",
                                        "kTrailingBytes",
                                        "kDataInCompleteRecovery",
                                        "kUnterminatedRecovery",
                                        "kEmptyPacket"};
static_assert(std::size(kStatusNames) == pfap::kDecodeStatusCount);

std::string hex(const uint8_t* data, size_t size) {
  static const char digits[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * size);
  for (size_t i = 0; i < size; ++i) {
    out += digits[data[i] >> 4];
    out += digits[data[i] & 15];
  }
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string fap_json(const Fap& f) {
  return "{\"index\":" + std::to_string(f.index) + ",\"amplitude\":" + std::to_string(f.amplitude) +
         ",\"transition\":" + std::to_string(f.transition_ms) +
         ",\"curve\":" + std::to_string(static_cast<int>(f.curve)) + "}";
}

std::string faps_json(std::span<const Fap> faps) {
  std::string out = "[";
  for (size_t i = 0; i < faps.size(); ++i) out += (i ? "," : "") + fap_json(faps[i]);
  return out + "]";
}

// A decoded packet in the package's shape.
std::string packet_json(const Packet& p) {
  std::string out = "{\"complete\":";
  out += p.recovery_kind == pfap::RecoveryKind::kComplete ? "true" : "false";
  out += ",\"coverage\":" + std::to_string(p.covered_packets);
  out += ",\"recovery\":" + faps_json(p.recovery) + ",\"phonemes\":[";
  for (size_t i = 0; i < p.phonemes.size(); ++i) {
    const pfap::Phoneme& ph = p.phonemes[i].phoneme;
    out += std::string(i ? "," : "") + "{\"symbol\":" + std::to_string(ph.symbol) +
           ",\"duration\":" + std::to_string(ph.duration_ms) +
           ",\"f0\":" + std::to_string(ph.f0_hz()) +
           ",\"stress\":" + (ph.stress ? "true" : "false") +
           ",\"wordBegin\":" + (ph.word_begin ? "true" : "false") +
           ",\"endOfText\":" + (ph.end_of_text ? "true" : "false") +
           ",\"faps\":" + faps_json(p.faps_of(i)) + "}";
  }
  return out + "]}";
}

// {"bytes": hex, "status": name, "offset": n, "packet": packet or null}
std::string decode_record(const Bytes& bytes) {
  Packet packet;
  const pfap::DecodeResult r = pfap::decode_payload(bytes, packet);
  return "{\"bytes\":\"" + hex(bytes.data(), bytes.size()) + "\",\"status\":\"" +
         kStatusNames[static_cast<int>(r.status)] + "\",\"offset\":" + std::to_string(r.offset) +
         ",\"packet\":" + (r.ok() ? packet_json(packet) : "null") + "}";
}

Bytes encode(const Packet& packet) {
  Bytes bytes(pfap::encoded_size(packet));
  if (pfap::encode_payload(packet, bytes) != pfap::EncodeStatus::kOk) {
    std::fprintf(stderr, "export_vectors: a generated packet does not encode\n");
    std::exit(1);
  }
  return bytes;
}

// Any packet the encoder takes: no, dynamic or complete recovery, and up to 6 phonemes.
Packet random_packet(pfap::testing::RandomMarkup& random) {
  Packet p;
  const int kind = random.uniform(0, 2);
  if (kind == 2) {
    p.recovery_kind = pfap::RecoveryKind::kComplete;
    for (int n = random.uniform(0, 4); n > 0; --n) p.recovery.push_back(random.fap());
    return p;
  }
  if (kind == 1) {
    p.recovery_kind = pfap::RecoveryKind::kDynamic;
    p.covered_packets = pfap::kCoverageSteps[random.uniform(0, 6)];
    for (int n = random.uniform(0, 4); n > 0; --n) p.recovery.push_back(random.fap());
  }
  const int phonemes = random.uniform(p.recovery.empty() ? 1 : 0, 6);
  for (int i = 0; i < phonemes; ++i) {
    pfap::Phoneme ph = random.phoneme();
    ph.end_of_text = i + 1 == phonemes && random.chance(0.3);
    std::vector<Fap> faps;
    for (int n = random.chance(0.5) ? 0 : random.uniform(1, 3); n > 0; --n) {
      faps.push_back(random.fap());
    }
    p.add_phoneme(ph, faps);
  }
  return p;
}

// A few of the changes a network, a bug or an attacker makes to a payload.
void mutate(Bytes& b, pfap::testing::RandomMarkup& random) {
  for (int n = random.uniform(1, 3); n > 0; --n) {
    const int size = static_cast<int>(b.size());
    switch (random.uniform(0, 5)) {
      case 0:  // one bit flipped
        if (size > 0)
          b[random.uniform(0, size - 1)] ^= static_cast<uint8_t>(1 << random.uniform(0, 7));
        break;
      case 1:  // one byte replaced
        if (size > 0) b[random.uniform(0, size - 1)] = static_cast<uint8_t>(random.uniform(0, 255));
        break;
      case 2:  // cut short
        b.resize(static_cast<size_t>(random.uniform(0, size)));
        break;
      case 3:  // bytes appended
        for (int k = random.uniform(1, 8); k > 0; --k)
          b.push_back(static_cast<uint8_t>(random.uniform(0, 255)));
        break;
      case 4:  // one byte removed
        if (size > 0) b.erase(b.begin() + random.uniform(0, size - 1));
        break;
      default:  // the InfoBits of one byte changed: the chains are where the decoder branches
        if (size > 0) {
          uint8_t& byte = b[random.uniform(0, size - 1)];
          byte = static_cast<uint8_t>((byte & ~3u) | static_cast<unsigned>(random.uniform(0, 3)));
        }
        break;
    }
  }
}

int export_payloads(const char* corpus_dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(corpus_dir)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  std::cout << "{\"corpus\":[";
  for (size_t i = 0; i < files.size(); ++i) {
    std::ifstream in(files[i], std::ios::binary);
    const Bytes bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::cout << (i ? ",\n" : "") << decode_record(bytes);
  }
  pfap::testing::RandomMarkup random(17);
  const auto section = [&](const char* name, int count, auto make) {
    std::cout << "],\n\"" << name << "\":[";
    for (int i = 0; i < count; ++i) std::cout << (i ? ",\n" : "") << decode_record(make());
  };
  section("valid", 15000, [&] { return encode(random_packet(random)); });
  section("mutated", 15000, [&] {
    Bytes b = encode(random_packet(random));
    mutate(b, random);
    return b;
  });
  section("arbitrary", 5000, [&] {
    Bytes b(static_cast<size_t>(random.uniform(0, 40)));
    for (uint8_t& byte : b) byte = static_cast<uint8_t>(random.uniform(0, 255));
    return b;
  });
  std::cout << "]}\n";
  return 0;
}

int export_decode() {
  std::cin >> std::noskipws;
  const Bytes all((std::istreambuf_iterator<char>(std::cin)), std::istreambuf_iterator<char>());
  std::cout << "[";
  for (size_t pos = 0, n = 0; pos + 4 <= all.size(); ++n) {
    const size_t size = size_t{all[pos]} << 24 | size_t{all[pos + 1]} << 16 |
                        size_t{all[pos + 2]} << 8 | all[pos + 3];
    pos += 4;
    if (size > all.size() - pos) return 1;
    std::cout << (n ? ",\n" : "")
              << decode_record(Bytes(all.begin() + pos, all.begin() + pos + size));
    pos += size;
  }
  std::cout << "]\n";
  return 0;
}

// RTP headers of every shape, well formed and not, and what GStreamer reads in them.
int export_rtp() {
  gst_init(nullptr, nullptr);
  std::mt19937 rng(3550);
  const auto uniform = [&](int lo, int hi) {
    return std::uniform_int_distribution<int>(lo, hi)(rng);
  };
  std::cout << "[";
  for (int i = 0; i < 20000; ++i) {
    // Mostly near-valid headers: version 2, CSRCs, extensions and padding of random sizes.
    Bytes b(static_cast<size_t>(uniform(0, 11) == 0 ? uniform(0, 16) : uniform(12, 60)));
    for (uint8_t& byte : b) byte = static_cast<uint8_t>(uniform(0, 255));
    if (!b.empty() && uniform(0, 7) != 0) b[0] = static_cast<uint8_t>((b[0] & 0x3F) | 0x80);
    if (!b.empty() && uniform(0, 1)) b[0] &= static_cast<uint8_t>(uniform(0, 1) ? 0xF0 : 0xF3);
    if (b.size() >= 16 && (b[0] & 0x10) && uniform(0, 1)) {
      const size_t at = 12 + 4u * (b[0] & 0x0F);  // a short extension length, often in bounds
      if (at + 4 <= b.size()) {
        b[at + 2] = 0;
        b[at + 3] = static_cast<uint8_t>(uniform(0, 6));
      }
    }
    if (!b.empty() && (b[0] & 0x20) && uniform(0, 1))
      b.back() = static_cast<uint8_t>(uniform(0, 8));

    GstBuffer* buffer = b.empty() ? gst_buffer_new() : gst_buffer_new_memdup(b.data(), b.size());
    GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
    std::cout << (i ? ",\n" : "") << "{\"bytes\":\"" << hex(b.data(), b.size()) << "\",\"rtp\":";
    if (gst_rtp_buffer_map(buffer, GST_MAP_READ, &rtp)) {
      const guint8* payload = static_cast<const guint8*>(gst_rtp_buffer_get_payload(&rtp));
      std::cout << "{\"marker\":" << (gst_rtp_buffer_get_marker(&rtp) ? "true" : "false")
                << ",\"payloadType\":" << int{gst_rtp_buffer_get_payload_type(&rtp)}
                << ",\"sequenceNumber\":" << gst_rtp_buffer_get_seq(&rtp)
                << ",\"timestamp\":" << gst_rtp_buffer_get_timestamp(&rtp)
                << ",\"ssrc\":" << gst_rtp_buffer_get_ssrc(&rtp) << ",\"payload\":\""
                << hex(payload, gst_rtp_buffer_get_payload_len(&rtp)) << "\"}";
      gst_rtp_buffer_unmap(&rtp);
    } else {
      std::cout << "null";
    }
    std::cout << "}";
    gst_buffer_unref(buffer);
  }
  std::cout << "]\n";
  return 0;
}

// Seeded bookmarks on a few FAPs, each followed by samples at and around the times where the
// curves change: start, half, end, a nanosecond either side, and random times.
int export_curves() {
  pfap::testing::RandomMarkup random(2001);
  std::cout << "[";
  for (int run = 0; run < 200; ++run) {
    pfap::FapState state;
    int64_t t = 0;
    std::cout << (run ? ",\n" : "") << "[";
    for (int step = 0; step < 40; ++step) {
      Fap f = random.fap();
      f.index = static_cast<uint8_t>(random.uniform(3, 5));  // the same FAPs, again and again
      if (random.chance(0.5)) f.amplitude = random.uniform(-1000, 1000);
      if (random.chance(0.7)) f.transition_ms = static_cast<uint16_t>(random.uniform(0, 700));
      if (!random.chance(0.15))
        t += int64_t{random.uniform(0, 600)} * 1'000'000 + random.uniform(0, 999'999);
      state.apply(f, t);
      std::cout << (step ? "," : "") << "{\"apply\":" << fap_json(f) << ",\"startNs\":" << t
                << ",\"samples\":[";
      const int64_t d = int64_t{f.transition_ms} * 1'000'000;
      const int64_t times[] = {t - 1,
                               t,
                               t + 1,
                               t + d / 4,
                               t + d / 2 - 1,
                               t + d / 2,
                               t + d / 2 + 1,
                               t + d - 1,
                               t + d,
                               t + d + 1,
                               t + random.uniform(0, 900'000'000)};
      bool first = true;
      for (int64_t at : times) {
        for (int index = 3; index <= 5; ++index) {
          const Fap e = state.recovery_entry(index, std::max(at, t));
          std::cout << (first ? "" : ",") << "{\"index\":" << index << ",\"timeNs\":" << at
                    << ",\"amplitude\":" << number(state.amplitude(index, at))
                    << ",\"settled\":" << state.settled(index)
                    << ",\"atRest\":" << (state.at_rest(index, at) ? "true" : "false")
                    << ",\"recoveryEntry\":" << fap_json(e) << "}";
          first = false;
        }
      }
      std::cout << "]}";
    }
    std::cout << "]";
  }
  std::cout << "]\n";
  return 0;
}

std::string values_json(const pfap::face::FapValues& f) {
  std::string out = "[";
  for (size_t i = 0; i < f.size(); ++i) out += (i ? "," : "") + number(f[i]);
  return out + "]";
}

// Seeded events for the animator: phonemes of x-pfap-arpabet and unknown symbols, with FAPs,
// recovered and complete states, and the FAP values it gives at times in between.
int export_animator() {
  pfap::testing::RandomMarkup random(1848);
  std::cout << "[";
  for (int run = 0; run < 20; ++run) {
    pfap::face::Animator animator;
    animator.set_alphabet(run % 4 == 3 ? nullptr : pfap::find_alphabet(pfap::kArpabetAlphabet));
    int64_t t = int64_t{random.uniform(0, 1000)} * 1'000'000;
    std::cout << (run ? ",\n" : "")
              << "{\"alphabet\":" << (run % 4 == 3 ? "null" : "\"x-pfap-arpabet\"")
              << ",\"steps\":[";
    for (int step = 0; step < 30; ++step) {
      pfap::MarkupEvent event;
      const int kind = random.uniform(0, 9);
      event.kind = kind == 0   ? PFAP_EVENT_COMPLETE
                   : kind == 1 ? PFAP_EVENT_RECOVERED
                               : PFAP_EVENT_PHONEME;
      event.phoneme.symbol = static_cast<uint8_t>(random.chance(0.1) ? random.uniform(40, 255)
                                                                     : random.uniform(0, 39));
      event.phoneme.duration_ms = static_cast<uint16_t>(
          random.chance(0.1) ? random.uniform(0, 3) : random.uniform(30, 250));
      for (int n = random.chance(0.6) ? 0 : random.uniform(1, 3); n > 0; --n) {
        Fap f = random.fap();
        f.index = static_cast<uint8_t>(random.chance(0.3) ? random.uniform(69, 74)
                                                          : random.uniform(3, 60));
        f.amplitude = random.uniform(-300, 300);
        f.transition_ms = static_cast<uint16_t>(random.uniform(0, 800));
        event.faps.push_back(f);
      }
      // Sometimes an event earlier than the last, which the animator takes as the last.
      const int64_t at = t - (random.chance(0.05) ? 5'000'000 : 0);
      const bool known = animator.apply(event, at);
      const char* kind_name = event.kind == PFAP_EVENT_PHONEME     ? "phoneme"
                              : event.kind == PFAP_EVENT_RECOVERED ? "recovered"
                                                                   : "complete";
      std::cout << (step ? "," : "") << "{\"kind\":\"" << kind_name
                << "\",\"symbol\":" << int{event.phoneme.symbol}
                << ",\"duration\":" << event.phoneme.duration_ms
                << ",\"faps\":" << faps_json(event.faps) << ",\"timeNs\":" << at
                << ",\"known\":" << (known ? "true" : "false") << ",\"endNs\":" << animator.end_ns()
                << ",\"samples\":[";
      const int64_t next = t + int64_t{event.phoneme.duration_ms} * 1'000'000 +
                           (random.chance(0.2) ? int64_t{random.uniform(0, 400)} * 1'000'000 : 0);
      for (int k = 0; k < 4; ++k) {
        const int64_t s = t + (next - t) * k / 4 + (k == 3 ? 200'000'000 : 0);
        std::cout << (k ? "," : "") << "{\"timeNs\":" << s
                  << ",\"faps\":" << values_json(animator.faps(s)) << ",\"describe\":\""
                  << animator.describe(s) << "\"}";
      }
      std::cout << "]}";
      t = next;
    }
    std::cout << "]}";
  }
  std::cout << "]\n";
  return 0;
}

int export_alphabet() {
  const pfap::PhonemeAlphabet* alphabet = pfap::find_alphabet(pfap::kArpabetAlphabet);
  std::cout << "[";
  for (int symbol = 0; symbol < 256; ++symbol) {
    const pfap::PhonemeInfo* info = pfap::find_phoneme(*alphabet, static_cast<uint8_t>(symbol));
    std::cout << (symbol ? "," : "");
    if (info == nullptr) {
      std::cout << "null";
    } else {
      std::cout << "{\"name\":\"" << info->name
                << "\",\"viseme\":" << static_cast<int>(info->viseme) << "}";
    }
  }
  std::cout << "]\n";
  return 0;
}

// The seeded speech sessions of speech_session.h, packetized and sent with dynamic recovery
// (and complete states in some), lost at seeded places, received by RecoveryReceiver.
int export_recovery() {
  struct Setup {
    uint32_t seed;
    unsigned depth;
    int complete_every;  // packets; 0: only the first
    double loss;
    int max_run;  // longest loss in a row; larger than the depth leaves the state uncertain
  };
  const Setup setups[] = {{1, 1, 0, 0.05, 1},   {2, 4, 0, 0.10, 4},   {3, 7, 40, 0.20, 7},
                          {4, 15, 0, 0.20, 15}, {5, 4, 25, 0.15, 9},  {6, 0, 30, 0.05, 3},
                          {7, 2, 0, 0.30, 6},   {8, 40, 50, 0.25, 20}};
  std::cout << "[";
  bool first_setup = true;
  for (const Setup& s : setups) {
    const auto session = pfap::testing::speech_session(s.seed, 600, 0.4);
    pfap::Packetizer packetizer({.max_payload_size = 200, .max_delay_ns = 150'000'000});
    std::vector<pfap::PlannedPacket> planned;
    for (const auto& p : session) {
      packetizer.push({p.start_ns, p.phoneme, p.sentence_start}, p.faps, planned);
    }
    packetizer.drain(planned);

    pfap::RecoverySender sender(s.depth);
    pfap::RecoveryReceiver receiver;
    std::mt19937 rng(s.seed * 7919);
    std::bernoulli_distribution drop(s.loss);
    std::bernoulli_distribution unknown_loss(0.01);
    uint16_t seqnum = static_cast<uint16_t>(65536 - 100 - s.seed);  // wraps mid-session
    int run = 0;
    std::cout << (first_setup ? "" : ",\n") << "{\"seed\":" << s.seed << ",\"depth\":" << s.depth
              << ",\"packets\":[";
    first_setup = false;
    bool first_packet = true;
    const auto send = [&](const Packet& packet, int64_t time_ns) {
      sender.sent(packet, time_ns);
      const uint16_t seq = seqnum++;
      const bool lost = !first_packet && run < s.max_run && drop(rng);
      run = lost ? run + 1 : 0;
      if (lost) return;
      const bool unknown = !first_packet && unknown_loss(rng);
      if (unknown) receiver.lost_unknown();
      // The settled state after each phoneme: the packet cut after it, received by a copy.
      std::vector<std::string> phoneme_states;
      for (size_t i = 0; i < packet.phonemes.size(); ++i) {
        pfap::RecoveryReceiver copy = receiver;
        Packet cut = packet;
        cut.phonemes.resize(i + 1);
        cut.faps.resize(cut.phonemes.back().fap_end);
        copy.receive(cut, seq, time_ns);
        std::string settled = "[";
        for (int f = pfap::kMinFapIndex; f <= pfap::kMaxFapIndex; ++f) {
          settled += (f > pfap::kMinFapIndex ? "," : "") + std::to_string(copy.state().settled(f));
        }
        phoneme_states.push_back(settled + "]");
      }
      const pfap::ReceiveResult r = receiver.receive(packet, seq, time_ns);
      const Bytes bytes = encode(packet);
      const char* recovery = r.recovery == pfap::ReceiveResult::Recovery::kNone        ? "none"
                             : r.recovery == pfap::ReceiveResult::Recovery::kRecovered ? "recovered"
                                                                                       : "complete";
      std::cout << (first_packet ? "" : ",\n") << "{\"sequenceNumber\":" << seq
                << ",\"timeNs\":" << time_ns
                << ",\"lostUnknownBefore\":" << (unknown ? "true" : "false") << ",\"payload\":\""
                << hex(bytes.data(), bytes.size()) << "\",\"result\":{\"recovery\":\"" << recovery
                << "\",\"changed\":" << (r.changed ? "true" : "false")
                << ",\"stateWhole\":" << (r.state_whole ? "true" : "false")
                << ",\"requestComplete\":" << (r.request_complete ? "true" : "false")
                << ",\"lost\":" << r.lost << "},\"settled\":[";
      for (int f = pfap::kMinFapIndex; f <= pfap::kMaxFapIndex; ++f) {
        std::cout << (f > pfap::kMinFapIndex ? "," : "") << receiver.state().settled(f);
      }
      // Amplitudes at each phoneme's start and halfway through it, on the FAPs the sessions use.
      std::cout << "],\"phonemeSettled\":[";
      for (size_t i = 0; i < phoneme_states.size(); ++i)
        std::cout << (i ? "," : "") << phoneme_states[i];
      std::cout << "],\"amplitudes\":[";
      int64_t start = time_ns;
      bool first_sample = true;
      for (const auto& ph : packet.phonemes) {
        for (const int64_t at : {start, start + ph.phoneme.duration_ms * int64_t{500'000}}) {
          for (int f : {3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 69, 70, 71, 72, 73, 74}) {
            std::cout << (first_sample ? "" : ",") << "[" << f << "," << at << ","
                      << number(receiver.state().amplitude(f, at)) << "]";
            first_sample = false;
          }
        }
        start += ph.phoneme.duration_ms * int64_t{1'000'000};
      }
      std::cout << "]}";
      first_packet = false;
    };
    for (size_t i = 0; i < planned.size(); ++i) {
      if (i == 0 || (s.complete_every > 0 && i % static_cast<size_t>(s.complete_every) == 0)) {
        Packet complete;
        if (sender.make_complete(complete, planned[i].start_ns, 1388))
          send(complete, planned[i].start_ns);
      }
      Packet packet = planned[i].packet;
      sender.add_dynamic(packet, planned[i].start_ns, 1388 - pfap::encoded_size(packet));
      send(packet, planned[i].start_ns);
    }
    std::cout << "]}";
  }
  std::cout << "]\n";
  return 0;
}

// Face states: the neutral face, every viseme, every expression, the head turned, the eyes,
// the brows and the cheeks; each drawn in both styles.
int export_render(const char* dir) {
  std::vector<std::pair<std::string, pfap::face::FapValues>> states;
  const auto state = [&](std::string name, std::initializer_list<std::pair<int, double>> faps) {
    pfap::face::FapValues f{};
    for (const auto& [index, amplitude] : faps) f[index] = amplitude;
    states.emplace_back(std::move(name), f);
  };
  state("neutral", {});
  for (int v = 1; v <= 14; ++v) {
    pfap::face::FapValues f{};
    const pfap::VisemeMouth m = pfap::viseme_mouth(static_cast<pfap::Viseme>(v));
    f[3] = m.open_jaw;
    f[4] = m.lower_t_midlip;
    f[5] = m.raise_b_midlip;
    f[6] = f[7] = m.stretch_corner;
    f[12] = f[13] = m.raise_corner;
    f[16] = f[17] = m.push_lip;
    states.emplace_back("viseme" + std::to_string(v), f);
  }
  for (int e = 1; e <= 6; ++e) {
    pfap::face::FapValues f{};
    f[68 + e] = 63;
    states.emplace_back("expression" + std::to_string(e), f);
  }
  state("turn", {{49, 30000}, {3, 200}});
  state("tilt", {{50, -12000}, {69, 40}});
  state("nod", {{48, 15000}});
  state("blink", {{19, 1024}, {20, 1024}, {21, 200}, {22, 200}});
  state("gaze", {{23, 30000}, {24, 30000}, {25, -20000}, {26, -20000}});
  state("brows", {{31, 200}, {32, -150}, {33, 120}, {34, 120}, {35, -90}, {36, 200}, {37, 100}});
  state("cheeks", {{39, 400}, {40, 250}, {41, 100}, {42, 300}});
  state("jaw", {{3, 300}, {14, 200}, {15, -150}, {18, 100}, {51, -50}, {52, 80}});

  std::cout << "[";
  for (size_t i = 0; i < states.size(); ++i) {
    pfap::face::FapValues f = states[i].second;
    pfap::face::add_expressions(f);
    const pfap::face::FacePose pose = pfap::face::pose_from_faps(f);
    std::cout << (i ? ",\n" : "") << "{\"name\":\"" << states[i].first
              << "\",\"faps\":" << values_json(states[i].second)
              << ",\"pose\":{\"roll\":" << number(pose.roll) << ",\"outline\":[";
    for (size_t k = 0; k < pose.outline.size(); ++k) {
      std::cout << (k ? "," : "") << number(pose.outline[k].x) << "," << number(pose.outline[k].y);
    }
    std::cout << "],\"outerLips\":[";
    for (size_t k = 0; k < 8; ++k) {
      std::cout << (k ? "," : "") << number(pose.outer_lips[k].x) << ","
                << number(pose.outer_lips[k].y);
    }
    std::cout << "],\"innerLips\":[";
    for (size_t k = 0; k < 8; ++k) {
      std::cout << (k ? "," : "") << number(pose.inner_lips[k].x) << ","
                << number(pose.inner_lips[k].y);
    }
    std::cout << "],\"eyes\":[";
    for (size_t k = 0; k < 2; ++k) {
      const pfap::face::Eye& e = pose.eyes[k];
      std::cout << (k ? "," : "") << number(e.center.x) << "," << number(e.center.y) << ","
                << number(e.half_width) << "," << number(e.upper_lid) << "," << number(e.lower_lid)
                << "," << number(e.pupil.x) << "," << number(e.pupil.y);
    }
    std::cout << "]}}";
    for (const auto& [style, style_name] : {std::pair{pfap::face::Style::kCartoon, "cartoon"},
                                            std::pair{pfap::face::Style::kLine, "line"}}) {
      constexpr int kWidth = 320, kHeight = 240;
      std::vector<uint8_t> pixels(4 * kWidth * kHeight);
      pfap::face::render(pose, style, "", {pixels.data(), kWidth, kHeight, 4 * kWidth, false});
      std::ofstream out(std::filesystem::path(dir) / (states[i].first + "-" + style_name + ".bgrx"),
                        std::ios::binary);
      out.write(reinterpret_cast<const char*>(pixels.data()),
                static_cast<std::streamsize>(pixels.size()));
    }
  }
  std::cout << "]\n";
  return 0;
}

// Amplitudes for pfap::expression_weight: every integer from -2 to 66, fractions and the
// nearest doubles at the ends of 0..63, the ends of the wire's range, and seeded random
// amplitudes in and around 0..63.
int export_expressions() {
  std::vector<double> amplitudes;
  for (int a = -2; a <= 66; ++a) amplitudes.push_back(a);
  for (const double a : {0.5, 1.0 / 3, 31.5, 62.5, 63.5}) amplitudes.push_back(a);
  for (const double end : {0.0, 63.0}) {
    amplitudes.push_back(std::nextafter(end, -1.0));
    amplitudes.push_back(std::nextafter(end, 64.0));
  }
  amplitudes.push_back(-pfap::kMaxAmplitude);
  amplitudes.push_back(pfap::kMaxAmplitude);
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> around(-20, 90);
  for (int i = 0; i < 1000; ++i) amplitudes.push_back(around(rng));

  std::cout << "[";
  for (size_t i = 0; i < amplitudes.size(); ++i) {
    std::cout << (i ? ",\n" : "") << "{\"amplitude\":" << number(amplitudes[i])
              << ",\"weight\":" << number(pfap::expression_weight(amplitudes[i])) << "}";
  }
  std::cout << "]\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "payloads" && argc == 3) return export_payloads(argv[2]);
  if (mode == "decode" && argc == 2) return export_decode();
  if (mode == "rtp" && argc == 2) return export_rtp();
  if (mode == "curves" && argc == 2) return export_curves();
  if (mode == "animator" && argc == 2) return export_animator();
  if (mode == "alphabet" && argc == 2) return export_alphabet();
  if (mode == "recovery" && argc == 2) return export_recovery();
  if (mode == "render" && argc == 3) return export_render(argv[2]);
  if (mode == "expressions" && argc == 2) return export_expressions();
  std::fprintf(
      stderr,
      "usage: export_vectors payloads CORPUS_DIR | decode | rtp | curves | animator | alphabet | "
      "recovery | render DIR | expressions\n");
  return 2;
}

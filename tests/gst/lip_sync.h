// SPDX-License-Identifier: LGPL-2.1-or-later
// Lip sync of audio and PFAP through a sending and a receiving rtpbin: what the sender sent and
// when, what the receiver output and when, and the comparison of the two streams' offsets
// (receiver minus sender running time). Used by LoopbackUdp.PhonemesKeepLipSyncWithAudio
// (test_pipeline.cc, which explains the measurement) and PfapTtsLoopback (test_pfaptts.cc).
#pragma once

#include <gst/gst.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "pad_time.h"
#include "pfap_buffers.h"

namespace pfap::testing {

constexpr size_t kAudioKeyBytes = 8;  // 4 samples identify a position (when unique)

// The running time of a sample's buffer in its segment.
inline GstClockTime running_time(GstSample* sample) {
  const GstSegment* segment = gst_sample_get_segment(sample);
  GstBuffer* buffer = gst_sample_get_buffer(sample);
  return gst_segment_to_running_time(segment, GST_FORMAT_TIME, GST_BUFFER_PTS(buffer));
}

// The audio a sender sent, recorded at its audio payloader's sink pad (record_sent_audio).
struct SentAudio {
  explicit SentAudio(int rate) : rate(rate) {}
  const int rate;
  std::mutex mutex;
  std::vector<uint8_t> bytes;  // every sample sent, S16BE mono, in order
  struct Chunk {
    size_t first_sample;
    GstClockTime running_time;
  };
  std::vector<Chunk> chunks;  // where each sent buffer starts

  // The sender running time of sample j.
  GstClockTime time_of(size_t j) const {
    auto it = std::upper_bound(chunks.begin(), chunks.end(), j,
                               [](size_t v, const Chunk& c) { return v < c.first_sample; });
    const Chunk& c = *(it - 1);
    return c.running_time + gst_util_uint64_scale_round(j - c.first_sample, GST_SECOND, rate);
  }
};

inline GstPadProbeReturn record_sent_audio(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
  auto* sent = static_cast<SentAudio*>(data);
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  const GstClockTime rt = running_time_of(pad, buffer);
  if (!GST_CLOCK_TIME_IS_VALID(rt)) return GST_PAD_PROBE_OK;
  GstMapInfo map;
  gst_buffer_map(buffer, &map, GST_MAP_READ);
  {
    std::lock_guard lock(sent->mutex);
    sent->chunks.push_back({sent->bytes.size() / 2, rt});
    sent->bytes.insert(sent->bytes.end(), map.data, map.data + map.size);
  }
  gst_buffer_unmap(buffer, &map);
  return GST_PAD_PROBE_OK;
}

struct Received {
  std::mutex mutex;
  std::condition_variable changed;
  std::atomic<int> syncs[2] = {0, 0};  // handle-sync calls per session (0 audio, 1 PFAP)

  struct Audio {
    GstClockTime running_time;
    std::vector<uint8_t> bytes;
  };
  std::vector<Audio> audio;
  struct Phoneme {
    Event event;
    GstClockTime running_time;
    int syncs;  // the fewer of the two sessions' sync counts when it arrived
  };
  std::vector<Phoneme> phonemes;
  std::vector<std::string> link_errors;
};

inline GstFlowReturn on_audio(GstElement* sink, gpointer data) {
  auto* r = static_cast<Received*>(data);
  GstSample* sample = nullptr;
  g_signal_emit_by_name(sink, "pull-sample", &sample);
  if (sample == nullptr) return GST_FLOW_EOS;
  GstMapInfo map;
  GstBuffer* buffer = gst_sample_get_buffer(sample);
  gst_buffer_map(buffer, &map, GST_MAP_READ);
  Received::Audio a{running_time(sample), std::vector<uint8_t>(map.data, map.data + map.size)};
  gst_buffer_unmap(buffer, &map);
  gst_sample_unref(sample);
  {
    std::lock_guard lock(r->mutex);
    r->audio.push_back(std::move(a));
  }
  r->changed.notify_all();
  return GST_FLOW_OK;
}

inline GstFlowReturn on_phoneme(GstElement* sink, gpointer data) {
  auto* r = static_cast<Received*>(data);
  GstSample* sample = nullptr;
  g_signal_emit_by_name(sink, "pull-sample", &sample);
  if (sample == nullptr) return GST_FLOW_EOS;
  const int syncs = std::min(r->syncs[0].load(), r->syncs[1].load());
  Received::Phoneme p{pfap::testing::read_event(gst_sample_get_buffer(sample)),
                      running_time(sample), syncs};
  gst_sample_unref(sample);
  {
    std::lock_guard lock(r->mutex);
    r->phonemes.push_back(std::move(p));
  }
  r->changed.notify_all();
  return GST_FLOW_OK;
}

inline void on_handle_sync(GstElement*, GstStructure*, gpointer data) {
  static_cast<std::atomic<int>*>(data)->fetch_add(1);
}

inline void on_new_jitterbuffer(GstElement*, GstElement* jitterbuffer, guint session, guint,
                                gpointer data) {
  auto* r = static_cast<Received*>(data);
  if (session > 1) return;
  // After rtpbin's own handler, which applies the sync.
  g_signal_connect_after(jitterbuffer, "handle-sync", G_CALLBACK(on_handle_sync),
                         &r->syncs[session]);
}

struct ReceiverLinks {
  GstElement* audio_depay;
  GstElement* pfap_depay;
  Received* received;
};

inline void on_rtpbin_pad(GstElement*, GstPad* pad, gpointer data) {
  auto* links = static_cast<ReceiverLinks*>(data);
  gchar* name = gst_pad_get_name(pad);
  const std::string pad_name = name;
  g_free(name);
  GstElement* depay = nullptr;
  if (pad_name.rfind("recv_rtp_src_0_", 0) == 0) depay = links->audio_depay;
  if (pad_name.rfind("recv_rtp_src_1_", 0) == 0) depay = links->pfap_depay;
  if (depay == nullptr) return;
  GstPad* sink = gst_element_get_static_pad(depay, "sink");
  const GstPadLinkReturn ret = gst_pad_link(pad, sink);
  gst_object_unref(sink);
  if (ret != GST_PAD_LINK_OK) {
    std::lock_guard lock(links->received->mutex);
    links->received->link_errors.push_back("cannot link " + pad_name + ": " +
                                           gst_pad_link_get_name(ret));
  }
}

struct AudioOffset {
  GstClockTime sent;        // sender running time of the buffer's first sample
  GstClockTimeDiff offset;  // receiver running time - sender running time
};

// The offsets of the received audio buffers found again in the sent audio by their bytes,
// ordered by sent time. A buffer whose first kAudioKeyBytes occur more than once in the sent
// audio (silence) is not found; `unmatched` counts those.
inline std::vector<AudioOffset> audio_offsets(const SentAudio& sent, const Received& received,
                                              size_t& unmatched) {
  std::unordered_map<uint64_t, int64_t> positions;  // -1: key not unique
  const std::vector<uint8_t>& bytes = sent.bytes;
  for (size_t j = 0; j + kAudioKeyBytes / 2 <= bytes.size() / 2; ++j) {
    uint64_t key;
    std::memcpy(&key, &bytes[2 * j], sizeof key);
    auto [it, fresh] = positions.emplace(key, static_cast<int64_t>(j));
    if (!fresh) it->second = -1;
  }
  std::vector<AudioOffset> offsets;
  unmatched = 0;
  for (const Received::Audio& a : received.audio) {
    if (a.bytes.size() < kAudioKeyBytes || !GST_CLOCK_TIME_IS_VALID(a.running_time)) continue;
    uint64_t key;
    std::memcpy(&key, a.bytes.data(), sizeof key);
    auto it = positions.find(key);
    const bool found = it != positions.end() && it->second >= 0 &&
                       2 * static_cast<size_t>(it->second) + a.bytes.size() <= bytes.size() &&
                       std::memcmp(&bytes[2 * it->second], a.bytes.data(), a.bytes.size()) == 0;
    if (!found) {
      ++unmatched;
      continue;
    }
    const GstClockTime t = sent.time_of(static_cast<size_t>(it->second));
    offsets.push_back({t, GST_CLOCK_DIFF(t, a.running_time)});
  }
  std::sort(offsets.begin(), offsets.end(),
            [](const AudioOffset& a, const AudioOffset& b) { return a.sent < b.sent; });
  return offsets;
}

struct LipSync {
  int compared = 0;          // phonemes after sync with audio sent within 50 ms before them
  int out_of_tolerance = 0;  // of those, how many differ from the audio by more than tolerance
  GstClockTimeDiff worst = 0;
  std::string table;  // per phoneme: index, sent ms, offsets, difference, syncs
};

// Phoneme by phoneme (received[i] was sent at sent_times[i]): its offset against the offset of
// the audio sent at the same time. Phonemes before both sessions had two syncs do not count.
inline LipSync compare_offsets(const std::vector<AudioOffset>& audio,
                               const std::vector<GstClockTime>& sent_times,
                               const std::vector<Received::Phoneme>& received,
                               GstClockTime tolerance) {
  LipSync r;
  std::ostringstream table;
  table << "index  sent_ms  offset_pfap_us  offset_audio_us  diff_us  syncs\n";
  for (size_t i = 0; i < std::min(sent_times.size(), received.size()); ++i) {
    const Received::Phoneme& p = received[i];
    const GstClockTime t = sent_times[i];
    auto it = std::upper_bound(audio.begin(), audio.end(), t,
                               [](GstClockTime v, const AudioOffset& a) { return v < a.sent; });
    if (it == audio.begin()) continue;
    const AudioOffset& a = *(it - 1);
    if (t - a.sent > 50 * GST_MSECOND) continue;  // no audio received around T
    const GstClockTimeDiff offset_p = GST_CLOCK_DIFF(t, p.running_time);
    const GstClockTimeDiff diff = offset_p - a.offset;
    table << i << "  " << t / GST_MSECOND << "  " << offset_p / 1000 << "  " << a.offset / 1000
          << "  " << diff / 1000 << "  " << p.syncs << "\n";
    if (p.syncs < 2) continue;
    ++r.compared;
    if (std::abs(diff) > static_cast<GstClockTimeDiff>(tolerance)) ++r.out_of_tolerance;
    if (std::abs(diff) > std::abs(r.worst)) r.worst = diff;
  }
  r.table = table.str();
  return r;
}

}  // namespace pfap::testing

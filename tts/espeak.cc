// SPDX-License-Identifier: LGPL-2.1-or-later
#include "espeak.h"

#include <espeak-ng/speak_lib.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <functional>
#include <mutex>
#include <type_traits>

namespace pfap::tts {
namespace {

// espeak-ng 1.51 carries state from one synthesis to the next that no call of its API resets:
// its wave generator's pitch flutter phase and roughness cycle count are function-level statics
// (wavegen.c: Flutter_ix in AdvanceParameters, cycle_count in Wavegen). The same text spoken
// twice in one process gave other audio (up to 12 ms longer or shorter, every sample
// different) and alignments that differed by up to 300 ms (issue 31). So this process only
// starts espeak-ng, and each call runs in a child forked from it, whose espeak-ng has never
// spoken: it does its work once, sends the answer over a pipe and exits.
std::mutex espeak_mutex;  // held while espeak-ng starts and while a child is forked
bool initialized = false;
int espeak_rate = 0;  // espeak_Initialize's answer; <= 0 when it failed

// The synthesis in progress, in the child.
struct Call {
  Synthesis* out = nullptr;
  size_t sentences = 0;  // sentence events so far
};
Call current;

size_t sentence_now() { return current.sentences > 0 ? current.sentences - 1 : 0; }

// espeak-ng hands over audio and the events up to it, in order.
int on_synth(short* wav, int n_samples, espeak_EVENT* events) {
  Synthesis& s = *current.out;
  for (espeak_EVENT* e = events; e != nullptr && e->type != espeakEVENT_LIST_TERMINATED; ++e) {
    switch (e->type) {
      case espeakEVENT_SAMPLERATE:
        s.sample_rate = static_cast<unsigned>(e->id.number);
        break;
      case espeakEVENT_SENTENCE:
        ++current.sentences;
        break;
      case espeakEVENT_WORD:
        // text_position counts code points from 1.
        s.words.push_back({static_cast<size_t>(std::max(e->text_position - 1, 0)), sentence_now(),
                           s.phonemes.size(), s.phonemes.size()});
        break;
      case espeakEVENT_PHONEME:
        s.phonemes.push_back({std::string(e->id.string, strnlen(e->id.string, sizeof e->id.string)),
                              static_cast<size_t>(std::max(e->sample, 0)), sentence_now()});
        break;
      default:
        break;
    }
  }
  if (wav != nullptr && n_samples > 0) s.samples.insert(s.samples.end(), wav, wav + n_samples);
  return 0;  // go on (the parent stops the child by killing it)
}

// A word's phonemes run to the next word's, without the pauses that end a clause.
void close_words(Synthesis& s) {
  for (size_t i = 0; i < s.words.size(); ++i) {
    Synthesis::Word& w = s.words[i];
    size_t end = i + 1 < s.words.size() ? s.words[i + 1].first_phoneme : s.phonemes.size();
    while (end > w.first_phoneme && s.phonemes[end - 1].mnemonic.starts_with('_')) --end;
    w.end_phoneme = end;
  }
}

bool set_voice(const VoiceSettings& settings, std::string& error) {
  if (espeak_SetVoiceByName(settings.voice.c_str()) != EE_OK) {
    error = "espeak-ng has no voice \"" + settings.voice + "\"";
    return false;
  }
  espeak_SetParameter(espeakRATE, settings.rate, 0);
  espeak_SetParameter(espeakPITCH, settings.pitch, 0);
  espeak_SetParameter(espeakVOLUME, settings.volume, 0);
  return true;
}

// Under espeak_mutex.
bool start(std::string& error) {
  if (!initialized) {
    initialized = true;
    espeak_rate = espeak_Initialize(AUDIO_OUTPUT_SYNCHRONOUS, 0, nullptr,
                                    espeakINITIALIZE_PHONEME_EVENTS | espeakINITIALIZE_DONT_EXIT);
    if (espeak_rate > 0) espeak_SetSynthCallback(on_synth);
  }
  if (espeak_rate <= 0) {
    error = "espeak-ng could not start (its data not installed?)";
    return false;
  }
  return true;
}

// The child's answer, as bytes: an error (empty when none), then what the call gives.
struct Writer {
  std::string bytes;
  template <typename T>
  requires std::is_trivially_copyable_v<T>
  void put(const T& v) { bytes.append(reinterpret_cast<const char*>(&v), sizeof v); }
  void put(std::string_view text) {
    put(uint64_t{text.size()});
    bytes.append(text);
  }
};

struct Reader {
  std::string_view rest;
  bool whole = true;  // false once something was cut short
  template <typename T>
  requires std::is_trivially_copyable_v<T>
  void get(T& v) {
    if (rest.size() < sizeof v) {
      whole = false;
      return;
    }
    std::memcpy(&v, rest.data(), sizeof v);
    rest.remove_prefix(sizeof v);
  }
  void get(std::string& text) {
    uint64_t n = 0;
    get(n);
    if (!whole || rest.size() < n) {
      whole = false;
      return;
    }
    text.assign(rest.substr(0, n));
    rest.remove_prefix(n);
  }
};

void put(Writer& w, const Synthesis& s) {
  w.put(s.sample_rate);
  w.put(std::string_view(reinterpret_cast<const char*>(s.samples.data()),
                         s.samples.size() * sizeof(int16_t)));
  w.put(uint64_t{s.phonemes.size()});
  for (const Synthesis::Phoneme& p : s.phonemes) {
    w.put(p.mnemonic);
    w.put(p.sample);
    w.put(p.sentence);
  }
  w.put(uint64_t{s.words.size()});
  for (const Synthesis::Word& word : s.words) w.put(word);
  w.put(s.transcription);
}

void get(Reader& r, Synthesis& s) {
  r.get(s.sample_rate);
  std::string samples;
  r.get(samples);
  s.samples.resize(samples.size() / sizeof(int16_t));
  std::memcpy(s.samples.data(), samples.data(), s.samples.size() * sizeof(int16_t));
  uint64_t n = 0;
  r.get(n);
  for (uint64_t i = 0; i < n && r.whole; ++i) {
    Synthesis::Phoneme p;
    r.get(p.mnemonic);
    r.get(p.sample);
    r.get(p.sentence);
    s.phonemes.push_back(std::move(p));
  }
  r.get(n);
  for (uint64_t i = 0; i < n && r.whole; ++i) {
    Synthesis::Word word;
    r.get(word);
    s.words.push_back(word);
  }
  r.get(s.transcription);
}

// Runs `work` (espeak-ng's calls; it sets its error or puts its answer) in a child whose
// espeak-ng has never spoken, and hands its answer to `take`. False with `error` when espeak-ng
// cannot start, the child cannot, `work` failed, or the child died before it answered. When
// `*cancel` becomes true, the child is killed within 10 ms and `take` is not called.
bool in_child(const std::function<void(Writer&, std::string&)>& work,
              const std::function<void(Reader&)>& take, std::string& error,
              const std::atomic<bool>* cancel = nullptr) {
  int fds[2];
  pid_t pid = -1;
  {
    std::lock_guard lock(espeak_mutex);
    if (!start(error)) return false;
    if (pipe(fds) != 0) {
      error = std::string("no pipe for espeak-ng: ") + std::strerror(errno);
      return false;
    }
    pid = fork();
  }
  if (pid == 0) {
    // The child: one thread, this one; nothing of the parent's is touched but espeak-ng.
    close(fds[0]);
    Writer answer;
    std::string failure;
    work(answer, failure);
    Writer w;
    w.put(failure);
    w.bytes += answer.bytes;
    for (size_t done = 0; done < w.bytes.size();) {
      const ssize_t n = write(fds[1], w.bytes.data() + done, w.bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) _exit(1);
      done += static_cast<size_t>(n);
    }
    _exit(0);
  }
  close(fds[1]);
  if (pid < 0) {
    close(fds[0]);
    error = std::string("espeak-ng's process could not start: ") + std::strerror(errno);
    return false;
  }
  std::string bytes;
  bool cancelled = false;
  for (;;) {
    if (cancel != nullptr && cancel->load()) {
      cancelled = true;
      kill(pid, SIGKILL);
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    if (poll(&p, 1, cancel != nullptr ? 10 : -1) == 0) continue;
    char buffer[65536];
    const ssize_t n = read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    bytes.append(buffer, static_cast<size_t>(n));
  }
  close(fds[0]);
  // Whoever reaps it (a SIGCHLD handler of the application may), the answer is in `bytes`.
  while (waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
  }
  if (cancelled) return true;
  Reader r{bytes};
  std::string failure;
  r.get(failure);
  if (r.whole && !failure.empty()) {
    error = failure;
    return false;
  }
  if (r.whole) take(r);
  if (!r.whole || !r.rest.empty()) {
    error = "espeak-ng stopped before it answered";
    return false;
  }
  return true;
}

}  // namespace

bool check_voice(const VoiceSettings& settings, unsigned& sample_rate, std::string& error) {
  return in_child([&](Writer&, std::string& failure) { set_voice(settings, failure); },
                  [&](Reader&) { sample_rate = static_cast<unsigned>(espeak_rate); }, error);
}

bool synthesize(std::string_view text, const VoiceSettings& settings, Synthesis& out,
                std::string& error, const std::atomic<bool>* cancel) {
  out = Synthesis{};
  const auto work = [&](Writer& answer, std::string& failure) {
    if (!set_voice(settings, failure)) return;
    Synthesis s;
    s.sample_rate = static_cast<unsigned>(espeak_rate);  // until its event says otherwise
    const std::string input(text);

    // The stressed transcription, clause by clause, as espeak-ng -x prints it.
    const void* clause = input.c_str();
    while (clause != nullptr) {
      const char* phonemes = espeak_TextToPhonemes(&clause, espeakCHARS_UTF8, 0);
      if (phonemes == nullptr) break;
      if (!s.transcription.empty()) s.transcription += ' ';
      s.transcription += phonemes;
    }

    current = {&s, 0};
    const espeak_ERROR result = espeak_Synth(input.c_str(), input.size() + 1, 0, POS_CHARACTER, 0,
                                             espeakCHARS_UTF8, nullptr, nullptr);
    if (result != EE_OK) {
      failure = "espeak-ng could not speak the text (error " + std::to_string(result) + ")";
      return;
    }
    close_words(s);
    put(answer, s);
  };
  return in_child(
      work, [&](Reader& r) { get(r, out); }, error, cancel);
}

}  // namespace pfap::tts

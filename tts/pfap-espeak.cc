// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap-espeak: espeak-ng for libpfaptts, in a process of its own. libpfaptts (espeak.cc) starts
// it once per calling process, with its end of a SOCK_SEQPACKET socket as file descriptor 3,
// and sends it requests (espeakwire.h). It starts espeak-ng, never speaks itself, and forks a
// child per request whose espeak-ng has never spoken: espeak-ng 1.51 keeps state from one
// synthesis to the next that no call of its API resets (wavegen.c's function-level statics
// Flutter_ix and cycle_count), so a fresh child is the only way the same text gives the same
// audio whatever was spoken before (issue 31). It exits when the caller's end of the socket
// closes. It runs only espeak-ng's code and this file's, in its main thread and one that
// espeak_Initialize starts and that then waits for good, so a fork of it is cheap and safe.
#include <espeak-ng/speak_lib.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "espeakwire.h"

namespace pfap::tts {
namespace {

using wire::Ask;
using wire::Reader;
using wire::Writer;

int espeak_rate = 0;  // espeak_Initialize's answer

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
  return 0;  // go on (the caller stops a synthesis by killing its child)
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

// Speaks `text` with the voice set, in the child.
void speak(const std::string& text, Writer& answer, std::string& failure) {
  Synthesis s;
  s.sample_rate = static_cast<unsigned>(espeak_rate);  // until its event says otherwise

  // The stressed transcription, clause by clause, as espeak-ng -x prints it.
  const void* clause = text.c_str();
  while (clause != nullptr) {
    const char* phonemes = espeak_TextToPhonemes(&clause, espeakCHARS_UTF8, 0);
    if (phonemes == nullptr) break;
    if (!s.transcription.empty()) s.transcription += ' ';
    s.transcription += phonemes;
  }

  current = {&s, 0};
  const espeak_ERROR result = espeak_Synth(text.c_str(), text.size() + 1, 0, POS_CHARACTER, 0,
                                           espeakCHARS_UTF8, nullptr, nullptr);
  if (result != EE_OK) {
    failure = "espeak-ng could not speak the text (error " + std::to_string(result) + ")";
    return;
  }
  close_words(s);
  put(answer, s);
}

// Writes all of `bytes` to `fd`; false when the reader has gone.
bool write_all(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes.remove_prefix(static_cast<size_t>(n));
  }
  return true;
}

void reap(int) {
  const int saved = errno;
  while (waitpid(-1, nullptr, WNOHANG) > 0) {
  }
  errno = saved;
}

// Starts espeak-ng, tells the caller its sample rate (<= 0: it did not start, and this ends),
// then serves requests until the caller's end of `sock` closes.
int serve(int sock) {
  // Its children are waited for (not SIG_IGN), so that their processor time counts in this
  // process's children's, as a measure of the caller's cost can read.
  struct sigaction reaping {};
  reaping.sa_handler = reap;
  reaping.sa_flags = SA_RESTART | SA_NOCLDSTOP;
  sigaction(SIGCHLD, &reaping, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a caller that has gone makes a write fail, nothing more
  espeak_rate = espeak_Initialize(AUDIO_OUTPUT_SYNCHRONOUS, 0, nullptr,
                                  espeakINITIALIZE_PHONEME_EVENTS | espeakINITIALIZE_DONT_EXIT);
  if (espeak_rate > 0) {
    espeak_SetSynthCallback(on_synth);
    // The default voice, loaded once here, leaves less for each child to load (0.2 to 0.8 ms
    // of 2.1 a short sentence); no other voice is ever set here (below).
    std::string ignored;
    set_voice(VoiceSettings{}, ignored);
  }
  if (send(sock, &espeak_rate, sizeof espeak_rate, 0) != sizeof espeak_rate || espeak_rate <= 0)
    return 1;
  const pid_t self = getpid();
  std::vector<char> request(wire::kMaxRequest);
  for (;;) {
    iovec iov{request.data(), request.size()};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))];
    msghdr m{};
    m.msg_iov = &iov;
    m.msg_iovlen = 1;
    m.msg_control = control;
    m.msg_controllen = sizeof control;
    const ssize_t n = recvmsg(sock, &m, MSG_CMSG_CLOEXEC);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return 0;  // the caller's process has gone
    int fd = -1;
    if (const cmsghdr* c = CMSG_FIRSTHDR(&m);
        c != nullptr && c->cmsg_type == SCM_RIGHTS && c->cmsg_len == CMSG_LEN(sizeof fd))
      std::memcpy(&fd, CMSG_DATA(c), sizeof fd);
    if (fd < 0) continue;

    Reader r{std::string_view(request.data(), static_cast<size_t>(n))};
    Ask ask{};
    VoiceSettings settings;
    std::string text;
    r.get(ask);
    get(r, settings);
    r.get(text);
    if (!r.whole || !r.rest.empty() || (m.msg_flags & MSG_TRUNC) != 0) {
      close(fd);  // the caller reads no answer, which is its error
      continue;
    }

    // Each request in a child that sets its voice, voice checks too, so that every child
    // starts from the same state. Voices set here one after another made a child's first
    // phoneme event come or not, at random ("Think of the thin thread." in en-us, after
    // syntheses in en: 18 of 30 without their T, the samples the same).
    std::string failure;
    const pid_t pid = fork();
    if (pid == 0) {
      close(sock);
      signal(SIGCHLD, SIG_DFL);
      // Killed when this process's one thread, the one that forks, ends: when it does.
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (getppid() != self) _exit(1);
      Writer w;
      w.put(getpid());  // first, so that the caller can kill it
      if (!write_all(fd, w.bytes)) _exit(1);
      Writer answer;
      if (set_voice(settings, failure)) {
        if (ask == Ask::synthesize)
          speak(text, answer, failure);
        else
          answer.put(static_cast<unsigned>(espeak_rate));
      }
      w.bytes.clear();
      w.put(failure);
      if (failure.empty()) w.bytes += answer.bytes;
      _exit(write_all(fd, w.bytes) ? 0 : 1);
    }
    if (pid < 0) {
      Writer w;
      w.put(pid_t{0});
      w.put(std::string("pfap-espeak could not fork: ") + std::strerror(errno));
      write_all(fd, w.bytes);
    }
    close(fd);
  }
}

}  // namespace
}  // namespace pfap::tts

int main(int argc, char** argv) {
  int type = 0;
  socklen_t size = sizeof type;
  if (argc != 1 || getsockopt(pfap::tts::wire::kSocketFd, SOL_SOCKET, SO_TYPE, &type, &size) != 0 ||
      type != SOCK_SEQPACKET) {
    std::fprintf(stderr,
                 "%s: espeak-ng for libpfaptts, which starts it with a socket as file "
                 "descriptor %d; not to be run by hand\n",
                 argv[0], pfap::tts::wire::kSocketFd);
    return 2;
  }
  return pfap::tts::serve(pfap::tts::wire::kSocketFd);
}

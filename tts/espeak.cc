// SPDX-License-Identifier: LGPL-2.1-or-later
#include "espeak.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <functional>
#include <mutex>

#include "espeakwire.h"

extern char** environ;

namespace pfap::tts {
namespace {

using wire::Ask;
using wire::Reader;
using wire::Writer;

// espeak-ng 1.51 carries state from one synthesis to the next that no call of its API resets
// (wavegen.c's function-level statics Flutter_ix and cycle_count): the same text spoken twice
// in one process gave other audio and alignments that differed by up to 300 ms (issue 31). So
// espeak-ng runs in a helper program, pfap-espeak, that the first call starts (posix_spawn: the
// caller, which may be large and many-threaded, never runs its own code in a child). It starts
// espeak-ng, never speaks, and forks a child per request whose espeak-ng never has
// (pfap-espeak.cc). Each call sends it a request with the write end of a fresh pipe, on which
// the answer comes (espeakwire.h).
std::mutex helper_mutex;  // held while pfap-espeak starts and while a request is sent
int helper_socket = -1;   // the caller's end; -1 when there is no pfap-espeak
pid_t helper_pid = -1;
bool espeak_failed = false;  // espeak-ng did not start in pfap-espeak: not tried again
constexpr char espeak_failure[] = "espeak-ng could not start (its data not installed?)";

// pfap-espeak is installed beside this library, and built beside it: found from where the
// loader found this library, in the build tree and installed alike.
std::string helper_path() {
  Dl_info info{};
  dladdr(reinterpret_cast<void*>(&helper_path), &info);  // finds this library's file
  const std::string library = info.dli_fname != nullptr ? info.dli_fname : "";
  return library.substr(0, library.rfind('/') + 1) + "pfap-espeak";
}

// Under helper_mutex: pfap-espeak runs, or `error` says why not.
bool start(std::string& error) {
  if (helper_socket >= 0) return true;
  if (espeak_failed) {
    error = espeak_failure;
    return false;
  }
  int sv[2];
  if (socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) != 0) {
    error = std::string("no socket for espeak-ng: ") + std::strerror(errno);
    return false;
  }
  // Its end becomes kSocketFd, which a dup2 onto itself would leave close-on-exec.
  if (sv[1] == wire::kSocketFd) {
    const int moved = fcntl(sv[1], F_DUPFD_CLOEXEC, wire::kSocketFd + 1);
    close(sv[1]);
    sv[1] = moved;
  }
  // pfap-espeak holds only its socket and the standard streams, with no signal blocked or
  // ignored, whatever the caller holds and does with signals.
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_adddup2(&files, sv[1], wire::kSocketFd);
  posix_spawn_file_actions_addclosefrom_np(&files, wire::kSocketFd + 1);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t signals;
  sigemptyset(&signals);
  posix_spawnattr_setsigmask(&attributes, &signals);
  sigfillset(&signals);
  posix_spawnattr_setsigdefault(&attributes, &signals);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  static const std::string path = helper_path();
  char* argv[] = {const_cast<char*>(path.c_str()), nullptr};
  pid_t pid = -1;
  const int spawned = posix_spawn(&pid, path.c_str(), &files, &attributes, argv, environ);
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&files);
  close(sv[1]);
  if (spawned != 0) {
    close(sv[0]);
    error = "espeak-ng's helper " + path + " could not start: " + std::strerror(spawned);
    return false;
  }
  int rate = 0;
  ssize_t n;
  while ((n = recv(sv[0], &rate, sizeof rate, 0)) < 0 && errno == EINTR) {
  }
  if (n != sizeof rate || rate <= 0) {
    close(sv[0]);
    while (waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
    }
    espeak_failed = n == sizeof rate;  // it answered: espeak-ng itself did not start
    error = espeak_failed ? std::string(espeak_failure)
                          : "espeak-ng's helper " + path + " ended as it started";
    return false;
  }
  helper_socket = sv[0];
  helper_pid = pid;
  return true;
}

// Sends `request` and `fd` to pfap-espeak; starts it if it does not run, and again once if it
// has died.
bool send_request(const std::string& request, int fd, std::string& error) {
  std::lock_guard lock(helper_mutex);
  for (bool restarted = false;;) {
    if (!start(error)) return false;
    iovec iov{const_cast<char*>(request.data()), request.size()};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof fd)] = {};
    msghdr m{};
    m.msg_iov = &iov;
    m.msg_iovlen = 1;
    m.msg_control = control;
    m.msg_controllen = sizeof control;
    cmsghdr* c = CMSG_FIRSTHDR(&m);
    c->cmsg_level = SOL_SOCKET;
    c->cmsg_type = SCM_RIGHTS;
    c->cmsg_len = CMSG_LEN(sizeof fd);
    std::memcpy(CMSG_DATA(c), &fd, sizeof fd);
    if (sendmsg(helper_socket, &m, MSG_NOSIGNAL) >= 0) return true;
    if (errno == EINTR) continue;
    // pfap-espeak has died (its end of the socket closed).
    const int cause = errno;
    close(helper_socket);
    helper_socket = -1;
    while (waitpid(helper_pid, nullptr, 0) < 0 && errno == EINTR) {
    }
    if (restarted || (cause != EPIPE && cause != ECONNRESET)) {
      error = std::string("espeak-ng's helper has gone: ") + std::strerror(cause);
      return false;
    }
    restarted = true;
  }
}

// Asks pfap-espeak for `ask` and hands the answer to `take`. False with `error` when espeak-ng
// cannot start, has no such voice, could not speak or died before it answered. When `*cancel`
// becomes true, the child speaking is killed within 10 ms and `take` is not called.
bool call(Ask ask, std::string_view text, const VoiceSettings& settings,
          const std::function<void(Reader&)>& take, std::string& error,
          const std::atomic<bool>* cancel = nullptr) {
  Writer request;
  request.put(ask);
  put(request, settings);
  request.put(text);
  // pfap-espeak reads at most that much, and would take a longer request for a broken one.
  if (request.bytes.size() > wire::kMaxRequest) {
    error = "the text is too long for espeak-ng (" + std::to_string(text.size()) +
            " bytes; at most about " + std::to_string(wire::kMaxRequest / 1024) + " KiB)";
    return false;
  }
  int fds[2];
  // Close-on-exec: a child another thread forks and execs must not hold the pipe open.
  if (pipe2(fds, O_CLOEXEC) != 0) {
    error = std::string("no pipe for espeak-ng: ") + std::strerror(errno);
    return false;
  }
  const bool sent = send_request(request.bytes, fds[1], error);
  close(fds[1]);
  if (!sent) {
    close(fds[0]);
    return false;
  }
  std::string bytes;
  pid_t pid = -1;  // the speaking child's, 0 when pfap-espeak answered; -1 until it came
  bool cancelled = false;
  for (;;) {
    if (pid < 0 && bytes.size() >= sizeof pid) std::memcpy(&pid, bytes.data(), sizeof pid);
    if (cancel != nullptr && cancel->load() && pid >= 0) {
      cancelled = true;
      // It has not closed the pipe, so it has not exited and the pid is still its own.
      if (pid > 0) kill(pid, SIGKILL);
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
  if (cancelled) return true;
  Reader r{bytes};
  std::string failure;
  r.get(pid);
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
  return call(
      Ask::check_voice, {}, settings, [&](Reader& r) { r.get(sample_rate); }, error);
}

bool synthesize(std::string_view text, const VoiceSettings& settings, Synthesis& out,
                std::string& error, const std::atomic<bool>* cancel) {
  out = Synthesis{};
  return call(
      Ask::synthesize, text, settings, [&](Reader& r) { get(r, out); }, error, cancel);
}

}  // namespace pfap::tts

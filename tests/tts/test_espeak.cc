// SPDX-License-Identifier: LGPL-2.1-or-later
// espeak.cc's helper program pfap-espeak: one per calling process, started by the first call
// from beside libpfaptts, that holds none of the caller's files, is started again when it dies
// and exits when the caller does; and a clear error when it is not there.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "espeak.h"

namespace pfap::tts {
namespace {

// The children of this process, from each thread's /proc children list.
std::vector<pid_t> children() {
  std::vector<pid_t> out;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream list(task.path() / "children");
    for (pid_t pid; list >> pid;) out.push_back(pid);
  }
  return out;
}

// Whether `pid` has exited, all its threads (so its files are closed): gone, or a zombie
// nobody has reaped with no other thread left.
bool exited(pid_t pid) {
  const std::string dir = "/proc/" + std::to_string(pid);
  std::ifstream stat(dir + "/stat");
  std::string skip, state;
  if (!(stat >> skip >> skip >> state)) return true;
  std::error_code error;
  const auto threads = std::distance(std::filesystem::directory_iterator(dir + "/task", error),
                                     std::filesystem::directory_iterator());
  return state == "Z" && threads <= 1;
}

// The file the loader found libpfaptts in.
std::filesystem::path libpfaptts() {
  Dl_info info{};
  EXPECT_NE(dladdr(reinterpret_cast<void*>(&check_voice), &info), 0);
  return info.dli_fname;
}

std::vector<int16_t> say(const std::string& text) {
  Synthesis s;
  std::string error;
  EXPECT_TRUE(synthesize(text, {}, s, error)) << error;
  EXPECT_FALSE(s.samples.empty());
  return s.samples;
}

// First (gtest keeps the file's order), so that the forked caller has no helper yet.
TEST(Espeak, TheHelperExitsWithTheCaller) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t caller = fork();
  ASSERT_GE(caller, 0);
  if (caller == 0) {
    // A fresh process of one thread, whose first call starts its own helper.
    Synthesis s;
    std::string error;
    const std::vector<pid_t> before = children();
    synthesize("Hello.", {}, s, error);
    pid_t helper = 0;
    for (pid_t pid : children())
      if (std::find(before.begin(), before.end(), pid) == before.end()) helper = pid;
    _exit(write(fds[1], &helper, sizeof helper) == sizeof helper ? 0 : 1);
  }
  close(fds[1]);
  pid_t helper = 0;
  ASSERT_EQ(read(fds[0], &helper, sizeof helper), static_cast<ssize_t>(sizeof helper));
  close(fds[0]);
  int status = 0;
  ASSERT_EQ(waitpid(caller, &status, 0), caller);
  ASSERT_GT(helper, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!exited(helper) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(exited(helper));
}

// Before any other call of this process: the pipe is open when the helper starts.
TEST(Espeak, TheHelperHoldsNoneOfTheCallersFiles) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);  // not close-on-exec, so a fork or exec would inherit it
  say("Hello.");
  close(fds[1]);
  pollfd p{fds[0], POLLIN, 0};
  ASSERT_EQ(poll(&p, 1, 1000), 1) << "someone else holds the write end";
  char c;
  EXPECT_EQ(read(fds[0], &c, 1), 0);
  close(fds[0]);
}

// One helper, the program pfap-espeak beside libpfaptts (exec'd, not a fork of this process).
TEST(Espeak, OneHelperForAllCalls) {
  say("Hello.");
  const std::vector<pid_t> helper = children();
  ASSERT_EQ(helper.size(), 1u);
  EXPECT_EQ(std::filesystem::read_symlink("/proc/" + std::to_string(helper[0]) + "/exe"),
            std::filesystem::canonical(libpfaptts().parent_path() / "pfap-espeak"));
  unsigned rate = 0;
  std::string error;
  EXPECT_TRUE(check_voice({"de"}, rate, error)) << error;
  EXPECT_EQ(rate, 22050u);
  for (int i = 0; i < 5; ++i) say("Always remember the open ocean.");
  EXPECT_EQ(children(), helper);
}

// Each synthesis's phoneme events are the same whatever voices were asked for before: with
// the voices set in pfap-espeak itself, one after another, this text's first phoneme (T at
// sample 264) came in 12 of 30 syntheses and was missing in 18, the samples the same.
TEST(Espeak, TheSameEventsWhateverVoiceCameBefore) {
  const VoiceSettings us{"en-us"};
  const auto events = [&] {
    Synthesis s;
    std::string error;
    EXPECT_TRUE(synthesize("Think of the thin thread.", us, s, error)) << error;
    std::string out;
    for (const Synthesis::Phoneme& p : s.phonemes)
      out += p.mnemonic + "@" + std::to_string(p.sample) + " ";
    return out;
  };
  const std::string first = events();
  EXPECT_TRUE(first.starts_with("T@")) << first;
  for (int i = 0; i < 20; ++i) {
    say("Hello there, how are you today?");  // the default voice
    EXPECT_EQ(events(), first) << "after " << i + 1 << " in the default voice";
  }
}

// A text too long for one request to pfap-espeak is refused with the reason, and the helper
// goes on speaking (pfaptts speaks pieces of at most 400 code points; pfapalign a whole text).
TEST(Espeak, ATextTooLongForARequestIsAnError) {
  Synthesis out;
  std::string error;
  EXPECT_FALSE(synthesize(std::string(200 * 1024, 'a'), {"en"}, out, error));
  EXPECT_NE(error.find("too long"), std::string::npos) << error;
  EXPECT_FALSE(say("Hello.").empty());
}

TEST(Espeak, ANewHelperWhenOneDied) {
  const std::vector<int16_t> first = say("Always remember the open ocean.");
  const std::vector<pid_t> helper = children();
  ASSERT_EQ(helper.size(), 1u);
  ASSERT_EQ(kill(helper[0], SIGKILL), 0);
  while (!exited(helper[0])) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(say("Always remember the open ocean."), first);
  const std::vector<pid_t> now = children();
  ASSERT_EQ(now.size(), 1u);
  EXPECT_NE(now[0], helper[0]);
}

// A copy of libpfaptts in a directory without pfap-espeak: its calls fail and say why. (The
// loader keeps the copy apart from the libpfaptts this test links, being another file.)
TEST(Espeak, AMissingHelperIsAnError) {
  char dir_template[] = "/tmp/test_espeak_XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  const std::filesystem::path dir = dir_template;
  const std::filesystem::path copy = dir / "libpfaptts.so";
  std::filesystem::copy_file(libpfaptts(), copy);
  void* library = dlopen(copy.c_str(), RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(library, nullptr) << dlerror();
  using CheckVoice = bool (*)(const VoiceSettings&, unsigned&, std::string&);
  const auto copied_check_voice = reinterpret_cast<CheckVoice>(
      dlsym(library,
            "_ZN4pfap3tts11check_voiceERKNS0_13VoiceSettingsERjRNSt7__cxx1112basic_"
            "stringIcSt11char_traitsIcESaIcEEE"));
  ASSERT_NE(copied_check_voice, nullptr) << dlerror();
  ASSERT_NE(copied_check_voice, &check_voice);
  const std::vector<pid_t> before = children();
  unsigned rate = 0;
  std::string error;
  EXPECT_FALSE(copied_check_voice({}, rate, error));
  EXPECT_EQ(error, "espeak-ng's helper " + (dir / "pfap-espeak").string() +
                       " could not start: No such file or directory");
  EXPECT_EQ(children(), before);
  dlclose(library);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pfap::tts

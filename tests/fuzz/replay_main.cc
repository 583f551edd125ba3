// SPDX-License-Identifier: LGPL-2.1-or-later
// main() for a fuzz harness built without libFuzzer: runs every file in the directories (or
// the files) named on the command line through LLVMFuzzerTestOneInput once, so the normal and
// sanitizer builds check the seed corpus and the saved regressions. A harness check that
// fails aborts; a directory with no inputs is an error unless it is marked optional with a
// trailing '?' (regressions/<harness>/ exists only once a crash has been saved there).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  int status = 0;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    const bool optional = arg.ends_with('?');
    if (optional) arg.pop_back();
    std::vector<fs::path> inputs;
    std::error_code error;
    if (fs::is_directory(arg, error)) {
      for (const fs::directory_entry& entry : fs::directory_iterator(arg)) {
        if (entry.is_regular_file()) inputs.push_back(entry.path());
      }
      std::sort(inputs.begin(), inputs.end());
    } else if (fs::is_regular_file(arg, error)) {
      inputs.push_back(arg);
    }
    if (inputs.empty() && !optional) {
      std::fprintf(stderr, "%s: no inputs\n", arg.c_str());
      status = 1;
      continue;
    }
    for (const fs::path& path : inputs) {
      std::ifstream file(path, std::ios::binary);
      const std::vector<char> bytes{std::istreambuf_iterator<char>(file),
                                    std::istreambuf_iterator<char>()};
      if (!file.good() && !file.eof()) {
        std::fprintf(stderr, "%s: cannot read\n", path.c_str());
        status = 1;
        continue;
      }
      // A copy of its own, as libFuzzer gives, so that reads past the end are caught.
      std::vector<uint8_t> input(bytes.begin(), bytes.end());
      const uint8_t* data = input.empty() ? nullptr : input.data();
      LLVMFuzzerTestOneInput(data, input.size());
    }
    std::printf("%s: %zu inputs ran\n", arg.c_str(), inputs.size());
  }
  return status;
}

// SPDX-License-Identifier: LGPL-2.1-or-later
// A temporary directory for a test's files, removed with the files in it (not subdirectories)
// when the test ends.
#pragma once

#include <glib.h>
#include <glib/gstdio.h>

#include <string>

namespace pfap::testing {

class TempDir {
 public:
  TempDir() {
    gchar* path = g_dir_make_tmp("pfap-test-XXXXXX", nullptr);
    path_ = path != nullptr ? path : "";
    g_free(path);
  }
  ~TempDir() {
    if (GDir* dir = g_dir_open(path_.c_str(), 0, nullptr)) {
      while (const gchar* name = g_dir_read_name(dir)) g_remove(file(name).c_str());
      g_dir_close(dir);
    }
    g_rmdir(path_.c_str());
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  // How many entries the directory holds.
  int count() const {
    int n = 0;
    if (GDir* dir = g_dir_open(path_.c_str(), 0, nullptr)) {
      while (g_dir_read_name(dir) != nullptr) ++n;
      g_dir_close(dir);
    }
    return n;
  }

 private:
  std::string path_;
};

}  // namespace pfap::testing

// SPDX-License-Identifier: LGPL-2.1-or-later
// Counts the GLib criticals and warnings logged while it lives (GStreamer's
// g_return_if_fail checks, GObject's property checks), instead of printing them, so that a test
// can assert that bad input got an element's own message and no CRITICAL.
#pragma once

#include <glib.h>

#include <atomic>
#include <initializer_list>
#include <string>
#include <vector>

namespace pfap::testing {

class GlibLogCounter {
 public:
  GlibLogCounter() {
    for (const char* domain : {"GStreamer", "GLib", "GLib-GObject"}) {
      handlers_.push_back({domain, g_log_set_handler(domain, kLevels, on_log, this)});
    }
  }
  ~GlibLogCounter() {
    for (const Handler& h : handlers_) g_log_remove_handler(h.domain, h.id);
  }
  GlibLogCounter(const GlibLogCounter&) = delete;
  GlibLogCounter& operator=(const GlibLogCounter&) = delete;

  int count() const { return count_; }
  const std::string& first() const { return first_; }

 private:
  static constexpr auto kLevels = static_cast<GLogLevelFlags>(
      G_LOG_LEVEL_CRITICAL | G_LOG_LEVEL_WARNING | G_LOG_FLAG_FATAL | G_LOG_FLAG_RECURSION);
  struct Handler {
    const char* domain;
    guint id;
  };

  static void on_log(const gchar* domain, GLogLevelFlags, const gchar* message, gpointer data) {
    auto* self = static_cast<GlibLogCounter*>(data);
    if (self->count_++ == 0) self->first_ = std::string(domain) + ": " + message;
  }

  std::vector<Handler> handlers_;
  std::atomic<int> count_{0};
  std::string first_;  // written by the first message only
};

}  // namespace pfap::testing

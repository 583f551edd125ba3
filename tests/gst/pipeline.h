// SPDX-License-Identifier: LGPL-2.1-or-later
// A pipeline from a gst-launch description for element tests: made, driven and released in
// one place. Methods that can fail return "" when fine, else what went wrong.
#pragma once

#include <gst/base/gstbasesink.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pfap::testing {

class Pipeline {
 public:
  explicit Pipeline(const std::string& description) {
    GError* error = nullptr;
    GstElement* element = gst_parse_launch(description.c_str(), &error);
    if (error != nullptr) {
      error_ = std::string(error->message) + " in: " + description;
      g_error_free(error);
      if (element != nullptr) gst_object_unref(element);
      return;
    }
    pipeline_ = element;
    bus_ = gst_element_get_bus(pipeline_);
  }
  ~Pipeline() {
    if (pipeline_ == nullptr) return;
    gst_element_set_state(pipeline_, GST_STATE_NULL);
    gst_object_unref(bus_);
    gst_object_unref(pipeline_);
  }
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  bool ok() const { return pipeline_ != nullptr; }
  const std::string& error() const { return error_; }
  GstElement* get() const { return pipeline_; }

  // The named element (the pipeline keeps it alive), or nullptr.
  GstElement* by_name(const char* name) const {
    GstElement* e = gst_bin_get_by_name(GST_BIN(pipeline_), name);
    if (e != nullptr) gst_object_unref(e);
    return e;
  }

  // The first element made by `factory`, searched through bins (not a new reference).
  GstElement* find(const char* factory) const {
    GstElement* found = nullptr;
    GstIterator* it = gst_bin_iterate_recurse(GST_BIN(pipeline_));
    GValue item = G_VALUE_INIT;
    while (found == nullptr && gst_iterator_next(it, &item) == GST_ITERATOR_OK) {
      auto* element = GST_ELEMENT(g_value_get_object(&item));
      GstElementFactory* f = gst_element_get_factory(element);
      if (f != nullptr && std::string(GST_OBJECT_NAME(f)) == factory) found = element;
      g_value_reset(&item);
    }
    g_value_unset(&item);
    gst_iterator_free(it);
    return found;
  }

  // Sets a state without waiting for it (a live pipeline completes PLAYING only when data
  // comes).
  std::string set_state(GstState state) {
    if (gst_element_set_state(pipeline_, state) != GST_STATE_CHANGE_FAILURE) return "";
    std::string text = std::string("cannot set state ") + gst_element_state_get_name(state);
    const std::string bus_error = poll_error();
    if (!bus_error.empty()) text += ": " + bus_error;
    return text;
  }

  // The first error on the bus so far (with `warnings`, or warning), without waiting.
  std::string poll_error(bool warnings = false) {
    if (GstMessage* m = gst_bus_pop_filtered(bus_, failures(warnings))) {
      std::string text = describe(m);
      gst_message_unref(m);
      return text;
    }
    return "";
  }

  // Waits for EOS: "" or why it did not come (an error, with `warnings` a warning, or the
  // timeout). A timeout says where each sink is, the pipeline's state and the warnings
  // posted meanwhile.
  std::string wait_eos(std::chrono::milliseconds timeout, bool warnings = false) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::string seen;  // the warnings that do not end the wait
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      GstMessage* m = gst_bus_timed_pop_filtered(
          bus_, static_cast<GstClockTime>(std::max<int64_t>(left.count(), 0)) * GST_MSECOND,
          static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR | GST_MESSAGE_WARNING));
      if (m == nullptr) {
        GstState state = GST_STATE_VOID_PENDING, pending = GST_STATE_VOID_PENDING;
        gst_element_get_state(pipeline_, &state, &pending, 0);
        return "no EOS within " + std::to_string(timeout.count()) + " ms (" + sinks() +
               "; pipeline " + gst_element_state_get_name(state) + ", pending " +
               gst_element_state_get_name(pending) + ")" + seen;
      }
      const bool ends = GST_MESSAGE_TYPE(m) != GST_MESSAGE_WARNING || warnings;
      std::string text = GST_MESSAGE_TYPE(m) == GST_MESSAGE_EOS ? "" : describe(m);
      gst_message_unref(m);
      if (ends) return text;
      seen += "; " + text;
    }
  }

  // Sends EOS into every source, as gst-launch-1.0 -e does on Ctrl-C, and waits for it.
  std::string end(std::chrono::milliseconds timeout) {
    gst_element_send_event(pipeline_, gst_event_new_eos());
    return wait_eos(timeout);
  }

  // Warnings posted so far (counted, then dropped).
  int count_warnings() {
    int n = 0;
    while (GstMessage* m = gst_bus_pop_filtered(bus_, GST_MESSAGE_WARNING)) {
      ++n;
      gst_message_unref(m);
    }
    return n;
  }

 private:
  // Where each sink is: whether it has EOS and its position, so that a missing EOS says which
  // branch stopped and where.
  std::string sinks() const {
    std::string text;
    GstIterator* it = gst_bin_iterate_sinks(GST_BIN(pipeline_));
    GValue item = G_VALUE_INIT;
    while (gst_iterator_next(it, &item) == GST_ITERATOR_OK) {
      GstElement* e = GST_ELEMENT(g_value_get_object(&item));
      gint64 position = -1;
      gst_element_query_position(e, GST_FORMAT_TIME, &position);
      bool eos = false;
      if (GST_IS_BASE_SINK(e)) {
        GST_OBJECT_LOCK(e);
        eos = GST_BASE_SINK(e)->eos;
        GST_OBJECT_UNLOCK(e);
      }
      gchar* name = gst_element_get_name(e);
      if (!text.empty()) text += "; ";
      text += std::string(name) + (eos ? " at EOS" : " not at EOS") + ", position " +
              (position < 0 ? std::string("none")
                            : std::to_string(position / static_cast<gint64>(GST_MSECOND)) + " ms");
      g_free(name);
      g_value_reset(&item);
    }
    g_value_unset(&item);
    gst_iterator_free(it);
    return text;
  }

  static GstMessageType failures(bool warnings) {
    return static_cast<GstMessageType>(GST_MESSAGE_ERROR |
                                       (warnings ? GST_MESSAGE_WARNING : GST_MESSAGE_UNKNOWN));
  }

  static std::string describe(GstMessage* m) {
    GError* error = nullptr;
    gchar* debug = nullptr;
    if (GST_MESSAGE_TYPE(m) == GST_MESSAGE_ERROR) {
      gst_message_parse_error(m, &error, &debug);
    } else {
      gst_message_parse_warning(m, &error, &debug);
    }
    std::string text = std::string(GST_MESSAGE_TYPE_NAME(m)) + " from " +
                       GST_OBJECT_NAME(GST_MESSAGE_SRC(m)) + ": " +
                       (error != nullptr ? error->message : "?") + " (" +
                       (debug != nullptr ? debug : "") + ")";
    if (error != nullptr) g_error_free(error);
    g_free(debug);
    return text;
  }

  GstElement* pipeline_ = nullptr;
  GstBus* bus_ = nullptr;
  std::string error_;
};

// Fails the test unless every named element can be made: the plugin comes from
// GST_PLUGIN_PATH, which meson sets to the build's gst/ directory.
inline ::testing::AssertionResult plugin_available(std::span<const char* const> elements) {
  for (const char* name : elements) {
    GstElementFactory* factory = gst_element_factory_find(name);
    if (factory == nullptr) {
      const char* path = g_getenv("GST_PLUGIN_PATH");
      return ::testing::AssertionFailure()
             << "no element " << name
             << "; GST_PLUGIN_PATH=" << (path != nullptr ? path : "(unset)")
             << " should be the build's gst/ directory";
    }
    gst_object_unref(factory);
  }
  return ::testing::AssertionSuccess();
}

inline GstFlowReturn push(GstElement* appsrc, GstBuffer* buffer) {
  GstFlowReturn ret = GST_FLOW_ERROR;
  g_signal_emit_by_name(appsrc, "push-buffer", buffer, &ret);
  gst_buffer_unref(buffer);
  return ret;
}

inline void end_of_stream(GstElement* appsrc) {
  GstFlowReturn ret = GST_FLOW_ERROR;
  g_signal_emit_by_name(appsrc, "end-of-stream", &ret);
}

// The messages of the errors (or warnings) posted on `bus` so far, taken off it.
inline std::vector<std::string> pop_messages(GstBus* bus, GstMessageType type) {
  std::vector<std::string> out;
  while (GstMessage* message = gst_bus_pop_filtered(bus, type)) {
    GError* error = nullptr;
    if (type == GST_MESSAGE_ERROR) {
      gst_message_parse_error(message, &error, nullptr);
    } else {
      gst_message_parse_warning(message, &error, nullptr);
    }
    out.emplace_back(error->message);
    g_error_free(error);
    gst_message_unref(message);
  }
  return out;
}

// Every sample an appsink (emit-signals=false) holds now; the caller unrefs them.
inline std::vector<GstSample*> pull_all(GstElement* appsink) {
  std::vector<GstSample*> samples;
  for (;;) {
    GstSample* sample = nullptr;
    g_signal_emit_by_name(appsink, "try-pull-sample", GstClockTime{0}, &sample);
    if (sample == nullptr) break;
    samples.push_back(sample);
  }
  return samples;
}

// RTCP every ~100 ms in rtpbin's sessions 0 and 1, so that sync and feedback come within a
// test's few seconds.
inline void fast_rtcp(GstElement* rtpbin) {
  for (guint id : {0u, 1u}) {
    GObject* session = nullptr;
    g_signal_emit_by_name(rtpbin, "get-internal-session", id, &session);
    if (session == nullptr) continue;
    g_object_set(session, "rtcp-min-interval", guint64{100 * GST_MSECOND}, "rtcp-fraction",
                 200000.0, nullptr);
    g_object_unref(session);
  }
}

// The port a udpsrc bound: port=0 picks a free one, known from READY on.
inline guint bound_port(GstElement* udpsrc) {
  gint port = 0;
  g_object_get(udpsrc, "port", &port, nullptr);
  return static_cast<guint>(port);
}

}  // namespace pfap::testing

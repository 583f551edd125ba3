// SPDX-License-Identifier: LGPL-2.1-or-later
// The command lines of the tools and examples, parsed as GStreamer's own tools parse theirs
// (gst-launch-1.0, gst-inspect-1.0): GLib's GOptionContext gives every tool the same --help
// and the same errors, and the programs that run GStreamer add its option group
// (gst_init_get_option_group(): --help-gst, --gst-debug and the rest), which initializes
// GStreamer as the command line is parsed.
#pragma once

#include <glib.h>

#include <cstdarg>
#include <cstdio>

// The exit status of a usage error, in every tool.
constexpr int kUsageError = 2;

// Prints NAME: WHAT and where the options are listed on standard error; returns kUsageError.
inline int usage_error(const char* format, ...) G_GNUC_PRINTF(1, 2);
inline int usage_error(const char* format, ...) {
  va_list args;
  va_start(args, format);
  gchar* what = g_strdup_vprintf(format, args);
  va_end(args);
  std::fprintf(stderr, "%s: %s\nRun '%s --help' to see the options.\n", g_get_prgname(), what,
               g_get_prgname());
  g_free(what);
  return kUsageError;
}

// Parses *ARGC and *ARGV against ENTRIES (ending with an empty entry) and GROUP (GStreamer's,
// or nullptr for a tool that does not run GStreamer), leaving the program name and the
// operands in them. OPERANDS names the operands in the usage line, SUMMARY says what the
// program does, below it. --help prints the usage and exits with status 0 (GLib does). 0 when
// the program goes on; after an unknown option or a value of the wrong type, the error is
// printed and the result is kUsageError.
inline int parse_command_line(int* argc, char*** argv, const char* operands, const char* summary,
                              const GOptionEntry* entries, GOptionGroup* group) {
  GOptionContext* context = g_option_context_new(operands);
  g_option_context_set_summary(context, summary);
  g_option_context_add_main_entries(context, entries, nullptr);
  if (group != nullptr) g_option_context_add_group(context, group);  // takes it
  GError* error = nullptr;
  const bool parsed = g_option_context_parse(context, argc, argv, &error);
  g_option_context_free(context);
  if (parsed) return 0;
  // g_get_prgname() is set from argv[0] by the parse, even when it fails.
  const int status = usage_error("%s", error->message);
  g_error_free(error);
  return status;
}

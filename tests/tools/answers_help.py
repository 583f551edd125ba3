# SPDX-License-Identifier: LGPL-2.1-or-later
"""Checks that PROGRAM, called NAME, takes its command line as GStreamer's own tools do
(GOptionContext, tools/command_line.h). CHECK is one of:

  help            --help: status 0, nothing on standard error, and on standard output GLib's
                  usage ("Usage:", then "  NAME [OPTION...] ..."), at least one line saying
                  what the program does, and the help options
  help-gst        --help-gst: status 0, GStreamer's options (--gst-debug-level and the rest)
                  on standard output; for a program that runs GStreamer
  unknown-option  --no-such-option: status 2, nothing on standard output, and on standard
                  error one line "NAME: ..." naming the option, one pointing to --help, and
                  nothing else (no GLib warning or critical)

In the sanitizer build the sanitizer runtimes are preloaded into every test process, this one
too: PROGRAM is leak-checked, python is not ours, so this ends with os._exit, which skips
LeakSanitizer's check at exit."""
import os
import subprocess
import sys

program, name, check = sys.argv[1], sys.argv[2], sys.argv[3]
argument = {"help": "--help", "help-gst": "--help-gst",
            "unknown-option": "--no-such-option"}[check]
run = subprocess.run([program, argument], capture_output=True, text=True, timeout=20)
out, err = run.stdout.splitlines(), run.stderr.splitlines()
problems = []
if check == "help":
    if run.returncode != 0:
        problems.append(f"exit status {run.returncode}")
    if err:
        problems.append("standard error: " + run.stderr.strip())
    if out[:1] != ["Usage:"] or len(out) < 2 or not out[1].startswith(f"  {name} "):
        problems.append(f"does not start with 'Usage:' and '  {name} ...': {out[:2]}")
    if len([line for line in out[2:] if line and not line.startswith(" ")
            and not line.endswith("Options:")]) < 1:
        problems.append("no line saying what it does")
    if "  -h, --help" not in run.stdout:
        problems.append("no -h, --help among the options")
elif check == "help-gst":
    if run.returncode != 0:
        problems.append(f"exit status {run.returncode}")
    if err:
        problems.append("standard error: " + run.stderr.strip())
    if "--gst-debug-level" not in run.stdout:
        problems.append("no --gst-debug-level among the options")
else:
    if run.returncode != 2:
        problems.append(f"exit status {run.returncode}, not 2")
    if out:
        problems.append("standard output: " + run.stdout.strip())
    if (len(err) != 2 or not err[0].startswith(f"{name}: ") or "--no-such-option" not in err[0]
            or "--help" not in err[1]):
        problems.append("standard error is not NAME: the error, then a pointer to --help: "
                        + repr(run.stderr))
print(run.stdout, end="")
print(run.stderr, end="", file=sys.stderr)
if problems:
    print(f"{name} {argument}: " + "; ".join(problems), file=sys.stderr)
sys.stdout.flush()
sys.stderr.flush()
os._exit(1 if problems else 0)

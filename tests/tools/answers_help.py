# SPDX-License-Identifier: LGPL-2.1-or-later
"""Runs PROGRAM --help and checks that it answers: status 0, nothing on standard error, and a
usage line naming NAME, then at least one line saying what it does, on standard output.

In the sanitizer build the sanitizer runtimes are preloaded into every test process, this one
too: PROGRAM is leak-checked, python is not ours, so this ends with os._exit, which skips
LeakSanitizer's check at exit."""
import os
import subprocess
import sys

program, name = sys.argv[1], sys.argv[2]
run = subprocess.run([program, "--help"], capture_output=True, text=True, timeout=20)
lines = run.stdout.splitlines()
problems = []
if run.returncode != 0:
    problems.append(f"exit status {run.returncode}")
if run.stderr:
    problems.append("standard error: " + run.stderr.strip())
if not lines or not lines[0].startswith(f"usage: {name} "):
    problems.append(f"first line is not 'usage: {name} ...': {lines[:1]}")
if len(lines) < 2:
    problems.append("no line after the usage line")
print(run.stdout, end="")
if problems:
    print(f"{name} --help: " + "; ".join(problems), file=sys.stderr)
sys.stdout.flush()
sys.stderr.flush()
os._exit(1 if problems else 0)

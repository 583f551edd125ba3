# SPDX-License-Identifier: LGPL-2.1-or-later
"""Checks the manual page PAGE of the tool PROGRAM called NAME: groff formats it without a
warning, its NAME line and synopsis name the tool, and its SYNOPSIS and OPTIONS sections
name every option that PROGRAM --help names, and no other (so the two stay one story).

Ends with os._exit, as answers_help.py does, for the sanitizer build's preloaded runtimes."""
import os
import re
import subprocess
import sys

program, name, page = sys.argv[1], sys.argv[2], sys.argv[3]
problems = []
text = open(page, encoding="utf-8").read()

# groff is not ours: without the sanitizer runtimes the sanitizer build preloads (troff's own
# new/free mismatch would abort it under AddressSanitizer).
groff_env = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
groff = subprocess.run(["groff", "-man", "-ww", "-z", page], capture_output=True, text=True,
                       timeout=20, env=groff_env)
if groff.returncode != 0 or groff.stderr:
    problems.append(f"groff: status {groff.returncode}: {groff.stderr.strip()}")

if not re.search(rf"^\.SH NAME\n{re.escape(name)} \\- ", text, re.M):
    problems.append(f"no '.SH NAME' line '{name} \\- ...'")
if not re.search(rf"^\.SH SYNOPSIS\n\.B {re.escape(name)}$", text, re.M):
    problems.append(f"the synopsis does not start with '.B {name}'")

option = re.compile(r"--[a-z][a-z-]*")
usage = subprocess.run([program, "--help"], capture_output=True, text=True, timeout=20).stdout
in_help = set(option.findall(usage)) | {"--help"}
sections = re.findall(r"^\.SH (SYNOPSIS|OPTIONS)\n(.*?)(?=^\.SH )", text, re.M | re.S)
in_page = set(option.findall(" ".join(body for _, body in sections).replace("\\-", "-")))
for o in sorted(in_help - in_page):
    problems.append(f"--help names {o}, the manual page does not")
for o in sorted(in_page - in_help):
    problems.append(f"the manual page names {o}, --help does not")

print(f"{name}: options {' '.join(sorted(in_help))}")
if problems:
    print(f"{page}: " + "; ".join(problems), file=sys.stderr)
sys.stdout.flush()
sys.stderr.flush()
os._exit(1 if problems else 0)

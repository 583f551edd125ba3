# SPDX-License-Identifier: LGPL-2.1-or-later
# Sourced by scripts/check-install and scripts/check-packages: `record LOG NAME RESULT FILE`
# appends one check to LOG as a line of meson's testlog.json (name, result OK/FAIL/SKIP, and
# FILE's text as its output), so that scripts/count-tests.py counts it with the meson tests,
# and prints the result.
record() {
  python3 - "$@" <<'PY'
import json, sys
log, name, result, out = sys.argv[1:5]
with open(out, errors="replace") as f:
    text = f.read()
with open(log, "a") as f:
    f.write(json.dumps({"name": name, "result": result, "stdout": text}) + "\n")
detail = {"OK": "", "SKIP": ": " + text.strip(), "FAIL": ":\n" + text}[result]
print(f"{result:4} {name}{detail}", file=sys.stderr)
PY
}

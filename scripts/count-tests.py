# SPDX-License-Identifier: LGPL-2.1-or-later
"""Counts the test cases behind meson test logs: GoogleTest cases from each gtest program's
result lines, pytest's from its summary line, node's test runner's from its closing '# pass N'
and '# fail N' (web/), one case for any other test (scripts/check-install and
scripts/check-packages write their checks in the same format). First a line for each case
that failed, naming its log, its test and the case (CI shows the end of the output, where the
failure's own log may not be). With one log, then prints 'tests: N passed, M failed' (and ',
K skipped' when a test was skipped); with several (one per build or step), a line for each and
then that line for them all."""
import json
import re
import sys


# A GoogleTest case that failed, by name (the list at the end repeats names without a time).
GTEST_FAILED = re.compile(r"^\[  FAILED  \] (.*) \(\d+ ms\)$", re.M)


def failed_cases(out):
    """The names of the cases that failed in a test's output: GoogleTest's, pytest's and
    node's test runner's."""
    return (GTEST_FAILED.findall(out) +
            re.findall(r"^FAILED (\S+)", out, re.M) +
            re.findall(r"^not ok \d+ - (.*)$", out, re.M))


def count(path):
    passed = failed = skipped = 0
    with open(path) as log:
        for line in log:
            test = json.loads(line)
            out = test.get("stdout") or ""
            if test["result"] not in ("OK", "EXPECTEDFAIL", "SKIP"):
                cases = failed_cases(out) or ["(no case named)"]
                for case in cases:
                    print(f"failed: {path}: {test['name']} ({test['result']}): {case}")
            ok = len(re.findall(r"^\[       OK \]", out, re.M))
            bad = len(GTEST_FAILED.findall(out))
            # pytest (tests/python): its closing summary, "== 3 failed, 21 passed in 2.1s ==".
            summary = re.findall(r"^=+ (.*\d+ (?:passed|failed|errors?).*) in [\d.]+s.* =+$",
                                 out, re.M)
            if summary and not (ok or bad):
                words = dict((w, int(n)) for n, w in re.findall(r"(\d+) (\w+)", summary[-1]))
                ok = words.get("passed", 0)
                bad = words.get("failed", 0) + words.get("error", 0) + words.get("errors", 0)
            node_pass = re.search(r"^# pass (\d+)$", out, re.M)
            node_fail = re.search(r"^# fail (\d+)$", out, re.M)
            if node_pass and node_fail:
                ok, bad = ok + int(node_pass.group(1)), bad + int(node_fail.group(1))
            if ok or bad:
                passed, failed = passed + ok, failed + bad
                if test["result"] != "OK" and not bad:
                    failed += 1  # crashed or timed out after its last finished case
            elif test["result"] in ("OK", "EXPECTEDFAIL"):
                passed += 1
            elif test["result"] == "SKIP":
                skipped += 1
            else:
                failed += 1
    return passed, failed, skipped


def line(passed, failed, skipped):
    return f"{passed} passed, {failed} failed" + (f", {skipped} skipped" if skipped else "")


total = [0, 0, 0]
for path in sys.argv[1:]:
    counts = count(path)
    if len(sys.argv) > 2:
        print(f"{path}: {line(*counts)}")
    total = [t + c for t, c in zip(total, counts)]
print(f"tests: {line(*total)}")

"""Counts the test cases behind a meson test log: GoogleTest cases from each gtest program's
result lines, one case for any other test. Prints 'tests: N passed, M failed'."""
import json
import re
import sys

passed = failed = 0
with open(sys.argv[1]) as log:
    for line in log:
        test = json.loads(line)
        out = test.get("stdout") or ""
        ok = len(re.findall(r"^\[       OK \]", out, re.M))
        bad = len(re.findall(r"^\[  FAILED  \] .*\(\d+ ms\)$", out, re.M))
        if ok or bad:
            passed, failed = passed + ok, failed + bad
            if test["result"] != "OK" and not bad:
                failed += 1  # crashed or timed out after its last finished case
        elif test["result"] in ("OK", "EXPECTEDFAIL"):
            passed += 1
        elif test["result"] != "SKIP":
            failed += 1
print(f"tests: {passed} passed, {failed} failed")

#!/usr/bin/env python3
"""Checks tools/unit_sizes.py against unit_sizes_fixture.cpp.in, whose `// expect: NAME LINES`
comments give every function and its length counted by hand, and its --check mode (exit status,
the violations listed)."""
import io
import os
import re
import sys
from contextlib import redirect_stdout

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "..", "tools"))
import unit_sizes  # noqa: E402

fixture = os.path.join(here, "unit_sizes_fixture.cpp.in")
text = open(fixture, encoding="utf-8").read()
expected = {}
for m in re.finditer(r"// expect: (.+) (\d+)\n", text):
    expected[m.group(1).split("::")[-1] if "::" not in m.group(1) else m.group(1)] = int(m.group(2))
found = {}
for name, first, last in unit_sizes.scan_functions(text):
    found[name] = last - first + 1
# members defined inside their class are reported by their own name
expected = {k.split("Widget::")[-1] if k == "Widget::resize" else k: v for k, v in expected.items()}
errors = []
if found != expected:
    errors.append(f"functions: expected {sorted(expected.items())}, found {sorted(found.items())}")

out = io.StringIO()
with redirect_stdout(out):
    status = unit_sizes.main([fixture, "--check", "--check-dirs", os.path.dirname(fixture),
                              "--max-function-lines", "10", "--max-file-lines", "80"])
lines = out.getvalue()
if status != 1 or "twice" not in lines or "square" in lines or "unit_sizes_fixture.cpp.in" not in lines:
    errors.append(f"--check: status {status}, output:\n{lines}")
out = io.StringIO()
with redirect_stdout(out):
    status = unit_sizes.main([fixture, "--check", "--check-dirs", os.path.dirname(fixture),
                              "--max-function-lines", "11", "--max-file-lines", "1000"])
if status != 0:
    errors.append(f"--check within the limits: status {status}, output:\n{out.getvalue()}")

for e in errors:
    print("FAIL:", e)
print("ok" if not errors else f"{len(errors)} failure(s)")
sys.exit(1 if errors else 0)

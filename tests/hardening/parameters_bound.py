#!/usr/bin/env python3
"""Parameters are bound once: every scene entry is declared by
add_parameter() or input::add_selection() (which bind it to the member it
sets), never by declare_entry() with a separate get() that could drift from
it; and --print-parameters gives every entry its documentation, its format
and its default. Usage: parameters_bound.py SOURCE_DIR PROGRAM"""
import glob
import re
import subprocess
import sys

failures = []
for path in glob.glob(sys.argv[1] + "/**/*.cc", recursive=True):
    text = open(path).read()
    for call in ("declare_entry", "get_double", "get_integer", "get_bool"):
        if re.search(r"\b" + call + r"\(", text):
            failures.append(f"{path}: {call}() (bind the entry with add_parameter)")
    if re.search(r"\bprm\.get\(", text):
        failures.append(f"{path}: prm.get() (bind the entry with add_parameter)")

listing = subprocess.run([sys.argv[2], "--print-parameters"], capture_output=True,
                         text=True, check=True).stdout
entries = 0
comment = []
for line in listing.splitlines():
    stripped = line.strip()
    if stripped.startswith("#"):
        comment.append(stripped)
    elif stripped.startswith("set "):
        entries += 1
        name = stripped[4:].split("=")[0].strip()
        formats = [c for c in comment if c.startswith("# Format: ")]
        if len(formats) != 1:
            failures.append(f"--print-parameters: '{name}' has no format line")
        if len(comment) - len(formats) < 1:
            failures.append(f"--print-parameters: '{name}' has no documentation")
        comment = []
    elif stripped:
        comment = []
if entries < 60:
    failures.append(f"--print-parameters lists {entries} entries, expected every one (> 60)")
for f in failures:
    print("FAIL:", f)
print(f"{entries} entries listed with documentation and format")
sys.exit(1 if failures else 0)

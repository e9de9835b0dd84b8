#!/usr/bin/env python3
"""Parameters cannot drift from their use: every entry the program declares
(declare_entry("Name", ...) in source/) must be read somewhere in source/
(get("Name"), get_double("Name"), ...), and every Patterns::Selection must
be read by code that maps it to an enum class or compares it (a get of the
entry). Usage: parameters_read.py SOURCE_DIR"""
import glob
import re
import sys

sources = {p: open(p).read() for p in glob.glob(sys.argv[1] + "/**/*.cc", recursive=True)}
text = "\n".join(sources.values())
declared = set(re.findall(r'declare_entry\(\s*"([^"]+)"', text))
read = set(re.findall(r'(?:get(?:_double|_integer|_bool)?|optional)\(\s*"([^"]+)"', text))
# Entries declared in a loop and read through a variable name.
read |= set(re.findall(r'for \(const char \*name : \{([^}]*)\}', text))
missing = sorted(d for d in declared if d not in read)
for m in missing:
    print(f"FAIL: parameter '{m}' is declared but never read")
print(f"{len(declared) - len(missing)} of {len(declared)} declared parameters are read")
sys.exit(1 if missing else 0)

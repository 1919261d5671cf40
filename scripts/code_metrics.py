#!/usr/bin/env python3
"""Size of the library's code and of its public surface, for before/after notes.

    python3 scripts/code_metrics.py [ROOT]      # ROOT: a checkout (default: this one)

Counts, over src/ (the binary's src/cli* and src/main.rs apart):
- lines of code: neither blank nor only a comment;
- `pub` declarations (functions, methods, types, fields, constants, traits, re-exports,
  modules), `pub(crate)` ones, and the `pub mod`s;
- the modules reachable from the crate root through `pub mod` only, and the `pub`
  declarations in them (the surface `cargo doc` shows);
- functions longer than 100 lines (from `fn` to its closing brace).
"""

import os
import re
import sys

root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
src = os.path.join(root, "src")


def library_files():
    for base, _, names in os.walk(src):
        for name in names:
            path = os.path.join(base, name)
            rel = os.path.relpath(path, src)
            if name.endswith(".rs") and not (rel.startswith("cli") or rel == "main.rs"):
                yield path


PUB = re.compile(r"\s*pub (fn|struct|enum|const|type|trait|static|use|mod|unsafe fn|\w+\s*:)")


def module_file(parent, name):
    base = os.path.dirname(parent) if parent.endswith(("lib.rs", "mod.rs")) else parent[:-3]
    for candidate in (os.path.join(base, name + ".rs"), os.path.join(base, name, "mod.rs")):
        if os.path.exists(candidate):
            return candidate
    return None


def public_files():
    found, stack = [], [os.path.join(src, "lib.rs")]
    while stack:
        path = stack.pop()
        found.append(path)
        for line in open(path, encoding="utf-8"):
            m = re.match(r"\s*pub mod (\w+);", line)
            if m and (child := module_file(path, m.group(1))):
                stack.append(child)
    return found


def long_functions(lines, limit=100):
    count, i = 0, 0
    while i < len(lines):
        if re.match(r"\s*(pub(\([^)]*\))? )?(const )?(async )?(unsafe )?fn \w+", lines[i]):
            depth, start, opened = 0, i, False
            j = i
            while j < len(lines):
                code = lines[j].split("//")[0]
                depth += code.count("{") - code.count("}")
                opened = opened or "{" in code
                if opened and depth <= 0:
                    break
                if not opened and code.rstrip().endswith(";"):
                    break
                j += 1
            if opened and j - start + 1 > limit:
                count += 1
            i = j + 1 if opened else i + 1
        else:
            i += 1
    return count


files = sorted(library_files())
loc = pub = crate = pub_mods = long = 0
for path in files:
    lines = open(path, encoding="utf-8").read().split("\n")
    loc += sum(1 for line in lines if line.strip() and not line.strip().startswith("//"))
    pub += sum(1 for line in lines if PUB.match(line))
    crate += sum(1 for line in lines if re.match(r"\s*pub\(crate\)", line))
    pub_mods += sum(1 for line in lines if re.match(r"\s*pub mod \w+", line))
    long += long_functions(lines)
reachable = public_files()
surface = sum(1 for path in reachable for line in open(path, encoding="utf-8") if PUB.match(line))
print(f"lines of code            {loc}")
print(f"pub declarations         {pub}")
print(f"pub(crate) declarations  {crate}")
print(f"pub mods                 {pub_mods}")
print(f"public modules           {len(reachable)} (with the crate root)")
print(f"pub in public modules    {surface}")
print(f"functions > 100 lines    {long}")

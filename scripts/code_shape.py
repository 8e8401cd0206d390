#!/usr/bin/env python3
"""Structure checks over the workspace's library code (crates/*/src and src/, test modules
excluded): import cycles between files, functions longer than a limit, and
`too_many_arguments` allowances.

Import edges are the `use` lines and `crate::`/`super::`/`self::` paths of each file (comments
dropped), resolved to the file defining the longest matching module; edges into the crate root
(lib.rs / main.rs, a re-export hub) are not counted. A cycle is a strongly connected group of
two or more files. A function's length is its lines from `fn` to the closing brace at the same
indentation.

Usage: python3 scripts/code_shape.py [--max-lines N]   (run from the repository's root)

Exits with status 1 when it finds any of the three (`.ci/run` runs it with the default limit).
"""

import os
import re
import sys

MAX_LINES = int(sys.argv[sys.argv.index("--max-lines") + 1]) if "--max-lines" in sys.argv else 100


def source_roots():
    roots = [os.path.join("crates", c, "src") for c in sorted(os.listdir("crates"))]
    return [r for r in roots + ["src"] if os.path.isdir(r)]


def module_path(src, path):
    parts = os.path.relpath(path, src)[:-3].split(os.sep)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return tuple(parts)


def expand(prefix, body):
    """`a::{b, c::{d}}` as full paths."""
    items, depth, cur = [], 0, ""
    for ch in body:
        depth += (ch == "{") - (ch == "}")
        if ch == "," and depth == 0:
            items.append(cur)
            cur = ""
        else:
            cur += ch
    items.append(cur)
    out = []
    for it in (i.strip() for i in items):
        if not it:
            continue
        m = re.match(r"^([\w:]*?)(?:::)?\{(.*)\}$", it, re.S)
        if m:
            out += expand(prefix + [p for p in m.group(1).split("::") if p], m.group(2))
        else:
            out.append(prefix + [p for p in re.split(r"\s+as\s+", it)[0].split("::") if p])
    return out


def cycles(src):
    files = {}
    for d, _, names in os.walk(src):
        for n in names:
            if n.endswith(".rs"):
                files[module_path(src, os.path.join(d, n))] = os.path.join(d, n)
    edges = {m: set() for m in files}
    for m, f in files.items():
        text = re.sub(r"//[^\n]*", "", open(f).read())
        paths = [p for u in re.finditer(r"\buse\s+([^;]+);", text) for p in expand([], u.group(1))]
        paths += [p.group(1).split("::") for p in re.finditer(r"\b((?:crate|super|self)(?:::\w+)+)", text)]
        for p in paths:
            if p[0] == "crate":
                full = p[1:]
            elif p[0] == "super":
                base, k = list(m)[:-1], 1
                while k < len(p) and p[k] == "super":
                    base, k = base[:-1], k + 1
                full = base + p[k:]
            elif p[0] == "self":
                full = list(m) + p[1:]
            else:
                continue
            for n in range(len(full), 0, -1):
                if tuple(full[:n]) in files:
                    if tuple(full[:n]) not in (m, ()):
                        edges[m].add(tuple(full[:n]))
                    break
    index, low, stack, on, groups, counter = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                groups.append(sorted("::".join(x) for x in group))

    for v in edges:
        if v not in index:
            visit(v)
    return groups


def long_functions(path):
    lines = open(path).read().split("\n")
    out, in_tests = [], False
    for i, line in enumerate(lines):
        if line.startswith("#[cfg(test)]"):
            in_tests = True
        m = re.match(r"^(\s*)(?:pub(?:\([\w:]+\))?\s+)?(?:const\s+)?(?:async\s+)?(?:unsafe\s+)?fn\s+(\w+)", line)
        if not m or in_tests or line.rstrip().endswith(";"):
            continue
        indent = m.group(1)
        for j in range(i + 1, len(lines)):
            if lines[j] == indent + "}":
                if j - i + 1 > MAX_LINES:
                    out.append((j - i + 1, f"{path}:{i + 1}", m.group(2)))
                break
    return out


def main():
    total_cycles, longs, allows = 0, [], []
    for src in source_roots():
        for group in cycles(src):
            total_cycles += 1
            print(f"cycle in {src}: {', '.join(group)}")
        for d, _, names in os.walk(src):
            for n in names:
                if n.endswith(".rs"):
                    p = os.path.join(d, n)
                    longs += long_functions(p)
                    for k, line in enumerate(open(p)):
                        if "too_many_arguments" in line:
                            allows.append(f"{p}:{k + 1}")
    for n, where, name in sorted(longs, reverse=True):
        print(f"{n:5} lines  {name}  {where}")
    for a in allows:
        print(f"too_many_arguments  {a}")
    print(f"import cycles: {total_cycles}; library functions over {MAX_LINES} lines: {len(longs)}; "
          f"too_many_arguments: {len(allows)}")
    return 1 if total_cycles or longs or allows else 0


if __name__ == "__main__":
    sys.exit(main())

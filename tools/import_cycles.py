#!/usr/bin/env python3
"""Import cycles between the files of a Rust crate.

Usage: tools/import_cycles.py [SRC_DIR ...]   (default: app/src core/src)

Each .rs file is a node; an edge A -> B means A names a path that resolves to the module
file B: `use crate::x::y`, an inline `crate::x::y::f()`, `super::...`, or a path into one of
A's own submodules (`use render::RenderJob`, `fmt::run(..)`). Not counted: `mod x;` lines,
and `pub use` of A's own submodules (a folder's mod.rs re-exporting its files' items is its
interface, not a dependency). Test modules (`#[cfg(test)] mod tests { ... }` to the end of
the file) are skipped: they may use anything. Prints each
cycle (a strongly connected component of more than one file) and exits 1 if there is any.
"""
import os
import re
import sys


def modules(src):
    """Module path (tuple) -> file, for every .rs file under src."""
    out = {}
    for root, _, files in os.walk(src):
        for f in files:
            if not f.endswith(".rs"):
                continue
            path = os.path.join(root, f)
            rel = os.path.relpath(path, src)[:-3].split(os.sep)
            if rel[-1] in ("mod", "lib", "main"):
                rel = rel[:-1]
            out[tuple(rel)] = path
    return out


def strip(text):
    """The code without comments, strings and char literals (a small Rust lexer)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            i = text.find("\n", i)
            i = n if i < 0 else i
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    i += 1
        elif re.match(r'b?r(#*)"', text[i : i + 40]) and (i == 0 or not text[i - 1].isalnum()):
            m = re.match(r'b?r(#*)"', text[i:])
            end = text.find('"' + m.group(1), i + m.end())
            i = n if end < 0 else end + 1 + len(m.group(1))
            out.append('""')
        elif c == '"':
            i += 1
            while i < n and text[i] != '"':
                i += 2 if text[i] == "\\" else 1
            i += 1
            out.append('""')
        elif c == "'" and re.match(r"'(\\[^']*|[^\\'])'", text[i : i + 12]):
            i += re.match(r"'(\\[^']*|[^\\'])'", text[i : i + 12]).end()
            out.append("' '")
        else:
            out.append(c)
            i += 1
    text = "".join(out)
    # `#[cfg(test)]` or `#[cfg(all(test, unix))]` and the like.
    m = re.search(r"#\[cfg\((?:all\()?test\b[^\]]*\]\s*mod\s+\w+\s*\{", text)
    return text[: m.start()] if m else text


def paths_in(text):
    """Every `crate::a::b::{c, d}` / `super::a` path, expanded one level of braces."""
    for m in re.finditer(r"\b(crate|super)(?=::)((?:::\w+)*)(::\{([^}]*)\})?", text):
        head = [m.group(1)] + [p for p in m.group(2).split("::") if p]
        if m.group(4) is not None:
            for item in m.group(4).split(","):
                item = item.strip().split(" as ")[0]
                if item:
                    yield head + [p for p in item.split("::") if p and p != "self"]
        else:
            yield head


def resolve(path, here, mods):
    if path[0] == "crate":
        parts = path[1:]
    else:  # super, possibly repeated
        base = list(here)
        while path and path[0] == "super":
            base = base[:-1]
            path = path[1:]
        parts = base + list(path)
    # The longest prefix that is a module file.
    for n in range(len(parts), -1, -1):
        if tuple(parts[:n]) in mods:
            return tuple(parts[:n])
    return ()


def import_graph(src):
    """(module -> file, module -> the modules it imports) for the crate under src."""
    mods = modules(src)
    graph = {m: set() for m in mods}
    for m, f in mods.items():
        # A file's own submodule files are reached through `mod` declarations, not imports.
        text = strip(open(f, encoding="utf-8").read())
        for p in paths_in(text):
            t = resolve(p, m, mods)
            if t != m:
                graph[m].add(t)
        own = re.sub(r"\bpub(\([\w:]+\))?\s+use\s+(self::)?\w+::[^;]*;", "", text)
        own = re.sub(r"\bmod\s+\w+\s*;", "", own)
        for c in re.finditer(r"(?<![:\w])(\w+)::", own):
            if m + (c.group(1),) in mods:
                graph[m].add(m + (c.group(1),))
    return mods, graph


def cycles(src):
    mods, graph = import_graph(src)
    # Tarjan's strongly connected components.
    index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                sccs.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in graph:
        if v not in index:
            visit(v)
    name = lambda m: os.path.relpath(mods[m], src)
    edges = sum(len(v) for v in graph.values())
    return [[name(m) for m in c] for c in sccs], len(mods), edges


def main():
    srcs = sys.argv[1:] or ["app/src", "core/src"]
    bad = False
    for src in srcs:
        found, files, edges = cycles(src)
        print(f"{src}: {files} files, {edges} import edges, {len(found)} cycle(s)")
        for c in found:
            bad = True
            print("  cycle: " + " <-> ".join(c))
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()

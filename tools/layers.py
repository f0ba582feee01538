#!/usr/bin/env python3
"""Upward imports between the layers of a crate.

Usage: tools/layers.py [SRC_DIR ...]   (default: app/src core/src)

A layer is a tier of top-level folders and files of a crate (`gui/`, `story.rs`), listed
below from the top; ARCHITECTURE.md writes the same order. A file may import from its own
unit, from units of its own tier and from any tier below; an import of a unit in a tier
above is an upward import and fails, as does a unit that no tier lists (place a new folder
or file here first). Imports are found as tools/import_cycles.py finds them (test modules
and `tests.rs` files, which may use anything, are skipped). Exits 1 on any failure.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from import_cycles import import_graph  # noqa: E402

# Top tier first. The crate root (lib.rs, main.rs) is above every tier.
LAYERS = {
    "core/src": [
        ["render", "format"],
        ["scene"],
        ["accel"],
        ["geometry"],
        ["memory", "simd", "test_data"],
    ],
    "app/src": [
        ["cli"],
        ["bench", "gui"],
        ["animation", "document", "render_worker", "story", "navigation", "bounds"],
        ["node_label", "logging", "test_support"],
        ["io"],
        ["exit"],
    ],
}


def tiers_of(src):
    key = os.path.normpath(src).replace(os.sep, "/")
    return next((t for k, t in LAYERS.items() if key.endswith(k)), None)


def check(src):
    tiers = tiers_of(src)
    if tiers is None:
        return [f"no layer order for {src}"], 0
    rank = {u: i for i, tier in enumerate(tiers) for u in tier}
    mods, graph = import_graph(src)
    bad = []
    for m in sorted(mods):
        if m and m[0] not in rank:
            bad.append(f"{os.path.relpath(mods[m], src)}: `{m[0]}` is in no layer")
    seen = 0
    for a in sorted(graph):
        if not a or os.path.basename(mods[a]) == "tests.rs":
            continue
        for b in sorted(graph[a]):
            if not b or b[0] == a[0] or a[0] not in rank or b[0] not in rank:
                continue
            seen += 1
            if rank[b[0]] < rank[a[0]]:
                bad.append(
                    f"upward: {os.path.relpath(mods[a], src)} ({a[0]}) imports "
                    f"{os.path.relpath(mods[b], src)} ({b[0]}, a higher layer)"
                )
    return bad, seen


def main():
    srcs = sys.argv[1:] or ["app/src", "core/src"]
    failed = False
    for src in srcs:
        bad, seen = check(src)
        tiers = tiers_of(src) or []
        order = " > ".join(", ".join(t) for t in tiers)
        print(f"{src}: {seen} imports between layers, {len(bad)} upward or unplaced ({order})")
        for b in bad:
            failed = True
            print("  " + b)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Two JSON files compared by structure: keys only in one, values of another type, and for the
numbers both have, how much they changed.

    scripts/json-diff.py BEFORE.json AFTER.json

Paths are written like `tests[3].eij.EXY.value`; lists are compared element by element (a
list of different length is reported with both lengths). The numbers' report groups the
changed ones by path with the array indices removed (`tests[].eij.EXY.value`), each with the
count and the largest relative change |a − b| / max(|a|, |b|). Used by
scripts/demo-outputs-diff.sh; exit 0 always (it only describes).
"""
import json
import re
import sys
from collections import defaultdict


def walk(b, a, path, out):
    if isinstance(b, dict) and isinstance(a, dict):
        for k in b:
            if k not in a:
                out["only_before"].append(f"{path}.{k}" if path else k)
        for k in a:
            if k not in b:
                out["only_after"].append(f"{path}.{k}" if path else k)
        for k in b:
            if k in a:
                walk(b[k], a[k], f"{path}.{k}" if path else k, out)
    elif isinstance(b, list) and isinstance(a, list):
        if len(b) != len(a):
            out["length"].append(f"{path}: {len(b)} -> {len(a)}")
        for i, (x, y) in enumerate(zip(b, a)):
            walk(x, y, f"{path}[{i}]", out)
    elif isinstance(b, bool) or isinstance(a, bool) or b is None or a is None:
        if b != a:
            out["values"].append(f"{path}: {json.dumps(b)} -> {json.dumps(a)}")
    elif isinstance(b, (int, float)) and isinstance(a, (int, float)):
        if b != a:
            rel = abs(a - b) / max(abs(a), abs(b))
            group = re.sub(r"\[\d+\]", "[]", path)
            out["numbers"][group].append((rel, path, b, a))
    elif type(b) is not type(a):
        out["values"].append(f"{path}: {type(b).__name__} -> {type(a).__name__}")
    elif b != a:
        out["values"].append(f"{path}: {json.dumps(b)[:80]} -> {json.dumps(a)[:80]}")


def main():
    with open(sys.argv[1]) as f:
        before = json.load(f)
    with open(sys.argv[2]) as f:
        after = json.load(f)
    out = {"only_before": [], "only_after": [], "length": [], "values": [],
           "numbers": defaultdict(list)}
    walk(before, after, "", out)
    for key, title in [("only_before", "keys only in BEFORE"), ("only_after", "keys only in AFTER"),
                       ("length", "lists of another length"), ("values", "other values changed")]:
        items = out[key]
        if items:
            print(f"   {title} ({len(items)}):")
            for item in items[:30]:
                print(f"     {item}")
            if len(items) > 30:
                print(f"     … {len(items) - 30} more")
    if out["numbers"]:
        print(f"   numbers changed ({sum(len(v) for v in out['numbers'].values())}), by path:")
        for group, items in sorted(out["numbers"].items(), key=lambda g: -max(i[0] for i in g[1])):
            rel, path, b, a = max(items)
            print(f"     {group}: {len(items)} changed, largest relative {rel:.2e} ({path}: {b} -> {a})")


if __name__ == "__main__":
    main()

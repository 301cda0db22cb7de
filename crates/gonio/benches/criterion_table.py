#!/usr/bin/env python3
"""Summarise `cargo bench -p gonio --bench mapping` into a Markdown table (median per sample).

Reads target/criterion/*/**/new/estimates.json (criterion's own output); prints Markdown.
Usage: python3 crates/gonio/benches/criterion_table.py [TARGET_DIR]
"""
import json, os, sys

root = os.path.join(sys.argv[1] if len(sys.argv) > 1 else "target", "criterion")
METHODS = ["hds", "piecewise-constant", "bilinear", "rejection", "uniform"]


def median_ns(path):
    try:
        with open(os.path.join(path, "new", "estimates.json")) as f:
            return json.load(f)["median"]["point_estimate"]
    except OSError:
        return None


def fmt(x, unit=1.0, digits=1):
    return "—" if x is None else f"{x / unit:.{digits}f}"


for grid in ["19x36", "181x361", "1024x1024"]:
    print(f"\n#### {grid.replace('x', ' × ')} (parallels × meridians)\n")
    print("| method | build ms | sample ns | pdf ns | invert ns |")
    print("|---|---|---|---|---|")
    for m in METHODS:
        b = median_ns(os.path.join(root, f"build_{grid}", m))
        per = [median_ns(os.path.join(root, f"per-sample_{grid}", op, m)) for op in ["sample", "pdf", "invert"]]
        print(f"| {m} | {fmt(b, 1e6, 2)} | " + " | ".join(fmt(p, 4096) for p in per) + " |")

print("\n#### Batch sampling, 181 × 361, 2^18 points (wall time per sample)\n")
print("| method | 1 thread ns | all threads ns | scaling |")
print("|---|---|---|---|")
bdir = os.path.join(root, "batch_181x361")
for m in METHODS:
    d = os.path.join(bdir, m)
    if not os.path.isdir(d):
        continue
    runs = sorted(os.listdir(d))
    one = median_ns(os.path.join(d, "1-threads"))
    many = [r for r in runs if r != "1-threads" and r.endswith("-threads")]
    alln = median_ns(os.path.join(d, many[0])) if many else None
    sc = f"{one / alln:.2f} ({many[0]})" if one and alln else "—"
    print(f"| {m} | {fmt(one, 1 << 18)} | {fmt(alln, 1 << 18)} | {sc} |")

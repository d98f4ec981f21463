#!/usr/bin/python3
"""Prints the side-by-side ratios of a Google Benchmark CSV: for each argument (mesh), the
reference benchmark's time divided by Flexfit's (median rows when repetitions were run).
Usage: bench_ratios.py CSV FLEXFIT_PREFIX REFERENCE_PREFIX"""
import csv
import sys


def load(path):
    rows = {}
    with open(path, newline="") as f:
        lines = [line for line in f if not line.startswith(("Run on", "CPU", "  L", "Load", "***"))]
    start = next(i for i, line in enumerate(lines) if line.startswith("name,"))
    for row in csv.DictReader(lines[start:]):
        name = row["name"]
        if "_mean" in name or "_stddev" in name or "_cv" in name:
            continue
        rows[name.replace("_median", "")] = row
    return rows


def main(path, ours, reference):
    rows = load(path)
    print(f"| model | {reference} (ns) | {ours} (ns) | speed-up |")
    print("|---|---|---|---|")
    for name, row in rows.items():
        if not name.startswith(ours + "/"):
            continue
        arg = name.split("/", 1)[1]
        ref = rows.get(f"{reference}/{arg}")
        if ref is None:
            continue
        t_ours, t_ref = float(row["real_time"]), float(ref["real_time"])
        print(f"| {row['label']} | {t_ref:.0f} | {t_ours:.0f} | {t_ref / t_ours:.2f}x |")


if __name__ == "__main__":
    main(*sys.argv[1:4])

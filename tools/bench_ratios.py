#!/usr/bin/python3
"""Side-by-side ratios from a Google Benchmark CSV (median rows when repetitions were run).

  bench_ratios.py CSV --prefixes OURS REFERENCE    per argument: time(REFERENCE) / time(OURS)
  bench_ratios.py CSV --pair A B [--pair C D ...]  time(A) / time(B) for full benchmark names
  bench_ratios.py CSV --counter NAME               the counter NAME of every benchmark that has it
  --statistic min                                  the "_min" rows instead (each benchmark's
                                                   fastest repetition, where the benchmark adds it)
"""
import argparse
import csv


AGGREGATES = ("_mean", "_median", "_stddev", "_cv", "_min")


def load(path, statistic="median"):
    """Each benchmark's row: its aggregate `statistic` when repetitions were run, else its one run."""
    rows = {}
    with open(path, newline="") as f:
        lines = f.readlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("name,"))
    for row in csv.DictReader(lines[start:]):
        name = row["name"]
        if name.endswith("_" + statistic):
            rows[name[: -len(statistic) - 1]] = row
        elif not name.endswith(AGGREGATES):
            rows.setdefault(name, row)
    return rows


def prefixes(rows, ours, reference):
    print(f"| model | {reference} (ns) | {ours} (ns) | speed-up |")
    print("|---|---|---|---|")
    for name, row in rows.items():
        if not name.startswith(ours + "/"):
            continue
        ref = rows.get(f"{reference}/{name.split('/', 1)[1]}")
        if ref is not None:
            t_ours, t_ref = float(row["real_time"]), float(ref["real_time"])
            print(f"| {row['label']} | {t_ref:.0f} | {t_ours:.0f} | {t_ref / t_ours:.2f}x |")


def pairs(rows, wanted):
    print("| A | B | time A (ns) | time B (ns) | A / B |")
    print("|---|---|---|---|---|")
    for a, b in wanted:
        ta, tb = float(rows[a]["real_time"]), float(rows[b]["real_time"])
        print(f"| {a} ({rows[a]['label']}) | {b} ({rows[b]['label']}) | {ta:.1f} | {tb:.1f} | {ta / tb:.3f} |")


def counter(rows, name):
    print(f"| benchmark | what | {name} |")
    print("|---|---|---|")
    for bench, row in rows.items():
        if row.get(name):
            print(f"| {bench} | {row['label']} | {float(row[name]):.3f} |")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("csv")
    parser.add_argument("--prefixes", nargs=2)
    parser.add_argument("--pair", nargs=2, action="append", default=[])
    parser.add_argument("--counter")
    parser.add_argument("--statistic", choices=("median", "min"), default="median")
    args = parser.parse_args()
    rows = load(args.csv, args.statistic)
    if args.prefixes:
        prefixes(rows, *args.prefixes)
    if args.pair:
        pairs(rows, args.pair)
    if args.counter:
        counter(rows, args.counter)


if __name__ == "__main__":
    main()

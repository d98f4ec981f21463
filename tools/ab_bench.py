#!/usr/bin/python3
"""Two builds of one Google Benchmark binary, side by side, against a reference in each run.

Runs BEFORE and AFTER alternately (their order swapped every round, so the machine's drift falls
on both alike), each with `--benchmark_repetitions=3`, random interleaving and a 0.2 s minimum
time, and takes every benchmark's median over the rounds of its per-run medians. For each
benchmark not under the reference prefix: both times, before / after, and each build's
reference time (the benchmark of the same argument under --reference) over its own.

  tools/ab_bench.py --bench before=/tmp/base/build/release/bench/bench_msd_step \\
      --bench after=build/release/bench/bench_msd_step \\
      --filter 'BM_(FlexfitFullStep|NaiveFullStep|FlexfitAvx2)/' --reference BM_NaiveFullStep \\
      --rounds 8 --csv bench/results/fused_position_check.csv
"""
import argparse
import collections
import csv
import json
import statistics
import subprocess


def run_report(binary, pattern, *flags):
    """One run of a benchmark binary as a JSON report: 3 repetitions, 0.2 s minimum, aggregates only."""
    return subprocess.run([binary, f"--benchmark_filter={pattern}", "--benchmark_repetitions=3", "--benchmark_min_time=0.2",
                           *flags, "--benchmark_report_aggregates_only=true", "--benchmark_format=json"],
                          capture_output=True, text=True, check=True).stdout


def median_rows(report):
    """The median rows (dicts, with their counters) of a benchmark JSON report."""
    return [bm for bm in json.loads(report)["benchmarks"] if bm.get("aggregate_name") == "median"]


def medians(report):
    """(run_name, label, real time in ns) of each median row of a benchmark JSON report."""
    for bm in median_rows(report):
        yield bm["run_name"], bm.get("label", ""), bm["real_time"] * {"ns": 1, "us": 1e3, "ms": 1e6}[bm["time_unit"]]


def table(times, labels, builds, reference, rounds):
    """Rows of the CSV from times[(build, run_name)] = [ns per round]."""
    (first, second) = builds
    rows = []
    for name in sorted({n for (_, n) in times}):
        if name.startswith(reference + "/"):
            continue
        ref = reference + "/" + name.split("/", 1)[1]
        b, a = (statistics.median(times[(x, name)]) for x in builds)
        nb, na = (statistics.median(times[(x, ref)]) for x in builds)
        rows.append([name, labels[name], f"{b / 1e3:.3f}", f"{a / 1e3:.3f}", f"{b / a:.3f}", f"{nb / 1e3:.3f}",
                     f"{na / 1e3:.3f}", f"{nb / b:.3f}", f"{na / a:.3f}", rounds])
    header = ["benchmark", "mesh", f"{first}_us", f"{second}_us", "speedup", f"naive_{first}_us", f"naive_{second}_us",
              f"{first}_over_naive", f"{second}_over_naive", "rounds"]
    return header, rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", action="append", required=True, help="NAME=PATH, twice: the build before, then after")
    ap.add_argument("--filter", required=True)
    ap.add_argument("--reference", required=True, help="benchmark name prefix of the reference, e.g. BM_NaiveFullStep")
    ap.add_argument("--rounds", type=int, default=8)
    ap.add_argument("--csv", required=True)
    args = ap.parse_args()
    builds = [b.split("=", 1) for b in args.bench]
    if len(builds) != 2:
        ap.error("--bench twice: before, then after")
    times, labels = collections.defaultdict(list), {}
    for r in range(args.rounds):
        for name, path in builds if r % 2 == 0 else builds[::-1]:
            report = run_report(path, args.filter, "--benchmark_enable_random_interleaving=true")
            for run_name, label, ns in medians(report):
                times[(name, run_name)].append(ns)
                labels[run_name] = label
    header, rows = table(times, labels, [n for n, _ in builds], args.reference, args.rounds)
    with open(args.csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)
    for row in rows:
        print(f"{row[0]:24s} {row[1][:34]:34s} {row[2]:>10} -> {row[3]:>10} us  {row[4]}x   vs reference {row[7]} -> {row[8]}x")


if __name__ == "__main__":
    main()

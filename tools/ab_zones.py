#!/usr/bin/python3
"""Two builds of bench_zone_coverage side by side: each region's step time over the whole model's.

Runs BEFORE and AFTER alternately (their order swapped every round, so the machine's drift falls on
both alike), each with `--benchmark_repetitions=3`, a 0.2 s minimum time and aggregates only, and
takes the median over the rounds of each build's per-run median counters: region_over_whole (the
region step alone), chosen_over_whole (the default rule), and the region's cost per computed
spring against the whole model's (region_over_whole / coverage).

  tools/ab_zones.py --before /tmp/old/build/bench/bench_zone_coverage \\
      --after build/release/bench/bench_zone_coverage --filter 'BM_Zones/' --rounds 3 \\
      --csv bench/results/vector_octets_1206.csv
"""
import argparse
import collections
import csv
import statistics

from ab_bench import median_rows, run_report


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--filter", default="BM_Zones/")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--csv", required=True)
    args = ap.parse_args()
    builds = {"before": args.before, "after": args.after}
    values = collections.defaultdict(list)
    info = {}
    for r in range(args.rounds):
        for build in (["before", "after"] if r % 2 == 0 else ["after", "before"]):
            for bm in median_rows(run_report(builds[build], args.filter)):
                values[(bm["run_name"], build, "region")].append(bm["region_over_whole"])
                values[(bm["run_name"], build, "chosen")].append(bm["chosen_over_whole"])
                info[bm["run_name"]] = (bm["label"], bm["coverage"])
    names = sorted(info, key=lambda n: tuple(int(x) for x in n.split("/")[1:3]))
    with open(args.csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["name", "label", "coverage", "region_before", "region_after", "after_over_before", "chosen_before",
                    "chosen_after", "region_per_spring_before", "region_per_spring_after"])
        for n in names:
            label, coverage = info[n]
            rb, ra = (statistics.median(values[(n, b, "region")]) for b in ("before", "after"))
            cb, ca = (statistics.median(values[(n, b, "chosen")]) for b in ("before", "after"))
            w.writerow([n, label, f"{coverage:.3f}", f"{rb:.3f}", f"{ra:.3f}", f"{ra / rb:.3f}", f"{cb:.3f}", f"{ca:.3f}",
                        f"{rb / coverage:.2f}", f"{ra / coverage:.2f}"])
    print(open(args.csv).read(), end="")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""In-contact step tails of example scenes under each rigid-deformable query, side by side.

For each round, each scene and each query (`auto`, `faces`, `point-shell`), runs
`flexfit run` on a copy of the scene with `[world] rigid_deformable_query` set, and reads
summary.json's contact_step_us_p50 / p99 / max. Runs alternate, so the machine's drift falls
on every column alike; the medians over rounds are written.

  tools/query_tails.py --flexfit build/release/apps/flexfit/flexfit \
      --scene examples/ball_torus.toml --scene examples/ball_torus_friction.toml \
      --csv bench/results/query_tails.csv
"""
import argparse
import csv
import json
import os
import re
import statistics
import subprocess
import tempfile


def with_query(text, query):
    text = re.sub(r'(?m)^rigid_deformable_query\s*=.*\n', '', text)
    return re.sub(r'(?m)^\[world\]\s*$', '[world]\nrigid_deformable_query = "%s"' % query, text, count=1)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--flexfit", required=True)
    ap.add_argument("--scene", action="append", required=True)
    ap.add_argument("--query", action="append", default=None)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--csv", required=True)
    args = ap.parse_args()
    queries = args.query or ["auto", "faces"]
    keys = ["contact_steps", "contact_step_us_p50", "contact_step_us_p99", "contact_step_us_max"]
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.rounds):
            for scene in args.scene:
                text = open(scene).read()
                for query in queries:
                    name = os.path.splitext(os.path.basename(scene))[0]
                    path = os.path.join(os.path.dirname(os.path.abspath(scene)), ".%s_%s.toml" % (name, query))
                    with open(path, "w") as f:
                        f.write(with_query(text, query))
                    try:
                        out = os.path.join(tmp, "%s_%s" % (name, query))
                        subprocess.run([args.flexfit, "run", path, "--out", out], check=True, stdout=subprocess.DEVNULL)
                    finally:
                        os.remove(path)
                    summary = json.load(open(os.path.join(out, "summary.json")))
                    row = results.setdefault((name, query), {k: [] for k in keys + ["state_hash"]})
                    for k in keys:
                        row[k].append(summary[k])
                    row["state_hash"].append(summary["state_hash"])
    with open(args.csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "query"] + keys + ["state_hash", "rounds"])
        for (name, query), row in results.items():
            assert len(set(row["state_hash"])) == 1, (name, query, "not deterministic")
            w.writerow([name, query] + ["%.1f" % statistics.median(row[k]) for k in keys] + [row["state_hash"][0], args.rounds])
    print(open(args.csv).read(), end="")


if __name__ == "__main__":
    main()

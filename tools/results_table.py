"""Shared by the measuring scripts in tools/: a list of rows printed as a Markdown table and
written as CSV (bench/results/)."""
import csv
import tempfile
from pathlib import Path


def report(rows, csv_path=None):
    """Prints `rows` (dicts with the same keys) as a Markdown table, floats to one decimal, and
    writes them to `csv_path` as given when there is one."""
    keys = list(rows[0])
    print("| " + " | ".join(keys) + " |")
    print("|" + "---|" * len(keys))
    for row in rows:
        print("| " + " | ".join(f"{row[k]:.1f}" if isinstance(row[k], float) else str(row[k]) for k in keys) + " |")
    if csv_path:
        with open(csv_path, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=keys)
            writer.writeheader()
            writer.writerows(rows)


def alternating_runs(builds, scenes, rounds, run):
    """run(path, scene, out) for every scene and (name, path) of `builds`, `rounds` times, the
    builds' order reversed every other round so that the machine's drift falls on each alike
    (`out`: a scratch directory per build). Returns {(scene, name): [run's results, in order]}."""
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(rounds):
            order = builds if r % 2 == 0 else builds[::-1]
            for scene in scenes:
                for name, path in order:
                    results.setdefault((scene, name), []).append(run(path, scene, str(Path(tmp) / name)))
    return results

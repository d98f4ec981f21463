"""Shared by the measuring scripts in tools/: a list of rows printed as a Markdown table and
written as CSV (bench/results/)."""
import csv


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

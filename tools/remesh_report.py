#!/usr/bin/python3
"""Simulation remeshing on third-party meshes: `flexfit remesh` on Debian's assimp test models at
target edges set as shares of each part's bounding-box diagonal; the quality before and after
(smallest angle, share of triangles with an angle below 20 degrees, edge-length spread) and the
Hausdorff distance as a share of the diagonal, one CSV row per mesh and edge. Each is remeshed
twice: keeping every sharp edge (`--thin-features keep`: its slivers and Hausdorff distance in the
`*_keep` columns) and as by default (`auto`: rounding thin features where that leaves fewer
slivers within the target edge of the input; `thin_features` says what it did; `dropped_faces`
counts the output faces left of zero area and dropped).

  tools/remesh_report.py --flexfit build/release/apps/flexfit/flexfit --csv bench/results/remesh.csv
"""
import argparse
import re
import subprocess
import tempfile
import time

from results_table import report

MODELS = "/usr/share/assimp/models"
MESHES = [f"{MODELS}/OFF/Wuson.off", f"{MODELS}/STL/Spider_binary.stl", f"{MODELS}/OBJ/regr01.obj", f"{MODELS}/STL/3DSMaxExport.STL"]
SHARES = [0.005, 0.01, 0.02]  # target edge / bounding-box diagonal

QUALITY = re.compile(r"(input|output)\s+(\d+) faces, min angle\s+([0-9.]+) deg,\s+([0-9.]+) % of triangles.*spread ([0-9.]+)")
DROPPED = re.compile(r"(\d+) degenerate output faces dropped")
HAUSDORFF = re.compile(r"Hausdorff distance (\S+) \(([0-9.]+) % of the bounding-box diagonal ([0-9.e+-]+)\)")


def diagonal(flexfit, mesh):
    out = subprocess.run([flexfit, "info", mesh, "--json"], check=True, capture_output=True, text=True).stdout
    lo, hi = ([float(x) for x in re.search(key + r'": \[([^\]]+)\]', out).group(1).split(",")] for key in ("bbox_min", "bbox_max"))
    return sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5


def remesh(flexfit, mesh, out, edge, *options):
    start = time.perf_counter()
    run = subprocess.run([flexfit, "remesh", mesh, out, "--edge", f"{edge:.6g}", *options], check=True, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    q = {m.group(1): m.groups()[1:] for m in QUALITY.finditer(run.stdout)}
    h = HAUSDORFF.search(run.stdout)
    thin = "rounded" if "thin features rounded" in run.stdout else "kept" if "thin features kept" in run.stderr else "none"
    dropped = DROPPED.search(run.stderr)
    return q, h.group(2), thin, dropped.group(1) if dropped else "0", seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--flexfit", required=True)
    parser.add_argument("--csv")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as directory:
        for mesh in MESHES:
            d = diagonal(args.flexfit, mesh)
            for share in SHARES:
                kept, hausdorff_kept, _, _, _ = remesh(args.flexfit, mesh, f"{directory}/out.obj", share * d, "--thin-features", "keep")
                q, hausdorff, thin, dropped, seconds = remesh(args.flexfit, mesh, f"{directory}/out.obj", share * d)
                rows.append({"mesh": mesh.split("/")[-1], "edge_share": f"{share:g}", "faces_in": q["input"][0], "min_angle_in": q["input"][1],
                             "slivers_in_pct": q["input"][2], "spread_in": q["input"][3], "slivers_keep_pct": kept["output"][2],
                             "hausdorff_keep_pct": hausdorff_kept, "thin_features": thin, "faces_out": q["output"][0],
                             "min_angle_out": q["output"][1], "slivers_out_pct": q["output"][2], "spread_out": q["output"][3],
                             "hausdorff_pct": hausdorff, "dropped_faces": dropped, "seconds": f"{seconds:.2f}"})
    report(rows, args.csv)


if __name__ == "__main__":
    main()

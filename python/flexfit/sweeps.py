"""Parameter sweeps on a Dask distributed cluster (Debian's python3-distributed).

``sweep(path, out)`` runs a sweep file's missing runs on a local cluster (``workers``
processes) or on any scheduler (``scheduler="tcp://host:8786"``): the only change between a
laptop and a cluster (Dask on Slurm, Kubernetes or SSH). Each run is one task calling the C++
runner, which writes ``out/runs/<id>/`` and the run's row; the table ``out/results.csv`` is
then written from the rows in the sweep's order, so it is the same bit for bit whatever the
number of workers, the order runs finish in, or whether the sweep was interrupted and
restarted (a restart runs only the runs without a row). ``flexfit sweep`` (the command) runs
the same runs on threads and writes the same table.

On a remote cluster every worker must import the same flexfit build and see ``out`` and the
sweep's files at the same paths (a shared file system).
"""

import os
import pathlib

_loaded = {}


def _load(path, run, run_id, read):
    """The sweep on a worker, loaded once per version of the file and read options (a worker
    that outlives a sweep, on a long-lived cluster, reloads an edited file); checks the run is
    the one meant."""
    from . import _flexfit

    stat = os.stat(path)
    key = (path, stat.st_mtime_ns, stat.st_size, read)
    if key not in _loaded:
        _loaded.clear()
        # The client checked the runs.
        _loaded[key] = _flexfit.load_sweep(path, check_runs=False, strict=read[0], remesh_cache=read[1])
    s = _loaded[key]
    if run >= len(s) or s.run_ids[run] != run_id:
        raise RuntimeError(f"{path} changed while its sweep was running (run {run_id} is no longer run {run})")
    return s


def _run_one(path, run, run_id, out, read):
    """One run on a worker; returns (its id, whether it ran now)."""
    from . import _flexfit

    return run_id, _flexfit.run_sweep_run(_load(path, run, run_id, read), run, out)


def sweep(path, out, scheduler=None, workers=2, table=True, strict=False, remesh_cache=None):
    """Runs the sweep file ``path`` into the directory ``out`` on a Dask cluster.

    scheduler: None for a LocalCluster of ``workers`` processes (one thread each), or the
        address of a running scheduler (``workers`` is then ignored).
    table: return the results as a pandas DataFrame (python3-pandas), else the CSV's path.
    strict, remesh_cache: as ``load_scene``'s, for every run's scene (on a remote cluster the
        cache directory is a path on the workers; None: each worker's default).

    The DataFrame's ``attrs["ran"]`` lists the ids run by this call (the others were done).
    Raises flexfit.InputError for a bad sweep file, before anything runs.
    """
    from distributed import Client, LocalCluster

    from . import _flexfit

    path = str(pathlib.Path(path).resolve())
    out = str(pathlib.Path(out).resolve())
    # A relative cache directory is the client's, whatever a worker's working directory is ("" is off).
    cache = remesh_cache if remesh_cache in (None, "") else str(pathlib.Path(remesh_cache).resolve())
    read = (bool(strict), cache)
    s = _flexfit.load_sweep(path, strict=read[0], remesh_cache=read[1])
    os.makedirs(out, exist_ok=True)
    missing = _flexfit.missing_sweep_runs(s, out)
    ran = []
    if missing:
        cluster = None
        if scheduler is None:
            # Worker processes import this very package: its directory goes on their path.
            package_parent = str(pathlib.Path(__file__).resolve().parent.parent)
            paths = [package_parent] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
            os.environ["PYTHONPATH"] = os.pathsep.join(dict.fromkeys(paths))
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster if cluster is not None else scheduler)
        try:
            ids = [s.run_ids[r] for r in missing]
            n = len(missing)
            futures = client.map(_run_one, [path] * n, missing, ids, [out] * n, [read] * n, pure=False)
            ran = [run_id for run_id, now in client.gather(futures) if now]
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    csv = _flexfit.write_sweep_table(s, out)
    if not table:
        return csv
    import pandas

    frame = pandas.read_csv(csv, dtype={"run": str, "state_hash": str})
    frame.attrs["ran"] = ran
    return frame

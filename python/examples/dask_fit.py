"""Fit a database of measured spectra over partitions with Dask, on a laptop or a cluster.

    pip install ./python "dask[distributed]"
    python python/examples/dask_fit.py --workers 2 --spectra 400 --method multipole

The spectra (here the ISSA subset in validation/data, repeated to --spectra) become a dask array
chunked along the spectra; each chunk is one `spectral_skin.fit_spectrum` call on one worker
(`threads=1`: the workers are the parallelism). The same code runs unchanged on a Slurm
(`dask_jobqueue.SLURMCluster`) or Kubernetes (`dask_kubernetes`) cluster: only the cluster object
changes. The script checks that the distributed fits equal the single-process call bit for bit and
prints both throughputs.
"""

from __future__ import annotations

import argparse
import csv
import pathlib
import time

import dask.array as da
import numpy as np
from dask.distributed import Client, LocalCluster

import spectral_skin as ss

ROOT = pathlib.Path(__file__).resolve().parents[2]
# Columns of the result block: the fitted parameters and the residual.
COLUMNS = ("melanin", "eumelanin", "hemoglobin", "oil", "rms")


def load_spectra(count: int) -> tuple[np.ndarray, np.ndarray]:
    """(M,) wavelengths in nm and (count, M) SCI reflectances from the ISSA subset, repeated."""
    rows, wl = [], None
    for name in ("issa_explore.csv", "issa_heldout.csv"):
        with open(ROOT / "validation" / "data" / name) as f:
            reader = csv.reader(line for line in f if not line.startswith("#"))
            header = next(reader)
            cols = [i for i, h in enumerate(header) if h.startswith("r") and h[1:].isdigit()]
            wl = np.array([float(header[i][1:]) for i in cols])
            rows += [[float(r[i]) for i in cols] for r in reader if r]
    spectra = np.array(rows)
    reps = -(-count // len(spectra))
    return wl, np.tile(spectra, (reps, 1))[:count]


def fit_block(block: np.ndarray, wl: np.ndarray, method: str) -> np.ndarray:
    """One partition: (n, M) spectra → (n, len(COLUMNS)) fitted parameters and residuals."""
    fit = ss.fit_spectrum(wl, block, geometry="sci", method=method, threads=1)
    return np.column_stack([getattr(fit, c) for c in COLUMNS])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--spectra", type=int, default=400)
    p.add_argument("--chunk", type=int, default=25, help="spectra per partition")
    p.add_argument("--method", choices=["exact", "multipole"], default="multipole")
    args = p.parse_args()

    wl, spectra = load_spectra(args.spectra)

    t = time.perf_counter()
    single = fit_block(spectra, wl, args.method)  # one process, one thread
    t_one = time.perf_counter() - t
    t = time.perf_counter()
    fit = ss.fit_spectrum(wl, spectra, geometry="sci", method=args.method)  # one process, all cores
    t_all = time.perf_counter() - t
    assert np.array_equal(np.column_stack([getattr(fit, c) for c in COLUMNS]), single)

    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True) as cluster, Client(cluster):
        x = da.from_array(spectra, chunks=(args.chunk, spectra.shape[1]))
        job = x.map_blocks(
            fit_block, wl, args.method, dtype=np.float64, chunks=(args.chunk, len(COLUMNS))
        )
        job.compute()  # warm-up: workers import the package
        t = time.perf_counter()
        distributed = job.compute()
        t_dask = time.perf_counter() - t
    assert np.array_equal(distributed, single), "distributed fits differ from the single-process ones"

    n = len(spectra)
    print(f"{n} spectra, method={args.method}, geometry=sci, {args.chunk} per partition")
    print(f"single process, 1 thread      : {t_one:7.2f} s  {n / t_one:8.2f} spectra/s")
    print(f"single process, all cores     : {t_all:7.2f} s  {n / t_all:8.2f} spectra/s")
    print(f"dask LocalCluster, {args.workers} workers : {t_dask:7.2f} s  {n / t_dask:8.2f} spectra/s")
    print("distributed results equal the single-process call bit for bit")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""The peer of eij's FE reduction speed: scipy's eigsh in shift-invert mode on the same matrices.

    cargo run --release --example fe_column -- 150 --write /tmp/fecol   # writes the matrices
    python3 benches/fe_scipy.py /tmp/fecol [MODES] [SHIFT_HZ]

Reads column-M.mtx and column-K.mtx (Matrix Market, as eij's example wrote them), then finds
the MODES lowest elastic free-free modes plus the 6 rigid-body modes with
scipy.sparse.linalg.eigsh(K, MODES + 6, M, sigma=-(2 pi SHIFT_HZ)^2) -- the same task as
eij::fe::free_free_frequencies_hz -- and prints the wall times, the peak memory and the first
frequencies. Needs scipy (pip install scipy).
"""
import math
import resource
import sys
import time

import numpy as np
import scipy.io
import scipy.sparse.linalg


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "/tmp/fecol"
    modes = int(sys.argv[2]) if len(sys.argv) > 2 else 30
    shift_hz = float(sys.argv[3]) if len(sys.argv) > 3 else 21.4
    t = time.perf_counter()
    m = scipy.io.mmread(f"{folder}/column-M.mtx").tocsc()
    k = scipy.io.mmread(f"{folder}/column-K.mtx").tocsc()
    read_s = time.perf_counter() - t
    sigma = -((2 * math.pi * shift_hz) ** 2)
    t = time.perf_counter()
    vals, _ = scipy.sparse.linalg.eigsh(k, modes + 6, m, sigma=sigma, which="LM")
    eig_s = time.perf_counter() - t
    hz = np.sqrt(np.clip(np.sort(vals), 0, None)) / (2 * math.pi)
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"scipy {scipy.__version__}: {k.shape[0]} DOFs, read {read_s:.2f} s, "
          f"eigsh shift-invert {modes} elastic + 6 rigid modes {eig_s:.2f} s, peak {peak_mib:.0f} MiB")
    print("first elastic: " + " ".join(f"{f:.2f}" for f in hz[6:9]) + f" Hz, {modes}th {hz[5 + modes]:.2f} Hz")


if __name__ == "__main__":
    main()

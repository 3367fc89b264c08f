#!/usr/bin/env python3
"""The spectral work of `seatrial_core::quality::quality_report`, in scipy.

Same shapes and parameters as `benches/quality.rs` (the data are random,
not the Rust bench's; Welch's cost does not depend on the values):
6 inputs and 6 outputs at 10 Hz, all 36 input->output pairs, periodic
Hann, nperseg = 4096, noverlap = 2048, constant detrend, density scaling.

  1h:  36,000 samples      10h: 360,000 samples

Two ways to do it in scipy:

  vectorized    scipy at its best: one welch on the (12, N) array, one csd
                on broadcast inputs (6, 1, N) x (1, 6, N) for all 36 pairs,
                coherence and H1 (|H1|, dB, unwrapped phase) from those.
  pair_by_pair  as most analysis scripts do: for each of the 36 pairs,
                welch(x), welch(y), csd(x, y), coherence(x, y) and H1.

Prints one JSON object: medians (s) over `timeit` repetitions.

    python3 scipy_quality.py [--reps-1h 7] [--reps-10h 3]
"""

import argparse
import json
import platform
import timeit

import numpy as np
import scipy
from scipy import signal

FS = 10.0
NPERSEG = 4096
N_IN = 6
N_OUT = 6


def vectorized(u, y):
    kw = dict(fs=FS, window="hann", nperseg=NPERSEG, noverlap=NPERSEG // 2)
    _, p = signal.welch(np.concatenate([u, y]), **kw)
    p_in, p_out = p[:N_IN], p[N_IN:]
    _, pxy = signal.csd(u[:, None, :], y[None, :, :], **kw)
    coh = np.abs(pxy) ** 2 / (p_in[:, None, :] * p_out[None, :, :])
    h1 = pxy / p_in[:, None, :]
    mag = np.abs(h1)
    db = 20.0 * np.log10(mag)
    phase = np.unwrap(np.angle(h1), axis=-1)
    return p, np.abs(pxy), coh, mag, db, phase


def pair_by_pair(u, y):
    kw = dict(fs=FS, window="hann", nperseg=NPERSEG, noverlap=NPERSEG // 2)
    out = []
    for i in range(N_IN):
        for o in range(N_OUT):
            _, pxx = signal.welch(u[i], **kw)
            _, pyy = signal.welch(y[o], **kw)
            _, pxy = signal.csd(u[i], y[o], **kw)
            _, coh = signal.coherence(u[i], y[o], **kw)
            h1 = pxy / pxx
            out.append((pxx, pyy, np.abs(pxy), coh, np.abs(h1),
                        20.0 * np.log10(np.abs(h1)), np.unwrap(np.angle(h1))))
    return out


def median_time(fn, reps):
    times = timeit.repeat(fn, number=1, repeat=reps)
    return float(np.median(times)), [float(t) for t in times]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps-1h", type=int, default=7)
    ap.add_argument("--reps-10h", type=int, default=3)
    args = ap.parse_args()

    rng = np.random.default_rng(2024)
    result = {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "fs": FS,
        "nperseg": NPERSEG,
        "pairs": N_IN * N_OUT,
        "cases": {},
    }
    for label, n, reps in (("1h", 36_000, args.reps_1h), ("10h", 360_000, args.reps_10h)):
        u = rng.standard_normal((N_IN, n))
        y = rng.standard_normal((N_OUT, n))
        # Same numbers both ways (sanity check of the vectorized call).
        v = vectorized(u, y)
        pbp = pair_by_pair(u, y)
        assert np.allclose(v[2][1, 2], pbp[1 * N_OUT + 2][3], rtol=1e-9, atol=0)
        vec_med, vec_all = median_time(lambda: vectorized(u, y), reps)
        pbp_med, pbp_all = median_time(lambda: pair_by_pair(u, y), reps)
        result["cases"][label] = {
            "n_samples": n,
            "n_segments": (n - NPERSEG // 2) // (NPERSEG - NPERSEG // 2),
            "vectorized_s": vec_med,
            "pair_by_pair_s": pbp_med,
            "vectorized_all_s": vec_all,
            "pair_by_pair_all_s": pbp_all,
        }
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()

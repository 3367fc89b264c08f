#!/usr/bin/env python3
"""sippy's N4SID on the data of `benches/n4sid.rs`, for compare_sippy.sh.

Reads `train_<N>.csv` and `valid.csv` (columns u0..u5, y0..y5) written by
the Rust bench (`N4SID_EXPORT_DIR`), runs

    sippy_unipi.system_identification(y, u, 'N4SID', SS_f=10,
                                      SS_fixed_order=6, tsample=0.1)

(unweighted N4SID, past = future horizon 10, order 6, D = 0: the Rust
settings) on each N, each case in a child process under a time limit and an
address-space limit, and prints one JSON object: median wall time (s) of
`--reps` runs, and the validation NRMSE fit (1 - |y - yhat| / |y - mean y|,
mean over the 6 outputs) of the free-run simulation (x0 = 0, sippy's
convention) and of the 1-step prediction through sippy's K.

    python3 compare_sippy.py --dir DIR [--reps 3] [--timeout 300] [--mem-gb 8]
"""

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import time

import numpy as np

HORIZON = 10
ORDER = 6
H = 0.1
SIZES = (4_000, 40_000, 360_000)


def load(path):
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return data[:, :6], data[:, 6:]


def fit(y, yhat):
    err = np.linalg.norm(y - yhat, axis=0)
    spread = np.linalg.norm(y - y.mean(axis=0), axis=0)
    return float(np.mean(1.0 - err / spread))


def simulate(m, u):
    x = np.zeros(m.A.shape[0])
    out = np.empty((u.shape[0], m.C.shape[0]))
    for t in range(u.shape[0]):
        out[t] = m.C @ x + m.D @ u[t]
        x = m.A @ x + m.B @ u[t]
    return out


def one_step(m, u, y):
    x = np.zeros(m.A.shape[0])
    out = np.empty_like(y)
    for t in range(u.shape[0]):
        out[t] = m.C @ x + m.D @ u[t]
        x = m.A @ x + m.B @ u[t] + m.K @ (y[t] - out[t])
    return out


def child(directory, n, reps):
    """One case; prints its JSON on stdout (sippy's chatter goes to stderr)."""
    from sippy_unipi import system_identification

    u, y = load(os.path.join(directory, f"train_{n}.csv"))
    uv, yv = load(os.path.join(directory, "valid.csv"))
    real_stdout = sys.stdout
    sys.stdout = sys.stderr
    times = []
    model = None
    for _ in range(reps):
        t0 = time.perf_counter()
        model = system_identification(y, u, "N4SID", SS_f=HORIZON,
                                      SS_fixed_order=ORDER, tsample=H)
        times.append(time.perf_counter() - t0)
    result = {
        "median_s": float(np.median(times)),
        "times_s": times,
        "sim_fit": fit(yv, simulate(model, uv)),
        "one_step_fit": fit(yv, one_step(model, uv, yv)),
    }
    sys.stdout = real_stdout
    print(json.dumps(result))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dir", required=True)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=300.0)
    ap.add_argument("--mem-gb", type=float, default=8.0)
    ap.add_argument("--case", type=int)
    args = ap.parse_args()
    if args.case is not None:
        child(args.dir, args.case, args.reps)
        return

    import sippy_unipi  # noqa: F401  (fail early if missing)
    from importlib.metadata import version

    limit = int(args.mem_gb * 2**30)

    def guard():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    out = {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "sippy_unipi": version("sippy_unipi"),
        "blas_threads": os.environ.get("OPENBLAS_NUM_THREADS", "default"),
        "cases": {},
    }
    for n in SIZES:
        reps = 1 if n >= 360_000 else args.reps
        cmd = [sys.executable, __file__, "--dir", args.dir, "--case", str(n),
               "--reps", str(reps)]
        t0 = time.perf_counter()
        try:
            p = subprocess.run(cmd, capture_output=True, text=True,
                               timeout=args.timeout, preexec_fn=guard)
        except subprocess.TimeoutExpired:
            out["cases"][str(n)] = {"status": f"out of time (> {args.timeout:.0f} s)"}
            continue
        if p.returncode != 0:
            memory = "MemoryError" in p.stderr or p.returncode in (-9, 137)
            status = (f"out of memory (> {args.mem_gb:g} GB address space)"
                      if memory else f"failed (exit {p.returncode})")
            out["cases"][str(n)] = {"status": status,
                                    "stderr_tail": p.stderr[-400:],
                                    "wall_s": time.perf_counter() - t0}
            continue
        case = json.loads(p.stdout.strip().splitlines()[-1])
        case["status"] = "ok"
        out["cases"][str(n)] = case
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()

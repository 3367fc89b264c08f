#!/usr/bin/env python3
"""The 6-DOF case of `benches/ekf.rs` in filterpy's ExtendedKalmanFilter.

Same model, data, noise and step order as the Rust bench `ekf/six_dof_48_params`:
nu(k+1) = nu + dt*(A nu + b*u + c), 6 states, theta = [A row-major (36); b (6);
c (6)] = 48 parameters, augmented dimension 54, 4,000 samples, z = nu + noise.
Data from the project's SplitMix64 (seed 42) re-implemented here bit for bit.
Per sample: update with z(k) (filterpy's Joseph form), then, except after the
last sample, F = Jacobian at x(k|k) and predict with u(k).

Prints one JSON object: median seconds over repetitions and the final
estimate (for the agreement check against Rust).

    python3 compare_filterpy.py [--reps 5]
"""

import argparse
import json
import math
import platform
import time

import filterpy
import numpy as np
from filterpy.kalman import ExtendedKalmanFilter

NX, NP, STEPS, DT, NOISE = 6, 48, 4000, 0.1, 0.01
MASK = (1 << 64) - 1
GAMMA = 0x9E3779B97F4A7C15


class SplitMix64:
    def __init__(self, seed):
        self.state = seed & MASK

    def next_u64(self):
        self.state = (self.state + GAMMA) & MASK
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
        return z ^ (z >> 31)

    def uniform(self):
        return (self.next_u64() >> 11) * (1.0 / (1 << 53))

    def normal(self):
        u1 = 1.0 - self.uniform()
        u2 = self.uniform()
        return math.sqrt(-2.0 * math.log(u1)) * math.cos(math.tau * u2)


def a_true(i, j):
    return -(0.4 + 0.1 * i) if i == j else 0.02 * (((i * 7 + j * 3) % 5) - 2.0)


def data():
    rng = SplitMix64(42)
    level = [1.0] * NX
    u = np.zeros((STEPS, NX))
    for k in range(STEPS):
        if k % 10 == 0:
            for i in range(NX):
                if rng.uniform() < 0.5:
                    level[i] = -level[i]
        u[k] = level
    z = np.zeros((STEPS, NX))
    nu = [0.0] * NX
    for k in range(STEPS):
        for i in range(NX):
            z[k, i] = nu[i] + NOISE * rng.normal()
        nxt = [0.0] * NX
        for i in range(NX):
            acc = 0.0
            for j in range(NX):
                acc += a_true(i, j) * nu[j]
            acc += (1.0 + 0.1 * i) * u[k, i]
            acc += 0.01 * (i - 2.5)
            nxt[i] = nu[i] + DT * acc
        nu = nxt
    return u, z


class AugmentedEKF(ExtendedKalmanFilter):
    """x = [nu; theta]; the nonlinear propagation of the augmented state."""

    def predict_x(self, u=0):
        x = self.x[:, 0]
        nu, th = x[:NX], x[NX:]
        a = th[:36].reshape(NX, NX)
        nxt = nu + DT * (a @ nu + th[36:42] * u + th[42:48])
        self.x = np.concatenate([nxt, th])[:, None]


def jacobian(x, u):
    nu, th = x[:NX, 0], x[NX:, 0]
    f = np.eye(NX + NP)
    f[:NX, :NX] += DT * th[:36].reshape(NX, NX)
    for i in range(NX):
        f[i, NX + i * NX: NX + (i + 1) * NX] = DT * nu
        f[i, NX + 36 + i] = DT * u[i]
        f[i, NX + 42 + i] = DT
    return f


H = np.hstack([np.eye(NX), np.zeros((NX, NP))])


def run(u, z):
    ekf = AugmentedEKF(dim_x=NX + NP, dim_z=NX, dim_u=NX)
    x0 = np.zeros(NX + NP)
    x0[NX + 36: NX + 42] = 0.5
    ekf.x = x0[:, None]
    ekf.P = np.diag([1e-4] * NX + [1.0] * NP)
    ekf.Q = np.diag([1e-8] * NX + [0.0] * NP)
    ekf.R = np.eye(NX) * NOISE**2
    hj = lambda x: H  # noqa: E731
    hx = lambda x: H @ x  # noqa: E731
    for k in range(STEPS):
        ekf.update(z[k][:, None], hj, hx)
        if k + 1 < STEPS:
            ekf.F = jacobian(ekf.x, u[k])
            ekf.predict(u=u[k])
    return ekf


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args()
    u, z = data()
    times = []
    ekf = None
    for _ in range(args.reps):
        t0 = time.perf_counter()
        ekf = run(u, z)
        times.append(time.perf_counter() - t0)
    times.sort()
    print(json.dumps({
        "filterpy": filterpy.__version__,
        "numpy": np.__version__,
        "python": platform.python_version(),
        "median_s": times[len(times) // 2],
        "theta": ekf.x[NX:, 0].tolist(),
        "x": ekf.x[:NX, 0].tolist(),
        "theta_cov_diag": np.diag(ekf.P)[NX:].tolist(),
    }))


if __name__ == "__main__":
    main()

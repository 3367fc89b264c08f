#!/usr/bin/env python3
"""Loads seatrial's model exports with numpy/scipy and reproduces the
service's own ZOH step response to 1e-9.

Usage: check_exports.py DIR, where DIR holds per model TAG (written by
tests/api_exports.rs):
  TAG.npz        format=npz        (numpy.load)
  TAG-ss.json    format=ss_json    (A, B, C, D per point, sample time)
  TAG-view.json  GET /api/models/{id}?h=…  (the stored document and the
                 service's ZOH Φ, Γ at h)
  TAG-step.json  the service's step response: y(k) under a unit step on
                 every input from x = 0, per point, computed from that Φ, Γ
  TAG.m          format=matlab (run in Octave when it is installed: it
                 discretizes and simulates the step response itself)
  TAG.mat        format=mat        (scipy.io.loadmat)

For each model: the npz matrices equal the stored ones exactly; A, B of the
npz and of ss_json, discretized by scipy.signal.cont2discrete (or taken as
they are for a discrete model), simulated by scipy.signal.dlsim, give the
service's step response within 1e-9 (relative to its largest value). The
.mat holds the same arrays (a stack over grid speeds as MATLAB's r×c×p),
names and units as cell rows; its A, B simulate to the same response.
Prints one line per check and ends with 'N passed, M failed'; exits 1 on
any failure.
"""

import json
import pathlib
import shutil
import subprocess
import sys

import numpy as np
from scipy import io, signal

TOL = 1e-9
passed = 0
failed = 0


def check(ok, what):
    global passed, failed
    if ok:
        passed += 1
        print(f"ok   {what}")
    else:
        failed += 1
        print(f"FAIL {what}")


def close(a, b, what):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(np.max(np.abs(b)), 1e-300)
    err = np.max(np.abs(a - b)) / scale if a.size else 0.0
    check(a.shape == b.shape and err <= TOL, f"{what} (relative error {err:.2e})")


def simulate(ad, bd, c, d, steps):
    u = np.ones((steps, bd.shape[1]))
    _, y, _ = signal.dlsim((ad, bd, c, d, 1.0), u, x0=np.zeros(ad.shape[0]))
    return y


def zoh(a, b, h):
    n, m = a.shape[0], b.shape[1]
    ad, bd, *_ = signal.cont2discrete((a, b, np.eye(n), np.zeros((n, m))), h, method="zoh")
    return ad, bd


def check_model(d, tag):
    view = json.loads((d / f"{tag}-view.json").read_text())
    ss = json.loads((d / f"{tag}-ss.json").read_text())
    step = json.loads((d / f"{tag}-step.json").read_text())
    doc = view["document"]
    h = step["h"]
    z = np.load(d / f"{tag}.npz")  # no pickles: allow_pickle stays False
    meta = json.loads(str(z["metadata"]))
    check(meta["format"] == "seatrial-npz/1" and meta["kind"] == doc["kind"], f"{tag}: metadata")
    check(float(z["h"]) == h, f"{tag}: h = {h}")
    check(list(z["output_names"]) == [c["name"] for c in ss["outputs"]], f"{tag}: output names")
    check(list(z["input_units"]) == [c["unit"] for c in ss["inputs"]], f"{tag}: input units")
    discrete = view["discrete"]["points"]
    kind = doc["kind"]
    if kind == "lpv":
        pts = doc["lpv"]["points"]
        check(np.array_equal(z["grid_speeds_mps"], [p["speed_mps"] for p in pts]), f"{tag}: grid speeds")
        for key, field in [("M", "m"), ("M_std", "m_std"), ("Dbar", "d_bar"), ("A", "a"), ("B", "b")]:
            check(np.array_equal(z[key], np.array([p[field] for p in pts])), f"{tag}: {key} exact")
        models = [(z["A"][i], z["B"][i]) for i in range(len(pts))]
    elif kind == "dp_ship":
        dp = doc["dp_ship"]
        check(np.array_equal(z["A"], np.array(dp["a_si"])), f"{tag}: A (SI) exact")
        check(np.array_equal(z["M_bis"], np.array(dp["m"])), f"{tag}: M'' exact")
        models = [(z["A"], z["B"])]
    else:
        s = doc["state_space"]
        for key, field in [("A", "phi"), ("B", "gamma"), ("C", "c"), ("D", "d"), ("K", "k")]:
            check(np.array_equal(z[key], np.array(s[field])), f"{tag}: {key} exact")
        check(np.array_equal(z["u0"], s["u_offset"]), f"{tag}: u0 exact")
        models = [(z["A"], z["B"])]
    continuous = ss["sample_time_s"] == 0
    for i, (a, b) in enumerate(models):
        p = ss["points"][i]
        c, dd = np.array(p["C"], float), np.array(p["D"], float)
        service = np.array(step["points"][i])
        close(z["Ad"][i], discrete[i]["phi"], f"{tag}[{i}]: npz A_d = the service's Φ")
        close(z["Bd"][i], discrete[i]["gamma"], f"{tag}[{i}]: npz B_d = the service's Γ")
        for src, (aa, bb) in [("npz", (a, b)), ("ss_json", (np.array(p["A"]), np.array(p["B"])))]:
            ad, bd = zoh(aa, bb, h) if continuous else (aa, bb)
            if continuous:
                close(ad, discrete[i]["phi"], f"{tag}[{i}]: cont2discrete({src} A) = Φ")
                close(bd, discrete[i]["gamma"], f"{tag}[{i}]: cont2discrete({src} A, B) = Γ")
            y = simulate(ad, bd, c, dd, step["steps"])
            close(y, service, f"{tag}[{i}]: dlsim({src}) step response = the service's")
    check_mat(d, tag, z, ss, step, models, continuous)
    octave(d, tag, doc, ss, step, continuous)


def page(m, i, stacked):
    """Matrix i of a .mat array: page i of an r×c×p stack, or the matrix itself."""
    return m[:, :, i] if stacked and m.ndim == 3 else (m if m.ndim == 2 else m[:, :, 0])


def check_mat(d, tag, z, ss, step, models, continuous):
    """The .mat export: same arrays as the npz, names and units, a true simulation."""
    m = io.loadmat(d / f"{tag}.mat")
    meta = json.loads(str(m["metadata"][0]))
    check(meta["format"] == "seatrial-mat/1", f"{tag}.mat: metadata")
    names = [str(x[0]) for x in m["output_names"][0]]
    check(names == [c["name"] for c in ss["outputs"]], f"{tag}.mat: output names")
    units = [str(x[0]) for x in m["input_units"][0]]
    check(units == [c["unit"] for c in ss["inputs"]], f"{tag}.mat: input units")
    check(float(m["h"][0, 0]) == step["h"], f"{tag}.mat: h")
    stacked = "grid_speeds_mps" in z
    if stacked:
        check(np.array_equal(m["grid_speeds_mps"][0], z["grid_speeds_mps"]), f"{tag}.mat: grid speeds")
    for key in z.files:
        if z[key].dtype.kind == "f" and z[key].ndim == 3:
            check(np.array_equal(np.moveaxis(m[key], 2, 0), z[key]), f"{tag}.mat: {key} = npz {key} (r×c×p)")
        elif z[key].dtype.kind == "f" and z[key].ndim == 2:
            check(np.array_equal(m[key], z[key]), f"{tag}.mat: {key} = npz {key}")
    h = step["h"]
    for i in range(len(models)):
        p = ss["points"][i]
        c, dd = np.array(p["C"], float), np.array(p["D"], float)
        a, b = page(m["A"], i, stacked), page(m["B"], i, stacked)
        ad, bd = zoh(a, b, h) if continuous else (a, b)
        y = simulate(ad, bd, c, dd, step["steps"])
        close(y, np.array(step["points"][i]), f"{tag}[{i}].mat: dlsim step response = the service's")


def octave_matrix(m):
    """A matrix as an Octave literal, every float exact (repr round-trips)."""
    m = np.atleast_2d(np.asarray(m, float))
    return "[" + "; ".join(" ".join(repr(float(x)) for x in row) for row in m) + "]"


def octave(d, tag, doc, ss, step, continuous):
    """The .m export in Octave: it reads the stored matrix back exactly, and
    Octave itself discretizes each point's A, B (ZOH by expm([A B; 0 0] h)
    when continuous, as zoh() does) and runs the step recursion from x = 0:
    the result is the service's step response to 1e-9."""
    exe = shutil.which("octave") or shutil.which("octave-cli")
    if exe is None:
        print(f"skip {tag}.m: octave is not installed")
        return
    script = d / (tag + ".m")
    field = {"lpv": "model.lpv.A(:,:,1)", "dp_ship": "model.dp.A_si", "state_space": "model.ss.Phi"}[doc["kind"]]
    code = f"source('{script}'); printf('%.17g ', ({field})');"
    out = subprocess.run([exe, "--no-gui", "--quiet", "--eval", code], capture_output=True, text=True)
    if out.returncode != 0:
        check(False, f"{tag}.m runs in Octave: {out.stderr.strip()}")
        return
    got = np.array([float(x) for x in out.stdout.split()])
    want = {
        "lpv": lambda: doc["lpv"]["points"][0]["a"],
        "dp_ship": lambda: doc["dp_ship"]["a_si"],
        "state_space": lambda: doc["state_space"]["phi"],
    }[doc["kind"]]()
    check(np.array_equal(got, np.array(want, float).ravel()), f"{tag}.m: Octave reads the same matrix")
    for i, p in enumerate(ss["points"]):
        a, b = {
            "lpv": (f"model.lpv.A(:,:,{i + 1})", f"model.lpv.B(:,:,{i + 1})"),
            "dp_ship": ("model.dp.A_si", "model.dp.B_si"),
            "state_space": ("model.ss.Phi", "model.ss.Gamma"),
        }[doc["kind"]]
        # C, D: the script's own for a state-space model; the LPV and DP scripts
        # have none (the outputs are the velocities), so the ss_json's, as dlsim uses.
        c, dd = ("model.ss.C", "model.ss.D") if doc["kind"] == "state_space" else (
            octave_matrix(p["C"]), octave_matrix(p["D"]))
        code = f"""source('{script}');
A = {a}; B = {b}; C = {c}; D = {dd};
h = {step["h"]!r}; steps = {int(step["steps"])};
n = rows(A); m = columns(B);
if {1 if continuous else 0}
  E = expm([A B; zeros(m, n + m)] * h); Ad = E(1:n, 1:n); Bd = E(1:n, n+1:n+m);
else
  Ad = A; Bd = B;
end
x = zeros(n, 1); u = ones(m, 1); Y = zeros(steps, rows(C));
for k = 1:steps
  Y(k, :) = (C * x + D * u)'; x = Ad * x + Bd * u;
end
printf('%.17g ', Y');"""
        out = subprocess.run([exe, "--no-gui", "--quiet", "--eval", code], capture_output=True, text=True)
        if out.returncode != 0:
            check(False, f"{tag}[{i}].m: Octave step response: {out.stderr.strip()}")
            continue
        service = np.array(step["points"][i], float)
        y = np.array([float(x) for x in out.stdout.split()]).reshape(service.shape)
        close(y, service, f"{tag}[{i}].m: Octave's own ZOH and step recursion = the service's step response")


def main():
    d = pathlib.Path(sys.argv[1])
    tags = sorted(p.name[: -len("-view.json")] for p in d.glob("*-view.json"))
    if not tags:
        print(f"no exports in {d}")
        sys.exit(1)
    for tag in tags:
        try:
            check_model(d, tag)
        except Exception as e:  # a missing array or file is a failure, not a crash
            check(False, f"{tag}: {type(e).__name__}: {e}")
    print(f"{passed} passed, {failed} failed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()

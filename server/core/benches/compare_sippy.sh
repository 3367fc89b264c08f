#!/usr/bin/env bash
# Acceptance figures of N4SID: Rust (`benches/n4sid.rs`, criterion) against
# sippy's N4SID (`benches/compare_sippy.py`) on the same data, same horizon
# (i = 10), same order (6), D = 0, in one run on this machine.
#
#   bash server/core/benches/compare_sippy.sh
#
# sippy is the CPCLAB-UNIPI "Systems Identification Package for PYthon",
# published on PyPI as `sippy_unipi` (the PyPI name `sippy` is an unrelated
# SIP stack). Installed once with `pip install --user`, pinned below.
#
# Steps: `cargo bench -p seatrial-core --bench n4sid` with N4SID_EXPORT_DIR
# (writes the training runs, the held-out run and Rust's validation fits,
# then times n4sid at N = 4,000 / 40,000 / 360,000); the sippy script on
# those files (each case in a child process with a time limit and an
# address-space limit, reported honestly when hit); a table of medians,
# ratios and validation fits.
#
# Environment: OUT_DIR (default /tmp/seatrial-n4sid-bench), SIPPY_REPS
# (default 3; 1 at 360,000), SIPPY_TIMEOUT (s, default 300), SIPPY_MEM_GB
# (default 8), BLAS_THREADS (numpy's BLAS threads, default 1: the Rust code
# is single-threaded), CRITERION_ARGS (extra criterion options).
set -euo pipefail

SIPPY_PKG="sippy_unipi==1.0.1"
HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
OUT="${OUT_DIR:-/tmp/seatrial-n4sid-bench}"
PY="${PYTHON:-python3}"
mkdir -p "$OUT"

if ! "$PY" -c 'import sippy_unipi' 2>/dev/null; then
  echo "== installing $SIPPY_PKG"
  "$PY" -m pip install -q --user --disable-pip-version-check "$SIPPY_PKG"
fi

echo "== rust: cargo bench -p seatrial-core --bench n4sid"
# shellcheck disable=SC2086
(cd "$ROOT" && N4SID_EXPORT_DIR="$OUT" cargo bench -p seatrial-core --bench n4sid -- ${CRITERION_ARGS:-}) \
  > "$OUT/cargo-bench.log" 2>&1 || { tail -40 "$OUT/cargo-bench.log"; exit 1; }
grep -E "^n4sid/|time:" "$OUT/cargo-bench.log" || true

echo "== sippy ($SIPPY_PKG, BLAS threads ${BLAS_THREADS:-1})"
export OPENBLAS_NUM_THREADS="${BLAS_THREADS:-1}" OMP_NUM_THREADS="${BLAS_THREADS:-1}" MKL_NUM_THREADS="${BLAS_THREADS:-1}"
"$PY" "$HERE/compare_sippy.py" --dir "$OUT" --reps "${SIPPY_REPS:-3}" \
  --timeout "${SIPPY_TIMEOUT:-300}" --mem-gb "${SIPPY_MEM_GB:-8}" > "$OUT/sippy.json"

TARGET_DIR="$(cd "$ROOT" && cargo metadata --format-version 1 --no-deps \
  | "$PY" -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')"

"$PY" - "$OUT/sippy.json" "$OUT/rust_fits.json" "$TARGET_DIR/criterion/n4sid" <<'PY'
import json
import sys

sippy = json.load(open(sys.argv[1]))
fits = json.load(open(sys.argv[2]))["cases"]
crit = sys.argv[3]


def rust(n):
    with open(f"{crit}/{n}/new/estimates.json") as f:
        return json.load(f)["median"]["point_estimate"] * 1e-9  # s


print()
print(f"sippy_unipi {sippy['sippy_unipi']}, numpy {sippy['numpy']}, python {sippy['python']}, "
      f"BLAS threads {sippy['blas_threads']}; Rust single-threaded")
print("6 inputs x 6 outputs, order 6, horizon i = 10, D = 0; validation run of 20,000 samples")
print()
hdr = (f"{'N':>8}{'rust median':>13}{'sippy median':>15}{'sippy/rust':>12}"
       f"{'sim fit rust':>14}{'sim fit sippy':>15}{'1-step rust':>13}{'1-step sippy':>14}")
print(hdr)
print("-" * len(hdr))
for n in ("4000", "40000", "360000"):
    r = rust(n)
    c = sippy["cases"][n]
    fr = fits[n]
    if c.get("status") == "ok":
        print(f"{n:>8}{r:>12.3f}s{c['median_s']:>14.3f}s{c['median_s'] / r:>11.1f}x"
              f"{fr['sim_fit']:>14.4f}{c['sim_fit']:>15.4f}"
              f"{fr['one_step_fit']:>13.4f}{c['one_step_fit']:>14.4f}")
    else:
        print(f"{n:>8}{r:>12.3f}s   sippy: {c['status']}"
              f"   (rust fits: sim {fr['sim_fit']:.4f}, 1-step {fr['one_step_fit']:.4f})")
print()
print("targets: >= 10x faster than sippy at N = 40,000 with the same validation fit; "
      "N = 360,000 in a few seconds")
PY

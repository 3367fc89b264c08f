#!/usr/bin/env bash
# The parallel EKF against filterpy: Rust (`benches/ekf.rs`, criterion) and
# the same filter in filterpy's ExtendedKalmanFilter
# (`benches/compare_filterpy.py`), in one run on this machine.
#
#   bash server/core/benches/compare_filterpy.sh
#
# Creates (once) a virtualenv with numpy and filterpy 1.4.5 under /tmp, runs
# the filterpy script, then `cargo bench -p seatrial-core --bench ekf`, and
# prints medians, the ratio, and the agreement of the two final estimates
# (6-DOF case: 6 states, 48 parameters, augmented dimension 54, 4,000
# samples; same model, data, Q, R, P0 and step order on both sides).
#
# Environment: FILTERPY_VENV (default /tmp/seatrial-filterpy-venv), OUT_DIR
# (default /tmp/seatrial-ekf-bench), FILTERPY_REPS (default 5),
# CRITERION_ARGS (extra criterion options).
set -euo pipefail

HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
VENV="${FILTERPY_VENV:-/tmp/seatrial-filterpy-venv}"
OUT="${OUT_DIR:-/tmp/seatrial-ekf-bench}"
FILTERPY_VERSION="1.4.5"
mkdir -p "$OUT"

if [ ! -x "$VENV/bin/python" ]; then
  echo "== creating $VENV"
  python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install -q --disable-pip-version-check numpy "filterpy==$FILTERPY_VERSION"

echo "== filterpy ($("$VENV/bin/python" -c 'import filterpy, numpy; print("filterpy", filterpy.__version__, "numpy", numpy.__version__)'))"
"$VENV/bin/python" "$HERE/compare_filterpy.py" --reps "${FILTERPY_REPS:-5}" > "$OUT/filterpy.json"

echo "== rust: cargo bench -p seatrial-core --bench ekf"
# shellcheck disable=SC2086
(cd "$ROOT" && EKF_COMPARE_OUT="$OUT/rust.json" \
  cargo bench -p seatrial-core --bench ekf -- ${CRITERION_ARGS:-}) \
  > "$OUT/cargo-bench.log" 2>&1 || { tail -40 "$OUT/cargo-bench.log"; exit 1; }
grep -E "^ekf/|time:" "$OUT/cargo-bench.log" || true

TARGET_DIR="$(cd "$ROOT" && cargo metadata --format-version 1 --no-deps \
  | "$VENV/bin/python" -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')"

"$VENV/bin/python" - "$OUT/filterpy.json" "$OUT/rust.json" "$TARGET_DIR/criterion/ekf" <<'PY'
import json
import sys

fp = json.load(open(sys.argv[1]))
rs = json.load(open(sys.argv[2]))
crit = sys.argv[3]


def rust(name):
    with open(f"{crit}/{name}/new/estimates.json") as f:
        return json.load(f)["median"]["point_estimate"] * 1e-9  # s


def ms(s):
    return f"{s * 1e3:10.2f} ms"


def max_rel(a, b):
    return max(abs(x - y) / max(abs(y), 1e-300) for x, y in zip(a, b))


r6 = rust("six_dof_48_params")
print()
print(f"filterpy {fp['filterpy']}, numpy {fp['numpy']}, python {fp['python']}")
print()
hdr = f"{'case':<40}{'rust median':>14}{'filterpy median':>17}{'filterpy / rust':>17}"
print(hdr)
print("-" * len(hdr))
print(f"{'6-DOF, 48 params, dim 54, 4000 steps':<40}{ms(r6):>14}{ms(fp['median_s']):>17}"
      f"{fp['median_s'] / r6:>16.1f}x")
print(f"{'supply vessel SI1-SI3 (N=2, 2 sweeps)':<40}{ms(rust('supply_vessel_si1_si3')):>14}"
      f"{'-':>17}{'-':>17}")
print()
print("target: 6-DOF at least 10x faster than filterpy")
print()
print("agreement of the final estimates (max relative difference):")
print(f"  theta (48)           {max_rel(rs['theta'], fp['theta']):.2e}")
print(f"  x (6)                {max_rel(rs['x'], fp['x']):.2e}")
print(f"  diag P_theta (48)    {max_rel(rs['theta_cov_diag'], fp['theta_cov_diag']):.2e}")
ok = max_rel(rs["theta"], fp["theta"]) < 1e-8
print(f"  theta within 1e-8:   {'yes' if ok else 'NO'}")
sys.exit(0 if ok else 1)
PY

#!/usr/bin/env bash
# Acceptance figures of the quality report: Rust (`benches/quality.rs`,
# criterion) against the same spectral work in scipy
# (`benches/scipy_quality.py`), in one run on this machine.
#
#   bash server/core/benches/compare_scipy.sh
#
# Creates (once) a virtualenv with numpy and scipy under /tmp, runs the
# scipy script, then `cargo bench -p seatrial-core --bench quality`, and
# prints a table of medians and ratios, plus the FFT floor: 12 real FFTs of
# 4096 points per Welch segment, counted as 5·n·log2(n) flops each and timed
# by a bare realfft loop of the same count (`fft_only_*`).
#
# Environment: SCIPY_VENV (default /tmp/seatrial-scipy-venv), OUT_DIR
# (default /tmp/seatrial-quality-bench), SCIPY_REPS_1H / SCIPY_REPS_10H
# (repetitions, default 15 / 5), CRITERION_ARGS (extra criterion options).
set -euo pipefail

HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
VENV="${SCIPY_VENV:-/tmp/seatrial-scipy-venv}"
OUT="${OUT_DIR:-/tmp/seatrial-quality-bench}"
mkdir -p "$OUT"

if [ ! -x "$VENV/bin/python" ]; then
  echo "== creating $VENV"
  python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install -q --disable-pip-version-check numpy scipy

echo "== scipy ($("$VENV/bin/python" -c 'import scipy, numpy; print("scipy", scipy.__version__, "numpy", numpy.__version__)'))"
"$VENV/bin/python" "$HERE/scipy_quality.py" \
  --reps-1h "${SCIPY_REPS_1H:-15}" --reps-10h "${SCIPY_REPS_10H:-5}" > "$OUT/scipy.json"

echo "== rust: cargo bench -p seatrial-core --bench quality"
# shellcheck disable=SC2086
(cd "$ROOT" && cargo bench -p seatrial-core --bench quality -- ${CRITERION_ARGS:-}) \
  > "$OUT/cargo-bench.log" 2>&1 || { tail -40 "$OUT/cargo-bench.log"; exit 1; }
grep -E "^quality/|time:" "$OUT/cargo-bench.log" || true

TARGET_DIR="$(cd "$ROOT" && cargo metadata --format-version 1 --no-deps \
  | "$VENV/bin/python" -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')"

"$VENV/bin/python" - "$OUT/scipy.json" "$TARGET_DIR/criterion/quality" <<'PY'
import json
import math
import sys

scipy = json.load(open(sys.argv[1]))
crit = sys.argv[2]


def rust(name):
    with open(f"{crit}/{name}/new/estimates.json") as f:
        return json.load(f)["median"]["point_estimate"] * 1e-9  # s


def ms(s):
    return f"{s * 1e3:9.2f} ms"


n = scipy["nperseg"]
channels = 12
print()
print(f"scipy {scipy['scipy']}, numpy {scipy['numpy']}, python {scipy['python']}; "
      f"6 inputs x 6 outputs at {scipy['fs']} Hz, nperseg {n}, 50 % overlap, 36 pairs")
print()
hdr = (f"{'case':<26}{'rust median':>13}{'scipy vectorized':>18}{'scipy pair-by-pair':>20}"
       f"{'vec / rust':>12}{'pbp / rust':>12}")
print(hdr)
print("-" * len(hdr))
for label in ("1h", "10h"):
    c = scipy["cases"][label]
    for what in ("report", "multi_welch"):
        r = rust(f"{what}_{label}")
        print(f"{what + ' ' + label + ' (' + str(c['n_samples']) + ')':<26}{ms(r):>13}"
              f"{ms(c['vectorized_s']):>18}{ms(c['pair_by_pair_s']):>20}"
              f"{c['vectorized_s'] / r:>11.1f}x{c['pair_by_pair_s'] / r:>11.1f}x")
print()
print("targets: report >= 3x faster than scipy vectorized, >= 50x faster than pair-by-pair")
print()
print("FFT floor (12 real FFTs of n = 4096 per segment; 5·n·log2(n) flops each):")
hdr = (f"{'case':<6}{'segments':>9}{'FFTs':>7}{'Gflop':>8}{'bare FFTs':>13}{'rate':>14}"
       f"{'of segments':>13}{'multi_welch':>13}{'/ FFTs':>8}{'report':>13}{'/ FFTs':>8}")
print(hdr)
print("-" * len(hdr))
for label in ("1h", "10h"):
    c = scipy["cases"][label]
    segs = c["n_segments"]
    ffts = segs * channels
    flops = 5 * n * math.log2(n) * ffts
    t_fft = rust(f"fft_only_{label}")
    t_mw = rust(f"multi_welch_{label}")
    t_rep = rust(f"report_{label}")
    t_seg = rust(f"fft_segments_{label}")
    print(f"{label:<6}{segs:>9}{ffts:>7}{flops / 1e9:>8.3f}{ms(t_fft):>13}"
          f"{flops / t_fft / 1e9:>9.1f} GF/s{ms(t_seg):>13}{ms(t_mw):>13}{t_mw / t_fft:>7.2f}x"
          f"{ms(t_rep):>13}{t_rep / t_fft:>7.2f}x")
print()
print("'bare FFTs' transform one cached segment; 'of segments' the log's own segments,")
print("windowed from memory. Ratios are to the bare FFTs.")
PY

#!/usr/bin/env python3
"""Ship-hour ratio of a designed campaign on the independent truth.

Reads the TSV files `precision_table --tsv` writes: one for the designed
campaign, and one per repetition of the rule-based plan (x1, x2, x3, ...).
Precision of a campaign = the geometric mean, over the parameters every
file has, of the empirical std (over the truth's seeds) relative to the
mean estimate. The rule-based plans give precision against ship hours; the
hours they need for the designed campaign's precision are interpolated
linearly in (log hours, log precision) between the bracketing plans (beyond
the last, precision ∝ hours^-1/2). Ratio = those hours / the design's.

    python3 ship_hours.py designed.tsv rule1.tsv rule2.tsv rule3.tsv
"""
import math
import sys


def read(path):
    rows, hours = {}, None
    with open(path) as f:
        next(f)
        for line in f:
            name, _pred, emp, mean, h = line.rstrip("\n").split("\t")
            rows[name] = (float(emp), float(mean))
            hours = float(h)
    return rows, hours


def main(paths):
    designed, *rules = [read(p) for p in paths]
    common = set(designed[0])
    for r, _ in rules:
        common &= set(r)
    # Relative precision needs a mean estimate clearly away from zero.
    common = sorted(n for n in common if all(abs(r[n][1]) > 0 for r, _ in [designed] + rules))

    def precision(rows):
        logs = [math.log(rows[n][0] / abs(rows[n][1])) for n in common]
        return math.exp(sum(logs) / len(logs))

    d_prec, d_hours = precision(designed[0]), designed[1]
    front = sorted((h, precision(r)) for r, h in rules)
    print(f"{len(common)} parameters in every file")
    print(f"designed:       {d_hours:7.2f} h   geometric-mean relative std {100 * d_prec:.3f} %")
    for h, p in front:
        print(f"rule-based:     {h:7.2f} h   geometric-mean relative std {100 * p:.3f} %")
    need, extrapolated = None, False
    if d_prec >= front[0][1]:
        need = front[0][0] * (front[0][1] / d_prec) ** 2
    for (h0, p0), (h1, p1) in zip(front, front[1:]):
        if p1 <= d_prec <= p0:
            s = (math.log(d_prec) - math.log(p0)) / (math.log(p1) - math.log(p0))
            need = math.exp(math.log(h0) + s * (math.log(h1) - math.log(h0)))
    if need is None:
        h, p = front[-1]
        need, extrapolated = h * (p / d_prec) ** 2, True
    print(
        f"rule-based hours for the designed precision: {need:.2f} h"
        f"{' (extrapolated: precision ∝ hours^-1/2)' if extrapolated else ''}; "
        f"ratio {need / d_hours:.2f}x"
    )


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1:])

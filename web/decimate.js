// Display decimation of long spectra on a log frequency axis. Pure functions
// (no DOM), shared by the run plots and the tests.
//
// A Welch spectrum of a long log has up to 2049 bins on a linear grid; on a
// log axis nearly all of them crowd into the top decade. Per log-spaced
// bucket we keep the first and last bin and, for every series, the bin of
// its minimum and of its maximum: peaks and notches survive, and since only
// original bins are kept every number shown (legend, tooltip) is exact.

/** Bins inside [lo, hi] above which a spectrum is decimated for display. */
export const DECIMATE_ABOVE = 1200;
/** Log-spaced buckets over the shown range when decimating. */
export const BUCKETS = 300;

/**
 * Indices of `x` (ascending) to draw for the window [lo, hi] (default: all
 * of x > 0). All of them when there are at most `above`; else per
 * log-spaced bucket the first, last, argmin and argmax of each series in
 * `ys` (null / non-finite values ignored). Sorted, without duplicates.
 */
export function logDecimate(x, ys = [], { lo = -Infinity, hi = Infinity, above = DECIMATE_ABOVE, buckets = BUCKETS } = {}) {
  let i0 = 0;
  while (i0 < x.length && !(x[i0] > 0 && x[i0] >= lo)) i0 += 1;
  let i1 = x.length - 1;
  while (i1 >= i0 && !(x[i1] <= hi)) i1 -= 1;
  if (i1 < i0) return [];
  const out = [];
  if (i1 - i0 + 1 <= above) {
    for (let i = i0; i <= i1; i += 1) out.push(i);
    return out;
  }
  const l0 = Math.log(x[i0]);
  const span = Math.log(x[i1]) - l0 || 1;
  let i = i0;
  while (i <= i1) {
    const b = Math.min(buckets - 1, Math.floor(((Math.log(x[i]) - l0) / span) * buckets));
    let j = i;
    while (j + 1 <= i1 && Math.min(buckets - 1, Math.floor(((Math.log(x[j + 1]) - l0) / span) * buckets)) === b) j += 1;
    // bucket b holds bins i..j
    const keep = new Set([i, j]);
    for (const y of ys) {
      let mn = -1;
      let mx = -1;
      for (let k = i; k <= j; k += 1) {
        const v = y[k];
        if (v == null || !Number.isFinite(v)) continue;
        if (mn < 0 || v < y[mn]) mn = k;
        if (mx < 0 || v > y[mx]) mx = k;
      }
      if (mn >= 0) keep.add(mn);
      if (mx >= 0) keep.add(mx);
    }
    out.push(...[...keep].sort((a, c) => a - c));
    i = j + 1;
  }
  return out;
}

/** Union of two sorted index lists, sorted. */
export function mergeSorted(a, b) {
  const out = [];
  let i = 0;
  let j = 0;
  while (i < a.length || j < b.length) {
    const v = j >= b.length || (i < a.length && a[i] <= b[j]) ? a[i++] : b[j++];
    if (out.length === 0 || out[out.length - 1] !== v) out.push(v);
  }
  return out;
}

// A tiny deterministic ROV simulator for the browser tests, ported from
// tests/common/sim.rs: decoupled first-order DOFs T_i·ν̇_i = −ν_i + τ_i/d_i,
// driven by held random-binary forces, with small measurement noise, written
// as the log contract's CSV (t, tau_X..tau_N, u..r, x..psi).

const MASK = (1n << 64n) - 1n;

/** SplitMix64: deterministic, seedable (same stream as the Rust tests). */
export class Rng {
  constructor(seed) { this.s = BigInt(seed) & MASK; }
  nextU64() {
    this.s = (this.s + 0x9E3779B97F4A7C15n) & MASK;
    let z = this.s;
    z = ((z ^ (z >> 30n)) * 0xBF58476D1CE4E5B9n) & MASK;
    z = ((z ^ (z >> 27n)) * 0x94D049BB133111EBn) & MASK;
    return z ^ (z >> 31n);
  }
  uniform() { return Number(this.nextU64() >> 11n) / 2 ** 53; }
  normal() {
    const u1 = Math.max(this.uniform(), 1e-300);
    const u2 = this.uniform();
    return Math.sqrt(-2 * Math.log(u1)) * Math.cos(2 * Math.PI * u2);
  }
}

export const FORCES = ['tau_X', 'tau_Y', 'tau_Z', 'tau_K', 'tau_M', 'tau_N'];
export const VELS = ['u', 'v', 'w', 'p', 'q', 'r'];
export const POSE = ['x', 'y', 'z', 'phi', 'theta', 'psi'];
export const ALL_COLUMNS = [...FORCES, ...VELS, ...POSE];
export const TC = [4.0, 3.0, 3.0, 1.5, 1.5, 2.0];
export const D = [2000, 4000, 4000, 3000, 3000, 3000];
/** Righting moments of roll and pitch (N·m/rad): attitudes stay within a few degrees, as a real ROV's. */
export const G = [0, 0, 0, 6000, 6000, 0];

/**
 * Simulates `duration` s at `fs` Hz. `amp[i]` is the force amplitude of DOF i
 * (0 holds it still); forces switch every `clock` s. `force[i]`, if given, is
 * a function k → τ_i (e.g. a planned schedule) that replaces the random force.
 * `surge` is the forward speed (m/s) the surge bias force holds.
 */
export function simulate({ seed, fs, duration, amp, clock, noise, force = [], surge = 0.5 }) {
  const n = Math.floor(duration * fs);
  const h = 1 / fs;
  const rng = new Rng(seed);
  const run = { t: Array.from({ length: n }, (_, k) => k * h), tau: [], nu: [], eta: [] };
  for (let i = 0; i < 6; i += 1) {
    const hold = Math.max(Math.round(clock * fs), 1);
    let level = 0;
    let v = i === 0 ? surge : 0;
    let pos = i === 2 ? 20 : 0;
    const a = Math.exp(-h / TC[i]);
    const tau = new Float64Array(n);
    const nu = new Float64Array(n);
    const eta = new Float64Array(n);
    for (let k = 0; k < n; k += 1) {
      if (k % hold === 0) level = rng.uniform() < 0.5 ? -amp[i] : amp[i];
      const bias = i === 0 ? surge * D[0] : 0;
      const f = force[i] ? force[i](k) : bias + level;
      tau[k] = f;
      nu[k] = v + noise * rng.normal();
      eta[k] = pos + noise * rng.normal();
      v = a * v + (1 - a) * (f - G[i] * pos) / D[i];
      pos += v * h;
    }
    run.tau.push(tau);
    run.nu.push(nu);
    run.eta.push(eta);
  }
  // Depth gets a slow dive profile so two-file runs have a shared channel that varies.
  for (let k = 0; k < n; k += 1) {
    const t = run.t[k];
    run.eta[2][k] += 3 * Math.sin(t / 40) + 1.5 * Math.sin(t / 13);
  }
  return run;
}

/** CSV with the given columns (`t` first), optional clock offset added to t, every `every`-th sample. */
export function csv(run, cols, tOffset = 0, every = 1) {
  const src = cols.map((c) => {
    let i = FORCES.indexOf(c);
    if (i >= 0) return run.tau[i];
    i = VELS.indexOf(c);
    if (i >= 0) return run.nu[i];
    i = POSE.indexOf(c);
    if (i >= 0) return run.eta[i];
    return null;
  });
  const lines = [['t', ...cols].join(',')];
  for (let k = 0; k < run.t.length; k += Math.max(every, 1)) {
    let s = String(run.t[k] + tOffset);
    for (const col of src) s += `,${col ? col[k] : 0}`;
    lines.push(s);
  }
  return `${lines.join('\n')}\n`;
}

// Number, unit and time formatting shared by every view.

export const KN = 1852 / 3600; // 1 kn in m/s
export const DOFS = ['surge', 'sway', 'heave', 'roll', 'pitch', 'yaw'];
export const LINEAR = new Set(['surge', 'sway', 'heave']);

export const FAMILIES = {
  rov6: ['static', 'dynamic', 'recursive', 'validation'],
  dp3: ['dp_surge', 'dp_sway_yaw', 'dp_azimuth', 'validation'],
};
export const FAMILY_LABEL = {
  static: 'Static',
  dynamic: 'Dynamic',
  recursive: 'Recursive',
  validation: 'Validation',
  dp_surge: 'DP surge (SI1)',
  dp_sway_yaw: 'DP sway–yaw (SI2)',
  dp_azimuth: 'DP azimuth (SI3)',
};
export const KIND_LABEL = { rov6: '6-DOF ROV', dp3: '3-DOF DP vessel' };
export const SIGNALS = ['prbs', 'square', 'multisine', 'random_binary'];
export const SIGNAL_LABEL = {
  prbs: 'PRBS', square: 'Square wave', multisine: 'Multisine', random_binary: 'Random binary',
};

const MINUS = '\u2212';
const THIN = '\u2009';

/** A number for people: 3 decimals, integers bare, big/small ones in e-notation. */
export function fmt(x, digits = 3) {
  if (x == null || typeof x !== 'number' || Number.isNaN(x)) return '–';
  if (!Number.isFinite(x)) return x > 0 ? '∞' : `${MINUS}∞`;
  if (x === 0) return '0';
  const a = Math.abs(x);
  let s;
  if (a >= 1e6 || a < 1e-3) s = x.toExponential(digits - 1).replace('e+', 'e');
  else if (Number.isInteger(x)) s = String(x);
  else if (a >= 1000) s = String(Math.round(x));
  else s = x.toFixed(digits);
  if (a >= 1000 && a < 1e6) s = s.replace(/\B(?=(\d{3})+(?!\d))/g, THIN);
  return s.replace('-', MINUS);
}

/** A number with `n` significant digits (4 by default), e-notation when very big or small. */
export function fmtSig(x, n = 4) {
  if (x == null || typeof x !== 'number' || Number.isNaN(x)) return '–';
  if (!Number.isFinite(x)) return x > 0 ? '∞' : `${MINUS}∞`;
  if (x === 0) return '0';
  const a = Math.abs(x);
  // Trailing zeros kept (3.730 s says 4 digits); whole numbers beyond 10ⁿ stay whole.
  let s;
  if (a >= 1e6 || a < 1e-3) s = x.toExponential(n - 1).replace('e+', 'e');
  else if (a >= 10 ** n) s = String(Math.round(x));
  else s = x.toPrecision(n);
  return s.replace(/-/g, MINUS);
}

/** A value as entered (grid speeds, settings): no trailing zeros, no float noise. */
export function fmtShort(x) {
  if (x == null || typeof x !== 'number' || !Number.isFinite(x)) return fmt(x);
  const a = Math.abs(x);
  if (a !== 0 && (a < 1e-3 || a >= 1e6)) return fmt(x);
  return String(Number(x.toFixed(3))).replace('-', MINUS);
}

/** Value with its unit, e.g. "0.386 m/s". */
export function fmtU(x, unit) {
  const u = unitLabel(unit);
  return u ? `${fmt(x)} ${u}` : fmt(x);
}

/** "1" (dimensionless, the normalized thruster commands) reads better as "–". */
export function unitLabel(unit) {
  return unit === '1' ? '–' : unit || '';
}

/** h:mm:ss */
export function hms(seconds) {
  if (seconds == null || !Number.isFinite(seconds)) return '–';
  const s = Math.round(seconds);
  const h = Math.floor(s / 3600);
  const m = Math.floor((s % 3600) / 60);
  const r = s % 60;
  return `${h}:${String(m).padStart(2, '0')}:${String(r).padStart(2, '0')}`;
}

/** Run length: seconds with at most one decimal. */
export function secs(x) {
  if (x == null || !Number.isFinite(x)) return '–';
  return `${Number(x.toFixed(1))} s`;
}

export function knots(mps) {
  return mps / KN;
}

/** A grid speed as "1.5 kn" (2 decimals at most). */
export function fmtKn(mps) {
  if (mps == null) return '–';
  return `${Number(knots(mps).toFixed(2))}`;
}

export function dofUnits(dof) {
  const lin = LINEAR.has(dof);
  return {
    velocity: lin ? 'm/s' : 'rad/s',
    force: lin ? 'N' : 'N·m',
    force_rate: lin ? 'N/s' : 'N·m/s',
    accel: lin ? 'm/s²' : 'rad/s²',
  };
}

export function fmtDate(iso) {
  if (!iso) return '–';
  const d = new Date(iso);
  if (Number.isNaN(d.getTime())) return iso;
  const p = (n) => String(n).padStart(2, '0');
  return `${d.getFullYear()}-${p(d.getMonth() + 1)}-${p(d.getDate())} ${p(d.getHours())}:${p(d.getMinutes())}`;
}

/** Describe a Waveform object in one line. */
export function describeWaveform(w, unit) {
  if (!w) return '–';
  switch (w.shape) {
    case 'constant': return 'hold';
    case 'step': return `step ${w.sign > 0 ? '+' : MINUS}`;
    case 'prbs': return `PRBS n=${w.order}, Tc=${fmtShort(w.clock_period_s)} s${w.shift_chips ? `, shift ${w.shift_chips}` : ''}`;
    case 'square': return `square, P=${fmt(w.period_s)} s`;
    case 'multisine': return `multisine ${fmt(w.f_lo_hz)}–${fmt(w.f_hi_hz)} Hz, P=${fmt(w.period_s)} s`;
    case 'random_binary': return `random binary, Tc=${fmtShort(w.clock_period_s)} s`;
    case 'constant_then_random':
      return `segments ${fmt(w.segment_s)} s: ${Math.round(w.constant_fraction * 100)} % hold, then random Tc=${fmt(w.clock_period_s)} s`;
    case 'staircase':
      return `staircase ${w.levels.map((l) => fmt(l)).join(' → ')} ${unitLabel(unit)} × ${fmt(w.segment_s)} s`;
    default: return w.shape;
  }
}

export function peText(a) {
  if (!a) return '';
  const at = a.pe_order >= a.pe_cap ? '≥' : '';
  return `${at}${a.pe_order}/${a.pe_required}`;
}

export function bandText(band) {
  if (!band || band.length < 2) return '–';
  if (band[0] === band[1]) return `${fmt(band[0])} Hz`;
  return `${fmt(band[0])}–${fmt(band[1])} Hz`;
}

/** A file size for people, e.g. "217.6 kB" (SI units; exact bytes belong in a title). */
export function bytes(n) {
  if (n == null || !Number.isFinite(n)) return '–';
  if (n < 1000) return `${n} B`;
  const units = ['kB', 'MB', 'GB', 'TB'];
  let x = n;
  let i = -1;
  do { x /= 1000; i += 1; } while (x >= 1000 && i < units.length - 1);
  return `${x >= 100 ? x.toFixed(0) : x.toFixed(1)} ${units[i]}`;
}

/** Data-quality verdicts and coverage states. */
export const VERDICT_ICON = { good: '✓', weak: '!', insufficient: '✗', rejected: '✗', check_units: '⚠' };
export const COVERAGE_LABEL = {
  covered: 'covered', weak: 'weak', check_units: 'check units', repeat: 'fly again', missing: 'not flown',
};
export const COVERAGE_HELP = {
  covered: 'a good run in every DOF the experiment excites',
  weak: 'its best run is weak in some excited DOF: usable, but consider flying it again',
  check_units: 'flown, but the log’s units look wrong (milliseconds, degrees): fix them and upload it again before deciding to fly',
  repeat: 'flown, but no run is usable: fly it again',
  missing: 'not flown yet',
};

//! Design for precision per ship-hour: the excitation (signal, amplitude,
//! clock per DOF), run lengths, repetitions and estimation families that
//! minimise the D criterion ([`super::information`]) within a budget of
//! ship hours, and the trade-off of precision against hours beside the
//! rule-based plan's.
//!
//! The search is in two stages, both over plans the planner itself
//! generates (so every candidate respects the actuator force, rate and
//! attitude limits — a candidate the planner refuses is skipped):
//! 1. the shape of each DOF's excitation by coordinate descent on the
//!    information per hour, D + ln(hours / reference hours) (information
//!    grows with run time, so a shape that lengthens the runs must pay for
//!    it);
//! 2. lengths, repetitions and families, each combination scored by D; the
//!    best within the budget is the design, and the lower-left (Pareto)
//!    front of all combinations is the trade-off curve.
//!
//! The rule-based front is the same lengths × repetitions × families with
//! the campaign's own excitation: "what more ship time buys with today's
//! rules". The ship-hour ratio is the hours that front needs to reach the
//! design's precision over the design's hours.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::DesignError;
use super::information::{InformationCache, Scaling, d_criterion, plan_information};
use crate::estimation::Progress;
use crate::planning::campaign::{DofExcitation, Quantity, SignalKind};
use crate::planning::dof::Dof;
use crate::planning::{CampaignSpec, ExperimentFamily, Plan, VesselProfile, generate_plan};
use crate::simulation::rov::RovTruth;

/// Run lengths of dynamic runs tried (s; the thesis's minimum is 30 s).
const DYNAMIC_S: [f64; 3] = [30.0, 60.0, 120.0];
/// Run lengths of recursive runs tried (s; the thesis's minimum is 100 s).
const RECURSIVE_S: [f64; 3] = [100.0, 200.0, 400.0];
/// Repetitions tried.
const REPETITIONS: [u32; 2] = [1, 2];
/// Amplitudes tried, as fractions of the DOF's limit.
const AMPLITUDE_FRACTIONS: [f64; 3] = [0.5, 0.75, 1.0];
/// The rule-based plan flown up to this many times over.
const RULE_REPETITIONS: u32 = 4;
/// Coordinate-descent sweeps over the DOFs at most.
const SWEEPS: usize = 2;

/// One point of a trade-off curve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct TradePoint {
    /// Ship hours of the plan (runs and set-up).
    pub hours: f64,
    /// D criterion (lower is better).
    pub criterion: f64,
    /// Geometric-mean std relative to the campaign's current plan,
    /// exp((D − D_current)/2): 0.5 halves every std on the geometric mean.
    pub relative_std: f64,
    /// Dynamic-run length (s).
    pub dynamic_s: f64,
    /// Recursive-run length (s).
    pub recursive_s: f64,
    /// Repetitions per grid point and DOF.
    pub repetitions: u32,
    /// Estimation families flown (`dynamic`, `recursive`).
    pub families: Vec<String>,
}

/// The excitation chosen for one DOF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DofChoice {
    /// DOF name.
    pub dof: String,
    /// Signal shape.
    pub signal: SignalKind,
    /// Amplitude (SI; absent where the planner's default is kept: surge's
    /// speed excursion, roll and pitch attitude already at their limit).
    pub amplitude: Option<f64>,
    /// Its unit.
    pub unit: String,
    /// Clock period (PRBS) or square-wave half period (s); absent for the
    /// planner's default.
    pub clock_period_s: Option<f64>,
    /// Information per hour gained over the campaign's excitation for
    /// this DOF (factor, ≥ 1 when kept).
    pub gain: f64,
}

/// A designed campaign within a ship-time budget.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ExperimentDesign {
    /// The budget (h).
    pub budget_hours: f64,
    /// The designed campaign: re-plan with it to adopt the design.
    pub spec: CampaignSpec,
    /// The design's point.
    pub design: TradePoint,
    /// The campaign's current plan.
    pub current: TradePoint,
    /// Per-DOF excitation chosen.
    pub choices: Vec<DofChoice>,
    /// Designed front: best precision for the hours.
    pub designed_front: Vec<TradePoint>,
    /// Rule-based front: the campaign's plan repeated 1–4 times.
    pub rule_front: Vec<TradePoint>,
    /// Hours the rule-based plans need for the design's precision.
    pub rule_hours_for_equal_precision: f64,
    /// That over the design's hours (≥ 1: the design saves ship time).
    pub hours_ratio: f64,
    /// True when the rule-based front never reaches the design's precision
    /// and its hours are extrapolated (information ∝ run time beyond its
    /// last point).
    pub extrapolated: bool,
    /// Candidate plans scored.
    pub candidates: usize,
    /// Distinct experiments flown through the simulator.
    pub flights: usize,
    /// How the design was made, and what it assumes.
    pub notes: Vec<String>,
}

/// Scores plans against the current plan's scaling.
struct Scorer<'a> {
    profile: &'a VesselProfile,
    truth: &'a RovTruth,
    cache: InformationCache,
    scaling: Scaling,
    current_d: f64,
    scored: usize,
}

impl Scorer<'_> {
    /// (hours, D) of `spec`, or None when the planner refuses it or a grid
    /// point gets no data.
    fn score(&mut self, spec: &CampaignSpec) -> Result<Option<(Plan, f64, f64)>, DesignError> {
        let Ok(plan) = generate_plan(self.profile, spec) else {
            return Ok(None);
        };
        self.scored += 1;
        let info = plan_information(self.profile, &plan, self.truth, &mut self.cache)?;
        let hours = plan.totals.total_time_s / 3600.0;
        Ok(d_criterion(self.profile, &info, &self.scaling).map(|d| (plan, hours, d)))
    }

    fn point(&self, spec: &CampaignSpec, hours: f64, d: f64) -> TradePoint {
        TradePoint {
            hours,
            criterion: d,
            relative_std: (0.5 * (d - self.current_d)).exp(),
            dynamic_s: spec.durations.dynamic_s,
            recursive_s: spec.durations.recursive_s,
            repetitions: spec.repetitions.unwrap_or(1),
            families: spec
                .families
                .iter()
                .filter(|f| estimation_family(**f))
                .map(|f| f.name().to_string())
                .collect(),
        }
    }
}

fn estimation_family(f: ExperimentFamily) -> bool {
    matches!(f, ExperimentFamily::Dynamic | ExperimentFamily::Recursive)
}

/// The shapes tried for DOF `d`: signal and clock (and amplitude where the
/// planner's default is not already the most a limit allows).
fn shape_candidates(profile: &VesselProfile, plan: &Plan, d: Dof) -> Vec<DofExcitation> {
    let t = profile.limit(d).time_constant_s;
    let attitude = matches!(d, Dof::Roll | Dof::Pitch);
    let limit = plan
        .experiments
        .iter()
        .filter(|p| p.experiment.family == ExperimentFamily::Dynamic)
        .flat_map(|p| &p.experiment.channels)
        .find(|c| c.excited && c.dof == Some(d))
        .map(|c| c.limit);
    let amplitudes: Vec<Option<f64>> = match limit {
        Some(l) if d != Dof::Surge && !attitude => {
            AMPLITUDE_FRACTIONS.iter().map(|f| Some(f * l)).collect()
        }
        _ => vec![None],
    };
    // Attitude loops are clocked on 2·T of the loop; the planner's default
    // clock is kept for them (None) with the signal varied.
    let shapes: Vec<(SignalKind, Option<f64>)> = if attitude {
        vec![
            (SignalKind::Prbs, None),
            (SignalKind::Square, None),
            (SignalKind::Multisine, None),
        ]
    } else {
        vec![
            (SignalKind::Prbs, Some(0.5 * t)),
            (SignalKind::Prbs, Some(t)),
            (SignalKind::Prbs, Some(2.0 * t)),
            (SignalKind::Square, Some(2.5 * t)),
            (SignalKind::Square, Some(5.0 * t)),
            (SignalKind::Multisine, None),
        ]
    };
    let mut out = Vec::new();
    for (signal, clock) in &shapes {
        for a in &amplitudes {
            out.push(DofExcitation {
                signal: Some(*signal),
                amplitude: *a,
                clock_period_s: *clock,
                prbs_order: None,
            });
        }
    }
    out
}

/// The families combinations tried: the campaign's own, with dynamic and
/// recursive runs together or alone where the campaign flies both.
fn family_sets(base: &[ExperimentFamily]) -> Vec<Vec<ExperimentFamily>> {
    let has = |f| base.contains(&f);
    let mut sets = vec![base.to_vec()];
    if has(ExperimentFamily::Dynamic) && has(ExperimentFamily::Recursive) {
        for drop in [ExperimentFamily::Recursive, ExperimentFamily::Dynamic] {
            sets.push(base.iter().copied().filter(|f| *f != drop).collect());
        }
    }
    sets
}

/// The lower-left front of (hours, D): each point beats every point of
/// fewer hours; sorted by hours.
fn front(mut points: Vec<TradePoint>) -> Vec<TradePoint> {
    points.sort_by(|a, b| {
        a.hours
            .total_cmp(&b.hours)
            .then(a.criterion.total_cmp(&b.criterion))
    });
    let mut out: Vec<TradePoint> = Vec::new();
    for p in points {
        if out.last().is_none_or(|l| p.criterion < l.criterion - 1e-9) {
            out.push(p);
        }
    }
    out
}

/// Hours `front` needs to reach criterion `d`: log-linear interpolation
/// in hours; beyond its last point, information ∝ hours (D falls by ln 2
/// per doubling). Returns (hours, extrapolated).
fn hours_for(front: &[TradePoint], d: f64) -> (f64, bool) {
    if let Some(first) = front.first()
        && first.criterion <= d
    {
        return (first.hours, false);
    }
    for w in front.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if b.criterion <= d {
            let s = (a.criterion - d) / (a.criterion - b.criterion);
            return (
                (a.hours.ln() + s * (b.hours.ln() - a.hours.ln())).exp(),
                false,
            );
        }
    }
    let last = front.last().expect("a front has a point");
    (last.hours * (last.criterion - d).exp(), true)
}

/// Designs the campaign `base` (flown on `profile`) for the most precision
/// within `budget_hours` (the current plan's hours when `None`), the plans
/// flown with `truth` (the prior).
///
/// # Errors
/// The current plan cannot be generated or gives no estimation data at a
/// grid point; a budget below the shortest plan that identifies every grid
/// point (the error names `settings.budget_hours` and the minimum);
/// cancellation.
pub fn design_campaign(
    profile: &VesselProfile,
    base: &CampaignSpec,
    truth: &RovTruth,
    budget_hours: Option<f64>,
    progress: &mut dyn Progress,
) -> Result<ExperimentDesign, DesignError> {
    let current_plan = generate_plan(profile, base)
        .map_err(|e| DesignError::new(format!("campaign.{}", e.field), e.to_string()))?;
    let mut cache = InformationCache::default();
    let current_info = plan_information(profile, &current_plan, truth, &mut cache)?;
    let grid = current_plan.grid_speeds();
    let scaling = Scaling::of(&current_info, &grid)?;
    let current_d = d_criterion(profile, &current_info, &scaling).ok_or_else(|| {
        DesignError::new(
            "plan",
            "the current plan's information is singular at a grid point",
        )
    })?;
    let current_hours = current_plan.totals.total_time_s / 3600.0;
    let budget = budget_hours.unwrap_or(current_hours);
    if !(budget.is_finite() && budget > 0.0) {
        return Err(DesignError::new(
            "settings.budget_hours",
            format!("must be a positive number of hours (got {budget})"),
        ));
    }
    let mut sc = Scorer {
        profile,
        truth,
        cache,
        scaling,
        current_d,
        scored: 1,
    };
    let current = sc.point(base, current_hours, current_d);

    // 1. Shapes, by coordinate descent on information per hour.
    let per_hour = |hours: f64, d: f64, ref_h: f64| d + (hours / ref_h).ln();
    let mut spec = base.clone();
    let mut best = per_hour(current_hours, current_d, current_hours);
    let mut gains: BTreeMap<Dof, f64> = BTreeMap::new();
    let dofs = profile.dofs.clone();
    let steps = (SWEEPS * dofs.len()) as f64;
    let mut changed = true;
    for sweep in 0..SWEEPS {
        if !changed {
            break;
        }
        changed = false;
        for (k, d) in dofs.iter().enumerate() {
            progress
                .update(
                    0.6 * (sweep * dofs.len() + k) as f64 / steps,
                    &format!("choosing the {} excitation", d.name()),
                )
                .map_err(|_| super::predict::cancelled())?;
            let before = best;
            for cand in shape_candidates(profile, &current_plan, *d) {
                let mut s = spec.clone();
                s.excitation.per_dof.insert(*d, cand.clone());
                if let Some((_, hours, dc)) = sc.score(&s)? {
                    let v = per_hour(hours, dc, current_hours);
                    if v < best - 1e-6 {
                        best = v;
                        spec = s;
                        changed = true;
                    }
                }
            }
            *gains.entry(*d).or_insert(1.0) *= (before - best).exp();
        }
    }

    // 2. Lengths, repetitions and families: the designed and rule fronts.
    let combos: Vec<(f64, f64, u32, Vec<ExperimentFamily>)> = DYNAMIC_S
        .iter()
        .flat_map(|&dy| {
            RECURSIVE_S
                .iter()
                .flat_map(move |&rc| REPETITIONS.iter().map(move |&n| (dy, rc, n)))
        })
        .flat_map(|(dy, rc, n)| {
            family_sets(&base.families)
                .into_iter()
                .map(move |f| (dy, rc, n, f))
        })
        .collect();
    // The current plan stays a candidate: a budget of its hours always has
    // an answer, even where the shapes chosen lengthen the runs.
    let mut designed = vec![current.clone()];
    let mut best_design: Option<(CampaignSpec, TradePoint)> =
        (current_hours <= budget + 1e-9).then(|| (base.clone(), current.clone()));
    for (i, (dy, rc, n, fams)) in combos.iter().enumerate() {
        progress
            .update(
                0.6 + 0.35 * i as f64 / combos.len() as f64,
                "trading run length and repetitions against ship hours",
            )
            .map_err(|_| super::predict::cancelled())?;
        let mut s = spec.clone();
        s.durations.dynamic_s = s.durations.dynamic_s.max(*dy);
        s.durations.recursive_s = s.durations.recursive_s.max(*rc);
        s.repetitions = Some(*n);
        s.families = fams.clone();
        if let Some((_, hours, d)) = sc.score(&s)? {
            let p = sc.point(&s, hours, d);
            if hours <= budget + 1e-9 && best_design.as_ref().is_none_or(|(_, b)| d < b.criterion) {
                best_design = Some((s, p.clone()));
            }
            designed.push(p);
        }
    }
    // Today's rules given more time: the campaign repeated.
    let mut rule = vec![current.clone()];
    for n in 2..=RULE_REPETITIONS {
        progress
            .update(0.95, "scoring the rule-based plan repeated")
            .map_err(|_| super::predict::cancelled())?;
        let mut s = base.clone();
        s.repetitions = Some(s.repetitions_for(profile.kind) * n);
        if let Some((_, hours, d)) = sc.score(&s)? {
            rule.push(sc.point(&s, hours, d));
        }
    }
    let designed_front = front(designed);
    let rule_front = front(rule);
    let Some((spec, design)) = best_design else {
        let min = designed_front.first().map_or(current_hours, |p| p.hours);
        return Err(DesignError::new(
            "settings.budget_hours",
            format!(
                "{budget:.2} h is less than the shortest plan that identifies every grid point ({min:.2} h)"
            ),
        ));
    };
    let (rule_hours, extrapolated) = hours_for(&rule_front, design.criterion);
    let choices = dofs
        .iter()
        .map(|d| {
            let o = spec.excitation.per_dof.get(d);
            DofChoice {
                dof: d.name().to_string(),
                signal: o.and_then(|o| o.signal).unwrap_or(spec.excitation.signal),
                amplitude: o.and_then(|o| o.amplitude),
                unit: match spec.excitation.quantity {
                    Quantity::Velocity if matches!(d, Dof::Roll | Dof::Pitch) => "rad".into(),
                    Quantity::Velocity => d.velocity_unit().to_string(),
                    Quantity::Force => d.force_unit().to_string(),
                },
                clock_period_s: o.and_then(|o| o.clock_period_s),
                gain: if o == base.excitation.per_dof.get(d) {
                    1.0
                } else {
                    gains.get(d).copied().unwrap_or(1.0)
                },
            }
        })
        .collect();
    let notes = vec![
        format!(
            "D criterion of the λ-filter regression (port–starboard structure, constant loads and g(η)'s shapes), flown noise-free with the prior through the project's simulator; {} candidate plans, {} distinct runs flown",
            sc.scored, sc.cache.flown
        ),
        "static and validation runs are kept as planned: they do not feed the regression's information".into(),
        "the excitation is chosen per DOF for every grid speed; lengths and repetitions for the whole campaign".into(),
    ];
    Ok(ExperimentDesign {
        budget_hours: budget,
        hours_ratio: rule_hours / design.hours,
        rule_hours_for_equal_precision: rule_hours,
        extrapolated,
        spec,
        design,
        current,
        choices,
        designed_front,
        rule_front,
        candidates: sc.scored,
        flights: sc.cache.flown,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(hours: f64, criterion: f64) -> TradePoint {
        TradePoint {
            hours,
            criterion,
            relative_std: 1.0,
            dynamic_s: 30.0,
            recursive_s: 100.0,
            repetitions: 1,
            families: vec![],
        }
    }

    #[test]
    fn the_front_keeps_only_points_better_than_every_shorter_plan() {
        let f = front(vec![
            p(3.0, 0.5),
            p(1.0, 1.0),
            p(2.0, 1.2),
            p(4.0, 0.5),
            p(2.5, 0.2),
        ]);
        let pts: Vec<(f64, f64)> = f.iter().map(|q| (q.hours, q.criterion)).collect();
        assert_eq!(pts, vec![(1.0, 1.0), (2.5, 0.2)]);
    }

    #[test]
    fn hours_for_interpolates_in_log_hours_and_extrapolates_information_in_proportion() {
        // D = −ln(hours): information ∝ hours; the interpolation is exact.
        let f: Vec<TradePoint> = [1.0, 2.0, 4.0]
            .iter()
            .map(|h: &f64| p(*h, -h.ln()))
            .collect();
        let (h, ex) = hours_for(&f, -3.0_f64.ln());
        assert!((h - 3.0).abs() < 0.2 && !ex, "{h}");
        let (h, ex) = hours_for(&f, -(8.0_f64.ln()));
        assert!((h - 8.0).abs() < 1e-9 && ex, "{h}");
        assert_eq!(hours_for(&f, 5.0), (1.0, false));
    }
}

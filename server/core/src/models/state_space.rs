//! Linear time-invariant state-space models, continuous ẋ = A x + B u,
//! y = C x + D u, and their exact zero-order-hold discretization
//! x(k+1) = Φ x(k) + Γ u(k) (thesis sec. 2.6, h = 0.1 s).
//!
//! Signals follow the crate's convention: one row per sample, one column per
//! channel (u is N × m, y is N × p).

use nalgebra::{Complex, DMatrix, DVector};

use super::error::{ModelError, check_finite, check_sample_time, check_shape};

/// Continuous-time ẋ = A x + B u, y = C x + D u with n states, m inputs and
/// p outputs. Built through [`StateSpace::new`], so the shapes always agree.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    a: DMatrix<f64>,
    b: DMatrix<f64>,
    c: DMatrix<f64>,
    d: DMatrix<f64>,
}

/// Discrete-time x(k+1) = Φ x(k) + Γ u(k) + w, y(k) = C x(k) + D u(k) with
/// the input held constant over each sample interval of length h; the
/// constant w (zero unless set) carries a constant load, w = −Γ·b for
/// M ν̇ + D̄ ν + b = γ.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscreteStateSpace {
    phi: DMatrix<f64>,
    gamma: DMatrix<f64>,
    c: DMatrix<f64>,
    d: DMatrix<f64>,
    h: f64,
    offset: DVector<f64>,
}

/// Validates the four matrices of a state-space model named `names`
/// (`A`/`Φ`, `B`/`Γ`, `C`, `D`); returns (n, m, p).
fn check_quadruple(
    names: [&str; 4],
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
) -> Result<(usize, usize, usize), ModelError> {
    let [na, nb, nc, nd] = names;
    let n = a.nrows();
    if n == 0 || a.ncols() != n {
        return Err(ModelError::Shape {
            name: na.into(),
            expected: "square with at least one state".into(),
            found: a.shape(),
        });
    }
    let m = b.ncols();
    let p = c.nrows();
    check_shape(nb, b, n, m, || format!("{n}×m (n = {n} rows, like {na})"))?;
    check_shape(nc, c, p, n, || {
        format!("p×{n} (one column per state of {na})")
    })?;
    check_shape(nd, d, p, m, || {
        format!("{p}×{m} (rows of {nc} × columns of {nb})")
    })?;
    for (name, mat) in [(na, a), (nb, b), (nc, c), (nd, d)] {
        check_finite(name, mat.iter())?;
    }
    Ok((n, m, p))
}

impl StateSpace {
    /// A model from its matrices; A must be n×n (n ≥ 1), B n×m, C p×n, D p×m,
    /// all finite.
    pub fn new(
        a: DMatrix<f64>,
        b: DMatrix<f64>,
        c: DMatrix<f64>,
        d: DMatrix<f64>,
    ) -> Result<Self, ModelError> {
        check_quadruple(["A", "B", "C", "D"], &a, &b, &c, &d)?;
        Ok(StateSpace { a, b, c, d })
    }

    /// System matrix A (n × n).
    pub fn a(&self) -> &DMatrix<f64> {
        &self.a
    }
    /// Input matrix B (n × m).
    pub fn b(&self) -> &DMatrix<f64> {
        &self.b
    }
    /// Output matrix C (p × n).
    pub fn c(&self) -> &DMatrix<f64> {
        &self.c
    }
    /// Feed-through D (p × m).
    pub fn d(&self) -> &DMatrix<f64> {
        &self.d
    }
    /// Number of states n.
    pub fn n_states(&self) -> usize {
        self.a.nrows()
    }
    /// Number of inputs m.
    pub fn n_inputs(&self) -> usize {
        self.b.ncols()
    }
    /// Number of outputs p.
    pub fn n_outputs(&self) -> usize {
        self.c.nrows()
    }

    /// Exact zero-order-hold discretization with sample time `h` (s):
    /// exp([[A B],[0 0]]·h) = [[Φ Γ],[0 I]], so Φ = e^{Ah} and
    /// Γ = ∫₀ʰ e^{As} ds B without inverting A (valid for singular A, e.g.
    /// an integrator or an undamped DOF).
    pub fn discretize_zoh(&self, h: f64) -> Result<DiscreteStateSpace, ModelError> {
        check_sample_time(h)?;
        let (n, m) = (self.n_states(), self.n_inputs());
        let mut aug = DMatrix::zeros(n + m, n + m);
        aug.view_mut((0, 0), (n, n)).copy_from(&(&self.a * h));
        aug.view_mut((0, n), (n, m)).copy_from(&(&self.b * h));
        let e = aug.exp();
        let phi = e.view((0, 0), (n, n)).into_owned();
        let gamma = e.view((0, n), (n, m)).into_owned();
        // exp of a finite matrix can still overflow for a violently unstable A.
        check_finite("Φ = e^{Ah}", phi.iter())?;
        check_finite("Γ", gamma.iter())?;
        Ok(DiscreteStateSpace {
            offset: DVector::zeros(n),
            phi,
            gamma,
            c: self.c.clone(),
            d: self.d.clone(),
            h,
        })
    }

    /// Eigenvalues of A (the continuous poles), complex, in no particular
    /// order. A is finite by construction, so the Schur iteration converges.
    pub fn eigenvalues(&self) -> Vec<Complex<f64>> {
        self.a.complex_eigenvalues().iter().copied().collect()
    }
}

impl DiscreteStateSpace {
    /// A discrete model from its matrices and sample time `h` (s).
    pub fn new(
        phi: DMatrix<f64>,
        gamma: DMatrix<f64>,
        c: DMatrix<f64>,
        d: DMatrix<f64>,
        h: f64,
    ) -> Result<Self, ModelError> {
        check_sample_time(h)?;
        check_quadruple(["Φ", "Γ", "C", "D"], &phi, &gamma, &c, &d)?;
        let offset = DVector::zeros(phi.nrows());
        Ok(DiscreteStateSpace {
            phi,
            gamma,
            c,
            d,
            h,
            offset,
        })
    }

    /// The same model with the constant state increment w (n entries,
    /// finite).
    pub fn with_offset(mut self, w: DVector<f64>) -> Result<Self, ModelError> {
        if w.len() != self.n_states() {
            return Err(ModelError::Shape {
                name: "w".into(),
                expected: format!("{}×1 (one entry per state)", self.n_states()),
                found: (w.len(), 1),
            });
        }
        check_finite("w", w.iter())?;
        self.offset = w;
        Ok(self)
    }

    /// Constant state increment w per step (zero for a linear model).
    pub fn offset(&self) -> &DVector<f64> {
        &self.offset
    }

    /// Transition matrix Φ (n × n).
    pub fn phi(&self) -> &DMatrix<f64> {
        &self.phi
    }
    /// Input matrix Γ (n × m).
    pub fn gamma(&self) -> &DMatrix<f64> {
        &self.gamma
    }
    /// Output matrix C (p × n).
    pub fn c(&self) -> &DMatrix<f64> {
        &self.c
    }
    /// Feed-through D (p × m).
    pub fn d(&self) -> &DMatrix<f64> {
        &self.d
    }
    /// Sample time h (s).
    pub fn h(&self) -> f64 {
        self.h
    }
    /// Number of states n.
    pub fn n_states(&self) -> usize {
        self.phi.nrows()
    }
    /// Number of inputs m.
    pub fn n_inputs(&self) -> usize {
        self.gamma.ncols()
    }
    /// Number of outputs p.
    pub fn n_outputs(&self) -> usize {
        self.c.nrows()
    }

    /// Eigenvalues of Φ (the discrete poles, e^{λh} of the continuous ones).
    pub fn eigenvalues(&self) -> Vec<Complex<f64>> {
        self.phi.complex_eigenvalues().iter().copied().collect()
    }

    /// One step x(k+1) = Φ x(k) + Γ u(k) + w (shapes are the caller's duty).
    pub(crate) fn step(&self, x: &DVector<f64>, u: &DVector<f64>) -> DVector<f64> {
        &self.phi * x + &self.gamma * u + &self.offset
    }

    /// Response from x(0) = `x0` to the inputs `u` (N × m, row k held over
    /// [kh, (k+1)h)): the outputs y(0..N) as an N × p matrix.
    pub fn simulate(
        &self,
        x0: &DVector<f64>,
        u: &DMatrix<f64>,
    ) -> Result<DMatrix<f64>, ModelError> {
        let (n, m, p) = (self.n_states(), self.n_inputs(), self.n_outputs());
        if x0.len() != n {
            return Err(ModelError::Shape {
                name: "x0".into(),
                expected: format!("{n}×1 (one entry per state)"),
                found: (x0.len(), 1),
            });
        }
        check_shape("u", u, u.nrows(), m, || {
            format!("N×{m} (one column per input)")
        })?;
        check_finite("x0", x0.iter())?;
        check_finite("u", u.iter())?;
        let mut y = DMatrix::zeros(u.nrows(), p);
        let mut x = x0.clone();
        for k in 0..u.nrows() {
            let uk = u.row(k).transpose();
            y.row_mut(k)
                .copy_from(&(&self.c * &x + &self.d * &uk).transpose());
            x = self.step(&x, &uk);
        }
        Ok(y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::integrate::simulate as rk4_simulate;

    fn m(rows: usize, cols: usize, data: &[f64]) -> DMatrix<f64> {
        DMatrix::from_row_slice(rows, cols, data)
    }

    #[test]
    fn scalar_zoh_matches_the_analytic_formula() {
        // ẋ = a x + b u: φ = e^{ah}, γ = (e^{ah} − 1) b / a.
        for &(a, b, h) in &[(-0.7, 2.0, 0.1), (0.3, -1.5, 0.5), (-25.0, 4.0, 0.05)] {
            let ss = StateSpace::new(
                m(1, 1, &[a]),
                m(1, 1, &[b]),
                m(1, 1, &[1.0]),
                m(1, 1, &[0.0]),
            )
            .unwrap();
            let dss = ss.discretize_zoh(h).unwrap();
            let phi = (a * h).exp();
            let gamma = (phi - 1.0) * b / a;
            assert!((dss.phi()[(0, 0)] - phi).abs() < 1e-14 * phi.max(1.0));
            assert!(
                (dss.gamma()[(0, 0)] - gamma).abs() < 1e-13 * gamma.abs(),
                "a={a}: {} vs {gamma}",
                dss.gamma()[(0, 0)]
            );
        }
        // a = 0 (pure integrator, A singular): γ = b h.
        let ss = StateSpace::new(
            m(1, 1, &[0.0]),
            m(1, 1, &[3.0]),
            m(1, 1, &[1.0]),
            m(1, 1, &[0.0]),
        )
        .unwrap();
        let dss = ss.discretize_zoh(0.2).unwrap();
        assert!((dss.gamma()[(0, 0)] - 0.6).abs() < 1e-15);
    }

    #[test]
    fn oscillator_zoh_matches_the_closed_form() {
        // ẍ + 2ζω ẋ + ω² x = ω² u, state [x, ẋ]. Φ = e^{Ah} in closed form for
        // the underdamped case; Γ from the step response x(h) = 1 − …
        let (w, z, h) = (2.0_f64, 0.1_f64, 0.3_f64);
        let a = m(2, 2, &[0.0, 1.0, -w * w, -2.0 * z * w]);
        let b = m(2, 1, &[0.0, w * w]);
        let ss = StateSpace::new(a, b, DMatrix::identity(2, 2), DMatrix::zeros(2, 1)).unwrap();
        let dss = ss.discretize_zoh(h).unwrap();
        let s = -z * w;
        let wd = w * (1.0 - z * z).sqrt();
        let (e, c, sn) = ((s * h).exp(), (wd * h).cos(), (wd * h).sin());
        // e^{Ah} = e^{sh} [cos I + (A − s I) sin/ω_d].
        let phi = [
            e * (c - s * sn / wd),
            e * sn / wd,
            e * (-w * w * sn / wd),
            e * (c + (-2.0 * z * w - s) * sn / wd),
        ];
        for (i, want) in phi.iter().enumerate() {
            let got = dss.phi()[(i / 2, i % 2)];
            assert!((got - want).abs() < 1e-13, "Φ[{i}] {got} vs {want}");
        }
        // Unit-step response from rest after h: x = 1 − e^{sh}(cos + (−s/ω_d) sin),
        // ẋ = e^{sh} (ω²/ω_d) sin.
        let x = 1.0 - e * (c - s / wd * sn);
        let xd = e * w * w / wd * sn;
        assert!((dss.gamma()[(0, 0)] - x).abs() < 1e-13);
        assert!((dss.gamma()[(1, 0)] - xd).abs() < 1e-13);
    }

    #[test]
    fn eigenvalues_of_a_known_matrix() {
        // Block diag of a rotation-like 2×2 (−1 ± 2i) and a real −3.
        let a = m(3, 3, &[-1.0, 2.0, 0.0, -2.0, -1.0, 0.0, 0.0, 0.0, -3.0]);
        let ss = StateSpace::new(
            a,
            DMatrix::zeros(3, 1),
            DMatrix::identity(3, 3),
            DMatrix::zeros(3, 1),
        )
        .unwrap();
        let mut ev = ss.eigenvalues();
        ev.sort_by(|p, q| p.re.total_cmp(&q.re).then(p.im.total_cmp(&q.im)));
        let want = [
            Complex::new(-3.0, 0.0),
            Complex::new(-1.0, -2.0),
            Complex::new(-1.0, 2.0),
        ];
        for (g, w) in ev.iter().zip(&want) {
            assert!((g - w).norm() < 1e-12, "{g} vs {w}");
        }
        // Discrete poles are e^{λh}.
        let dss = ss.discretize_zoh(0.1).unwrap();
        let mut dev = dss.eigenvalues();
        dev.sort_by(|p, q| p.re.total_cmp(&q.re).then(p.im.total_cmp(&q.im)));
        let mut dwant: Vec<Complex<f64>> = want.iter().map(|l| (l * 0.1).exp()).collect();
        dwant.sort_by(|p, q| p.re.total_cmp(&q.re).then(p.im.total_cmp(&q.im)));
        for (g, w) in dev.iter().zip(&dwant) {
            assert!((g - w).norm() < 1e-12, "{g} vs {w}");
        }
    }

    #[test]
    fn discrete_simulation_matches_fine_rk4() {
        // Coupled 2-state, 2-input system under a piecewise-constant input;
        // RK4 at h/200 with the same ZOH input converges to the exact ZOH map.
        let a = m(2, 2, &[-0.5, 1.2, -0.8, -0.3]);
        let b = m(2, 2, &[1.0, 0.2, -0.4, 0.7]);
        let c = m(1, 2, &[1.0, -2.0]);
        let d = m(1, 2, &[0.1, 0.0]);
        let ss = StateSpace::new(a.clone(), b.clone(), c.clone(), d.clone()).unwrap();
        let h = 0.1;
        let dss = ss.discretize_zoh(h).unwrap();
        let n = 150;
        let u = DMatrix::from_fn(n, 2, |k, j| ((k / 7 + 3 * j) % 5) as f64 - 2.0);
        let x0 = DVector::from_vec(vec![0.5, -1.0]);
        let y = dss.simulate(&x0, &u).unwrap();

        let sub = 200;
        let fine: Vec<Vec<f64>> = (0..n * sub)
            .map(|i| vec![u[(i / sub, 0)], u[(i / sub, 1)]])
            .collect();
        let xs = rk4_simulate(
            |x, uu, dx| {
                dx[0] = a[(0, 0)] * x[0] + a[(0, 1)] * x[1] + b[(0, 0)] * uu[0] + b[(0, 1)] * uu[1];
                dx[1] = a[(1, 0)] * x[0] + a[(1, 1)] * x[1] + b[(1, 0)] * uu[0] + b[(1, 1)] * uu[1];
            },
            &[0.5, -1.0],
            &fine,
            h / sub as f64,
        );
        let mut worst: f64 = 0.0;
        for k in 0..n {
            let x = &xs[k * sub];
            let yk =
                c[(0, 0)] * x[0] + c[(0, 1)] * x[1] + d[(0, 0)] * u[(k, 0)] + d[(0, 1)] * u[(k, 1)];
            worst = worst.max((y[(k, 0)] - yk).abs());
        }
        assert!(worst < 1e-10, "max |y_zoh − y_rk4| = {worst}");
        // The response is not trivially flat.
        assert!(y.column(0).amax() > 1.0);
    }

    #[test]
    fn bad_input_is_a_typed_error_naming_the_field() {
        let err = StateSpace::new(
            DMatrix::identity(3, 3),
            DMatrix::zeros(2, 1),
            DMatrix::identity(3, 3),
            DMatrix::zeros(3, 1),
        )
        .unwrap_err();
        assert!(matches!(&err, ModelError::Shape { name, found: (2, 1), .. } if name == "B"));
        assert_eq!(
            err.to_string(),
            "B is 2×1 but must be 3×m (n = 3 rows, like A)"
        );
        let err = StateSpace::new(
            DMatrix::identity(2, 2),
            DMatrix::zeros(2, 1),
            DMatrix::identity(2, 2),
            DMatrix::zeros(1, 1),
        )
        .unwrap_err();
        assert!(err.to_string().starts_with("D is 1×1"), "{err}");
        let mut a = DMatrix::identity(2, 2);
        a[(1, 0)] = f64::NAN;
        let err = StateSpace::new(
            a,
            DMatrix::zeros(2, 1),
            DMatrix::identity(2, 2),
            DMatrix::zeros(2, 1),
        )
        .unwrap_err();
        assert_eq!(err.to_string(), "A contains NaN or infinite entries");
        let ss = StateSpace::new(
            DMatrix::identity(2, 2),
            DMatrix::zeros(2, 1),
            DMatrix::identity(2, 2),
            DMatrix::zeros(2, 1),
        )
        .unwrap();
        for h in [0.0, -0.1, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                ss.discretize_zoh(h),
                Err(ModelError::InvalidSampleTime { .. })
            ));
        }
        let dss = ss.discretize_zoh(0.1).unwrap();
        let err = dss
            .simulate(&DVector::zeros(3), &DMatrix::zeros(5, 1))
            .unwrap_err();
        assert!(err.to_string().starts_with("x0 is 3×1"), "{err}");
        let err = dss
            .simulate(&DVector::zeros(2), &DMatrix::zeros(5, 2))
            .unwrap_err();
        assert!(
            err.to_string().starts_with("u is 5×2 but must be N×1"),
            "{err}"
        );
        let mut u = DMatrix::zeros(5, 1);
        u[(3, 0)] = f64::INFINITY;
        assert_eq!(
            dss.simulate(&DVector::zeros(2), &u)
                .unwrap_err()
                .to_string(),
            "u contains NaN or infinite entries"
        );
    }
}

//! What the parallel EKF needs of a model: one run's discrete transition
//! x(k+1) = f(x(k), u(k), θ) with its Jacobians (eq. 15, 18) and a linear
//! measurement z = H·x that does not involve θ (eq. 44–45).
//!
//! Continuous-time models ẋ = g(x, u, θ) are discretized by one RK4 step
//! per sample with the exact Jacobian of that step ([`Rk4`]).

use nalgebra::DMatrix;

/// One run's discrete model in the augmented EKF (Table 1, eq. 15–19).
pub trait RunModel {
    /// n, the states of one run.
    fn n_states(&self) -> usize;
    /// p, the unknown parameters θ shared by all runs.
    fn n_params(&self) -> usize;
    /// r, the inputs of one run.
    fn n_inputs(&self) -> usize;
    /// H (m × n) of z = H·x.
    fn measurement_matrix(&self) -> &DMatrix<f64>;
    /// Measured channels that are angles: their innovation is wrapped to
    /// (−π, π] (the heading ψ of a ship).
    fn angle_outputs(&self) -> &[usize] {
        &[]
    }
    /// x(k+1) = f(x(k), u(k), θ) into `x_next`, with Φ_x = ∂f/∂x (n × n) and
    /// Φ_θ = ∂f/∂θ (n × p) at (x(k), θ).
    fn transition(
        &self,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        x_next: &mut [f64],
        phi_x: &mut DMatrix<f64>,
        phi_theta: &mut DMatrix<f64>,
    );
}

/// A continuous-time run model ẋ = g(x, u, θ).
pub trait ContinuousRunModel {
    /// n, the states of one run.
    fn n_states(&self) -> usize;
    /// p, the unknown parameters.
    fn n_params(&self) -> usize;
    /// r, the inputs.
    fn n_inputs(&self) -> usize;
    /// H (m × n) of z = H·x.
    fn measurement_matrix(&self) -> &DMatrix<f64>;
    /// Measured channels that are angles.
    fn angle_outputs(&self) -> &[usize] {
        &[]
    }
    /// ẋ = g(x, u, θ) into `dx`, G_x = ∂g/∂x (n × n), G_θ = ∂g/∂θ (n × p).
    fn derivative(
        &self,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        dx: &mut [f64],
        g_x: &mut DMatrix<f64>,
        g_theta: &mut DMatrix<f64>,
    );
}

/// A continuous model discretized by one RK4 step of `h` per sample with the
/// input held (zero-order hold); the Jacobians are those of the RK4 map
/// itself (forward sensitivities through the four stages), not an Euler
/// approximation, so parameters are not biased by the discretization.
#[derive(Debug, Clone)]
pub struct Rk4<M> {
    /// The continuous model.
    pub model: M,
    /// Sample time.
    pub h: f64,
}

impl<M: ContinuousRunModel> RunModel for Rk4<M> {
    fn n_states(&self) -> usize {
        self.model.n_states()
    }
    fn n_params(&self) -> usize {
        self.model.n_params()
    }
    fn n_inputs(&self) -> usize {
        self.model.n_inputs()
    }
    fn measurement_matrix(&self) -> &DMatrix<f64> {
        self.model.measurement_matrix()
    }
    fn angle_outputs(&self) -> &[usize] {
        self.model.angle_outputs()
    }

    fn transition(
        &self,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        x_next: &mut [f64],
        phi_x: &mut DMatrix<f64>,
        phi_theta: &mut DMatrix<f64>,
    ) {
        let n = self.n_states();
        let p = self.n_params();
        let h = self.h;
        let mut gx = DMatrix::zeros(n, n);
        let mut gt = DMatrix::zeros(n, p);
        let mut k = vec![0.0; n];
        let mut xs = x.to_vec();
        // Sensitivities of the stage point ∂x_s/∂x, ∂x_s/∂θ and of the stage
        // slope ∂k_s/∂x, ∂k_s/∂θ.
        let mut dxs_x = DMatrix::identity(n, n);
        let mut dxs_t = DMatrix::zeros(n, p);
        let mut dk_x = DMatrix::zeros(n, n);
        let mut dk_t = DMatrix::zeros(n, p);
        x_next.copy_from_slice(x);
        phi_x.fill_with_identity();
        phi_theta.fill(0.0);
        let weights = [1.0, 2.0, 2.0, 1.0];
        let next_step = [0.5 * h, 0.5 * h, h];
        for s in 0..4 {
            self.model
                .derivative(&xs, u, theta, &mut k, &mut gx, &mut gt);
            dk_x.gemm(1.0, &gx, &dxs_x, 0.0);
            dk_t.copy_from(&gt);
            dk_t.gemm(1.0, &gx, &dxs_t, 1.0);
            let w = h / 6.0 * weights[s];
            for i in 0..n {
                x_next[i] += w * k[i];
            }
            *phi_x += w * &dk_x;
            *phi_theta += w * &dk_t;
            if s < 3 {
                let c = next_step[s];
                for i in 0..n {
                    xs[i] = x[i] + c * k[i];
                }
                dxs_x.fill_with_identity();
                dxs_x += c * &dk_x;
                dxs_t.copy_from(&dk_t);
                dxs_t *= c;
            }
        }
    }
}

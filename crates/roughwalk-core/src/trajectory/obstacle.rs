//! CHOMP's workspace obstacle term (Ratliff et al. 2009; Zucker 2011, §5.1).
//!
//! Every body point (a sphere of radius r) pays the potential c of its
//! clearance d = SDF(x) − r: −d + ε/2 (d < 0), (d − ε)²/(2ε) (0 ≤ d ≤ ε),
//! 0 beyond; weighted by arc length, f_obs = Σ_t c(x_t)·‖x_{t+1} − x_{t−1}‖/2
//! over the interior samples. The functional gradient
//! ‖ẋ‖·[(I − x̂′x̂′ᵀ)∇c − c·κ], κ = ‖ẋ‖⁻²(I − x̂′x̂′ᵀ)ẍ, acts orthogonally to
//! each point's path; [`GradientMode::Exact`] is the Euclidean gradient of
//! the discrete sum instead (they agree as the sampling gets finer).

// Samples and legs index several parallel arrays at once.
#![allow(clippy::needless_range_loop)]

use crate::error::{CoreError, CoreResult};
use crate::kinematics::math::{add, dot, scale, sub, Vec3};
use crate::sdf::SignedDistanceField;

/// Smooths ‖v‖ near zero so that resting points keep a differentiable cost [m].
const NORM_EPS: f64 = 1e-6;

/// A signed distance [m] and its gradient at a point [m].
pub trait DistanceQuery {
    /// Signed distance at `p` and ∇d.
    fn distance(&self, p: Vec3) -> (f64, Vec3);
}

impl DistanceQuery for SignedDistanceField {
    #[inline]
    fn distance(&self, p: Vec3) -> (f64, Vec3) {
        self.distance_and_gradient(p)
    }
}

impl<F: Fn(Vec3) -> (f64, Vec3)> DistanceQuery for F {
    #[inline]
    fn distance(&self, p: Vec3) -> (f64, Vec3) {
        self(p)
    }
}

/// Which gradient of the arc-length-weighted cost to take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GradientMode {
    /// CHOMP's functional gradient, orthogonal to each point's path.
    Functional,
    /// The Euclidean gradient of the discrete sum.
    Exact,
}

impl GradientMode {
    /// `"functional"` or `"exact"`.
    pub fn parse(name: &str) -> CoreResult<Self> {
        match name {
            "functional" => Ok(Self::Functional),
            "exact" => Ok(Self::Exact),
            _ => Err(CoreError::InvalidArgument(format!(
                "obstacle gradient must be 'functional' or 'exact', got '{name}'"
            ))),
        }
    }
}

/// c(d) and dc/dd of a clearance d [m] for the margin ε [m].
#[inline]
pub fn obstacle_potential(d: f64, epsilon: f64) -> (f64, f64) {
    if d < 0.0 {
        (-d + 0.5 * epsilon, -1.0)
    } else if d <= epsilon {
        (
            (d - epsilon) * (d - epsilon) / (2.0 * epsilon),
            (d - epsilon) / epsilon,
        )
    } else {
        (0.0, 0.0)
    }
}

/// The obstacle term's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObstacleTerm {
    /// ε [m], the clearance beyond which the potential vanishes.
    pub epsilon: f64,
    /// Factor on the term.
    pub weight: f64,
    /// Which gradient.
    pub mode: GradientMode,
}

/// One evaluation of the obstacle term over a trajectory of U points.
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleEvaluation {
    /// f_obs, weight included.
    pub value: f64,
    /// Clearances d (T·U, sample-major) [m].
    pub clearance: Vec<f64>,
    /// ∂f/∂x_t ((T − 2)·U) at the interior samples.
    pub gradient: Vec<Vec3>,
}

impl ObstacleTerm {
    /// Checks ε > 0 and a finite weight.
    pub fn new(epsilon: f64, weight: f64, mode: GradientMode) -> CoreResult<Self> {
        if !(epsilon > 0.0 && epsilon.is_finite()) {
            return Err(CoreError::InvalidArgument(format!(
                "obstacle epsilon must be a positive length [m], got {epsilon}"
            )));
        }
        if !weight.is_finite() {
            return Err(CoreError::InvalidArgument(format!(
                "obstacle weight must be finite, got {weight}"
            )));
        }
        Ok(Self {
            epsilon,
            weight,
            mode,
        })
    }

    /// Value, clearances and workspace gradient of points (T·U, sample-major) [m].
    ///
    /// `radius` (U) are the spheres' radii [m]; `active` (T·U) says which
    /// points count (a supporting foot does not).
    pub fn evaluate(
        &self,
        points: &[Vec3],
        radius: &[f64],
        active: &[bool],
        field: &impl DistanceQuery,
    ) -> ObstacleEvaluation {
        let u = radius.len();
        let t_len = points.len().checked_div(u).unwrap_or(0);
        let mut clearance = vec![0.0; points.len()];
        let mut c = vec![0.0; points.len()];
        let mut grad_c = vec![[0.0; 3]; points.len()];
        for (k, p) in points.iter().enumerate() {
            let (d, g) = field.distance(*p);
            let d = d - radius[k % u];
            clearance[k] = d;
            if active[k] {
                let (ck, dck) = obstacle_potential(d, self.epsilon);
                c[k] = ck;
                grad_c[k] = scale(g, dck);
            }
        }
        let n = t_len.saturating_sub(2);
        let mut gradient = vec![[0.0; 3]; n * u];
        if n == 0 {
            return ObstacleEvaluation {
                value: 0.0,
                clearance,
                gradient,
            };
        }
        let central = |i: usize, j: usize| sub(points[(i + 2) * u + j], points[i * u + j]);
        let length = |v: Vec3| 0.5 * (dot(v, v) + NORM_EPS * NORM_EPS).sqrt();
        let mut value = 0.0;
        for i in 0..n {
            for j in 0..u {
                let ci = c[(i + 1) * u + j];
                let v = central(i, j);
                let len = length(v);
                value += ci * len;
                let gc = grad_c[(i + 1) * u + j];
                let g = match self.mode {
                    GradientMode::Exact => {
                        // Sample i's length term depends on x_{i±1}: push to neighbours.
                        let mut g = scale(gc, len);
                        if i > 0 {
                            let w = central(i - 1, j);
                            g = add(g, scale(w, c[i * u + j] / (4.0 * length(w))));
                        }
                        if i + 1 < n {
                            let w = central(i + 1, j);
                            g = sub(g, scale(w, c[(i + 2) * u + j] / (4.0 * length(w))));
                        }
                        g
                    }
                    GradientMode::Functional => {
                        if ci == 0.0 && gc.iter().all(|v| *v == 0.0) {
                            continue;
                        }
                        let tangent = scale(v, 1.0 / (2.0 * len));
                        let along = dot(gc, tangent);
                        let x0 = points[i * u + j];
                        let x1 = points[(i + 1) * u + j];
                        let x2 = points[(i + 2) * u + j];
                        let second = add(sub(x2, scale(x1, 2.0)), x0);
                        let normal = sub(second, scale(tangent, dot(second, tangent)));
                        // With ẋ = Δx/2h and ẍ = Δ²x/h²: ‖ẋ‖h·c·κ = c·(I − x̂′x̂′ᵀ)Δ²x/ℓ_t.
                        sub(
                            scale(sub(gc, scale(tangent, along)), len),
                            scale(normal, ci / len),
                        )
                    }
                };
                gradient[i * u + j] = scale(g, self.weight);
            }
        }
        ObstacleEvaluation {
            value: self.weight * value,
            clearance,
            gradient,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ground plane z = 0 with a bump, smooth enough for finite differences.
    fn field(p: Vec3) -> (f64, Vec3) {
        let bump = 0.01 * (-(p[0] * p[0] + p[1] * p[1]) / 0.01).exp();
        let db = [-2.0 * p[0] / 0.01 * bump, -2.0 * p[1] / 0.01 * bump];
        (p[2] - bump, [-db[0], -db[1], 1.0])
    }

    fn path(u: usize, t: usize) -> Vec<Vec3> {
        (0..t)
            .flat_map(|i| {
                (0..u).map(move |j| {
                    let s = i as f64 / (t - 1) as f64;
                    [
                        -0.1 + 0.2 * s + 0.01 * j as f64,
                        0.003 * j as f64,
                        0.004 + 0.006 * (1.0 - (2.0 * s - 1.0).powi(2)) - 0.002 * j as f64,
                    ]
                })
            })
            .collect()
    }

    #[test]
    fn exact_gradient_matches_finite_differences() {
        let (u, t) = (3, 12);
        let radius = vec![0.002, 0.003, 0.001];
        let mut active = vec![true; u * t];
        active[5 * u + 1] = false;
        let term = ObstacleTerm::new(0.015, 3.0, GradientMode::Exact).unwrap();
        let x = path(u, t);
        let ev = term.evaluate(&x, &radius, &active, &field);
        assert!(ev.value > 0.0);
        let h = 1e-7;
        let mut worst: f64 = 0.0;
        for i in 1..t - 1 {
            for j in 0..u {
                for a in 0..3 {
                    let mut xp = x.clone();
                    xp[i * u + j][a] += h;
                    let mut xm = x.clone();
                    xm[i * u + j][a] -= h;
                    let fd = (term.evaluate(&xp, &radius, &active, &field).value
                        - term.evaluate(&xm, &radius, &active, &field).value)
                        / (2.0 * h);
                    let g = ev.gradient[(i - 1) * u + j][a];
                    worst = worst.max((fd - g).abs());
                }
            }
        }
        assert!(worst < 1e-6, "worst gradient error {worst}");
    }

    #[test]
    fn functional_gradient_is_orthogonal_to_the_path_without_curvature() {
        // On a straight path at constant speed κ = 0: the gradient is ∇c projected off the tangent.
        let t = 9;
        let x: Vec<Vec3> = (0..t).map(|i| [0.01 * i as f64, 0.0, 0.005]).collect();
        let term = ObstacleTerm::new(0.015, 1.0, GradientMode::Functional).unwrap();
        let ev = term.evaluate(&x, &[0.0], &vec![true; t], &field);
        for (i, g) in ev.gradient.iter().enumerate() {
            let tangent = [1.0, 0.0, 0.0];
            assert!(dot(*g, tangent).abs() < 1e-9, "sample {i}: {g:?}");
            assert!(g[2] < 0.0, "pushes away from the ground: {g:?}");
        }
    }

    #[test]
    fn potential_is_continuous_and_its_slope_too() {
        let eps = 0.02;
        for d in [0.0, eps] {
            let (a, da) = obstacle_potential(d - 1e-12, eps);
            let (b, db) = obstacle_potential(d + 1e-12, eps);
            assert!((a - b).abs() < 1e-9 && (da - db).abs() < 1e-9);
        }
        assert!(ObstacleTerm::new(0.0, 1.0, GradientMode::Exact).is_err());
        assert!(GradientMode::parse("exactly").is_err());
    }
}

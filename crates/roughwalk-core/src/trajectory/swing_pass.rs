//! CHOMP's swing-leg block evaluated in one call (Zucker 2011, §5.3).
//!
//! "Second, the swing leg joint angles are optimized with CHOMP given the
//! current body poses." The variables are the swing leg's three joint angles
//! at the airborne samples (lift-off and touchdown fixed); its points move with
//! ∂p/∂q = R·J_pB. A joint-speed term ½·w·Σ max(0, |Δq|/dt − ρ·v)² keeps the
//! leg from dashing at its velocity limits.

// Samples and legs index several parallel arrays at once.
#![allow(clippy::needless_range_loop)]

use crate::error::{CoreError, CoreResult};
use crate::kinematics::math::{add, mat_mul, mat_t_vec, mat_vec, Mat3, Vec3};
use crate::kinematics::LegChain;
use crate::trajectory::body_points::{joint_columns, BodyPoints};
use crate::trajectory::obstacle::{DistanceQuery, ObstacleTerm};

/// What the swing pass holds fixed while CHOMP moves the airborne joint angles.
#[derive(Debug, Clone, PartialEq)]
pub struct SwingPassSetup {
    /// Trunk positions over the swing window (W) [m].
    pub base_pos: Vec<Vec3>,
    /// Trunk orientations over the window (W).
    pub rotation: Vec<Mat3>,
    /// The swing leg's joint angles at the window's two ends [rad].
    pub ends: [Vec3; 2],
    /// Which of the leg's points count (W·U_leg, sample-major).
    pub active: Vec<bool>,
    /// The leg's joint velocity limits [rad/s].
    pub velocity_limit: Vec3,
    /// ρ: the fraction of each limit above which the speed term acts.
    pub speed_fraction: f64,
    /// w·h of the speed term [s²/rad²].
    pub speed_weight: f64,
    /// Sample period [s].
    pub dt: f64,
}

/// The swing-leg pass of one footstep.
#[derive(Debug, Clone)]
pub struct SwingPass {
    leg: LegChain,
    /// The leg's body points (indices into the robot's, and their data).
    index: Vec<usize>,
    link: Vec<usize>,
    local: Vec<Vec3>,
    radius: Vec<f64>,
    setup: SwingPassSetup,
    obstacle: ObstacleTerm,
}

/// Everything one evaluation of the swing pass finds.
#[derive(Debug, Clone, PartialEq)]
pub struct SwingPassEvaluation {
    /// Obstacle term value.
    pub obstacle: f64,
    /// Joint-speed term value.
    pub joint_speed: f64,
    /// ∂(obstacle + joint speed)/∂ξ (W − 2) [per rad].
    pub gradient: Vec<Vec3>,
    /// The leg's point clearances (W·U_leg) [m].
    pub clearance: Vec<f64>,
    /// The leg's points in the world (W·U_leg) [m].
    pub points: Vec<Vec3>,
    /// Σ max(0, |Δq| − v·dt) over the window [rad].
    pub velocity_excess: f64,
}

impl SwingPass {
    /// The pass of leg `leg` (0–3) of `robot` over a window of W samples.
    pub fn new(
        robot: &crate::kinematics::Quadruped,
        points: &BodyPoints,
        leg: usize,
        setup: SwingPassSetup,
        obstacle: ObstacleTerm,
    ) -> CoreResult<Self> {
        if leg > 3 {
            return Err(CoreError::InvalidArgument(format!(
                "swing leg {leg} out of range; valid: 0–3"
            )));
        }
        let index: Vec<usize> = (0..points.len())
            .filter(|&u| points.leg[u] == Some(leg))
            .collect();
        let w = setup.base_pos.len();
        if w < 3 || setup.rotation.len() != w || setup.active.len() != w * index.len() {
            return Err(CoreError::InvalidArgument(format!(
                "a swing pass needs ≥ 3 samples with one orientation each and {} active flags \
                 per sample; got {w} positions, {} orientations, {} flags",
                index.len(),
                setup.rotation.len(),
                setup.active.len()
            )));
        }
        if !(setup.dt > 0.0 && setup.dt.is_finite()) {
            return Err(CoreError::InvalidArgument(format!(
                "sample period must be positive [s], got {}",
                setup.dt
            )));
        }
        Ok(Self {
            leg: robot.legs()[leg].clone(),
            link: index.iter().map(|&u| points.link[u]).collect(),
            local: index.iter().map(|&u| points.local[u]).collect(),
            radius: index.iter().map(|&u| points.radius[u]).collect(),
            index,
            setup,
            obstacle,
        })
    }

    /// The robot's body-point indices this pass moves.
    pub fn point_index(&self) -> &[usize] {
        &self.index
    }

    /// Evaluates the obstacle and joint-speed terms at the airborne joint angles ξ (W − 2) [rad].
    pub fn evaluate(
        &self,
        xi: &[Vec3],
        field: &impl DistanceQuery,
    ) -> CoreResult<SwingPassEvaluation> {
        let s = &self.setup;
        let w_len = s.base_pos.len();
        let n = w_len - 2;
        if xi.len() != n {
            return Err(CoreError::InvalidArgument(format!(
                "ξ must have {n} rows (the airborne samples), got {}",
                xi.len()
            )));
        }
        if let Some(i) = xi.iter().position(|r| !r.iter().all(|v| v.is_finite())) {
            return Err(CoreError::InvalidArgument(format!(
                "ξ must be finite, got {:?} in row {i}",
                xi[i]
            )));
        }
        let q: Vec<Vec3> = std::iter::once(s.ends[0])
            .chain(xi.iter().copied())
            .chain(std::iter::once(s.ends[1]))
            .collect();
        let u_len = self.index.len();
        let frames: Vec<_> = q.iter().map(|&qt| self.leg.link_frames(qt)).collect();
        let mut p_base = Vec::with_capacity(w_len * u_len);
        let mut points = Vec::with_capacity(w_len * u_len);
        for (t, fr) in frames.iter().enumerate() {
            for u in 0..u_len {
                let k = self.link[u];
                let pb = add(fr.pos[k], mat_vec(&fr.rot[k], self.local[u]));
                p_base.push(pb);
                points.push(add(s.base_pos[t], mat_vec(&s.rotation[t], pb)));
            }
        }
        let obs = self
            .obstacle
            .evaluate(&points, &self.radius, &s.active, field);
        let mut gradient = vec![[0.0; 3]; n];
        for (i, grad) in gradient.iter_mut().enumerate() {
            let t = i + 1;
            for u in 0..u_len {
                let g = obs.gradient[i * u_len + u];
                if g.iter().all(|v| *v == 0.0) {
                    continue;
                }
                let jac = mat_mul(
                    &s.rotation[t],
                    &joint_columns(&frames[t], p_base[t * u_len + u], self.link[u]),
                );
                let gq = mat_t_vec(&jac, g);
                for a in 0..3 {
                    grad[a] += gq[a];
                }
            }
        }
        // Joint speed: q_t enters D_{t−1} with +1 and D_t with −1.
        let mut joint_speed = 0.0;
        let mut velocity_excess = 0.0;
        let mut g_d = vec![[0.0; 3]; w_len - 1];
        for (k, gd) in g_d.iter_mut().enumerate() {
            for j in 0..3 {
                let d = q[k + 1][j] - q[k][j];
                let excess = (d.abs() / s.dt - s.speed_fraction * s.velocity_limit[j]).max(0.0);
                joint_speed += excess * excess;
                let sign = if d > 0.0 {
                    1.0
                } else if d < 0.0 {
                    -1.0
                } else {
                    0.0
                };
                gd[j] = s.speed_weight * excess * sign / s.dt;
                velocity_excess += (d.abs() - s.velocity_limit[j] * s.dt).max(0.0);
            }
        }
        for (i, grad) in gradient.iter_mut().enumerate() {
            for j in 0..3 {
                grad[j] += g_d[i][j] - g_d[i + 1][j];
            }
        }
        Ok(SwingPassEvaluation {
            obstacle: obs.value,
            joint_speed: 0.5 * s.speed_weight * joint_speed,
            gradient,
            clearance: obs.clearance,
            points,
            velocity_excess,
        })
    }
}

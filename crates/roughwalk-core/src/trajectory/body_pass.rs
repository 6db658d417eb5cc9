//! CHOMP's trunk block evaluated in one call (Zucker 2011, §5.3).
//!
//! "First, the body trajectory is optimized with CHOMP, given the current
//! swing leg joint angles." The variables are the trunk's (x, y, z, roll,
//! pitch, yaw) at the interior samples; the supporting legs follow by IK, the
//! lifted leg keeps its joint angles. A point p on a supporting leg moves with
//! J_p(x) = I − R·J_pB·J_fB⁻¹·Rᵀ and J_p(R) = R·(J_pB·J_fB⁻¹·[f_B]× − [p_B]×)·Rᵀ
//! (§3.4), other points rigidly with the trunk; ∂p/∂rpy = J_p(R)·E(rpy).
//! Reachability is the §3.2 virtual force as the gradient of ½·w·Σ‖e‖².

// Samples and legs index several parallel arrays at once.
#![allow(clippy::needless_range_loop)]

use crate::error::{CoreError, CoreResult};
use crate::kinematics::math::{
    add, cross, inverse, mat_mul, mat_sub, mat_t_vec, mat_vec, norm, scale, skew, sub, transpose,
    Mat3, Vec3, IDENTITY,
};
use crate::kinematics::{LinkFrames, Quadruped};
use crate::trajectory::body_points::{joint_columns, BodyPoints};
use crate::trajectory::obstacle::{DistanceQuery, ObstacleTerm};
use crate::trajectory::rpy::{rpy_rate_matrix, rpy_to_matrix};
use crate::trajectory::zmp_support::ZmpSupport;

/// Samples whose feet are this close to full stretch get the reach check.
const NEAR_STRETCH: f64 = 0.93;

/// What the trunk pass holds fixed while CHOMP moves the interior samples.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyPassSetup {
    /// The trunk path (T) [m, rad]; its first and last rows stay.
    pub body: Vec<[f64; 6]>,
    /// Foot targets (T) in the world [m].
    pub feet: Vec<[Vec3; 4]>,
    /// Which feet bear weight (T).
    pub support: Vec<[bool; 4]>,
    /// Joint angles of the lifted leg (T), leg-major [rad].
    pub held_q: Vec<[f64; 12]>,
    /// Which body points count in the obstacle term (T·U, sample-major).
    pub active: Vec<bool>,
    /// HAA anchors in the base frame [m].
    pub hips: [Vec3; 4],
    /// Farthest each foot gets from its hip [m].
    pub max_reach: [f64; 4],
    /// How far past its target a foot is asked to reach [m].
    pub reach_margin: f64,
    /// w·h of the reachability term [1/m²].
    pub reach_weight: f64,
    /// Joint velocity limits, leg-major [rad/s].
    pub velocity_limit: [f64; 12],
    /// Sample period [s].
    pub dt: f64,
    /// μ of the damped J_fB⁻¹ [m/rad].
    pub damping: f64,
}

/// The trunk pass of one footstep.
#[derive(Debug, Clone)]
pub struct BodyPass {
    robot: Quadruped,
    points: BodyPoints,
    setup: BodyPassSetup,
    obstacle: ObstacleTerm,
    support: ZmpSupport,
}

/// Everything one evaluation of the trunk pass finds.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyPassEvaluation {
    /// Obstacle term value.
    pub obstacle: f64,
    /// Reachability term value.
    pub reachability: f64,
    /// ZMP support term value.
    pub support: f64,
    /// ∂(obstacle + reachability + support)/∂ξ (T − 2).
    pub gradient: Vec<[f64; 6]>,
    /// Body point clearances (T·U) [m].
    pub clearance: Vec<f64>,
    /// Body points in the world (T·U) [m].
    pub points: Vec<Vec3>,
    /// Joint angles (T): IK for supporting legs, held for the lifted one [rad].
    pub q: Vec<[f64; 12]>,
    /// Whether each foot is where it should be (T); lifted feet count as reached.
    pub reached: Vec<[bool; 4]>,
    /// ZMP margins to the support polygon at the interior samples [m].
    pub margins: Vec<f64>,
    /// Σ max(0, |Δq| − v·dt) over samples and joints [rad].
    pub velocity_excess: f64,
}

impl BodyPass {
    /// A trunk pass over T samples; refuses inconsistent row counts.
    pub fn new(
        robot: Quadruped,
        points: BodyPoints,
        setup: BodyPassSetup,
        obstacle: ObstacleTerm,
        support: ZmpSupport,
    ) -> CoreResult<Self> {
        let t = setup.body.len();
        if t < 3 {
            return Err(CoreError::InvalidArgument(format!(
                "a trunk pass needs at least 3 samples, got {t}"
            )));
        }
        let rows = [
            setup.feet.len(),
            setup.support.len(),
            setup.held_q.len(),
            support.len(),
        ];
        if rows.iter().any(|&r| r != t) || setup.active.len() != t * points.len() {
            return Err(CoreError::InvalidArgument(format!(
                "trunk pass rows must match its {t} samples: feet, support, held q, ZMP samples \
                 {rows:?}, active {} (expected {})",
                setup.active.len(),
                t * points.len()
            )));
        }
        if !(setup.dt > 0.0 && setup.dt.is_finite()) {
            return Err(CoreError::InvalidArgument(format!(
                "sample period must be positive [s], got {}",
                setup.dt
            )));
        }
        Ok(Self {
            robot,
            points,
            setup,
            obstacle,
            support,
        })
    }

    /// Number of samples T.
    pub fn samples(&self) -> usize {
        self.setup.body.len()
    }

    /// Evaluates the obstacle, reachability and support terms at the interior trunk path ξ.
    pub fn evaluate(
        &self,
        xi: &[[f64; 6]],
        field: &impl DistanceQuery,
    ) -> CoreResult<BodyPassEvaluation> {
        let s = &self.setup;
        let t_len = s.body.len();
        let n = t_len - 2;
        if xi.len() != n {
            return Err(CoreError::InvalidArgument(format!(
                "ξ must have {n} rows (the interior samples), got {}",
                xi.len()
            )));
        }
        if let Some(i) = xi.iter().position(|r| !r.iter().all(|v| v.is_finite())) {
            return Err(CoreError::InvalidArgument(format!(
                "ξ must be finite, got {:?} in row {i}",
                xi[i]
            )));
        }
        let u_len = self.points.len();
        let legs = self.robot.legs();
        let mut body = s.body.clone();
        body[1..=n].copy_from_slice(xi);
        let mut rotations = Vec::with_capacity(t_len);
        let mut frames: Vec<[LinkFrames; 4]> = Vec::with_capacity(t_len);
        let mut feet_base = Vec::with_capacity(t_len);
        let mut q = Vec::with_capacity(t_len);
        let mut reached = Vec::with_capacity(t_len);
        let mut p_base = Vec::with_capacity(t_len * u_len);
        let mut points = Vec::with_capacity(t_len * u_len);
        for t in 0..t_len {
            let x = [body[t][0], body[t][1], body[t][2]];
            let r = rpy_to_matrix([body[t][3], body[t][4], body[t][5]]);
            let mut qt = s.held_q[t];
            let mut ok = [true; 4];
            for l in 0..4 {
                if s.support[t][l] {
                    let res = legs[l].ik(mat_t_vec(&r, sub(s.feet[t][l], x)), None);
                    qt[3 * l..3 * l + 3].copy_from_slice(&res.q);
                    ok[l] = res.reachable;
                }
            }
            let fr: [LinkFrames; 4] = std::array::from_fn(|l| {
                legs[l].link_frames([qt[3 * l], qt[3 * l + 1], qt[3 * l + 2]])
            });
            let fb: [Vec3; 4] = std::array::from_fn(|l| {
                add(fr[l].pos[2], mat_vec(&fr[l].rot[2], legs[l].params().foot))
            });
            for u in 0..u_len {
                let pb = self.points.base_position(&fr, u);
                p_base.push(pb);
                points.push(add(x, mat_vec(&r, pb)));
            }
            rotations.push(r);
            frames.push(fr);
            feet_base.push(fb);
            q.push(qt);
            reached.push(ok);
        }
        let obs = self
            .obstacle
            .evaluate(&points, &self.points.radius, &s.active, field);

        let mut gradient = vec![[0.0; 6]; n];
        for i in 0..n {
            let t = i + 1;
            let r = &rotations[t];
            let rt = transpose(r);
            let e = rpy_rate_matrix([body[t][3], body[t][4], body[t][5]]);
            for u in 0..u_len {
                let g = obs.gradient[i * u_len + u];
                if g.iter().all(|v| *v == 0.0) {
                    continue;
                }
                let pb = p_base[t * u_len + u];
                let (jx, jw) = match self.points.leg[u] {
                    Some(l) if s.support[t][l] => {
                        let fr = &frames[t][l];
                        let j_pb = joint_columns(fr, pb, self.points.link[u]);
                        let fb = feet_base[t][l];
                        let j_fb = joint_columns(fr, fb, 2);
                        // Damped pseudo-inverse: (JᵀJ + μ²I)⁻¹Jᵀ.
                        let jt = transpose(&j_fb);
                        let mut a = mat_mul(&jt, &j_fb);
                        for (d, row) in a.iter_mut().enumerate() {
                            row[d] += s.damping * s.damping;
                        }
                        let pinv = mat_mul(&inverse(&a).unwrap_or([[0.0; 3]; 3]), &jt);
                        let m = mat_mul(&j_pb, &pinv);
                        let jx = mat_sub(&IDENTITY, &mat_mul(&mat_mul(r, &m), &rt));
                        let inner = mat_sub(&mat_mul(&m, &skew(fb)), &skew(pb));
                        (jx, mat_mul(&mat_mul(r, &inner), &rt))
                    }
                    _ => {
                        let neg = scale(mat_vec(r, pb), -1.0);
                        (IDENTITY, skew(neg))
                    }
                };
                let gx = mat_t_vec(&jx, g);
                let gr = mat_t_vec(&e, mat_t_vec(&jw, g));
                for a in 0..3 {
                    gradient[i][a] += gx[a];
                    gradient[i][3 + a] += gr[a];
                }
            }
        }

        let reachability = self.reachability(&body, &rotations, &mut gradient);
        let xy: Vec<[f64; 2]> = body.iter().map(|b| [b[0], b[1]]).collect();
        let (support, sup_grad, margins) = self.support.evaluate(&xy);
        for (g, sg) in gradient.iter_mut().zip(&sup_grad) {
            g[0] += sg[0];
            g[1] += sg[1];
        }
        let velocity_excess = velocity_excess(&q, s.dt, &s.velocity_limit);
        for (ok, sup) in reached.iter_mut().zip(&s.support) {
            for l in 0..4 {
                ok[l] |= !sup[l];
            }
        }
        Ok(BodyPassEvaluation {
            obstacle: obs.value,
            reachability,
            support,
            gradient,
            clearance: obs.clearance,
            points,
            q,
            reached,
            margins,
            velocity_excess,
        })
    }

    /// ½·w·Σ‖e‖² over supporting feet at the interior samples; adds its gradient.
    ///
    /// e = f′ − FK(IK(f′)) in the world, f′ the target pushed `reach_margin`
    /// away from its hip so the term acts before a foot is lost.
    fn reachability(
        &self,
        body: &[[f64; 6]],
        rotations: &[Mat3],
        gradient: &mut [[f64; 6]],
    ) -> f64 {
        let s = &self.setup;
        let legs = self.robot.legs();
        let w = s.reach_weight;
        let mut value = 0.0;
        for (i, grad) in gradient.iter_mut().enumerate() {
            let t = i + 1;
            let x = [body[t][0], body[t][1], body[t][2]];
            let r = &rotations[t];
            let mut pushed = [[0.0; 3]; 4];
            let mut near = false;
            for l in 0..4 {
                let fb = mat_t_vec(r, sub(s.feet[t][l], x));
                let towards = sub(fb, s.hips[l]);
                let dist = norm(towards);
                pushed[l] = add(fb, scale(towards, s.reach_margin / dist.max(1e-9)));
                near |= dist > NEAR_STRETCH * s.max_reach[l];
            }
            if !near {
                continue;
            }
            let e = rpy_rate_matrix([body[t][3], body[t][4], body[t][5]]);
            let (mut g_x, mut g_w) = ([0.0; 3], [0.0; 3]);
            for l in 0..4 {
                if !s.support[t][l] {
                    continue;
                }
                let res = legs[l].ik(pushed[l], None);
                if res.reachable {
                    continue;
                }
                let err = mat_vec(r, sub(pushed[l], legs[l].fk(res.q)));
                value += 0.5 * w * (err[0] * err[0] + err[1] * err[1] + err[2] * err[2]);
                g_x = sub(g_x, scale(err, w));
                g_w = sub(g_w, scale(cross(sub(s.feet[t][l], x), err), w));
            }
            let g_rpy = mat_t_vec(&e, g_w);
            for a in 0..3 {
                grad[a] += g_x[a];
                grad[3 + a] += g_rpy[a];
            }
        }
        value
    }
}

/// Σ max(0, |q_{t+1} − q_t| − v·dt) [rad] over samples and joints.
pub fn velocity_excess(q: &[[f64; 12]], dt: f64, limit: &[f64; 12]) -> f64 {
    q.windows(2)
        .map(|w| {
            (0..12)
                .map(|j| ((w[1][j] - w[0][j]).abs() - limit[j] * dt).max(0.0))
                .sum::<f64>()
        })
        .sum()
}

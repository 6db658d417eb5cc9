//! Pose certificates (Zucker 2011, §4.3–4.4): a full 18-DOF configuration
//! that puts the feet on their footholds, keeps the centre of mass over the
//! support triangle and the body (feet excluded) clear of the terrain.
//!
//! The search starts from a trunk pose guessed from the feet and, for at
//! most `max_iterations` rounds, adds up the corrections the pose still
//! needs: the reachability step (§3.2) for legs IK cannot place, a
//! horizontal nudge of the centre of mass into the triangle, and the
//! obstacle-avoidance step (§3.4) at the point of least clearance; it stops
//! with a certificate when none is needed.
//!
//! Which triangle: the three feet that stay down during the NEXT step, so
//! that the pose holding this stance lets the next leg lift. The start
//! stance is certified the same way.

use crate::footstep::collision::{Clearance, CollisionModel};
use crate::footstep::config::CertificateConfig;
use crate::footstep::mass_model::MassModel;
use crate::kinematics::body_pose::point_pose_jacobians_at;
use crate::kinematics::leg::{IkResult, LegChain, LinkFrames};
use crate::kinematics::math::{
    add, cross, det, dot, exp_so3, mat_mul, mat_t_vec, mat_to_quat, mat_vec, norm, scale, sub,
    Mat3, Quat, Vec3,
};
use crate::kinematics::quadruped::{BodyPose, Quadruped};
use crate::kinematics::support::support_triangle_incircle;
use crate::sdf::SignedDistanceField;

/// How much closer than the clearance check reports [m], per metre of the
/// distance field's resolution, any point of the body may be when the
/// field is sampled finer (see [`CollisionModel::closest_below`]): √3/2,
/// the trilinear interpolation error bound of the field (half a cell
/// diagonal, the `sdf_error` the certified clearance already adds), so a
/// certified pose is never rejected by a finer sampling by more than the
/// field's own error. The old fixed 1-voxel spacing allowed L·h/2 with
/// L ≈ 1.4–1.7, the same order.
pub const CLEARANCE_TOLERANCE: f64 = 0.866_025_403_784_438_6;

/// A point in the x–y plane [m].
pub type Vec2 = [f64; 2];

/// The CoM correction aims this fraction of the margin deeper than the
/// margin, so that the CoM's shift with the legs' joint angles in the next
/// round does not call for another correction.
const COM_AIM: f64 = 0.3;

/// The guessed pose keeps every foot within this fraction of its leg's
/// reach, lowering the trunk if need be: stretched legs otherwise cost a
/// reachability round on most forward steps.
const REACH_FRACTION: f64 = 0.97;

/// The shell a leg's foot can reach: distances [m] from its HAA joint
/// anchor (base frame), found by sampling the joint box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegReach {
    /// HAA anchor in the base frame [m].
    pub hip: Vec3,
    /// Least foot distance from it [m].
    pub min: f64,
    /// Greatest foot distance from it [m].
    pub max: f64,
}

impl LegReach {
    /// Samples `leg`'s joint box (infinite limits taken as ±π).
    pub fn of(leg: &LegChain) -> Self {
        let p = leg.params();
        let hip = leg.link_frames([0.0; 3]).anchor[0];
        let axis = |k: usize, n: usize| {
            let lo = p.lower[k].max(-std::f64::consts::PI);
            let hi = p.upper[k].min(std::f64::consts::PI);
            (0..n).map(move |i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        };
        let (mut min, mut max) = (f64::INFINITY, 0.0f64);
        for q0 in axis(0, 5) {
            for q1 in axis(1, 61) {
                for q2 in axis(2, 121) {
                    let d = norm(sub(leg.fk([q0, q1, q2]), hip));
                    min = min.min(d);
                    max = max.max(d);
                }
            }
        }
        Self { hip, min, max }
    }

    /// Where to aim IK for a foot target `t` (base frame [m]): `t` itself
    /// inside the shell, else its radial projection just inside it.
    #[inline]
    fn aim(&self, t: Vec3) -> Option<Vec3> {
        let r = sub(t, self.hip);
        let d = norm(r);
        let limit = if d > self.max {
            0.999 * self.max
        } else if d < self.min {
            1.001 * self.min
        } else {
            return None;
        };
        (d > 0.0).then(|| add(self.hip, scale(r, limit / d)))
    }
}

/// A certified whole-body pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseCertificate {
    /// Trunk (base frame) origin [m].
    pub base_pos: Vec3,
    /// Trunk orientation (w, x, y, z).
    pub base_quat: Quat,
    /// Joint angles [rad], canonical leg-major order.
    pub q: [f64; 12],
    /// Correction rounds it took (1: the guessed pose needed none).
    pub iterations: u32,
    /// Whole-body centre of mass [m].
    pub com: Vec3,
    /// Its distance inside the support triangle [m].
    pub com_margin: f64,
    /// Least body clearance [m] as the distance field measures it, less the
    /// field's error bound; capped at `preferred_clearance` (it is at least that).
    pub clearance: f64,
    /// Least normalised foot-Jacobian volume over the legs (1 far from
    /// singular, 0 singular).
    pub singularity: f64,
    /// Singularity and clearance penalties (Zucker 2011, §4.3) [cost].
    pub penalty: f64,
}

/// What the last round still had to correct when the search gave up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CertificateFailure {
    /// A foot was out of reach (or past a joint limit).
    Unreachable,
    /// The centre of mass was outside the support triangle's margin.
    CenterOfMass,
    /// The body was closer to the terrain than the clearance.
    Collision,
}

impl CertificateFailure {
    /// A short reason.
    pub fn describe(self) -> &'static str {
        match self {
            CertificateFailure::Unreachable => "a foot is out of reach",
            CertificateFailure::CenterOfMass => {
                "the centre of mass cannot be kept over the support triangle"
            }
            CertificateFailure::Collision => "the body cannot be kept clear of the terrain",
        }
    }
}

/// Signed distance [m] of `p` inside the triangle `tri` (positive inside):
/// the least signed distance to its edge lines.
pub fn triangle_margin(p: Vec2, tri: &[Vec2; 3]) -> f64 {
    let area2 = (tri[1][0] - tri[0][0]) * (tri[2][1] - tri[0][1])
        - (tri[1][1] - tri[0][1]) * (tri[2][0] - tri[0][0]);
    let orient = if area2 >= 0.0 { 1.0 } else { -1.0 };
    let mut m = f64::INFINITY;
    for k in 0..3 {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        let e = [b[0] - a[0], b[1] - a[1]];
        let len = e[0].hypot(e[1]);
        if len == 0.0 {
            return f64::NEG_INFINITY;
        }
        let side = orient * (e[0] * (p[1] - a[1]) - e[1] * (p[0] - a[0])) / len;
        m = m.min(side);
    }
    m
}

fn closest_on_segment(p: Vec2, a: Vec2, b: Vec2) -> Vec2 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let l2 = ab[0] * ab[0] + ab[1] * ab[1];
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    [a[0] + t * ab[0], a[1] + t * ab[1]]
}

/// The point at least `margin` [m] inside every edge of `tri` that is
/// closest to `p`; the incircle centre when no point keeps that margin.
///
/// The points with that margin form the triangle shrunk about the incircle
/// centre by (r − margin)/r, so this is a closest point on a triangle.
pub fn closest_point_in_triangle(p: Vec2, tri: &[Vec2; 3], margin: f64) -> Vec2 {
    let (centre, r) = support_triangle_incircle(tri[0], tri[1], tri[2]);
    if r <= margin {
        return centre;
    }
    let s = (r - margin) / r;
    let inner = tri.map(|v| {
        [
            centre[0] + s * (v[0] - centre[0]),
            centre[1] + s * (v[1] - centre[1]),
        ]
    });
    if triangle_margin(p, &inner) >= 0.0 {
        return p;
    }
    let mut best = (f64::INFINITY, p);
    for k in 0..3 {
        let c = closest_on_segment(p, inner[k], inner[(k + 1) % 3]);
        let d = (c[0] - p[0]).hypot(c[1] - p[1]);
        if d < best.0 {
            best = (d, c);
        }
    }
    best.1
}

/// |det J| / (|J₀|·|J₁|·|J₂|) of a 3×3 Jacobian (columns J_k): 1 for
/// orthogonal columns, 0 at a singularity.
fn normalised_volume(j: &Mat3) -> f64 {
    let col = |k: usize| [j[0][k], j[1][k], j[2][k]];
    let lengths = norm(col(0)) * norm(col(1)) * norm(col(2));
    if lengths > 0.0 {
        (det(j).abs() / lengths).min(1.0)
    } else {
        0.0
    }
}

/// Foot Jacobian ∂f_B/∂q from a leg's link frames and its foot point.
fn foot_jacobian(frames: &LinkFrames, foot: Vec3) -> Mat3 {
    let c = |k: usize| cross(frames.axis[k], sub(foot, frames.anchor[k]));
    let (c0, c1, c2) = (c(0), c(1), c(2));
    [
        [c0[0], c1[0], c2[0]],
        [c0[1], c1[1], c2[1]],
        [c0[2], c1[2], c2[2]],
    ]
}

fn rot_z(a: f64) -> Mat3 {
    let (s, c) = a.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

fn rot_y(a: f64) -> Mat3 {
    let (s, c) = a.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}

fn rot_x(a: f64) -> Mat3 {
    let (s, c) = a.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

/// Everything a certificate search needs about the robot and the terrain.
#[derive(Debug, Clone)]
pub struct CertificateSearch<'a> {
    /// The legs.
    pub robot: &'a Quadruped,
    /// Link masses.
    pub mass: &'a MassModel,
    /// The body's capsules (no feet).
    pub collision: &'a CollisionModel,
    /// The terrain.
    pub sdf: &'a SignedDistanceField,
    /// Step sizes, margins and penalties.
    pub config: &'a CertificateConfig,
    /// Height of the trunk origin over the feet's mean contact height at the
    /// nominal stance [m].
    pub nominal_height: f64,
    /// Centroid of the nominal stance's feet in the base frame (x, y) [m].
    pub nominal_feet_centroid: Vec2,
    /// Centre of mass in the base frame at the nominal joint angles [m].
    pub nominal_com: Vec3,
    /// Bound on the distance field's interpolation error [m], added to every
    /// clearance it is asked to certify.
    pub sdf_error: f64,
    /// Each leg's reach shell.
    pub reach: &'a [LegReach; 4],
}

impl CertificateSearch<'_> {
    /// The trunk pose guessed from the footholds: over the feet's centroid at
    /// the nominal height above their mean contact height, facing `heading`
    /// [rad], tilted like the feet (clamped to `max_tilt`), shifted so that
    /// the nominal centre of mass sits over the support triangle, and
    /// lowered until the foot centres `feet` are within reach.
    pub fn initial_pose(
        &self,
        feet: &[Vec3; 4],
        contacts: &[Vec3; 4],
        support: &[usize; 3],
        heading: f64,
    ) -> BodyPose {
        let mid = |a: usize, b: usize| {
            [
                0.5 * (contacts[a][0] + contacts[b][0]),
                0.5 * (contacts[a][1] + contacts[b][1]),
                0.5 * (contacts[a][2] + contacts[b][2]),
            ]
        };
        let (front, hind, left, right) = (mid(0, 1), mid(2, 3), mid(0, 2), mid(1, 3));
        let tilt = |high: Vec3, low: Vec3| {
            let run = (high[0] - low[0]).hypot(high[1] - low[1]).max(1e-9);
            (high[2] - low[2])
                .atan2(run)
                .clamp(-self.config.max_tilt, self.config.max_tilt)
        };
        // Ry(pitch) with pitch > 0 lowers the nose; Rx(roll) > 0 raises the left side.
        let pitch = -tilt(front, hind);
        let roll = tilt(left, right);
        let r = mat_mul(&rot_z(heading), &mat_mul(&rot_y(pitch), &rot_x(roll)));
        let n = 0.25;
        let centroid = contacts.iter().fold([0.0; 3], |s, c| add(s, scale(*c, n)));
        let offset = mat_vec(
            &r,
            [
                self.nominal_feet_centroid[0],
                self.nominal_feet_centroid[1],
                0.0,
            ],
        );
        let mut x = [
            centroid[0] - offset[0],
            centroid[1] - offset[1],
            centroid[2] + self.nominal_height,
        ];
        let com = add(x, mat_vec(&r, self.nominal_com));
        let tri = support.map(|leg| [contacts[leg][0], contacts[leg][1]]);
        let target = closest_point_in_triangle(
            [com[0], com[1]],
            &tri,
            (1.0 + COM_AIM) * self.config.com_margin,
        );
        x[0] += target[0] - com[0];
        x[1] += target[1] - com[1];
        // Lower the trunk until every foot is within reach of its hip:
        // |hip − dz·ẑ − f| = REACH_FRACTION · reach.
        let mut drop: f64 = 0.0;
        for (i, reach) in self.reach.iter().enumerate() {
            let v = sub(add(x, mat_vec(&r, reach.hip)), feet[i]);
            let limit = REACH_FRACTION * reach.max;
            let horizontal = v[0] * v[0] + v[1] * v[1];
            if horizontal < limit * limit {
                drop = drop.max(v[2] - (limit * limit - horizontal).sqrt());
            }
        }
        x[2] -= drop;
        BodyPose { x, r }
    }

    /// Searches for a certificate of the stance whose foot centres are
    /// `feet` [m] and contact points `contacts` [m] (canonical order), with
    /// the centre of mass over the triangle of the legs `support`, starting
    /// from the pose [`Self::initial_pose`] guesses from the feet.
    pub fn find(
        &self,
        feet: &[Vec3; 4],
        contacts: &[Vec3; 4],
        support: &[usize; 3],
        heading: f64,
    ) -> Result<PoseCertificate, CertificateFailure> {
        let guess = self.initial_pose(feet, contacts, support, heading);
        let required = self.config.clearance + self.sdf_error;
        self.find_from(feet, contacts, support, guess, required)
    }

    /// [`Self::find`] starting from the trunk pose `pose` instead of the
    /// guess, with the body kept `required` [m] off the terrain as the
    /// distance field reads it (`find` asks `clearance` plus the field's
    /// error bound). For a stance the robot already stands on: its measured
    /// trunk pose, from which the corrections are fewest and the certificate
    /// nearest where the robot is. `max_drift` is measured from `pose`.
    pub fn find_from(
        &self,
        feet: &[Vec3; 4],
        contacts: &[Vec3; 4],
        support: &[usize; 3],
        pose: BodyPose,
        required: f64,
    ) -> Result<PoseCertificate, CertificateFailure> {
        let cfg = self.config;
        let legs = self.robot.legs();
        // Hips are rigid: two feet farther apart than their hips' distance plus
        // both reaches cannot be held by any trunk pose.
        for i in 0..4 {
            for j in i + 1..4 {
                let (a, b) = (&self.reach[i], &self.reach[j]);
                if norm(sub(feet[i], feet[j])) > norm(sub(a.hip, b.hip)) + a.max + b.max {
                    return Err(CertificateFailure::Unreachable);
                }
            }
        }
        let tri = support.map(|leg| [contacts[leg][0], contacts[leg][1]]);
        let cutoff = required.max(cfg.preferred_clearance + self.sdf_error);
        let tolerance = CLEARANCE_TOLERANCE * self.sdf.grid().spec().resolution;
        let mut pose = pose;
        let start = pose.x;
        let mut failure = CertificateFailure::Unreachable;
        let (mut best, mut stalled) = (f64::INFINITY, 0usize);
        for iteration in 1..=cfg.max_iterations {
            let mut violation = 0.0;
            let mut dx = [0.0; 3];
            let mut omega = [0.0; 3];
            let mut q = [0.0; 12];
            let mut reachable = true;
            let mut frames = [LinkFrames::default(); 4];
            for (i, leg) in legs.iter().enumerate() {
                let target = pose.to_body(feet[i]);
                // Out of the reach shell, the closest reachable foot is about
                // the target's radial projection: one analytic IK instead of
                // the exact closest-point search, 30-50x dearer (§3.2 needs
                // only the direction and size of the error).
                // Inside it, a target the joint limits keep the foot from
                // gets the clamped analytic solution, for the same reason.
                let ik = match self.reach[i].aim(target) {
                    Some(aim) => match leg.ik_exact_into(aim, None, &mut frames[i]) {
                        Some(near) => IkResult {
                            reachable: false,
                            ..near
                        },
                        None => leg.ik_or_clamped_into(target, None, &mut frames[i]),
                    },
                    None => leg.ik_or_clamped_into(target, None, &mut frames[i]),
                };
                q[3 * i..3 * i + 3].copy_from_slice(&ik.q);
                if !ik.reachable {
                    // Zucker 2011, §3.2: a virtual force at the reachable foot toward its target.
                    reachable = false;
                    let f_b = add(
                        frames[i].pos[2],
                        mat_vec(&frames[i].rot[2], leg.params().foot),
                    );
                    let reached = pose.to_world(f_b);
                    let e = sub(feet[i], reached);
                    let len = norm(e);
                    violation += len;
                    let e = if len > 0.0 {
                        scale(e, 1.0 + cfg.reach_overshoot / len)
                    } else {
                        e
                    };
                    dx = add(dx, scale(e, cfg.alpha_reach));
                    omega = add(omega, scale(cross(sub(reached, pose.x), e), cfg.beta_reach));
                }
            }
            let com = add(pose.x, mat_vec(&pose.r, self.mass.com_base(&frames)));
            let com_margin = triangle_margin([com[0], com[1]], &tri);
            let com_ok = com_margin >= cfg.com_margin;
            if !com_ok {
                violation += cfg.com_margin - com_margin;
                let target = closest_point_in_triangle(
                    [com[0], com[1]],
                    &tri,
                    (1.0 + COM_AIM) * cfg.com_margin,
                );
                dx = add(dx, [target[0] - com[0], target[1] - com[1], 0.0]);
            }
            // A round that fails on reach or CoM and cannot lower the
            // violation enough (the clearance deficit only adds to it) ends
            // the search whatever the clearance: skip its collision check.
            let last = iteration == cfg.max_iterations
                || (violation >= 0.9 * best && stalled + 1 >= cfg.stall_rounds);
            if last && !(reachable && com_ok) {
                failure = if reachable {
                    CertificateFailure::CenterOfMass
                } else {
                    CertificateFailure::Unreachable
                };
                break;
            }
            let closest = self
                .collision
                .closest_below(self.sdf, &pose, &frames, cutoff, tolerance);
            let collision = closest.filter(|c| c.distance < required);
            if let Some(c) = collision {
                violation += required - c.distance;
            }
            if reachable && com_ok && collision.is_none() {
                return Ok(self.certificate(&pose, q, &frames, com, com_margin, closest, iteration));
            }
            failure = if !reachable {
                CertificateFailure::Unreachable
            } else if !com_ok {
                CertificateFailure::CenterOfMass
            } else {
                CertificateFailure::Collision
            };
            if violation < 0.9 * best {
                (best, stalled) = (violation, 0);
            } else {
                stalled += 1;
                if stalled >= cfg.stall_rounds {
                    break;
                }
            }
            if iteration == cfg.max_iterations {
                break;
            }
            // The obstacle step only once the search goes on.
            if let Some(c) = collision {
                self.obstacle_step(feet, &pose, &frames, &c, required, &mut dx, &mut omega);
            }
            let (step, turn) = (norm(dx), norm(omega));
            if step > cfg.max_step {
                dx = scale(dx, cfg.max_step / step);
            }
            if turn > cfg.max_turn {
                omega = scale(omega, cfg.max_turn / turn);
            }
            pose = BodyPose {
                x: add(pose.x, dx),
                r: mat_mul(&exp_so3(omega), &pose.r),
            };
            if norm(sub(pose.x, start)) > cfg.max_drift {
                break;
            }
        }
        Err(failure)
    }

    /// Zucker 2011, §3.4: Δx = α·s·J_p(x)ᵀ·g, ω = β·s·J_p(R)ᵀ·g at the point
    /// of least clearance. The paper's direction; its length s is chosen so
    /// that the point's linearised motion along g, s·(α|J_xᵀg|² + β|J_Rᵀg|²),
    /// equals the distance it must gain — a fixed gain instead took four or
    /// more rounds for most collisions on rough boards, each with a full
    /// collision check. α and β weigh translation against rotation.
    fn obstacle_step(
        &self,
        feet: &[Vec3; 4],
        pose: &BodyPose,
        frames: &[LinkFrames; 4],
        c: &Clearance,
        required: f64,
        dx: &mut Vec3,
        omega: &mut Vec3,
    ) {
        let cfg = self.config;
        let g_len = norm(c.gradient);
        if g_len == 0.0 {
            return;
        }
        let g = scale(c.gradient, 1.0 / g_len);
        let Ok(jac) = point_pose_jacobians_at(self.robot, pose, feet, frames, c.point) else {
            return;
        };
        let (a, b) = (mat_t_vec(&jac.j_x, g), mat_t_vec(&jac.j_r, g));
        let gain = cfg.alpha_obstacle * dot(a, a) + cfg.beta_obstacle * dot(b, b);
        if gain <= 1e-12 {
            return;
        }
        let s = (required + cfg.clearance_overshoot - c.distance) / gain;
        *dx = add(*dx, scale(a, cfg.alpha_obstacle * s));
        *omega = add(*omega, scale(b, cfg.beta_obstacle * s));
    }

    fn certificate(
        &self,
        pose: &BodyPose,
        q: [f64; 12],
        frames: &[LinkFrames; 4],
        com: Vec3,
        com_margin: f64,
        closest: Option<Clearance>,
        iterations: usize,
    ) -> PoseCertificate {
        let cfg = self.config;
        let mut singularity: f64 = 1.0;
        let mut penalty = 0.0;
        for (leg, f) in self.robot.legs().iter().zip(frames) {
            let foot = add(f.pos[2], mat_vec(&f.rot[2], leg.params().foot));
            let s = normalised_volume(&foot_jacobian(f, foot));
            singularity = singularity.min(s);
            if cfg.singularity_margin > 0.0 {
                penalty += cfg.singularity_penalty * (1.0 - s / cfg.singularity_margin).max(0.0);
            }
        }
        let clearance = closest.map_or(cfg.preferred_clearance, |c| {
            (c.distance - self.sdf_error).min(cfg.preferred_clearance)
        });
        let band = cfg.preferred_clearance - cfg.clearance;
        if band > 0.0 {
            penalty += cfg.clearance_penalty
                * ((cfg.preferred_clearance - clearance) / band).clamp(0.0, 1.0);
        }
        PoseCertificate {
            base_pos: pose.x,
            base_quat: mat_to_quat(&pose.r),
            q,
            iterations: iterations as u32,
            com,
            com_margin,
            clearance,
            singularity,
            penalty,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::footstep::collision::tests::sdf_of;
    use crate::kinematics::math::quat_to_mat;
    use crate::kinematics::support::{closest_point_with_margin, support_polygon_margin};
    use crate::testing::CertificateFixture;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn footstep_triangle_helpers_match_the_support_polygon_routines(
            ax in -1.0..1.0f64, ay in -1.0..1.0f64, bx in -1.0..1.0f64, by in -1.0..1.0f64,
            cx in -1.0..1.0f64, cy in -1.0..1.0f64, px in -1.5..1.5f64, py in -1.5..1.5f64,
            margin in 0.0..0.3f64,
        ) {
            let tri = [[ax, ay], [bx, by], [cx, cy]];
            let (_, r) = support_triangle_incircle(tri[0], tri[1], tri[2]);
            prop_assume!(r > 0.02);
            let p = [px, py];
            let reference = support_polygon_margin(p, &tri);
            let m = triangle_margin(p, &tri);
            prop_assert_eq!(m >= 0.0, reference >= 0.0);
            if reference >= 0.0 {
                prop_assert!((m - reference).abs() < 1e-9, "{} vs {}", m, reference);
            }
            let ours = closest_point_in_triangle(p, &tri, margin);
            let theirs = closest_point_with_margin(p, &tri, margin);
            prop_assert!((ours[0] - theirs[0]).hypot(ours[1] - theirs[1]) < 1e-9,
                "{:?} vs {:?}", ours, theirs);
        }
    }

    fn stance(
        height: &impl Fn(f64, f64) -> f64,
        centre: [f64; 2],
        heading: f64,
    ) -> ([Vec3; 4], [Vec3; 4]) {
        let nominal = [
            [0.092, 0.06],
            [0.092, -0.06],
            [-0.092, 0.06],
            [-0.092, -0.06],
        ];
        let (s, c) = heading.sin_cos();
        let contacts = nominal.map(|[x, y]| {
            let (wx, wy) = (centre[0] + c * x - s * y, centre[1] + s * x + c * y);
            [wx, wy, height(wx, wy)]
        });
        let feet = contacts.map(|p| add(p, [0.0, 0.0, 0.0103]));
        (feet, contacts)
    }

    #[test]
    fn footstep_certificate_holds_feet_com_and_clearance() {
        let height = |x: f64, y: f64| 0.01 * (10.0 * x).sin() * (8.0 * y).cos();
        let (_, sdf) = sdf_of(height);
        let fixture = CertificateFixture::default();
        let search = fixture.search(&sdf, 0.5 * 3f64.sqrt() * 0.005);
        let (robot, mass, config) = (&fixture.robot, &fixture.mass, &fixture.config);
        let (feet, contacts) = stance(&height, [0.3, 0.0], 0.3);
        for support in [[1, 2, 3], [0, 1, 3]] {
            let cert = search
                .find(&feet, &contacts, &support, 0.3)
                .expect("certifiable stance");
            let pose = BodyPose {
                x: cert.base_pos,
                r: quat_to_mat(cert.base_quat),
            };
            let reached = robot
                .foot_positions_world(cert.base_pos, cert.base_quat, &cert.q)
                .unwrap();
            for i in 0..4 {
                assert!(norm(sub(reached[i], feet[i])) < 1e-9);
            }
            let tri = support.map(|l| [contacts[l][0], contacts[l][1]]);
            assert!(triangle_margin([cert.com[0], cert.com[1]], &tri) >= config.com_margin);
            let frames: [LinkFrames; 4] = std::array::from_fn(|i| {
                robot.legs()[i].link_frames([cert.q[3 * i], cert.q[3 * i + 1], cert.q[3 * i + 2]])
            });
            let com = add(pose.x, mat_vec(&pose.r, mass.com_base(&frames)));
            assert!(norm(sub(com, cert.com)) < 1e-12);
            assert!(cert.clearance >= config.clearance);
            assert!(cert.penalty >= 0.0 && cert.singularity > 0.0 && cert.singularity <= 1.0);
        }
        // Feet spread beyond the legs' reach: no certificate.
        let mut far = feet;
        far[0][0] += 0.4;
        let mut far_contacts = contacts;
        far_contacts[0][0] += 0.4;
        assert_eq!(
            search.find(&far, &far_contacts, &[1, 2, 3], 0.3),
            Err(CertificateFailure::Unreachable)
        );
    }

    /// A 13 cm mound centred at (0.3, 0): under the trunk of a stance placed there.
    fn mound_under_trunk(x: f64, y: f64) -> f64 {
        let r2 = (x - 0.3).powi(2) + y.powi(2);
        (0.2 - 30.0 * r2).clamp(0.0, 0.13)
    }

    #[test]
    fn footstep_certificate_from_a_given_pose_keeps_the_clearance_asked() {
        // The 13 cm mound under the trunk: the guessed pose's knees and trunk
        // touch it; searched from a pose 3 cm higher, the body is clear at once.
        let height = mound_under_trunk;
        let (_, sdf) = sdf_of(height);
        let fixture = CertificateFixture::default();
        let search = fixture.search(&sdf, 0.0);
        let (feet, contacts) = stance(&height, [0.3, 0.0], 0.0);
        let support = [1, 2, 3];
        let guess = search.initial_pose(&feet, &contacts, &support, 0.0);
        let required = fixture.config.clearance;
        let lifted = BodyPose {
            x: add(guess.x, [0.0, 0.0, 0.03]),
            r: guess.r,
        };
        let cert = search
            .find_from(&feet, &contacts, &support, lifted, required)
            .expect("clear from the lifted pose");
        assert_eq!(cert.iterations, 1);
        assert!(norm(sub(cert.base_pos, lifted.x)) < 1e-12);
        assert!(cert.clearance >= required);
        // No pose of these feet holds the body 10 cm off the mound: lifted
        // that far, the feet are out of reach.
        assert!(search
            .find_from(&feet, &contacts, &support, lifted, 0.1)
            .is_err());
    }

    #[test]
    fn footstep_certificate_lifts_the_body_off_a_bump_under_the_trunk() {
        // A 13 cm mound under the trunk, which the guessed pose's knees and
        // trunk touch: the obstacle step must lift the body clear.
        let height = mound_under_trunk;
        let (_, sdf) = sdf_of(height);
        let fixture = CertificateFixture::default();
        let search = fixture.search(&sdf, 0.0);
        let (robot, collision, config) = (&fixture.robot, &fixture.collision, &fixture.config);
        let (feet, contacts) = stance(&height, [0.3, 0.0], 0.0);
        let guess = search.initial_pose(&feet, &contacts, &[1, 2, 3], 0.0);
        let frames: [LinkFrames; 4] = std::array::from_fn(|i| {
            let ik = robot.legs()[i].ik(guess.to_body(feet[i]), None);
            robot.legs()[i].link_frames(ik.q)
        });
        let before = collision
            .closest_below(&sdf, &guess, &frames, 1.0, 0.001)
            .unwrap();
        assert!(before.distance < config.clearance, "{before:?}");
        let cert = search
            .find(&feet, &contacts, &[1, 2, 3], 0.0)
            .expect("liftable");
        assert!(
            cert.iterations > 1 && cert.base_pos[2] > guess.x[2],
            "{cert:?}"
        );
        assert!(cert.clearance >= config.clearance);
    }
}

//! One leg: a chain of three hinge joints (HAA hip abduction, HFE hip
//! flexion, KFE knee) from the trunk ("base") frame to the centre of a
//! spherical foot, with MuJoCo's hinge semantics, its Jacobians, and an
//! analytic inverse kinematics that returns the closest reachable foot
//! position when the target cannot be reached (Zucker 2011, §3.1).

use crate::error::{CoreError, CoreResult};
use crate::kinematics::math::{
    add, axis_angle, cross, dot, from_columns, mat_mul, mat_t_vec, mat_vec, norm, quat_normalize,
    quat_to_mat, scale, solve, sub, wrap_angle, Mat3, Quat, Vec3,
};

/// The foot is "on" its target when it is this close [m].
pub const IK_TOLERANCE: f64 = 1e-9;

/// Joint values this close to a limit [rad] count as on it (they are clamped onto it).
const LIMIT_SLACK: f64 = 1e-9;

/// Tolerance on the axis structure the analytic IK needs: |cos| of the angle
/// between axes that must be perpendicular, |sin| between axes that must be parallel.
const STRUCTURE_TOLERANCE: f64 = 1e-6;

/// Targets farther than this from the hip [m] are pulled in along their direction
/// before solving: no leg reaches that far, and it keeps squares finite.
const FAR_TARGET: f64 = 1e3;

/// The description of a leg, as a MuJoCo model states it.
///
/// Body k ∈ {1, 2, 3} is the body carrying joint k (HAA, HFE, KFE). Its pose
/// given the joint angle q_k follows MuJoCo's hinge:
/// T_k = T_{k−1} · [R(body_quat_k), body_pos_k] · Trans(anchor_k) · Rot(axis_k, q_k) · Trans(−anchor_k),
/// with T_0 the base (trunk) frame. The foot centre is T_3 · foot.
#[derive(Debug, Clone, PartialEq)]
pub struct LegParams {
    /// Position of body k's frame in its parent's frame [m].
    pub body_pos: [Vec3; 3],
    /// Orientation (w, x, y, z) of body k's frame in its parent's frame
    /// (massless fixed bodies between joints already folded in).
    pub body_quat: [Quat; 3],
    /// Joint k's anchor in body k's frame (MuJoCo `jnt_pos`) [m].
    pub anchor: [Vec3; 3],
    /// Joint k's axis in body k's frame (MuJoCo `jnt_axis`); normalised on construction.
    pub axis: [Vec3; 3],
    /// Lower joint limits [rad]; may be −∞.
    pub lower: Vec3,
    /// Upper joint limits [rad]; may be +∞.
    pub upper: Vec3,
    /// Joint speed limits [rad/s]; may be +∞.
    pub velocity_limit: Vec3,
    /// Foot centre in body 3's frame [m].
    pub foot: Vec3,
    /// Foot sphere radius [m].
    pub foot_radius: f64,
    /// Preferred knee branch of the IK, +1 or −1: the sign of the angle ψ,
    /// measured right-handed about the HFE axis, from the HFE-anchor→KFE-anchor
    /// segment to the KFE-anchor→foot segment (both projected on the plane
    /// ⟂ the HFE axis). For a leg that is straight at q_KFE = 0 and whose KFE
    /// axis points the same way as its HFE axis, this is the sign of q_KFE.
    pub knee_sign: f64,
}

/// The pose of every joint body of a leg, in the base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkFrames {
    /// Origin of body k [m].
    pub pos: [Vec3; 3],
    /// Orientation of body k (columns are its axes in the base frame).
    pub rot: [Mat3; 3],
    /// Joint k's anchor [m].
    pub anchor: [Vec3; 3],
    /// Joint k's unit axis.
    pub axis: [Vec3; 3],
}

/// What the inverse kinematics found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkResult {
    /// Joint angles [rad], always within the joint limits and finite.
    pub q: Vec3,
    /// Whether the foot centre at `q` is within [`IK_TOLERANCE`] of the target.
    pub reachable: bool,
    /// False when a joint limit is what keeps the foot off the target: the
    /// target was not reached and at least one joint sits on its limit.
    pub within_limits: bool,
    /// Distance from the foot centre at `q` to the target [m] (+∞ for a non-finite target).
    pub error: f64,
}

/// Geometry the analytic IK needs, fixed at construction. "Hip frame" is
/// body 1's frame; vectors here are in it unless stated.
#[derive(Debug, Clone, PartialEq)]
struct IkGeometry {
    /// HAA axis (exact, unit).
    u1: Vec3,
    /// HFE axis orthogonalised against u1: with u1 and w = u1 × n_perp, the
    /// basis in which HAA rotates the foot.
    n_perp: Vec3,
    w: Vec3,
    /// The foot's fixed offset along n_perp from the HAA anchor [m].
    lateral: f64,
    /// Planar basis ⟂ the HFE axis n, with e1 × e2 = n.
    e1: Vec3,
    e2: Vec3,
    /// +1 when the KFE axis points along the HFE axis, −1 when against it.
    knee_axis_sign: f64,
    /// HFE anchor [m].
    hfe_anchor: Vec3,
    /// Thigh (HFE anchor → KFE anchor) and shank (KFE anchor → foot) at q = 0, in (e1, e2).
    thigh: [f64; 2],
    shank: [f64; 2],
}

/// A validated leg with its precomputed rotations and IK geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct LegChain {
    name: String,
    params: LegParams,
    body_rot: [Mat3; 3],
    /// HAA anchor in the base frame [m].
    haa_anchor_base: Vec3,
    ik_geometry: IkGeometry,
}

fn check_finite(name: &str, what: &str, values: &[f64]) -> CoreResult<()> {
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(CoreError::RobotModel(format!(
            "leg '{name}': {what} must be finite, got {v} in {values:?}"
        )));
    }
    Ok(())
}

fn unit(v: Vec3) -> Vec3 {
    scale(v, 1.0 / norm(v))
}

fn clamp_to(q: Vec3, lower: Vec3, upper: Vec3) -> Vec3 {
    [0, 1, 2].map(|k| q[k].clamp(lower[k], upper[k]))
}

/// The representative q + 2πm inside [lower, upper] (the one nearest the
/// bottom of the range), clamped onto it; `None` when there is none.
fn wrap_into_limits(q: f64, lower: f64, upper: f64) -> Option<f64> {
    let w = wrap_angle(q);
    let lo = lower - LIMIT_SLACK;
    let hi = upper + LIMIT_SLACK;
    if (lo..=hi).contains(&w) {
        return Some(w.clamp(lower, upper));
    }
    let tau = std::f64::consts::TAU;
    let v = w + tau * ((lo - w) / tau).ceil();
    (v <= hi).then(|| v.clamp(lower, upper))
}

/// The representative q + 2πm nearest to [lower, upper], clamped onto it.
fn nearest_in_limits(q: f64, lower: f64, upper: f64) -> f64 {
    if let Some(v) = wrap_into_limits(q, lower, upper) {
        return v;
    }
    let tau = std::f64::consts::TAU;
    let w = wrap_angle(q);
    let above = w + tau * ((lower - w) / tau).ceil();
    let below = above - tau;
    if above - upper < lower - below {
        upper
    } else {
        lower
    }
}

impl LegChain {
    /// Validates `params` and precomputes what FK and IK need.
    ///
    /// Refuses (with [`CoreError::RobotModel`] naming `name`) non-finite
    /// numbers, zero quaternions or axes, inverted limits, and legs whose axes
    /// do not have the structure the analytic IK assumes: HFE ∥ KFE, both ⟂ HAA.
    pub fn new(name: &str, mut params: LegParams) -> CoreResult<Self> {
        for k in 0..3 {
            check_finite(name, &format!("body_pos[{k}]"), &params.body_pos[k])?;
            check_finite(name, &format!("body_quat[{k}]"), &params.body_quat[k])?;
            check_finite(name, &format!("anchor[{k}]"), &params.anchor[k])?;
            check_finite(name, &format!("axis[{k}]"), &params.axis[k])?;
            params.body_quat[k] = quat_normalize(params.body_quat[k]).ok_or_else(|| {
                CoreError::RobotModel(format!(
                    "leg '{name}': body_quat[{k}] = {:?} is not a rotation (zero norm)",
                    params.body_quat[k]
                ))
            })?;
            let a = norm(params.axis[k]);
            if a < 1e-9 {
                return Err(CoreError::RobotModel(format!(
                    "leg '{name}': axis[{k}] = {:?} has zero length",
                    params.axis[k]
                )));
            }
            params.axis[k] = scale(params.axis[k], 1.0 / a);
            let (lo, hi) = (params.lower[k], params.upper[k]);
            if lo.is_nan()
                || hi.is_nan()
                || lo > hi
                || lo == f64::INFINITY
                || hi == f64::NEG_INFINITY
            {
                return Err(CoreError::RobotModel(format!(
                    "leg '{name}': joint {k} limits [{lo}, {hi}] must satisfy lower ≤ upper (±∞ allowed)"
                )));
            }
            let v = params.velocity_limit[k];
            if v.is_nan() || v <= 0.0 {
                return Err(CoreError::RobotModel(format!(
                    "leg '{name}': velocity_limit[{k}] = {v} must be positive (+∞ allowed)"
                )));
            }
        }
        check_finite(name, "foot", &params.foot)?;
        if !(params.foot_radius.is_finite() && params.foot_radius >= 0.0) {
            return Err(CoreError::RobotModel(format!(
                "leg '{name}': foot_radius = {} must be finite and ≥ 0",
                params.foot_radius
            )));
        }
        if !(params.knee_sign.is_finite() && params.knee_sign != 0.0) {
            return Err(CoreError::RobotModel(format!(
                "leg '{name}': knee_sign = {} must be +1 or -1 (any finite nonzero value: its sign)",
                params.knee_sign
            )));
        }
        params.knee_sign = params.knee_sign.signum();
        let body_rot = params.body_quat.map(quat_to_mat);
        let haa_anchor_base = add(params.body_pos[0], mat_vec(&body_rot[0], params.anchor[0]));
        let ik_geometry = Self::ik_geometry(name, &params, &body_rot)?;
        Ok(Self {
            name: name.to_owned(),
            params,
            body_rot,
            haa_anchor_base,
            ik_geometry,
        })
    }

    fn ik_geometry(name: &str, p: &LegParams, body_rot: &[Mat3; 3]) -> CoreResult<IkGeometry> {
        let u1 = p.axis[0];
        let n = mat_vec(&body_rot[1], p.axis[1]);
        let knee_axis = mat_vec(&body_rot[1], mat_vec(&body_rot[2], p.axis[2]));
        let cos_haa_hfe = dot(u1, n);
        if cos_haa_hfe.abs() > STRUCTURE_TOLERANCE {
            return Err(CoreError::RobotModel(format!(
                "leg '{name}': the HFE axis must be perpendicular to the HAA axis for the analytic IK, \
                 but cos(angle) = {cos_haa_hfe:.3e} (tolerance {STRUCTURE_TOLERANCE:e})"
            )));
        }
        let sin_hfe_kfe = norm(cross(n, knee_axis));
        if sin_hfe_kfe > STRUCTURE_TOLERANCE {
            return Err(CoreError::RobotModel(format!(
                "leg '{name}': the KFE axis must be parallel to the HFE axis for the analytic IK, \
                 but sin(angle) = {sin_hfe_kfe:.3e} (tolerance {STRUCTURE_TOLERANCE:e})"
            )));
        }
        let knee_axis_sign = dot(n, knee_axis).signum();
        let n_perp = unit(sub(n, scale(u1, cos_haa_hfe)));
        let w = cross(u1, n_perp);
        let e1 = unit(sub(u1, scale(n, cos_haa_hfe)));
        let e2 = cross(n, e1);

        // Positions in the hip frame at q_HFE = q_KFE = 0.
        let in_hip = |v_thigh: Vec3| add(p.body_pos[1], mat_vec(&body_rot[1], v_thigh));
        let hfe_anchor = add(p.body_pos[1], mat_vec(&body_rot[1], p.anchor[1]));
        let kfe_anchor = in_hip(add(p.body_pos[2], mat_vec(&body_rot[2], p.anchor[2])));
        let foot = in_hip(add(p.body_pos[2], mat_vec(&body_rot[2], p.foot)));
        let planar = |v: Vec3| [dot(v, e1), dot(v, e2)];
        let thigh = planar(sub(kfe_anchor, hfe_anchor));
        let shank = planar(sub(foot, kfe_anchor));
        for (what, v) in [("thigh (HFE→KFE)", thigh), ("shank (KFE→foot)", shank)] {
            let len = v[0].hypot(v[1]);
            if len < 1e-6 {
                return Err(CoreError::RobotModel(format!(
                    "leg '{name}': the {what} has length {len:.3e} m in the plane of the HFE and KFE \
                     rotations; the leg cannot move its foot in that plane"
                )));
            }
        }
        Ok(IkGeometry {
            u1,
            n_perp,
            w,
            lateral: dot(n_perp, sub(foot, p.anchor[0])),
            e1,
            e2,
            knee_axis_sign,
            hfe_anchor,
            thigh,
            shank,
        })
    }

    /// The leg's name, used in error messages.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The validated description (quaternions and axes normalised).
    pub fn params(&self) -> &LegParams {
        &self.params
    }

    /// Joint angles [rad] the IK falls back to: 0 clamped into each joint's limits.
    pub fn nominal(&self) -> Vec3 {
        clamp_to([0.0; 3], self.params.lower, self.params.upper)
    }

    /// Whether every joint angle is within its limits (with a 1e-9 rad slack).
    pub fn is_within_limits(&self, q: Vec3) -> bool {
        (0..3).all(|k| {
            q[k] >= self.params.lower[k] - LIMIT_SLACK && q[k] <= self.params.upper[k] + LIMIT_SLACK
        })
    }

    /// Pose of every joint body, with the joints' world anchors and axes, in the base frame.
    pub fn link_frames(&self, q: Vec3) -> LinkFrames {
        let p = &self.params;
        let mut parent_pos = [0.0; 3];
        let mut parent_rot = crate::kinematics::math::IDENTITY;
        let mut out = LinkFrames {
            pos: [[0.0; 3]; 3],
            rot: [parent_rot; 3],
            anchor: [[0.0; 3]; 3],
            axis: [[0.0; 3]; 3],
        };
        for (k, &angle) in q.iter().enumerate() {
            // MuJoCo's mj_kinematics for a hinge: place the body, then rotate it about the anchor.
            let pos0 = add(parent_pos, mat_vec(&parent_rot, p.body_pos[k]));
            let rot0 = mat_mul(&parent_rot, &self.body_rot[k]);
            let anchor = add(pos0, mat_vec(&rot0, p.anchor[k]));
            let rot = mat_mul(&rot0, &axis_angle(p.axis[k], angle));
            let pos = sub(anchor, mat_vec(&rot, p.anchor[k]));
            out.pos[k] = pos;
            out.rot[k] = rot;
            out.anchor[k] = anchor;
            out.axis[k] = mat_vec(&rot0, p.axis[k]);
            parent_pos = pos;
            parent_rot = rot;
        }
        out
    }

    /// Foot centre in the base frame, FK_B(q) [m].
    pub fn fk(&self, q: Vec3) -> Vec3 {
        let f = self.link_frames(q);
        add(f.pos[2], mat_vec(&f.rot[2], self.params.foot))
    }

    /// Foot centre FK_B(q) [m] and its Jacobian ∂FK_B/∂q [m/rad], columns per joint.
    pub fn fk_and_jacobian(&self, q: Vec3) -> (Vec3, Mat3) {
        let f = self.link_frames(q);
        let foot = add(f.pos[2], mat_vec(&f.rot[2], self.params.foot));
        (foot, Self::columns(&f, foot, 2))
    }

    /// ∂FK_B/∂q [m/rad]: column k is how the foot moves per radian of joint k.
    pub fn jacobian(&self, q: Vec3) -> Mat3 {
        self.fk_and_jacobian(q).1
    }

    fn columns(f: &LinkFrames, point: Vec3, link: usize) -> Mat3 {
        let col = |k: usize| {
            if k <= link {
                cross(f.axis[k], sub(point, f.anchor[k]))
            } else {
                [0.0; 3]
            }
        };
        from_columns(col(0), col(1), col(2))
    }

    /// Base-frame position [m] and Jacobian ∂p/∂q [m/rad] of a point fixed on
    /// link `link` (0 hip, 1 thigh, 2 shank: the bodies of joints 1–3), given
    /// in that link's frame [m]. Columns of joints after `link` are zero.
    pub fn point_jacobian(&self, q: Vec3, link: usize, point: Vec3) -> CoreResult<(Vec3, Mat3)> {
        if link > 2 {
            return Err(CoreError::InvalidArgument(format!(
                "leg '{}': link index {link} out of range; valid: 0 (hip), 1 (thigh), 2 (shank)",
                self.name
            )));
        }
        let f = self.link_frames(q);
        let p = add(f.pos[link], mat_vec(&f.rot[link], point));
        Ok((p, Self::columns(&f, p, link)))
    }

    /// Inverse kinematics IK_B: joint angles placing the foot centre at
    /// `target` (base frame [m]), or, when that is impossible within the joint
    /// limits, the joint angles within limits whose foot is closest to it.
    ///
    /// `knee_sign` (±1) overrides the leg's preferred knee branch (see
    /// [`LegParams::knee_sign`]); the other branch is used only when the
    /// preferred one violates a limit. Never panics and never returns NaN.
    pub fn ik(&self, target: Vec3, knee_sign: Option<f64>) -> IkResult {
        if !target.iter().all(|v| v.is_finite()) {
            return IkResult {
                q: self.nominal(),
                reachable: false,
                within_limits: true,
                error: f64::INFINITY,
            };
        }
        let knee = if knee_sign.unwrap_or(self.params.knee_sign) < 0.0 {
            -1.0
        } else {
            1.0
        };
        let from_hip = sub(target, self.haa_anchor_base);
        let dist = norm(from_hip);
        let solve_target = if dist > FAR_TARGET {
            add(self.haa_anchor_base, scale(from_hip, FAR_TARGET / dist))
        } else {
            target
        };
        let candidates = self.analytic_candidates(solve_target, knee);
        for (q, _) in &candidates {
            let wrapped = [0, 1, 2]
                .map(|k| wrap_into_limits(q[k], self.params.lower[k], self.params.upper[k]));
            if let [Some(a), Some(b), Some(c)] = wrapped {
                let (q, error) = self.polish([a, b, c], target);
                if error <= IK_TOLERANCE {
                    return IkResult {
                        q,
                        reachable: true,
                        within_limits: true,
                        error,
                    };
                }
            }
        }
        let (q, _) = self.closest_within_limits(solve_target, &candidates);
        let error = norm(sub(self.fk(q), target));
        let reachable = error <= IK_TOLERANCE;
        let on_limit = (0..3).any(|k| {
            q[k] <= self.params.lower[k] + LIMIT_SLACK || q[k] >= self.params.upper[k] - LIMIT_SLACK
        });
        IkResult {
            q,
            reachable,
            within_limits: reachable || !on_limit,
            error,
        }
    }

    /// The four analytic solutions (2 HAA × 2 knee branches) of the limit-free
    /// chain, most preferred first, each with whether it is exact. A target
    /// out of the chain's reach is first moved to the nearest point of reach,
    /// stage by stage, so every candidate is finite.
    fn analytic_candidates(&self, target: Vec3, knee: f64) -> [(Vec3, bool); 4] {
        let g = &self.ik_geometry;
        let p = &self.params;
        // Rotating about HAA moves the foot on a circle about the HAA axis at a
        // fixed offset `lateral` along the HFE axis: solve HAA from the target's
        // polar angle about that axis (two solutions, ±v_w).
        let t = mat_t_vec(&self.body_rot[0], sub(target, self.haa_anchor_base));
        let (t_u, t_n, t_w) = (dot(t, g.u1), dot(t, g.n_perp), dot(t, g.w));
        let v_w2 = t_n * t_n + t_w * t_w - g.lateral * g.lateral;
        let haa_exact = v_w2 >= 0.0;
        let v_w_abs = v_w2.max(0.0).sqrt();
        let nominal_haa = self.nominal()[0];
        let mut haa = [v_w_abs, -v_w_abs].map(|v_w| (v_w, t_w.atan2(t_n) - v_w.atan2(g.lateral)));
        if wrap_angle(haa[0].1 - nominal_haa).abs() > wrap_angle(haa[1].1 - nominal_haa).abs() {
            haa.swap(0, 1);
        }
        let mut out = [([0.0; 3], false); 4];
        for (i, &(v_w, q1)) in haa.iter().enumerate() {
            // The HFE/KFE plane problem, in the hip frame: the two-link chain
            // thigh + Rot(φ)·shank, rotated by q2, must reach d (law of cosines).
            let foot_hip = add(
                p.anchor[0],
                add(
                    add(scale(g.u1, t_u), scale(g.n_perp, g.lateral)),
                    scale(g.w, v_w),
                ),
            );
            let rel = sub(foot_hip, g.hfe_anchor);
            let d = [dot(rel, g.e1), dot(rel, g.e2)];
            let l1 = g.thigh[0].hypot(g.thigh[1]);
            let l2 = g.shank[0].hypot(g.shank[1]);
            let cos_psi = (d[0] * d[0] + d[1] * d[1] - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
            let planar_exact = (-1.0..=1.0).contains(&cos_psi);
            let psi_abs = cos_psi.clamp(-1.0, 1.0).acos();
            let alpha1 = g.thigh[1].atan2(g.thigh[0]);
            let alpha2 = g.shank[1].atan2(g.shank[0]);
            for (j, branch) in [knee, -knee].into_iter().enumerate() {
                let phi = branch * psi_abs + alpha1 - alpha2;
                let (s, c) = phi.sin_cos();
                let m = [
                    g.thigh[0] + c * g.shank[0] - s * g.shank[1],
                    g.thigh[1] + s * g.shank[0] + c * g.shank[1],
                ];
                let q2 = d[1].atan2(d[0]) - m[1].atan2(m[0]);
                let q3 = g.knee_axis_sign * phi;
                out[2 * i + j] = ([q1, q2, q3], haa_exact && planar_exact);
            }
        }
        out
    }

    /// A few Newton steps from an analytic solution, to take out the error of
    /// a slightly imperfect axis structure or of acos near a straight knee.
    fn polish(&self, q: Vec3, target: Vec3) -> (Vec3, f64) {
        let (lower, upper) = (self.params.lower, self.params.upper);
        let (mut q, mut foot_jac) = (q, self.fk_and_jacobian(q));
        let mut error = norm(sub(foot_jac.0, target));
        for _ in 0..4 {
            if error <= 1e-14 {
                break;
            }
            let Some(dq) = solve(&foot_jac.1, sub(target, foot_jac.0)) else {
                break;
            };
            let q_new = clamp_to(add(q, dq), lower, upper);
            let fj = self.fk_and_jacobian(q_new);
            let e_new = norm(sub(fj.0, target));
            if !e_new.is_finite() || e_new >= error {
                break;
            }
            (q, foot_jac, error) = (q_new, fj, e_new);
        }
        (q, error)
    }

    /// The joint angles within limits whose foot is closest to `target`:
    /// projected Levenberg–Marquardt from several starts (the analytic
    /// candidates moved into the limits, the nominal pose, and the best point
    /// of a coarse grid over the limits), keeping the best.
    fn closest_within_limits(&self, target: Vec3, candidates: &[(Vec3, bool); 4]) -> (Vec3, f64) {
        let (lower, upper) = (self.params.lower, self.params.upper);
        let mut seeds: Vec<Vec3> = candidates
            .iter()
            .map(|(q, _)| [0, 1, 2].map(|k| nearest_in_limits(q[k], lower[k], upper[k])))
            .collect();
        seeds.push(self.nominal());
        seeds.push(self.grid_seed(target));
        let mut best = (self.nominal(), f64::INFINITY);
        for seed in seeds {
            let (q, err) = self.projected_lm(seed, target);
            if err < best.1 {
                best = (q, err);
            }
        }
        best
    }

    /// The best foot-to-target distance over a 7×7×7 grid spanning the limits
    /// (or a full turn for unlimited joints): a start that no analytic
    /// candidate may be near when limits cut the workspace into pieces.
    fn grid_seed(&self, target: Vec3) -> Vec3 {
        const N: usize = 7;
        let (lower, upper) = (self.params.lower, self.params.upper);
        let span = |k: usize| {
            let lo = if lower[k].is_finite() {
                lower[k]
            } else {
                -std::f64::consts::PI
            };
            let hi = if upper[k].is_finite() {
                upper[k]
            } else {
                lo + std::f64::consts::TAU
            };
            (lo, (hi - lo).min(std::f64::consts::TAU))
        };
        let spans = [span(0), span(1), span(2)];
        let at = |k: usize, i: usize| spans[k].0 + spans[k].1 * i as f64 / (N - 1) as f64;
        let mut best = (self.nominal(), f64::INFINITY);
        for i in 0..N {
            for j in 0..N {
                for l in 0..N {
                    let q = clamp_to([at(0, i), at(1, j), at(2, l)], lower, upper);
                    let e = norm(sub(self.fk(q), target));
                    if e < best.1 {
                        best = (q, e);
                    }
                }
            }
        }
        best.0
    }

    /// Levenberg–Marquardt on ½|FK(q) − target|² with the joints on an active
    /// limit (pushed outward by the gradient) held fixed, every step clamped
    /// into the box and accepted only if it reduces the distance.
    fn projected_lm(&self, seed: Vec3, target: Vec3) -> (Vec3, f64) {
        let (lower, upper) = (self.params.lower, self.params.upper);
        let mut q = clamp_to(seed, lower, upper);
        let (foot, mut jac) = self.fk_and_jacobian(q);
        let mut e = sub(target, foot);
        let mut cost = dot(e, e);
        let mut lambda = 1e-3;
        for _ in 0..100 {
            let grad = mat_t_vec(&jac, e);
            let free = [0, 1, 2].map(|k| {
                !((q[k] <= lower[k] && grad[k] < 0.0) || (q[k] >= upper[k] && grad[k] > 0.0))
            });
            let mut h = [[0.0; 3]; 3];
            for r in 0..3 {
                for c in 0..3 {
                    h[r][c] = if free[r] && free[c] {
                        (0..3).map(|i| jac[i][r] * jac[i][c]).sum()
                    } else {
                        0.0
                    };
                }
            }
            let g = [0, 1, 2].map(|k| if free[k] { grad[k] } else { 0.0 });
            if norm(g) <= 1e-15 * (1.0 + cost.sqrt()) {
                break;
            }
            let scale_h = (h[0][0] + h[1][1] + h[2][2]).max(1e-12) / 3.0;
            let mut improved = false;
            while lambda < 1e12 {
                let mut damped = h;
                for k in 0..3 {
                    damped[k][k] += if free[k] {
                        lambda * (h[k][k] + scale_h)
                    } else {
                        1.0
                    };
                }
                let Some(dq) = solve(&damped, g) else {
                    lambda *= 10.0;
                    continue;
                };
                let q_new = clamp_to(add(q, dq), lower, upper);
                let (f_new, j_new) = self.fk_and_jacobian(q_new);
                let e_new = sub(target, f_new);
                let cost_new = dot(e_new, e_new);
                if cost_new < cost {
                    let step = norm(sub(q_new, q));
                    (q, jac, e) = (q_new, j_new, e_new);
                    let gain = cost - cost_new;
                    cost = cost_new;
                    lambda = (lambda / 5.0).max(1e-9);
                    improved = gain > 1e-30 && step > 1e-15;
                    break;
                }
                lambda *= 5.0;
            }
            if !improved {
                break;
            }
        }
        (q, cost.sqrt())
    }
}

#[cfg(test)]
// Exact float equality is what these tests mean where they use it.
#[allow(clippy::float_cmp)]
pub(crate) mod tests {
    use super::*;
    use crate::kinematics::math::{axis_angle as rot, mat_to_quat};
    use proptest::prelude::*;

    /// A LittleDog-sized leg (URDF numbers), x = forward, y = left, z = up.
    pub fn littledog_leg(side: f64, front: bool) -> LegChain {
        let x = if front { 0.101 } else { -0.101 };
        let shin_x = if front { -0.0265 } else { 0.0265 };
        LegChain::new(
            "littledog",
            LegParams {
                body_pos: [
                    [x, side * 0.03625, 0.0],
                    [0.0, side * 0.0236, -0.0166],
                    [0.0, 0.0, -0.0751],
                ],
                body_quat: [[1.0, 0.0, 0.0, 0.0]; 3],
                anchor: [[0.0; 3]; 3],
                axis: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
                lower: if front {
                    [-0.6, -3.5, -3.1]
                } else {
                    [-0.6, -2.4, -1.0]
                },
                upper: if front {
                    [0.6, 2.4, 1.0]
                } else {
                    [0.6, 3.5, 3.1]
                },
                velocity_limit: [f64::INFINITY; 3],
                foot: [shin_x, 0.0, -0.0985],
                foot_radius: 0.01,
                knee_sign: if front { -1.0 } else { 1.0 },
            },
        )
        .unwrap()
    }

    /// A leg with rotated body frames, nonzero anchors, an antiparallel knee
    /// axis and an in-plane shank offset (ANYmal-like): every term of the
    /// hinge transform matters.
    pub fn skewed_leg() -> LegChain {
        let q_hip = mat_to_quat(&rot(unit([0.3, 0.2, 0.9]), 0.7));
        // Body 2 rotated about the HAA axis direction is still ⟂; then a twist about its own HFE axis.
        let r_thigh = mat_mul(&rot([1.0, 0.0, 0.0], 0.4), &rot([0.0, 1.0, 0.0], -0.3));
        let q_thigh = mat_to_quat(&r_thigh);
        // Joint 2's axis in body 2 is chosen so that, in body 1, it is ⟂ HAA (x).
        let n_hip = [0.0, 0.6, 0.8];
        let axis2 = mat_t_vec(&r_thigh, n_hip);
        // Knee body rotated about the (hip-frame) HFE axis, knee axis antiparallel.
        let r_shank = rot(axis2, 0.9);
        let q_shank = mat_to_quat(&r_shank);
        let axis3 = scale(mat_t_vec(&r_shank, axis2), -1.0);
        LegChain::new(
            "skewed",
            LegParams {
                body_pos: [[0.25, 0.1, 0.02], [0.05, 0.07, -0.03], [0.02, 0.01, -0.25]],
                body_quat: [q_hip, q_thigh, q_shank],
                anchor: [[0.01, -0.02, 0.03], [0.02, 0.0, -0.01], [-0.01, 0.03, 0.02]],
                axis: [[2.0, 0.0, 0.0], axis2, axis3],
                lower: [-0.8, -2.0, -2.6],
                upper: [0.8, 2.0, 2.6],
                velocity_limit: [20.0; 3],
                foot: [0.03, -0.02, -0.28],
                foot_radius: 0.02,
                knee_sign: 1.0,
            },
        )
        .unwrap()
    }

    /// The skewed leg with ANYmal's ±3π flexion limits: several turns of each
    /// solution lie within limits.
    pub fn multi_turn_leg() -> LegChain {
        let mut p = skewed_leg().params().clone();
        p.lower = [
            -0.8,
            -3.0 * std::f64::consts::PI,
            -3.0 * std::f64::consts::PI,
        ];
        p.upper = [0.8, 3.0 * std::f64::consts::PI, 3.0 * std::f64::consts::PI];
        LegChain::new("multi_turn", p).unwrap()
    }

    pub fn test_legs() -> Vec<LegChain> {
        vec![
            littledog_leg(1.0, true),
            littledog_leg(-1.0, true),
            littledog_leg(1.0, false),
            littledog_leg(-1.0, false),
            skewed_leg(),
            multi_turn_leg(),
        ]
    }

    fn finite_difference(f: impl Fn(Vec3) -> Vec3, q: Vec3) -> Mat3 {
        let h = 1e-6;
        let cols = [0, 1, 2].map(|k| {
            let mut qp = q;
            let mut qm = q;
            qp[k] += h;
            qm[k] -= h;
            scale(sub(f(qp), f(qm)), 0.5 / h)
        });
        from_columns(cols[0], cols[1], cols[2])
    }

    pub fn assert_mat_close(a: &Mat3, b: &Mat3, rel: f64) {
        let scale_ab = a
            .iter()
            .chain(b.iter())
            .flatten()
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        for r in 0..3 {
            for c in 0..3 {
                assert!(
                    (a[r][c] - b[r][c]).abs() <= rel * scale_ab.max(1e-12),
                    "{a:?} vs {b:?} differ at ({r}, {c})"
                );
            }
        }
    }

    fn sample_q(leg: &LegChain, u: Vec3) -> Vec3 {
        let p = leg.params();
        [0, 1, 2].map(|k| p.lower[k] + u[k] * (p.upper[k] - p.lower[k]))
    }

    #[test]
    fn littledog_fk_at_zero_is_the_stacked_offsets() {
        let leg = littledog_leg(1.0, true);
        let f = leg.fk([0.0; 3]);
        let expected = [0.101 - 0.0265, 0.03625 + 0.0236, -0.0166 - 0.0751 - 0.0985];
        assert!(norm(sub(f, expected)) < 1e-15, "{f:?}");
        // Bending the knee by a right angle swings the shin about y.
        let g = leg.fk([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        let knee = [0.101, 0.05985, -0.0917];
        let expected = add(knee, [-0.0985, 0.0, 0.0265]);
        assert!(norm(sub(g, expected)) < 1e-15, "{g:?}");
    }

    #[test]
    fn jacobians_match_central_differences() {
        for leg in test_legs() {
            for u in [[0.5, 0.5, 0.3], [0.2, 0.7, 0.9], [0.9, 0.1, 0.6]] {
                let q = sample_q(&leg, u);
                assert_mat_close(&leg.jacobian(q), &finite_difference(|q| leg.fk(q), q), 1e-6);
                for link in 0..3 {
                    let pt = [0.01, -0.02, -0.05];
                    let (_, jac) = leg.point_jacobian(q, link, pt).unwrap();
                    let fd = finite_difference(|q| leg.point_jacobian(q, link, pt).unwrap().0, q);
                    assert_mat_close(&jac, &fd, 1e-6);
                }
            }
        }
        assert!(matches!(
            skewed_leg().point_jacobian([0.0; 3], 3, [0.0; 3]),
            Err(CoreError::InvalidArgument(_))
        ));
    }

    #[test]
    fn point_on_shank_at_foot_is_the_foot() {
        let leg = skewed_leg();
        let q = [0.3, -0.4, 1.1];
        let (p, j) = leg.point_jacobian(q, 2, leg.params().foot).unwrap();
        assert!(norm(sub(p, leg.fk(q))) < 1e-15);
        assert_mat_close(&j, &leg.jacobian(q), 1e-14);
    }

    #[test]
    fn structure_check_names_the_leg() {
        let mut p = skewed_leg().params().clone();
        p.axis[2] = [0.0, 0.0, 1.0];
        let err = LegChain::new("RH", p).unwrap_err();
        assert!(
            matches!(&err, CoreError::RobotModel(m) if m.contains("'RH'") && m.contains("KFE"))
        );
        let mut p = littledog_leg(1.0, true).params().clone();
        p.axis[1] = [1.0, 0.0, 0.0];
        p.axis[2] = [1.0, 0.0, 0.0];
        let err = LegChain::new("LF", p).unwrap_err();
        assert!(
            matches!(&err, CoreError::RobotModel(m) if m.contains("'LF'") && m.contains("perpendicular"))
        );
        let mut p = littledog_leg(1.0, true).params().clone();
        p.lower[1] = 3.0;
        assert!(LegChain::new("LF", p).is_err());
    }

    #[test]
    fn knee_sign_selects_the_branch() {
        // LittleDog front leg: ψ = q_KFE + 0.263 (the shin's backward offset), so
        // the mirror of q_KFE = −1.2 (ψ = −0.937) is q_KFE = 0.674, inside the limit of 1.0.
        let leg = littledog_leg(1.0, true);
        let q = [0.1, 0.4, -1.2];
        let f = leg.fk(q);
        let minus = leg.ik(f, Some(-1.0));
        assert!(minus.reachable && norm(sub(minus.q, q)) < 1e-9, "{minus:?}");
        let plus = leg.ik(f, Some(1.0));
        assert!(
            plus.reachable && (plus.q[2] - 0.674).abs() < 2e-3,
            "{plus:?}"
        );
        // The mirror of q_KFE = −2.0 would need q_KFE = 1.47 > 1.0: the preferred
        // branch is then dropped for the one that fits.
        let q = [0.1, -0.2, -2.0];
        let fallback = leg.ik(leg.fk(q), Some(1.0));
        assert!(
            fallback.reachable && norm(sub(fallback.q, q)) < 1e-9,
            "{fallback:?}"
        );
    }

    #[test]
    fn degenerate_targets_give_finite_answers() {
        for leg in test_legs() {
            let hip = leg.haa_anchor_base;
            for target in [
                hip,
                [0.0; 3],
                [1e300, -1e300, 1e300],
                [f64::MAX, 0.0, 0.0],
                add(hip, [0.0, 0.0, 5.0]),
                [f64::NAN, 0.0, 0.0],
                [f64::INFINITY, 0.0, 0.0],
            ] {
                let r = leg.ik(target, None);
                assert!(r.q.iter().all(|v| v.is_finite()), "{target:?} → {r:?}");
                assert!(leg.is_within_limits(r.q));
                assert!(!r.reachable);
                assert!(!r.error.is_nan());
            }
        }
    }

    /// Best foot-to-target distance over a dense grid of joint angles within limits.
    fn brute_force_distance(leg: &LegChain, target: Vec3, n: usize) -> f64 {
        let mut best = f64::INFINITY;
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let u = [i, j, k].map(|v| v as f64 / (n - 1) as f64);
                    best = best.min(norm(sub(leg.fk(sample_q(leg, u)), target)));
                }
            }
        }
        best
    }

    #[test]
    fn out_of_reach_targets_get_the_closest_reachable_foot() {
        let mut rng = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        for leg in test_legs() {
            for _ in 0..12 {
                let dir = unit([next() - 0.5, next() - 0.5, next() - 0.5]);
                let target = add(leg.haa_anchor_base, scale(dir, 0.15 + 0.5 * next()));
                let r = leg.ik(target, None);
                let brute = brute_force_distance(&leg, target, 41);
                assert!(
                    r.error <= brute + 1e-9,
                    "{}: ik {} > brute {brute} for {target:?}",
                    leg.name(),
                    r.error
                );
                assert!(leg.is_within_limits(r.q));
                assert_eq!(r.reachable, r.error <= IK_TOLERANCE);
            }
        }
    }

    proptest! {
        #[test]
        fn ik_inverts_fk_inside_the_workspace(u in prop::array::uniform3(0.0..=1.0f64), which in 0usize..6) {
            let leg = &test_legs()[which];
            let q = sample_q(leg, u);
            let f = leg.fk(q);
            let r = leg.ik(f, None);
            prop_assert!(r.reachable, "{q:?} → {r:?}");
            prop_assert!(r.within_limits);
            prop_assert!(leg.is_within_limits(r.q));
            prop_assert!(norm(sub(leg.fk(r.q), f)) <= 1e-9);
        }
    }
}

//! One leg: a chain of three hinge joints (HAA hip abduction, HFE hip
//! flexion, KFE knee) from the trunk ("base") frame to the centre of a
//! spherical foot, with MuJoCo's hinge semantics, its Jacobians, and an
//! analytic inverse kinematics that returns the closest reachable foot
//! position when the target cannot be reached (Zucker 2011, §3.1).

use crate::error::{CoreError, CoreResult};
use crate::kinematics::math::{
    add, cross, from_columns, mat_mul, mat_vec, norm, quat_normalize, quat_to_mat, scale, skew,
    sub, Mat3, Quat, Vec3,
};

/// The foot is "on" its target when it is this close [m].
pub const IK_TOLERANCE: f64 = 1e-9;

/// Joint values this close to a limit [rad] count as on it (they are clamped onto it).
const LIMIT_SLACK: f64 = 1e-9;

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

/// The pose of every joint body of a leg, in the base frame (all zeros by
/// default: a buffer for the `*_into` IK calls to fill).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
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

mod closest;
mod ik;

/// A validated leg with its precomputed rotations and IK geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct LegChain {
    name: String,
    params: LegParams,
    body_rot: [Mat3; 3],
    /// HAA anchor in the base frame [m].
    haa_anchor_base: Vec3,
    ik_geometry: ik::IkGeometry,
    /// Arcs bounding the foot's reach in the HFE/KFE plane (see `closest`).
    arcs: Vec<closest::PlanarArc>,
    /// The HAA scan of the closest-point search.
    scan: closest::HaaScan,
    /// Each joint's hinge in its parent body's frame (boxed: legs are
    /// passed around by value in arrays of four).
    hinges: Box<[Hinge; 3]>,
}

/// Joint k's hinge transform with everything that does not depend on q_k
/// folded in, in the parent body's frame: the body's rotation is
/// B_k·Rot(a_k, q_k) = B_k + sin q_k·B_k[a_k]× + (1 − cos q_k)·B_k[a_k]×²
/// (Rodrigues), which spares building Rot and one matrix product per joint.
#[derive(Debug, Clone, PartialEq)]
struct Hinge {
    /// B_k, B_k[a_k]×, B_k[a_k]×².
    rot: [Mat3; 3],
    /// The joint's anchor and unit axis in the parent's frame [m].
    anchor: Vec3,
    axis: Vec3,
    /// The anchor in body k's own frame (MuJoCo `jnt_pos`) [m].
    anchor_local: Vec3,
}

impl Hinge {
    fn new(p: &LegParams, body_rot: &[Mat3; 3], k: usize) -> Self {
        let b = body_rot[k];
        let a = skew(p.axis[k]);
        let ba = mat_mul(&b, &a);
        Self {
            rot: [b, ba, mat_mul(&ba, &a)],
            anchor: add(p.body_pos[k], mat_vec(&b, p.anchor[k])),
            axis: mat_vec(&b, p.axis[k]),
            anchor_local: p.anchor[k],
        }
    }

    /// B_k·Rot(a_k, q) [rotation, parent frame].
    #[inline]
    fn rotation(&self, q: f64) -> Mat3 {
        let (s, c) = q.sin_cos();
        let t = 1.0 - c;
        let [b, b1, b2] = &self.rot;
        std::array::from_fn(|i| std::array::from_fn(|j| b[i][j] + s * b1[i][j] + t * b2[i][j]))
    }
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
        let ik_geometry = ik::IkGeometry::new(name, &params, &body_rot)?;
        let arcs = closest::planar_arcs(&ik_geometry, params.lower, params.upper);
        let scan = closest::haa_scan(&ik_geometry, params.lower, params.upper);
        let hinges = Box::new([0, 1, 2].map(|k| Hinge::new(&params, &body_rot, k)));
        Ok(Self {
            name: name.to_owned(),
            params,
            body_rot,
            haa_anchor_base,
            ik_geometry,
            arcs,
            scan,
            hinges,
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
        // MuJoCo's mj_kinematics for a hinge: place the body on its parent,
        // then rotate it about the joint's anchor.
        let h = &self.hinges;
        // HAA's parent is the trunk itself.
        let rot0 = h[0].rotation(q[0]);
        let pos0 = sub(h[0].anchor, mat_vec(&rot0, h[0].anchor_local));
        let mut out = LinkFrames {
            pos: [pos0, [0.0; 3], [0.0; 3]],
            rot: [rot0, rot0, rot0],
            anchor: [h[0].anchor, [0.0; 3], [0.0; 3]],
            axis: [h[0].axis, [0.0; 3], [0.0; 3]],
        };
        for k in 1..3 {
            let (parent_pos, parent_rot) = (out.pos[k - 1], out.rot[k - 1]);
            let rot = mat_mul(&parent_rot, &h[k].rotation(q[k]));
            let anchor = add(parent_pos, mat_vec(&parent_rot, h[k].anchor));
            out.pos[k] = sub(anchor, mat_vec(&rot, h[k].anchor_local));
            out.rot[k] = rot;
            out.anchor[k] = anchor;
            out.axis[k] = mat_vec(&parent_rot, h[k].axis);
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
        self.point_jacobian_at(&self.link_frames(q), link, point)
    }

    /// [`Self::point_jacobian`] from the link frames `f` of the joint angles
    /// (as [`Self::link_frames`] or the IK with frames give them), for
    /// callers that already hold them.
    pub fn point_jacobian_at(
        &self,
        f: &LinkFrames,
        link: usize,
        point: Vec3,
    ) -> CoreResult<(Vec3, Mat3)> {
        if link > 2 {
            return Err(CoreError::InvalidArgument(format!(
                "leg '{}': link index {link} out of range; valid: 0 (hip), 1 (thigh), 2 (shank)",
                self.name
            )));
        }
        let p = add(f.pos[link], mat_vec(&f.rot[link], point));
        Ok((p, Self::columns(f, p, link)))
    }

    /// The foot Jacobian ∂FK_B/∂q [m/rad] from the link frames `f` of the joint angles.
    pub fn jacobian_at(&self, f: &LinkFrames) -> Mat3 {
        let foot = add(f.pos[2], mat_vec(&f.rot[2], self.params.foot));
        Self::columns(f, foot, 2)
    }
}

#[cfg(test)]
// Exact float equality is what these tests mean where they use it.
#[allow(clippy::float_cmp)]
pub(crate) mod tests {
    use super::*;
    use crate::kinematics::math::{axis_angle as rot, mat_t_vec, mat_to_quat};

    pub use crate::testing::littledog_leg;

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

    pub fn finite_difference(f: impl Fn(Vec3) -> Vec3, q: Vec3) -> Mat3 {
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

    pub fn sample_q(leg: &LegChain, u: Vec3) -> Vec3 {
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
    fn link_frames_follow_mujocos_hinge_transform() {
        // T_k = T_{k-1}·[R(body_quat_k), body_pos_k]·Trans(anchor_k)·Rot(axis_k, q_k)·Trans(−anchor_k),
        // composed plainly.
        for leg in test_legs() {
            let p = leg.params();
            for u in [
                [0.5, 0.5, 0.3],
                [0.2, 0.7, 0.9],
                [0.9, 0.1, 0.6],
                [0.0, 1.0, 0.5],
            ] {
                let q = sample_q(&leg, u);
                let f = leg.link_frames(q);
                let (mut pos, mut r) = ([0.0; 3], crate::kinematics::math::IDENTITY);
                for (k, &angle) in q.iter().enumerate() {
                    let placed = mat_mul(&r, &quat_to_mat(p.body_quat[k]));
                    let origin = add(pos, mat_vec(&r, p.body_pos[k]));
                    let anchor = add(origin, mat_vec(&placed, p.anchor[k]));
                    r = mat_mul(&placed, &rot(p.axis[k], angle));
                    pos = sub(anchor, mat_vec(&r, p.anchor[k]));
                    let close = |a: Vec3, b: Vec3| norm(sub(a, b)) < 1e-14;
                    assert!(
                        close(f.pos[k], pos) && close(f.anchor[k], anchor),
                        "{k}: {f:?}"
                    );
                    assert!(close(f.axis[k], mat_vec(&placed, p.axis[k])), "{k}: {f:?}");
                    assert_mat_close(&f.rot[k], &r, 1e-14);
                }
            }
        }
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
    fn bad_descriptions_are_refused() {
        let good = littledog_leg(1.0, true).params().clone();
        let mut p = good.clone();
        p.lower[1] = 3.0;
        assert!(
            matches!(LegChain::new("LF", p), Err(CoreError::RobotModel(m)) if m.contains("joint 1 limits"))
        );
        let mut p = good.clone();
        p.body_quat[2] = [0.0; 4];
        assert!(LegChain::new("LF", p).is_err());
        let mut p = good.clone();
        p.foot[0] = f64::NAN;
        assert!(LegChain::new("LF", p).is_err());
        let mut p = good;
        p.knee_sign = 0.0;
        assert!(LegChain::new("LF", p).is_err());
    }

    /// A small seeded generator for random legs.
    struct Rng(u64);

    impl Rng {
        fn uniform(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            2.0 * ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 1.0
        }

        fn vec3(&mut self) -> Vec3 {
            [self.uniform(), self.uniform(), self.uniform()]
        }
    }

    /// A random leg with the IK's axis structure (HFE ∥ KFE ⟂ HAA): random
    /// body rotations, anchors, offsets, limits and knee-axis direction.
    pub fn random_leg(seed: u64) -> LegChain {
        let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
        let quats: [Quat; 3] = std::array::from_fn(|_| {
            let q = [rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()];
            quat_normalize(q).unwrap_or([1.0, 0.0, 0.0, 0.0])
        });
        let rots = quats.map(quat_to_mat);
        let haa = unit(rng.vec3());
        let hfe_in_hip = unit(cross(haa, rng.vec3()));
        let hfe = mat_t_vec(&rots[1], hfe_in_hip);
        let flip = if rng.uniform() < 0.0 { -1.0 } else { 1.0 };
        let kfe = scale(mat_t_vec(&rots[2], hfe), flip);
        let thigh = add(scale(rng.vec3(), 0.15), scale(unit(rng.vec3()), 0.2));
        let foot = add(scale(rng.vec3(), 0.05), scale(unit(rng.vec3()), 0.22));
        let width = [
            0.8 + 0.4 * rng.uniform(),
            2.5 + rng.uniform(),
            2.5 + rng.uniform(),
        ];
        let centre = [
            0.2 * rng.uniform(),
            0.5 * rng.uniform(),
            0.5 * rng.uniform(),
        ];
        LegChain::new(
            &format!("random{seed}"),
            LegParams {
                body_pos: [scale(rng.vec3(), 0.2), scale(rng.vec3(), 0.06), thigh],
                body_quat: quats,
                anchor: std::array::from_fn(|_| scale(rng.vec3(), 0.03)),
                axis: [haa, hfe, kfe],
                lower: std::array::from_fn(|k| centre[k] - width[k]),
                upper: std::array::from_fn(|k| centre[k] + width[k]),
                velocity_limit: [10.0; 3],
                foot,
                foot_radius: 0.01,
                knee_sign: 1.0,
            },
        )
        .unwrap()
    }
}

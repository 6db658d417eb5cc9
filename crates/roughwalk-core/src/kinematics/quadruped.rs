//! Four legs on a trunk: world-frame FK and IK (Zucker 2011, §3.1:
//! FK_W(x, R, q) = R·FK_B(q) + x, IK_W(x, R, f) = IK_B(Rᵀ(f − x))), the
//! 18-DOF whole-body configuration, and batched variants.

use rayon::prelude::*;

use crate::error::{CoreError, CoreResult};
use crate::kinematics::leg::{IkResult, LegChain};
use crate::kinematics::math::{
    add, mat_t_vec, mat_to_quat, mat_vec, quat_normalize, quat_to_mat, sub, Mat3, Quat, Vec3,
};

/// Canonical leg order: left front, right front, left hind, right hind.
pub const LEG_NAMES: [&str; 4] = ["LF", "RF", "LH", "RH"];

/// Batches at least this long run on rayon's thread pool.
const PARALLEL_BATCH: usize = 256;

/// The trunk's pose: p_W = R·p_B + x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPose {
    /// Trunk (base frame) origin in the world [m].
    pub x: Vec3,
    /// Trunk orientation: columns are the base axes in the world.
    pub r: Mat3,
}

impl BodyPose {
    /// A pose from a position [m] and a (w, x, y, z) quaternion (normalised here).
    pub fn new(base_pos: Vec3, base_quat: Quat) -> CoreResult<Self> {
        if !base_pos.iter().all(|v| v.is_finite()) {
            return Err(CoreError::InvalidArgument(format!(
                "base position must be finite, got {base_pos:?}"
            )));
        }
        let q = quat_normalize(base_quat).ok_or_else(|| {
            CoreError::InvalidArgument(format!(
                "base quaternion (w, x, y, z) must be finite and nonzero, got {base_quat:?}"
            ))
        })?;
        Ok(Self {
            x: base_pos,
            r: quat_to_mat(q),
        })
    }

    /// The orientation as a unit (w, x, y, z) quaternion with w ≥ 0.
    pub fn quat(&self) -> Quat {
        mat_to_quat(&self.r)
    }

    /// p_W = R·p_B + x [m].
    pub fn to_world(&self, p_body: Vec3) -> Vec3 {
        add(mat_vec(&self.r, p_body), self.x)
    }

    /// p_B = Rᵀ(p_W − x) [m].
    pub fn to_body(&self, p_world: Vec3) -> Vec3 {
        mat_t_vec(&self.r, sub(p_world, self.x))
    }
}

/// The 18-DOF whole-body configuration: trunk pose and 12 joint angles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Configuration {
    /// Trunk origin in the world [m].
    pub base_pos: Vec3,
    /// Trunk orientation (w, x, y, z).
    pub base_quat: Quat,
    /// Joint angles [rad], leg-major in canonical order (LF, RF, LH, RH), each HAA, HFE, KFE.
    pub q: [f64; 12],
}

impl Configuration {
    /// The trunk pose, refusing a non-finite position or a zero quaternion.
    pub fn pose(&self) -> CoreResult<BodyPose> {
        BodyPose::new(self.base_pos, self.base_quat)
    }
}

/// Leg `i`'s three joint angles out of the 12.
#[inline]
pub fn leg_q(q: &[f64; 12], i: usize) -> Vec3 {
    [q[3 * i], q[3 * i + 1], q[3 * i + 2]]
}

/// A quadruped: four legs on one trunk, in canonical order (LF, RF, LH, RH).
#[derive(Debug, Clone, PartialEq)]
pub struct Quadruped {
    legs: [LegChain; 4],
}

impl Quadruped {
    /// Four legs in canonical order LF, RF, LH, RH.
    pub fn new(legs: [LegChain; 4]) -> Self {
        Self { legs }
    }

    /// The legs, in canonical order.
    pub fn legs(&self) -> &[LegChain; 4] {
        &self.legs
    }

    /// Feet in the base frame, FK_B per leg [m].
    pub fn fk_base(&self, q: &[f64; 12]) -> [Vec3; 4] {
        std::array::from_fn(|i| self.legs[i].fk(leg_q(q, i)))
    }

    /// Feet in the world, FK_W(x, R, q_i) = R·FK_B(q_i) + x [m].
    pub fn foot_positions_world(
        &self,
        base_pos: Vec3,
        base_quat: Quat,
        q: &[f64; 12],
    ) -> CoreResult<[Vec3; 4]> {
        let pose = BodyPose::new(base_pos, base_quat)?;
        Ok(self.fk_base(q).map(|f| pose.to_world(f)))
    }

    /// IK_B for every leg, feet given in the base frame [m].
    pub fn ik_base(&self, feet_base: &[Vec3; 4]) -> [IkResult; 4] {
        std::array::from_fn(|i| self.legs[i].ik(feet_base[i], None))
    }

    /// IK_W(x, R, f_i) = IK_B(Rᵀ(f_i − x)) for every leg, with full results.
    pub fn ik_pose(&self, pose: &BodyPose, feet_world: &[Vec3; 4]) -> [IkResult; 4] {
        std::array::from_fn(|i| self.legs[i].ik(pose.to_body(feet_world[i]), None))
    }

    /// IK_W for every leg: the 12 joint angles [rad] (closest reachable where a
    /// foot cannot be reached) and, per leg, whether its foot reached its target.
    pub fn ik_world(
        &self,
        base_pos: Vec3,
        base_quat: Quat,
        feet_world: &[Vec3; 4],
    ) -> CoreResult<([f64; 12], [bool; 4])> {
        let pose = BodyPose::new(base_pos, base_quat)?;
        Ok(Self::pack(&self.ik_pose(&pose, feet_world)))
    }

    fn pack(results: &[IkResult; 4]) -> ([f64; 12], [bool; 4]) {
        let mut q = [0.0; 12];
        for (i, r) in results.iter().enumerate() {
            q[3 * i..3 * i + 3].copy_from_slice(&r.q);
        }
        (q, results.map(|r| r.reachable))
    }

    /// FK_B of many joint vectors (rows of 12 angles [rad]); parallel for long batches.
    pub fn fk_batch(&self, q: &[[f64; 12]]) -> Vec<[Vec3; 4]> {
        if q.len() >= PARALLEL_BATCH {
            q.par_iter().map(|row| self.fk_base(row)).collect()
        } else {
            q.iter().map(|row| self.fk_base(row)).collect()
        }
    }

    /// IK_B of many foot sets (base frame [m]): joint angles and reached flags.
    pub fn ik_batch(&self, feet_base: &[[Vec3; 4]]) -> (Vec<[f64; 12]>, Vec<[bool; 4]>) {
        let solve = |feet: &[Vec3; 4]| Self::pack(&self.ik_base(feet));
        if feet_base.len() >= PARALLEL_BATCH / 8 {
            feet_base.par_iter().map(solve).unzip()
        } else {
            feet_base.iter().map(solve).unzip()
        }
    }
}

#[cfg(test)]
// Exact float equality is what these tests mean where they use it.
#[allow(clippy::float_cmp)]
pub(crate) mod tests {
    use super::*;
    use crate::kinematics::math::norm;
    // One LittleDog for every test and bench: the shared fixture.
    pub use crate::testing::{littledog, STANCE_Q};

    #[test]
    fn world_ik_inverts_world_fk_and_batches_agree() {
        let robot = littledog();
        let pos = [0.3, -0.2, 0.25];
        let quat = [0.9, 0.1, -0.2, 0.3];
        let feet = robot.foot_positions_world(pos, quat, &STANCE_Q).unwrap();
        let (q, reached) = robot.ik_world(pos, quat, &feet).unwrap();
        assert!(reached.iter().all(|&r| r));
        assert!(
            q.iter().zip(STANCE_Q).all(|(a, b)| (a - b).abs() < 1e-9),
            "{q:?}"
        );
        let rows: Vec<[f64; 12]> = (0..300)
            .map(|k| STANCE_Q.map(|v| v * (0.5 + f64::from(k) / 600.0)))
            .collect();
        let batch = robot.fk_batch(&rows);
        for (row, feet) in rows.iter().zip(&batch) {
            assert_eq!(*feet, robot.fk_base(row));
        }
        let (qs, ok) = robot.ik_batch(&batch);
        for ((q, ok), feet) in qs.iter().zip(&ok).zip(&batch) {
            assert!(ok.iter().all(|&r| r));
            let again = robot.fk_base(q);
            assert!((0..4).all(|i| norm(sub(again[i], feet[i])) < 1e-9));
        }
    }

    #[test]
    fn bad_pose_is_refused() {
        let robot = littledog();
        assert!(robot
            .foot_positions_world([0.0; 3], [0.0; 4], &STANCE_Q)
            .is_err());
        assert!(robot
            .ik_world([f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], &[[0.0; 3]; 4])
            .is_err());
    }
}

//! The whole-body centre of mass from link masses: the point the pose
//! certificate keeps over the support triangle (Zucker 2011, §4.3–4.4).

use crate::error::{CoreError, CoreResult};
use crate::kinematics::leg::LinkFrames;
use crate::kinematics::math::{add, mat_vec, scale, Vec3};

/// Masses and centres of mass of the trunk and of every leg link.
#[derive(Debug, Clone, PartialEq)]
pub struct MassModel {
    base_mass: f64,
    base_com: Vec3,
    /// Per canonical leg, per link (hip, thigh, shank) [kg].
    link_mass: [[f64; 3]; 4],
    /// Per leg and link, the link's centre of mass in its own frame [m].
    link_com: [[Vec3; 3]; 4],
    total: f64,
}

impl MassModel {
    /// The trunk's mass [kg] (everything rigidly fixed to it) and centre of
    /// mass in the base frame [m]; per leg (canonical order) and link, the
    /// mass [kg] and centre of mass in the link's frame [m].
    pub fn new(
        base_mass: f64,
        base_com: Vec3,
        link_mass: [[f64; 3]; 4],
        link_com: [[Vec3; 3]; 4],
    ) -> CoreResult<Self> {
        let masses = std::iter::once(base_mass).chain(link_mass.iter().flatten().copied());
        let mut total = 0.0;
        for m in masses {
            if !(m.is_finite() && m >= 0.0) {
                return Err(CoreError::RobotModel(format!(
                    "masses must be finite and >= 0 [kg], got {m}"
                )));
            }
            total += m;
        }
        if total <= 0.0 {
            return Err(CoreError::RobotModel(
                "the robot's total mass must be > 0 [kg]".into(),
            ));
        }
        let points = std::iter::once(&base_com).chain(link_com.iter().flatten());
        if let Some(p) = points.clone().find(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(CoreError::RobotModel(format!(
                "centres of mass must be finite [m], got {p:?}"
            )));
        }
        Ok(Self {
            base_mass,
            base_com,
            link_mass,
            link_com,
            total,
        })
    }

    /// Total mass [kg].
    pub fn total_mass(&self) -> f64 {
        self.total
    }

    /// The whole-body centre of mass in the base frame [m], given every
    /// leg's link frames (base frame) at its joint angles.
    #[inline]
    pub fn com_base(&self, frames: &[LinkFrames; 4]) -> Vec3 {
        let mut weighted = scale(self.base_com, self.base_mass);
        for (leg, f) in frames.iter().enumerate() {
            for k in 0..3 {
                let c = add(f.pos[k], mat_vec(&f.rot[k], self.link_com[leg][k]));
                weighted = add(weighted, scale(c, self.link_mass[leg][k]));
            }
        }
        scale(weighted, 1.0 / self.total)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::kinematics::quadruped::tests::{littledog, STANCE_Q};
    use crate::kinematics::quadruped::{leg_q, Quadruped};

    pub use crate::testing::littledog_mass;

    fn frames(robot: &Quadruped, q: &[f64; 12]) -> [LinkFrames; 4] {
        std::array::from_fn(|i| robot.legs()[i].link_frames(leg_q(q, i)))
    }

    #[test]
    fn footstep_com_is_the_mass_weighted_mean_and_moves_with_the_legs() {
        let robot = littledog();
        let mass = littledog_mass();
        assert!((mass.total_mass() - (1.8 + 4.0 * 0.2366)).abs() < 1e-12);
        let com = mass.com_base(&frames(&robot, &STANCE_Q));
        // Legs hang below the trunk: the CoM is below the base origin.
        assert!(com[2] < -0.01 && com[2] > -0.05, "{com:?}");
        // +0.3 rad about every HFE axis (+y) swings the legs backward, and
        // the CoM with them.
        let mut q = STANCE_Q;
        for leg in 0..4 {
            q[3 * leg + 1] += 0.3;
        }
        let moved = mass.com_base(&frames(&robot, &q));
        assert!(moved[0] < com[0] - 1e-3, "{com:?} -> {moved:?}");
        assert!(MassModel::new(-1.0, [0.0; 3], [[0.0; 3]; 4], [[[0.0; 3]; 3]; 4]).is_err());
        assert!(MassModel::new(0.0, [0.0; 3], [[0.0; 3]; 4], [[[0.0; 3]; 3]; 4]).is_err());
    }
}

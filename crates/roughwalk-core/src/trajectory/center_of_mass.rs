//! The whole robot's centre of mass over a trajectory of joint angles.
//!
//! The trajectory generator recomputes it after every change of the legs
//! (the swing leg alone moves the CoM by millimetres, which the ZMP feels,
//! Zucker 2011, §5.2); one call per trajectory instead of per-sample numpy.

use crate::error::{CoreError, CoreResult};
use crate::kinematics::math::{add, mat_vec, scale, Vec3};
use crate::kinematics::Quadruped;

/// The robot's mass distribution: per leg link (hip, thigh, shank) a mass
/// [kg] and a CoM in that link's frame [m], and the trunk's.
#[derive(Debug, Clone, PartialEq)]
pub struct MassDistribution {
    /// Link masses [kg], canonical leg order.
    pub link_mass: [[f64; 3]; 4],
    /// Link CoMs in their link frames [m].
    pub link_com: [[Vec3; 3]; 4],
    /// Trunk mass [kg].
    pub base_mass: f64,
    /// Trunk CoM in the base frame [m].
    pub base_com: Vec3,
}

impl MassDistribution {
    /// Total mass [kg]; refuses a non-positive or non-finite one.
    pub fn total(&self) -> CoreResult<f64> {
        let m = self.base_mass + self.link_mass.iter().flatten().sum::<f64>();
        if m > 0.0 && m.is_finite() {
            Ok(m)
        } else {
            Err(CoreError::RobotModel(format!(
                "the robot's total mass must be positive and finite [kg], got {m}"
            )))
        }
    }
}

/// Whole-robot CoM in the base frame [m] for each row of 12 joint angles [rad].
pub fn center_of_mass_batch(
    robot: &Quadruped,
    mass: &MassDistribution,
    q: &[[f64; 12]],
) -> CoreResult<Vec<Vec3>> {
    let total = mass.total()?;
    let legs = robot.legs();
    Ok(q.iter()
        .map(|row| {
            let mut sum = scale(mass.base_com, mass.base_mass);
            for (l, leg) in legs.iter().enumerate() {
                let f = leg.link_frames([row[3 * l], row[3 * l + 1], row[3 * l + 2]]);
                for k in 0..3 {
                    let com = add(f.pos[k], mat_vec(&f.rot[k], mass.link_com[l][k]));
                    sum = add(sum, scale(com, mass.link_mass[l][k]));
                }
            }
            scale(sum, 1.0 / total)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::quadruped::tests::{littledog, STANCE_Q};

    #[test]
    fn point_masses_at_the_feet_give_the_feet_centroid() {
        let robot = littledog();
        let foot = |l: usize| robot.legs()[l].params().foot;
        let mass = MassDistribution {
            link_mass: [[0.0, 0.0, 1.0]; 4],
            link_com: std::array::from_fn(|l| [[0.0; 3], [0.0; 3], foot(l)]),
            base_mass: 0.0,
            base_com: [0.0; 3],
        };
        let com = center_of_mass_batch(&robot, &mass, &[STANCE_Q]).unwrap()[0];
        let feet = robot.fk_base(&STANCE_Q);
        for a in 0..3 {
            let mean = feet.iter().map(|f| f[a]).sum::<f64>() / 4.0;
            assert!((com[a] - mean).abs() < 1e-12);
        }
        let none = MassDistribution {
            link_mass: [[0.0; 3]; 4],
            ..mass
        };
        assert!(center_of_mass_batch(&robot, &none, &[STANCE_Q]).is_err());
    }
}

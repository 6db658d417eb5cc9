//! The trunk's height and tilt changed until four feet are within reach
//! (Zucker 2011, §3.2, the virtual force without its horizontal part).
//!
//! The initial trajectory keeps the trunk's x–y where the ZMP puts it at
//! touchdown; where the landing stance is then out of reach, the trunk is
//! lowered and tilted instead (vertical motion and rotation barely move the
//! ZMP, §5.2 footnote 3). Each round aims every foot 2 mm beyond its target
//! (away from its hip, for slack), solves IK, and moves the trunk by the
//! error between the aim and what the legs reach: Δz = α·Σe_z, then
//! ω = β·Σ(f′ − x) × e about the moved trunk.

use crate::kinematics::math::{
    add, cross, mat_mul, mat_t_vec, mat_vec, norm, scale, sub, Mat3, Vec3,
};
use crate::kinematics::Quadruped;

/// How far past each foot the legs aim [m], away from their hips.
const AIM_BEYOND: f64 = 0.002;
/// α: height change per metre of summed vertical error.
const HEIGHT_GAIN: f64 = 0.5;
/// β: rotation [rad] per m² of summed moment of the errors.
const TILT_GAIN: f64 = 2.0;

/// The trunk (position [m], orientation) moved until every foot of `feet`
/// (world [m]) is reached, or after `iterations` rounds; `None` when every
/// foot is reached from the start. `hips` are the legs' hip anchors in the
/// base frame [m].
pub fn reach_by_height_and_tilt(
    robot: &Quadruped,
    hips: &[Vec3; 4],
    feet: &[Vec3; 4],
    base_pos: Vec3,
    rotation: Mat3,
    iterations: usize,
) -> Option<(Vec3, Mat3)> {
    let mut x = base_pos;
    let mut rot = rotation;
    let mut changed = false;
    for _ in 0..iterations {
        let aim_b: [Vec3; 4] = std::array::from_fn(|l| {
            let foot_b = mat_t_vec(&rot, sub(feet[l], x));
            let out = sub(foot_b, hips[l]);
            add(foot_b, scale(out, AIM_BEYOND / norm(out)))
        });
        let solved = robot.ik_base(&aim_b);
        if solved.iter().all(|r| r.reachable) {
            break;
        }
        let mut q = [0.0; 12];
        for (l, r) in solved.iter().enumerate() {
            q[3 * l..3 * l + 3].copy_from_slice(&r.q);
        }
        let reached_b = robot.fk_base(&q);
        let reach: [Vec3; 4] = std::array::from_fn(|l| add(x, mat_vec(&rot, reached_b[l])));
        let error: [Vec3; 4] =
            std::array::from_fn(|l| sub(add(x, mat_vec(&rot, aim_b[l])), reach[l]));
        x[2] += HEIGHT_GAIN * error.iter().map(|e| e[2]).sum::<f64>();
        let mut omega = [0.0; 3];
        for l in 0..4 {
            omega = add(omega, cross(sub(reach[l], x), error[l]));
        }
        rot = mat_mul(&rotation_vector(scale(omega, TILT_GAIN)), &rot);
        changed = true;
    }
    changed.then_some((x, rot))
}

/// The rotation matrix of the rotation vector `omega` [rad] (Rodrigues).
fn rotation_vector(omega: Vec3) -> Mat3 {
    let angle = norm(omega);
    if angle < 1e-12 {
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    }
    crate::kinematics::math::axis_angle(scale(omega, 1.0 / angle), angle)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{littledog, NOMINAL_Q};

    const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    fn hips(robot: &Quadruped) -> [Vec3; 4] {
        std::array::from_fn(|l| robot.legs()[l].params().body_pos[0])
    }

    #[test]
    fn reachable_feet_leave_the_trunk_alone() {
        let robot = littledog();
        let x = [0.0, 0.0, 0.2];
        let feet = robot.fk_base(&NOMINAL_Q).map(|f| add(f, x));
        assert!(reach_by_height_and_tilt(&robot, &hips(&robot), &feet, x, IDENTITY, 30).is_none());
    }

    #[test]
    fn a_trunk_too_high_is_lowered_until_the_feet_are_reached() {
        let robot = littledog();
        let feet = robot.fk_base(&NOMINAL_Q);
        // Raised 8 cm over feet the nominal legs reach from the origin.
        let (x, rot) =
            reach_by_height_and_tilt(&robot, &hips(&robot), &feet, [0.0, 0.0, 0.08], IDENTITY, 60)
                .expect("the feet are out of reach at first");
        assert!(x[2] < 0.08, "lowered: z = {}", x[2]);
        let aim: [Vec3; 4] = std::array::from_fn(|l| mat_t_vec(&rot, sub(feet[l], x)));
        assert!(robot.ik_base(&aim).iter().all(|r| r.reachable));
    }
}

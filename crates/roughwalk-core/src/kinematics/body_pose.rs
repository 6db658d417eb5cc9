//! Gradient steps on the trunk pose (x, R) that leave the feet where they
//! are (Zucker 2011, §3.2–3.4, used iteratively by the pose-certificate
//! search of §4.4): toward kinematic reachability, away from a terrain
//! collision, and toward a support polygon that holds the centre of mass.
//!
//! Every step returns the new pose x ← x + Δx, R ← exp([ω]×)·R, with Δx and
//! ω in the world frame, and the value of the step's objective before it.

use crate::error::{CoreError, CoreResult};
use crate::kinematics::leg::{LegChain, LinkFrames};
use crate::kinematics::math::{
    add, cross, exp_so3, inverse, mat_mul, mat_sub, mat_t_vec, mat_vec, norm, scale, skew, sub,
    transpose, Mat3, Quat, Vec3, IDENTITY,
};
use crate::kinematics::quadruped::{BodyPose, Quadruped};
use crate::kinematics::support::{closest_point_with_margin, support_polygon_margin, Vec2};

/// One step of a body-pose routine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPoseStep {
    /// Trunk position after the step [m].
    pub base_pos: Vec3,
    /// Trunk orientation (w, x, y, z) after the step.
    pub base_quat: Quat,
    /// Translation applied, world frame [m].
    pub delta_x: Vec3,
    /// Rotation applied, world frame, as a rotation vector [rad].
    pub omega: Vec3,
    /// The routine's objective before the step (its doc says which) [m].
    pub value_before: f64,
}

/// A point on the robot that collides: on the trunk, or on link `link`
/// (0 hip, 1 thigh, 2 shank) of leg `leg` (canonical order LF, RF, LH, RH).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CollisionPoint {
    /// A point fixed on the trunk, in the base frame [m].
    Trunk(Vec3),
    /// A point fixed on a leg link, in that link's frame [m].
    Leg {
        /// Leg index 0..4.
        leg: usize,
        /// Link index 0..3.
        link: usize,
        /// The point in the link's frame [m].
        point: Vec3,
    },
}

/// How a point on the robot moves with the trunk when IK holds the feet
/// still (Zucker 2011, §3.4): dp = J_x·dx + J_R·ω.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointPoseJacobians {
    /// The point in the world [m].
    pub p: Vec3,
    /// J_p(x) = dp/dx [m/m].
    pub j_x: Mat3,
    /// J_p(R) = dp/dω [m/rad].
    pub j_r: Mat3,
}

fn check_step_size(name: &str, v: f64) -> CoreResult<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(CoreError::InvalidArgument(format!(
            "step size {name} = {v} must be finite and ≥ 0"
        )))
    }
}

fn check_points(name: &str, points: &[Vec3]) -> CoreResult<()> {
    match points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
        Some(i) => Err(CoreError::InvalidArgument(format!(
            "{name}[{i}] = {:?} is not finite",
            points[i]
        ))),
        None => Ok(()),
    }
}

fn finish(pose: &BodyPose, delta_x: Vec3, omega: Vec3, value_before: f64) -> BodyPoseStep {
    let moved = BodyPose {
        x: add(pose.x, delta_x),
        r: mat_mul(&exp_so3(omega), &pose.r),
    };
    BodyPoseStep {
        base_pos: moved.x,
        base_quat: moved.quat(),
        delta_x,
        omega,
        value_before,
    }
}

/// Reachability virtual-force step (Zucker 2011, §3.2).
///
/// With q_i the closest reachable IK of foot i at the current pose, f'_i its
/// foot and e_i = f_i − f'_i: Δx = α Σ e_i, ω = β Σ (f'_i − x) × e_i.
/// `alpha` [1] and `beta` [1/m²·rad] are step sizes. `value_before` is
/// Σ |e_i| [m]. Also returns the 12 IK joint angles [rad] at the old pose and
/// which feet they reach.
pub fn reachability_step(
    robot: &Quadruped,
    feet_world: &[Vec3; 4],
    base_pos: Vec3,
    base_quat: Quat,
    alpha: f64,
    beta: f64,
) -> CoreResult<(BodyPoseStep, [f64; 12], [bool; 4])> {
    check_step_size("alpha", alpha)?;
    check_step_size("beta", beta)?;
    check_points("feet", feet_world)?;
    let pose = BodyPose::new(base_pos, base_quat)?;
    let results = robot.ik_pose(&pose, feet_world);
    let (mut dx, mut omega, mut total) = ([0.0; 3], [0.0; 3], 0.0);
    let mut q = [0.0; 12];
    for (i, (leg, r)) in robot.legs().iter().zip(&results).enumerate() {
        q[3 * i..3 * i + 3].copy_from_slice(&r.q);
        let reached = pose.to_world(leg.fk(r.q));
        let e = sub(feet_world[i], reached);
        total += norm(e);
        dx = add(dx, e);
        omega = add(omega, cross(sub(reached, pose.x), e));
    }
    let step = finish(&pose, scale(dx, alpha), scale(omega, beta), total);
    Ok((step, q, results.map(|r| r.reachable)))
}

/// (J_f⁻¹), or a slightly damped least-squares inverse at a singular foot Jacobian.
fn foot_jacobian_inverse(j: &Mat3) -> Mat3 {
    if let Some(inv) = inverse(j) {
        return inv;
    }
    let jt = transpose(j);
    let mut jtj = mat_mul(&jt, j);
    let damping = 1e-10 * (jtj[0][0] + jtj[1][1] + jtj[2][2]).max(1e-300);
    for (k, row) in jtj.iter_mut().enumerate() {
        row[k] += damping;
    }
    inverse(&jtj).map_or([[0.0; 3]; 3], |m| mat_mul(&m, &jt))
}

/// J_p(x) and J_p(R) of a point on the robot with the feet held by IK
/// (Zucker 2011, §3.4):
///
/// J_p(x) = I − R·J_pB·J_fB⁻¹·Rᵀ,  J_p(R) = R·(J_pB·J_fB⁻¹·[f_B]× − [p_B]×)·Rᵀ,
///
/// where J_pB = ∂p_B/∂q and J_fB = ∂f_B/∂q are the leg's base-frame
/// Jacobians at q = IK_B(f_B), f_B = Rᵀ(f_W − x). For a trunk point J_pB = 0.
/// The leg's foot must be reachable for "feet held" to hold; otherwise the
/// Jacobians describe the IK's closest-reachable solution, and at a singular
/// J_fB a damped inverse is used.
pub fn point_pose_jacobians(
    robot: &Quadruped,
    feet_world: &[Vec3; 4],
    base_pos: Vec3,
    base_quat: Quat,
    point: CollisionPoint,
) -> CoreResult<PointPoseJacobians> {
    check_points("feet", feet_world)?;
    let pose = BodyPose::new(base_pos, base_quat)?;
    match point {
        CollisionPoint::Trunk(p_b) => {
            check_points("point", &[p_b])?;
            Ok(trunk_point_jacobians(&pose, p_b))
        }
        CollisionPoint::Leg { leg, link, point } => {
            check_points("point", &[point])?;
            let chain = leg_chain(robot, leg)?;
            let f_b = pose.to_body(feet_world[leg]);
            let (_, frames) = chain.ik_with_frames(f_b, None);
            leg_point_jacobians(chain, &pose, f_b, &frames, link, point)
        }
    }
}

/// [`point_pose_jacobians`] at the trunk pose `pose` from the legs' link
/// frames `frames` at their IK solutions for the feet `feet_world` [m]: the
/// pose-certificate search holds those from its round's IK and need not
/// solve it again. No checks of finiteness.
pub fn point_pose_jacobians_at(
    robot: &Quadruped,
    pose: &BodyPose,
    feet_world: &[Vec3; 4],
    frames: &[LinkFrames; 4],
    point: CollisionPoint,
) -> CoreResult<PointPoseJacobians> {
    match point {
        CollisionPoint::Trunk(p_b) => Ok(trunk_point_jacobians(pose, p_b)),
        CollisionPoint::Leg { leg, link, point } => {
            let chain = leg_chain(robot, leg)?;
            let f_b = pose.to_body(feet_world[leg]);
            leg_point_jacobians(chain, pose, f_b, &frames[leg], link, point)
        }
    }
}

fn leg_chain(robot: &Quadruped, leg: usize) -> CoreResult<&LegChain> {
    robot.legs().get(leg).ok_or_else(|| {
        CoreError::InvalidArgument(format!(
            "leg index {leg} out of range; valid: 0..4 (LF, RF, LH, RH)"
        ))
    })
}

/// A trunk point moves rigidly: J_p(x) = I, J_p(R) = −[R·p_B]×.
fn trunk_point_jacobians(pose: &BodyPose, p_b: Vec3) -> PointPoseJacobians {
    PointPoseJacobians {
        p: pose.to_world(p_b),
        j_x: IDENTITY,
        j_r: scale_mat(&skew(mat_vec(&pose.r, p_b)), -1.0),
    }
}

/// A point on link `link` of `chain`, whose link frames at IK_B(f_B) are `frames`.
fn leg_point_jacobians(
    chain: &LegChain,
    pose: &BodyPose,
    f_b: Vec3,
    frames: &LinkFrames,
    link: usize,
    point: Vec3,
) -> CoreResult<PointPoseJacobians> {
    let r = &pose.r;
    let rt = transpose(r);
    let (p_b, j_p) = chain.point_jacobian_at(frames, link, point)?;
    let m = mat_mul(&j_p, &foot_jacobian_inverse(&chain.jacobian_at(frames)));
    let j_x = mat_sub(&IDENTITY, &mat_mul(&mat_mul(r, &m), &rt));
    let inner = mat_sub(&mat_mul(&m, &skew(f_b)), &skew(p_b));
    let j_r = mat_mul(&mat_mul(r, &inner), &rt);
    Ok(PointPoseJacobians {
        p: pose.to_world(p_b),
        j_x,
        j_r,
    })
}

fn scale_mat(m: &Mat3, s: f64) -> Mat3 {
    m.map(|row| row.map(|v| v * s))
}

/// Obstacle-avoidance step (Zucker 2011, §3.4).
///
/// The caller supplies the colliding point, its signed distance `distance`
/// [m] to the terrain and the distance gradient `gradient` g = ∇d at it
/// (world frame, usually unit). The step is gradient descent on the
/// clearance penalty c = ½·max(0, clearance − d)², whose gradient with
/// respect to the trunk pose is −(clearance − d)·Jᵀg; that is the paper's
/// Δx = α·J_p(x)ᵀ·g, ω = β·J_p(R)ᵀ·g with g scaled by the penetration
/// (clearance − d), so the step vanishes once the point is clear.
/// `alpha` [1/m] and `beta` [rad/m³] are step sizes; `value_before` is `distance`.
pub fn obstacle_avoidance_step(
    robot: &Quadruped,
    feet_world: &[Vec3; 4],
    base_pos: Vec3,
    base_quat: Quat,
    point: CollisionPoint,
    distance: f64,
    gradient: Vec3,
    clearance: f64,
    alpha: f64,
    beta: f64,
) -> CoreResult<(BodyPoseStep, PointPoseJacobians)> {
    check_step_size("alpha", alpha)?;
    check_step_size("beta", beta)?;
    check_points("gradient", &[gradient])?;
    if !(distance.is_finite() && clearance.is_finite()) {
        return Err(CoreError::InvalidArgument(format!(
            "distance = {distance} and clearance = {clearance} must be finite"
        )));
    }
    let pose = BodyPose::new(base_pos, base_quat)?;
    let jac = point_pose_jacobians(robot, feet_world, base_pos, base_quat, point)?;
    let penetration = (clearance - distance).max(0.0);
    let dx = scale(mat_t_vec(&jac.j_x, gradient), alpha * penetration);
    let omega = scale(mat_t_vec(&jac.j_r, gradient), beta * penetration);
    Ok((finish(&pose, dx, omega, distance), jac))
}

/// Centre-of-mass support step (Zucker 2011, §4.4: "a horizontal increment
/// … nudges the body back into the triangle").
///
/// The CoM is x + R·`com_offset` (a point fixed in the base frame [m]). When
/// its x–y margin to the convex hull of the stance feet is below `margin`
/// [m], the trunk moves horizontally toward the closest point that keeps
/// `margin` from every edge (the Chebyshev centre, the incircle centre for
/// three feet, when none does), by at most `max_step` [m]. `value_before` is
/// the CoM's margin before the step [m] (see [`support_polygon_margin`]).
pub fn com_support_step(
    stance_feet_world: &[Vec3],
    base_pos: Vec3,
    base_quat: Quat,
    com_offset: Vec3,
    margin: f64,
    max_step: f64,
) -> CoreResult<BodyPoseStep> {
    if stance_feet_world.is_empty() {
        return Err(CoreError::InvalidArgument(
            "com_support_step needs at least one stance foot".into(),
        ));
    }
    check_points("stance feet", stance_feet_world)?;
    check_points("com_offset", &[com_offset])?;
    if !(margin.is_finite() && max_step.is_finite() && max_step >= 0.0) {
        return Err(CoreError::InvalidArgument(format!(
            "margin = {margin} must be finite and max_step = {max_step} finite and ≥ 0"
        )));
    }
    let pose = BodyPose::new(base_pos, base_quat)?;
    let com = pose.to_world(com_offset);
    let c: Vec2 = [com[0], com[1]];
    let feet: Vec<Vec2> = stance_feet_world.iter().map(|f| [f[0], f[1]]).collect();
    let before = support_polygon_margin(c, &feet);
    let mut dx = [0.0; 3];
    if before < margin {
        let target = closest_point_with_margin(c, &feet, margin);
        let d = [target[0] - c[0], target[1] - c[1], 0.0];
        let len = norm(d);
        dx = if len > max_step {
            scale(d, max_step / len)
        } else {
            d
        };
    }
    Ok(finish(&pose, dx, [0.0; 3], before))
}

/// The point's first-order motion for a trunk step: dp = J_x·dx + J_R·ω [m].
pub fn predicted_motion(jac: &PointPoseJacobians, dx: Vec3, omega: Vec3) -> Vec3 {
    add(mat_vec(&jac.j_x, dx), mat_vec(&jac.j_r, omega))
}

#[cfg(test)]
// Exact float equality is what these tests mean where they use it.
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use crate::kinematics::leg::tests::assert_mat_close;
    use crate::kinematics::math::{dot, from_columns, quat_to_mat};
    use crate::kinematics::quadruped::tests::{littledog, STANCE_Q};

    const POS: Vec3 = [0.1, 0.05, 0.2];
    const QUAT: Quat = [0.98, 0.05, -0.1, 0.15];

    fn stance_feet(robot: &Quadruped) -> [Vec3; 4] {
        robot.foot_positions_world(POS, QUAT, &STANCE_Q).unwrap()
    }

    /// Where the point is after moving the trunk and re-solving the IK with the feet fixed.
    fn point_after(
        robot: &Quadruped,
        feet: &[Vec3; 4],
        pose: &BodyPose,
        point: CollisionPoint,
    ) -> Vec3 {
        let quat = pose.quat();
        point_pose_jacobians(robot, feet, pose.x, quat, point)
            .unwrap()
            .p
    }

    fn moved(dx: Vec3, omega: Vec3) -> BodyPose {
        let pose = BodyPose::new(POS, QUAT).unwrap();
        BodyPose {
            x: add(pose.x, dx),
            r: mat_mul(&exp_so3(omega), &pose.r),
        }
    }

    #[test]
    fn pose_jacobians_match_central_differences() {
        let robot = littledog();
        let feet = stance_feet(&robot);
        let points = [
            CollisionPoint::Trunk([0.1, -0.05, 0.02]),
            CollisionPoint::Leg {
                leg: 0,
                link: 0,
                point: [0.01, 0.0, -0.01],
            },
            CollisionPoint::Leg {
                leg: 1,
                link: 1,
                point: [0.0, 0.0, -0.04],
            },
            CollisionPoint::Leg {
                leg: 2,
                link: 2,
                point: [0.01, 0.0, -0.05],
            },
            CollisionPoint::Leg {
                leg: 3,
                link: 2,
                point: [0.0, 0.01, -0.09],
            },
        ];
        let h = 1e-6;
        let pose = BodyPose::new(POS, QUAT).unwrap();
        // The certificate's variant, from link frames of the IK it already solved.
        let frames: [LinkFrames; 4] = std::array::from_fn(|i| {
            let q = robot.legs()[i].ik(pose.to_body(feet[i]), None).q;
            robot.legs()[i].link_frames(q)
        });
        for point in points {
            let jac = point_pose_jacobians(&robot, &feet, POS, QUAT, point).unwrap();
            let at = point_pose_jacobians_at(&robot, &pose, &feet, &frames, point).unwrap();
            assert!(norm(sub(at.p, jac.p)) < 1e-15);
            assert_mat_close(&at.j_x, &jac.j_x, 1e-14);
            assert_mat_close(&at.j_r, &jac.j_r, 1e-14);
            let column = |k: usize, rotational: bool| {
                let mut e = [0.0; 3];
                e[k] = h;
                let (plus, minus) = if rotational {
                    (moved([0.0; 3], e), moved([0.0; 3], scale(e, -1.0)))
                } else {
                    (moved(e, [0.0; 3]), moved(scale(e, -1.0), [0.0; 3]))
                };
                let d = sub(
                    point_after(&robot, &feet, &plus, point),
                    point_after(&robot, &feet, &minus, point),
                );
                scale(d, 0.5 / h)
            };
            let fd_x = from_columns(column(0, false), column(1, false), column(2, false));
            let fd_r = from_columns(column(0, true), column(1, true), column(2, true));
            assert_mat_close(&jac.j_x, &fd_x, 1e-6);
            assert_mat_close(&jac.j_r, &fd_r, 1e-6);
        }
    }

    #[test]
    fn obstacle_step_moves_the_point_along_the_gradient_with_feet_fixed() {
        let robot = littledog();
        let feet = stance_feet(&robot);
        let point = CollisionPoint::Leg {
            leg: 0,
            link: 2,
            point: [0.0, 0.0, -0.05],
        };
        let g = [0.3, 0.1, 0.95];
        let (step, jac) =
            obstacle_avoidance_step(&robot, &feet, POS, QUAT, point, -0.004, g, 0.0, 0.5, 5.0)
                .unwrap();
        assert!((step.value_before + 0.004).abs() < 1e-15);
        let new_pose = BodyPose::new(step.base_pos, step.base_quat).unwrap();
        let p_new = point_after(&robot, &feet, &new_pose, point);
        let actual = sub(p_new, jac.p);
        let predicted = predicted_motion(&jac, step.delta_x, step.omega);
        assert!(dot(actual, g) > 0.0);
        assert!(
            norm(sub(actual, predicted)) < 0.05 * norm(predicted),
            "{actual:?} vs {predicted:?}"
        );
        // The feet stay put: IK at the new pose reaches the same feet.
        let (q, ok) = robot
            .ik_world(step.base_pos, step.base_quat, &feet)
            .unwrap();
        assert!(ok.iter().all(|&r| r));
        let again = robot
            .foot_positions_world(step.base_pos, step.base_quat, &q)
            .unwrap();
        assert!((0..4).all(|i| norm(sub(again[i], feet[i])) < 1e-9));
        // A clear point does not move the trunk.
        let (clear, _) =
            obstacle_avoidance_step(&robot, &feet, POS, QUAT, point, 0.02, g, 0.01, 0.5, 5.0)
                .unwrap();
        assert_eq!((clear.delta_x, clear.omega), ([0.0; 3], [0.0; 3]));
    }

    #[test]
    fn reachability_steps_reduce_the_foot_error() {
        let robot = littledog();
        let feet = stance_feet(&robot);
        // Lift and tilt the trunk beyond the legs' reach.
        let mut pos = add(POS, [0.03, -0.02, 0.12]);
        let mut quat = moved([0.0; 3], [0.1, 0.2, 0.0]).quat();
        let mut errors = vec![];
        for _ in 0..15 {
            let (step, _, _) = reachability_step(&robot, &feet, pos, quat, 0.2, 2.0).unwrap();
            errors.push(step.value_before);
            (pos, quat) = (step.base_pos, step.base_quat);
        }
        assert!(errors[0] > 0.05, "{errors:?}");
        assert!(
            errors.windows(2).all(|w| w[1] < w[0] || w[1] < 1e-9),
            "{errors:?}"
        );
        assert!(errors[errors.len() - 1] < 0.1 * errors[0], "{errors:?}");
    }

    #[test]
    fn com_step_moves_the_com_into_the_triangle() {
        let feet = [[0.0, 0.0, 0.0], [0.3, 0.0, 0.01], [0.0, 0.4, -0.02]];
        let offset = [0.02, 0.0, -0.01];
        let r = quat_to_mat([1.0, 0.0, 0.0, 0.0]);
        let mut pos = [0.5, -0.2, 0.2];
        let mut margins = vec![];
        for _ in 0..20 {
            let step =
                com_support_step(&feet, pos, [1.0, 0.0, 0.0, 0.0], offset, 0.05, 0.1).unwrap();
            assert!(norm(step.delta_x) <= 0.1 + 1e-15 && step.delta_x[2] == 0.0);
            margins.push(step.value_before);
            pos = step.base_pos;
        }
        let com = add(pos, mat_vec(&r, offset));
        let feet2: Vec<Vec2> = feet.iter().map(|f| [f[0], f[1]]).collect();
        assert!(
            (support_polygon_margin([com[0], com[1]], &feet2) - 0.05).abs() < 1e-12,
            "{margins:?}"
        );
        assert!(margins[0] < 0.0 && margins.windows(2).all(|w| w[1] >= w[0] - 1e-15));
        assert!(com_support_step(&[], pos, [1.0, 0.0, 0.0, 0.0], offset, 0.05, 0.1).is_err());
    }
}

//! The robot's capsules against the terrain's signed distance field
//! (Zucker 2011, §3.3): the least clearance of the body, feet excluded, and
//! where it is attained, for the certificate's obstacle-avoidance step (§3.4).

use crate::error::{CoreError, CoreResult};
use crate::kinematics::body_pose::CollisionPoint;
use crate::kinematics::leg::LinkFrames;
use crate::kinematics::math::{add, mat_vec, norm, scale, sub, Vec3};
use crate::kinematics::quadruped::BodyPose;
use crate::sdf::SignedDistanceField;

/// Bound on the gradient norm of a trilinear interpolant of a distance
/// field: each component is an average of finite differences along one
/// axis, each at most 1, so |∇d| ≤ √3. Used to skip samples that cannot be
/// closer than the cut-off.
const LIPSCHITZ: f64 = 1.732_050_808_568_877_3;

/// The field's value [m] at `p` without its gradient (the trilinear value of
/// the lattice cell, or the exact fall-back outside the lattice): capsule
/// marching needs only values, and the gradient only at the minimum.
// Measured: LLVM left these out of the capsule-marching loop, ~6 % of a
// certificate's instructions on the rocky probe.
#[allow(clippy::inline_always)]
#[inline(always)]
fn distance(sdf: &SignedDistanceField, p: Vec3) -> f64 {
    match sdf.grid().value(p) {
        Some(v) => v,
        None => sdf.distance_and_gradient(p).0,
    }
}

/// A capsule fixed to the trunk or to a leg link (a sphere when a = b).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capsule {
    /// Canonical leg (0..4), or `None` for the trunk.
    pub leg: Option<usize>,
    /// Link of the leg (0 hip, 1 thigh, 2 shank); ignored for the trunk.
    pub link: usize,
    /// Segment start, in the link's frame (base frame for the trunk) [m].
    pub a: Vec3,
    /// Segment end [m].
    pub b: Vec3,
    /// Radius [m].
    pub radius: f64,
}

/// The closest approach of the robot to the terrain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearance {
    /// Signed distance of the capsule's surface to the terrain [m].
    pub distance: f64,
    /// The point on the capsule's axis where it is attained, in its link's frame.
    pub point: CollisionPoint,
    /// That point in the world [m].
    pub world: Vec3,
    /// The distance field's gradient there (unit-ish, away from the terrain).
    pub gradient: Vec3,
    /// Which capsule.
    pub capsule: usize,
}

/// Capsules that bound the robot's body, legs and trunk, but not its feet.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionModel {
    capsules: Vec<Capsule>,
}

impl CollisionModel {
    /// Checks the capsules (finite, radius ≥ 0, leg < 4, link < 3).
    pub fn new(capsules: Vec<Capsule>) -> CoreResult<Self> {
        for (k, c) in capsules.iter().enumerate() {
            let finite = c.a.iter().chain(&c.b).all(|v| v.is_finite());
            if !(finite && c.radius.is_finite() && c.radius >= 0.0) {
                return Err(CoreError::RobotModel(format!(
                    "collision capsule {k} must have finite ends and a radius >= 0, got {c:?}"
                )));
            }
            if c.leg.is_some_and(|leg| leg > 3) || (c.leg.is_some() && c.link > 2) {
                return Err(CoreError::RobotModel(format!(
                    "collision capsule {k}: leg {:?} / link {} out of range (legs 0..4, links 0..3)",
                    c.leg, c.link
                )));
            }
        }
        Ok(Self { capsules })
    }

    /// The capsules.
    pub fn capsules(&self) -> &[Capsule] {
        &self.capsules
    }

    /// World end points of capsule `k` [m].
    #[inline]
    pub fn world_segment(
        &self,
        k: usize,
        pose: &BodyPose,
        frames: &[LinkFrames; 4],
    ) -> (Vec3, Vec3) {
        let c = &self.capsules[k];
        let to_base = |p: Vec3| match c.leg {
            None => p,
            Some(leg) => {
                let f = &frames[leg];
                add(f.pos[c.link], mat_vec(&f.rot[c.link], p))
            }
        };
        (pose.to_world(to_base(c.a)), pose.to_world(to_base(c.b)))
    }

    /// The least clearance of any capsule, if it is below `cutoff` [m]
    /// (`None` means every capsule is at least `cutoff` from the terrain).
    ///
    /// Each capsule's axis is sampled at spacing `spacing` [m] where it is
    /// near the cut-off, and skipped ahead where the field proves it cannot
    /// be (a sample at clearance v rules out anything within
    /// (v − cutoff)/√3 of it), so a robot far from the terrain costs one
    /// query per capsule.
    pub fn closest_below(
        &self,
        sdf: &SignedDistanceField,
        pose: &BodyPose,
        frames: &[LinkFrames; 4],
        cutoff: f64,
        spacing: f64,
    ) -> Option<Clearance> {
        // (distance, capsule, fraction along it, world point)
        let mut best: Option<(f64, usize, f64, Vec3)> = None;
        let mut bound = cutoff;
        for (k, c) in self.capsules.iter().enumerate() {
            let (wa, wb) = self.world_segment(k, pose, frames);
            let ab = sub(wb, wa);
            let length = norm(ab);
            let d_mid = distance(sdf, add(wa, scale(ab, 0.5)));
            if d_mid - c.radius - LIPSCHITZ * 0.5 * length >= bound {
                continue;
            }
            let mut t = 0.0;
            loop {
                let f = if length > 0.0 { t / length } else { 0.0 };
                let p = add(wa, scale(ab, f));
                let v = distance(sdf, p) - c.radius;
                if v < bound {
                    bound = v;
                    best = Some((v, k, f, p));
                }
                if t >= length {
                    break;
                }
                t = (t + spacing.max((v - bound) / LIPSCHITZ)).min(length);
            }
        }
        best.map(|(v, k, f, p)| {
            let c = &self.capsules[k];
            let local = add(c.a, scale(sub(c.b, c.a), f));
            Clearance {
                distance: v,
                point: match c.leg {
                    None => CollisionPoint::Trunk(local),
                    Some(leg) => CollisionPoint::Leg {
                        leg,
                        link: c.link,
                        point: local,
                    },
                },
                world: p,
                gradient: sdf.distance_and_gradient(p).1,
                capsule: k,
            }
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::heightfield::HeightField;
    use crate::kinematics::math::IDENTITY;
    use crate::kinematics::quadruped::leg_q;
    use crate::kinematics::quadruped::tests::{littledog, STANCE_Q};
    pub use crate::testing::littledog_capsules;

    /// The SDF of a height field z(x, y) on [0, 0.6] × [−0.3, 0.3] at 5 mm.
    pub fn sdf_of(height: impl Fn(f64, f64) -> f64) -> (HeightField, SignedDistanceField) {
        crate::testing::terrain(0.6, height, 0.1, 0.3)
    }

    /// Brute force: every capsule sampled every 0.5 mm.
    fn brute_force(
        model: &CollisionModel,
        sdf: &SignedDistanceField,
        pose: &BodyPose,
        frames: &[LinkFrames; 4],
    ) -> f64 {
        let mut best = f64::INFINITY;
        for (k, c) in model.capsules().iter().enumerate() {
            let (a, b) = model.world_segment(k, pose, frames);
            let n = (norm(sub(b, a)) / 0.0005).ceil() as usize + 1;
            for s in 0..=n {
                let p = add(a, scale(sub(b, a), s as f64 / n as f64));
                best = best.min(sdf.distance_and_gradient(p).0 - c.radius);
            }
        }
        best
    }

    #[test]
    fn footstep_value_only_queries_match_the_field() {
        let (_, sdf) = sdf_of(|x, y| 0.04 * (20.0 * x).sin() * (15.0 * y).cos());
        let mut worst: f64 = 0.0;
        for k in 0..2000 {
            let f = f64::from(k);
            // Inside the lattice and, for some, above or beside it (fall-back).
            let p = [
                (f * 0.618_033_9).fract() * 0.7 - 0.05,
                (f * 0.414_213_5).fract() * 0.7 - 0.35,
                (f * 0.732_050_8).fract() * 0.6 - 0.1,
            ];
            worst = worst.max((distance(&sdf, p) - sdf.distance_and_gradient(p).0).abs());
        }
        assert!(worst < 1e-12, "{worst}");
    }

    #[test]
    fn footstep_closest_clearance_matches_dense_sampling() {
        let (_, sdf) = sdf_of(|x, y| 0.04 * (20.0 * x).sin() * (15.0 * y).cos());
        let robot = littledog();
        let model = littledog_capsules();
        let frames: [LinkFrames; 4] =
            std::array::from_fn(|i| robot.legs()[i].link_frames(leg_q(&STANCE_Q, i)));
        for (k, z) in [0.2, 0.16, 0.13, 0.1].into_iter().enumerate() {
            let pose = BodyPose {
                x: [0.3 + 0.01 * k as f64, 0.02, z],
                r: IDENTITY,
            };
            let truth = brute_force(&model, &sdf, &pose, &frames);
            match model.closest_below(&sdf, &pose, &frames, 0.02, 0.0005) {
                Some(c) => {
                    assert!((c.distance - truth).abs() < 2e-5, "{c:?} vs {truth}");
                    let (d, _) = sdf.distance_and_gradient(c.world);
                    let r = model.capsules()[c.capsule].radius;
                    assert!((d - r - c.distance).abs() < 1e-12);
                }
                None => assert!(truth >= 0.02 - 1e-9, "missed a clearance of {truth}"),
            }
        }
    }
}

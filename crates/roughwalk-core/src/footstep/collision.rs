//! The robot's capsules against the terrain's signed distance field
//! (Zucker 2011, §3.3): the least clearance of the body, feet excluded, and
//! where it is attained, for the certificate's obstacle-avoidance step (§3.4).

use crate::error::{CoreError, CoreResult};
use crate::kinematics::body_pose::CollisionPoint;
use crate::kinematics::leg::LinkFrames;
use crate::kinematics::math::{add, mat_vec, norm, scale, sub, Vec3};
use crate::kinematics::quadruped::BodyPose;
use crate::sdf::SignedDistanceField;

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

/// The part [t0, t1] (arc lengths [m] from `a` along the unit direction
/// `u`) of a segment of length `length` that lies in the closed box
/// [lo, hi], or None if it misses it (slab clipping).
fn clip_to_box(a: Vec3, u: Vec3, length: f64, lo: Vec3, hi: Vec3) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, length);
    for k in 0..3 {
        if u[k] == 0.0 {
            if a[k] < lo[k] || a[k] > hi[k] {
                return None;
            }
        } else {
            let (ta, tb) = ((lo[k] - a[k]) / u[k], (hi[k] - a[k]) / u[k]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// A stretch of a capsule's axis on which the field is one Lipschitz
/// function: the lattice's interpolant, or the exact fall-back beyond it.
#[derive(Clone, Copy)]
struct Piece {
    /// Arc lengths [m] along the axis.
    t0: f64,
    t1: f64,
    /// Bound on |d(field)/dt| on it [m/m].
    lipschitz: f64,
    /// Whether the lattice's interpolant applies (else the exact distance).
    lattice: bool,
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
    /// (`None` means every capsule is at least `cutoff` − `tolerance` from
    /// the terrain), up to `tolerance` [m] (> 0).
    ///
    /// The contract, against a sampling of the same field as fine as one
    /// likes: `None` means no point of any capsule's axis is closer than
    /// `cutoff − tolerance`; `Some(c)` means `c.distance` is attained at
    /// `c.world` and no point is closer than `c.distance − tolerance`.
    ///
    /// Each capsule's axis is sphere-traced with the field's Lipschitz
    /// bound L along it: the lattice's measured axis slopes
    /// ([`crate::sdf::DistanceGrid::directional_lipschitz`]) inside the
    /// node box, 1 beyond it (the exact distance), the two marched
    /// separately because the field jumps where they meet. Between samples
    /// at values v₁, v₂ a distance s apart the field is at least
    /// (v₁ + v₂ − L·s)/2, so from a sample at v, with the least value so
    /// far `bound`, the next may be (v − bound + 2·tolerance)/L ahead; and
    /// a capsule (or piece) whose centre is at v ≥ bound − tolerance +
    /// L·half-length needs no other sample. A robot far from the terrain
    /// costs one query per capsule.
    pub fn closest_below(
        &self,
        sdf: &SignedDistanceField,
        pose: &BodyPose,
        frames: &[LinkFrames; 4],
        cutoff: f64,
        tolerance: f64,
    ) -> Option<Clearance> {
        let grid = sdf.grid();
        let (lo, hi) = (grid.spec().origin, grid.spec().upper());
        // A floor keeps the march finite for a tolerance of 0 [m].
        let gap = 2.0 * tolerance.max(1e-9);
        // (distance, capsule, fraction along it, world point, on the lattice)
        let mut best: Option<(f64, usize, f64, Vec3, bool)> = None;
        let mut bound = cutoff;
        for (k, c) in self.capsules.iter().enumerate() {
            let (wa, wb) = self.world_segment(k, pose, frames);
            let ab = sub(wb, wa);
            let length = norm(ab);
            let (u, per_length) = if length > 0.0 {
                (scale(ab, 1.0 / length), 1.0 / length)
            } else {
                ([0.0; 3], 0.0)
            };
            let on_lattice = |t0: f64, t1: f64| Piece {
                t0,
                t1,
                lipschitz: grid.directional_lipschitz(u),
                lattice: true,
            };
            let exact = |t0: f64, t1: f64| Piece {
                t0,
                t1,
                lipschitz: 1.0,
                lattice: false,
            };
            let mut pieces = [None; 3];
            if grid.spec().contains(wa) && grid.spec().contains(wb) {
                pieces[0] = Some(on_lattice(0.0, length));
            } else {
                match clip_to_box(wa, u, length, lo, hi) {
                    None => pieces[0] = Some(exact(0.0, length)),
                    Some((t0, t1)) => {
                        pieces[0] = (t0 > 0.0).then(|| exact(0.0, t0));
                        pieces[1] = Some(on_lattice(t0, t1));
                        pieces[2] = (t1 < length).then(|| exact(t1, length));
                    }
                }
            }
            for piece in pieces.into_iter().flatten() {
                let at = |t: f64| add(wa, scale(u, t));
                // Beyond the box the exact distance, even on the box's face
                // (where `distance` would interpolate).
                let field = |p: Vec3| {
                    if piece.lattice {
                        distance(sdf, p)
                    } else {
                        sdf.surface().signed_distance(p).0
                    }
                };
                let l = piece.lipschitz;
                let half = 0.5 * (piece.t1 - piece.t0);
                let mid = field(at(piece.t0 + half)) - c.radius;
                if mid - l * half >= bound - tolerance {
                    if mid < bound {
                        bound = mid;
                        best = Some((
                            mid,
                            k,
                            (piece.t0 + half) * per_length,
                            at(piece.t0 + half),
                            piece.lattice,
                        ));
                    }
                    continue;
                }
                let mut t = piece.t0;
                loop {
                    let p = at(t);
                    let v = field(p) - c.radius;
                    if v < bound {
                        bound = v;
                        best = Some((v, k, t * per_length, p, piece.lattice));
                    }
                    if t >= piece.t1 {
                        break;
                    }
                    t = (t + (v - bound + gap) / l).min(piece.t1);
                }
            }
        }
        best.map(|(v, k, f, p, lattice)| {
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
                gradient: if lattice {
                    sdf.distance_and_gradient(p).1
                } else {
                    sdf.surface().signed_distance(p).1
                },
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

    /// Rounded rocks on [0, 0.6]² m: a far field that is not 1-Lipschitz.
    fn rocky_field() -> &'static (HeightField, SignedDistanceField) {
        static FIELD: std::sync::OnceLock<(HeightField, SignedDistanceField)> =
            std::sync::OnceLock::new();
        FIELD.get_or_init(|| {
            let (height, _) = crate::testing::rocky_board(30, 0.08, 7);
            // The board's rocks start 0.4 m in; shift them onto the lattice.
            crate::testing::terrain(0.6, move |x, y| height(x + 0.4, y), 0.05, 0.15)
        })
    }

    /// A point over the terrain at `u[2]`·6 cm − 1 cm above its surface,
    /// over and beyond the lattice (x ∈ [0, 0.6], y ∈ [−0.3, 0.3]).
    fn point_in(hf: &HeightField, u: [f64; 3]) -> Vec3 {
        let (x, y) = (-0.05 + 0.7 * u[0], -0.35 + 0.7 * u[1]);
        let (ix, iy) = (
            (x.clamp(0.0, 0.6) / 0.005) as isize,
            ((y.clamp(-0.3, 0.3) + 0.3) / 0.005) as isize,
        );
        let ground = hf.at(ix, iy);
        [x, y, ground - 0.01 + 0.06 * u[2]]
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(400))]
        /// The march's contract against dense sampling of the same field
        /// (every 0.05 mm, itself within L·0.025 mm of the true minimum).
        #[test]
        fn footstep_capsule_march_is_within_its_tolerance_of_dense_sampling(
            ends in proptest::collection::vec(proptest::array::uniform3(0.0..1.0f64), 6),
            radii in proptest::array::uniform3(0.0..0.04f64),
            short in proptest::array::uniform3(0.0..1.0f64),
            cutoff in -0.01..0.03f64,
            tolerance in 0.0003..0.005f64,
        ) {
            let (hf, sdf) = rocky_field();
            let capsules = (0..3)
                .map(|k| {
                    let a = point_in(hf, ends[2 * k]);
                    // Some short capsules, some spheres, some long ones.
                    let b = add(a, scale(sub(point_in(hf, ends[2 * k + 1]), a), short[k] * short[k]));
                    Capsule { leg: None, link: 0, a, b, radius: radii[k] }
                })
                .collect();
            let model = CollisionModel::new(capsules).unwrap();
            let pose = BodyPose { x: [0.0; 3], r: crate::kinematics::math::IDENTITY };
            let frames = [LinkFrames {
                pos: [[0.0; 3]; 3],
                rot: [[[0.0; 3]; 3]; 3],
                anchor: [[0.0; 3]; 3],
                axis: [[0.0; 3]; 3],
            }; 4];
            let mut dense = f64::INFINITY;
            for (k, c) in model.capsules().iter().enumerate() {
                let (a, b) = model.world_segment(k, &pose, &frames);
                let n = (norm(sub(b, a)) / 0.000_05).ceil() as usize + 1;
                for s in 0..=n {
                    let p = add(a, scale(sub(b, a), s as f64 / n as f64));
                    dense = dense.min(distance(sdf, p) - c.radius);
                }
            }
            let slack = 2.0 * 0.000_025 + 1e-12;
            match model.closest_below(sdf, &pose, &frames, cutoff, tolerance) {
                None => proptest::prop_assert!(
                    dense >= cutoff - tolerance - slack,
                    "missed {} below the cut-off {}", dense, cutoff
                ),
                Some(c) => {
                    proptest::prop_assert!(c.distance < cutoff);
                    proptest::prop_assert!(
                        dense >= c.distance - tolerance - slack,
                        "reported {} but dense sampling finds {}", c.distance, dense
                    );
                    proptest::prop_assert!(c.distance >= dense - slack);
                    let r = model.capsules()[c.capsule].radius;
                    // The field there: the lattice's, or on the lattice's face
                    // the exact one of the stretch beyond (the limit of its values).
                    let lattice = distance(sdf, c.world) - r - c.distance;
                    let exact = sdf.surface().signed_distance(c.world).0 - r - c.distance;
                    proptest::prop_assert!(lattice.abs() < 1e-12 || exact.abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn footstep_rocky_field_is_not_1_lipschitz() {
        // What makes the measured slopes matter in the test above.
        let s = rocky_field().1.grid().axis_slopes();
        assert!(s.iter().any(|&v| v > 1.0 + 1e-3), "{s:?}");
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

//! Clearance of every collision capsule over a trajectory (the validity check of
//! Zucker 2011, §5.3: "if the trajectory is still colliding ... the step is
//! lengthened"), in one call: link frames, capsule ends in the world, SDF.

use crate::error::{CoreError, CoreResult};
use crate::kinematics::math::{add, mat_vec, Mat3, Vec3};
use crate::kinematics::Quadruped;
use crate::sdf::SignedDistanceField;

/// Capsules fixed on the trunk or on leg links: segment a–b and a radius.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkCapsules {
    leg: Vec<Option<usize>>,
    link: Vec<usize>,
    a: Vec<Vec3>,
    b: Vec<Vec3>,
    radius: Vec<f64>,
}

impl LinkCapsules {
    /// Capsules from per-capsule rows; `leg` < 0 marks the trunk (ends in the base frame),
    /// otherwise ends are in the frame of link `link` (0 hip, 1 thigh, 2 shank) [m].
    pub fn new(
        leg: &[i64],
        link: &[i64],
        a: Vec<Vec3>,
        b: Vec<Vec3>,
        radius: Vec<f64>,
    ) -> CoreResult<Self> {
        let n = leg.len();
        if link.len() != n || a.len() != n || b.len() != n || radius.len() != n {
            return Err(CoreError::InvalidArgument(format!(
                "capsules need equally many legs, links, ends and radii, got {n}, {}, {}, {}, {}",
                link.len(),
                a.len(),
                b.len(),
                radius.len()
            )));
        }
        if let Some(i) =
            (0..n).find(|&i| leg[i] > 3 || (leg[i] >= 0 && !(0..=2).contains(&link[i])))
        {
            return Err(CoreError::InvalidArgument(format!(
                "capsule {i}: leg {} link {} out of range; valid: leg −1 (trunk) or 0–3 \
                 with link 0–2",
                leg[i], link[i]
            )));
        }
        Ok(Self {
            leg: leg.iter().map(|&l| usize::try_from(l).ok()).collect(),
            link: link.iter().map(|&k| k.clamp(0, 2) as usize).collect(),
            a,
            b,
            radius,
        })
    }

    /// Number of capsules.
    pub fn len(&self) -> usize {
        self.leg.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.leg.is_empty()
    }
}

/// Clearances (N·P, sample-major) [m] of the P capsules at N configurations:
/// joint angles (leg-major) [rad], trunk positions [m] and orientations.
pub fn capsule_clearances(
    robot: &Quadruped,
    capsules: &LinkCapsules,
    field: &SignedDistanceField,
    q: &[[f64; 12]],
    base_pos: &[Vec3],
    rotation: &[Mat3],
) -> CoreResult<Vec<f64>> {
    if base_pos.len() != q.len() || rotation.len() != q.len() {
        return Err(CoreError::InvalidArgument(format!(
            "capsule clearances need one trunk pose per configuration: {} q, {} positions, \
             {} orientations",
            q.len(),
            base_pos.len(),
            rotation.len()
        )));
    }
    let p = capsules.len();
    let mut a = Vec::with_capacity(3 * q.len() * p);
    let mut b = Vec::with_capacity(3 * q.len() * p);
    let legs = robot.legs();
    for ((row, x), r) in q.iter().zip(base_pos).zip(rotation) {
        let frames: [_; 4] = std::array::from_fn(|l| {
            legs[l].link_frames([row[3 * l], row[3 * l + 1], row[3 * l + 2]])
        });
        for c in 0..p {
            let (pa, pb) = match capsules.leg[c] {
                None => (capsules.a[c], capsules.b[c]),
                Some(l) => {
                    let f = &frames[l];
                    let k = capsules.link[c];
                    (
                        add(f.pos[k], mat_vec(&f.rot[k], capsules.a[c])),
                        add(f.pos[k], mat_vec(&f.rot[k], capsules.b[c])),
                    )
                }
            };
            a.extend_from_slice(&add(*x, mat_vec(r, pa)));
            b.extend_from_slice(&add(*x, mat_vec(r, pb)));
        }
    }
    let n = q.len() * p;
    let radii: Vec<f64> = (0..n).map(|i| capsules.radius[i % p]).collect();
    let (mut d, mut g, mut t) = (vec![0.0; n], vec![0.0; 3 * n], vec![0.0; n]);
    field.query_capsules(&a, &b, &radii, None, &mut d, &mut g, &mut t)?;
    Ok(d)
}

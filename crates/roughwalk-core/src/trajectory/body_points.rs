//! The body points u of CHOMP: spheres spread along the collision capsules.

use crate::error::{CoreError, CoreResult};
use crate::kinematics::math::{add, cross, from_columns, mat_vec, sub, Mat3, Vec3};
use crate::kinematics::LinkFrames;

/// Points fixed on the trunk or on a leg link, each with a sphere radius.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyPoints {
    /// Canonical leg (0–3) of each point, None for the trunk.
    pub leg: Vec<Option<usize>>,
    /// Link of each leg point (0 hip, 1 thigh, 2 shank); ignored for the trunk.
    pub link: Vec<usize>,
    /// Position in its link's frame (the base frame for the trunk) [m].
    pub local: Vec<Vec3>,
    /// Sphere radius [m].
    pub radius: Vec<f64>,
    /// Whether the point is a foot sphere.
    pub is_foot: Vec<bool>,
}

impl BodyPoints {
    /// Points from per-point rows; `leg` < 0 marks a trunk point.
    ///
    /// Refuses rows of unequal length, legs above 3, links above 2 and
    /// non-finite positions or radii.
    pub fn new(
        leg: &[i64],
        link: &[i64],
        local: Vec<Vec3>,
        radius: Vec<f64>,
        is_foot: Vec<bool>,
    ) -> CoreResult<Self> {
        let n = leg.len();
        if link.len() != n || local.len() != n || radius.len() != n || is_foot.len() != n {
            return Err(CoreError::InvalidArgument(format!(
                "body points need equally many legs, links, positions, radii and foot flags, \
                 got {n}, {}, {}, {}, {}",
                link.len(),
                local.len(),
                radius.len(),
                is_foot.len()
            )));
        }
        let mut legs = Vec::with_capacity(n);
        let mut links = Vec::with_capacity(n);
        for (u, (&l, &k)) in leg.iter().zip(link).enumerate() {
            if l > 3 {
                return Err(CoreError::InvalidArgument(format!(
                    "body point {u}: leg {l} out of range; valid: −1 (trunk), 0–3"
                )));
            }
            if l >= 0 && !(0..=2).contains(&k) {
                return Err(CoreError::InvalidArgument(format!(
                    "body point {u}: link {k} out of range; valid: 0 (hip), 1 (thigh), 2 (shank)"
                )));
            }
            legs.push(usize::try_from(l).ok());
            links.push(k.clamp(0, 2) as usize);
        }
        if let Some(u) = (0..n).find(|&u| {
            !(local[u].iter().all(|v| v.is_finite()) && radius[u].is_finite() && radius[u] >= 0.0)
        }) {
            return Err(CoreError::InvalidArgument(format!(
                "body point {u}: position and radius must be finite (radius ≥ 0), got {:?}, {}",
                local[u], radius[u]
            )));
        }
        Ok(Self {
            leg: legs,
            link: links,
            local,
            radius,
            is_foot,
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.leg.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.leg.is_empty()
    }

    /// Point u in the base frame [m] given the legs' link frames.
    #[inline]
    pub fn base_position(&self, frames: &[LinkFrames; 4], u: usize) -> Vec3 {
        match self.leg[u] {
            None => self.local[u],
            Some(l) => {
                let f = &frames[l];
                let k = self.link[u];
                add(f.pos[k], mat_vec(&f.rot[k], self.local[u]))
            }
        }
    }

    /// ∂p_B/∂q_leg [m/rad] of point u (at `p_base` [m]) w.r.t. its own leg's joints.
    ///
    /// Columns of joints below the point's link, and all of a trunk point, are zero.
    #[inline]
    pub fn joint_jacobian(&self, frames: &[LinkFrames; 4], u: usize, p_base: Vec3) -> Mat3 {
        match self.leg[u] {
            None => [[0.0; 3]; 3],
            Some(l) => joint_columns(&frames[l], p_base, self.link[u]),
        }
    }
}

/// ∂p/∂q of a point at `p` [m] moved by the joints 0 ..= `link` of a leg.
#[inline]
pub fn joint_columns(f: &LinkFrames, p: Vec3, link: usize) -> Mat3 {
    let col = |k: usize| {
        if k <= link {
            cross(f.axis[k], sub(p, f.anchor[k]))
        } else {
            [0.0; 3]
        }
    };
    from_columns(col(0), col(1), col(2))
}

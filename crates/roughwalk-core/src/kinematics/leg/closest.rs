//! The closest reachable foot when the target cannot be reached within the
//! joint limits (Zucker 2011, §3.1: "the IK is assumed to return the closest
//! reachable position").
//!
//! For a fixed HAA angle the problem is planar plus a fixed out-of-plane
//! offset, and the planar part has an exact answer: the region the foot
//! sweeps in the HFE/KFE plane is the image of the (q_HFE, φ) limit box, so
//! its boundary lies on the images of the box's edges and on the fold curves
//! where the knee is straight or fully bent, all circular arcs. A scan over
//! HAA of that exact slice distance finds the basins; damped Newton with the
//! exact Hessian, inside the limit box, finishes from the best few.

use super::ik::{wrap_into_limits, IkGeometry};
use super::{clamp_to, LegChain};
use crate::kinematics::math::{
    add, axis_angle, column, cross, dot, mat_t_vec, mat_vec, norm, solve, sub, Mat3, Vec3,
};

use std::f64::consts::{PI, TAU};

/// HAA samples of the slice scan.
const SCAN: usize = 33;
/// Newton refinements, from the best local minima of the scan.
const REFINED: usize = 3;

/// A circular arc of foot positions in the HFE/KFE plane (relative to the
/// HFE anchor, (e1, e2) coordinates), with the joint values along it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PlanarArc {
    centre: [f64; 2],
    radius: f64,
    /// Polar angle of the arc's start about its centre [rad].
    start: f64,
    /// Angular length [rad]; 2π for a full circle.
    span: f64,
    /// (q_HFE, φ) at the start; q_HFE grows along the arc when `along_q2`, else φ.
    q2_start: f64,
    phi_start: f64,
    along_q2: bool,
    /// radius·(cos, sin) of the start and end angles: the ends relative to
    /// the centre, fixed, so not recomputed per query.
    ends: [[f64; 2]; 2],
}

/// A joint range as (start, length), a full turn for unlimited or wider ranges.
fn range(lower: f64, upper: f64) -> (f64, f64) {
    match (lower.is_finite(), upper.is_finite()) {
        (true, true) => (lower, (upper - lower).min(TAU)),
        (true, false) => (lower, TAU),
        (false, true) => (upper - TAU, TAU),
        (false, false) => (-PI, TAU),
    }
}

/// The arcs that hold the boundary of the region the foot sweeps in the
/// HFE/KFE plane. Curves inside the region are harmless extras.
pub(super) fn planar_arcs(g: &IkGeometry, lower: Vec3, upper: Vec3) -> Vec<PlanarArc> {
    let (q2_start, q2_span) = range(lower[1], upper[1]);
    let (phi_lo, phi_hi) = if g.knee_axis_sign > 0.0 {
        (lower[2], upper[2])
    } else {
        (-upper[2], -lower[2])
    };
    let (phi_start, phi_span) = range(phi_lo, phi_hi);
    let mut arcs = Vec::new();
    // φ fixed (a knee-limit edge or a fold: knee straight, ψ = 0, or folded,
    // ψ = π): the foot circles the HFE anchor as q_HFE runs through its range.
    let fold0 = g.alpha1 - g.alpha2;
    let first_fold = ((phi_start - fold0) / PI).ceil() as i64;
    let last_fold = ((phi_start + phi_span - fold0) / PI).floor() as i64;
    let folds = (first_fold..=last_fold).map(|k| fold0 + k as f64 * PI);
    let edges = [phi_lo, phi_hi].into_iter().filter(|v| v.is_finite());
    for phi in edges.chain(folds) {
        let m = g.planar_foot(phi);
        let beta = m[1].atan2(m[0]);
        arcs.push(PlanarArc::new(
            [0.0, 0.0],
            m[0].hypot(m[1]),
            q2_start + beta,
            q2_span,
            (q2_start, phi),
            true,
        ));
    }
    // q_HFE fixed at a limit: the shank circles the knee as φ runs through its range.
    for q2 in [lower[1], upper[1]].into_iter().filter(|v| v.is_finite()) {
        let (s, c) = q2.sin_cos();
        arcs.push(PlanarArc::new(
            [
                c * g.thigh[0] - s * g.thigh[1],
                s * g.thigh[0] + c * g.thigh[1],
            ],
            g.l2,
            q2 + g.alpha2 + phi_start,
            phi_span,
            (q2, phi_start),
            false,
        ));
    }
    arcs
}

/// The HAA angles of the slice scan and the rotations −q_HAA about the HAA
/// axis that bring a target into each slice's frame: fixed by the limits,
/// so computed once per leg instead of once per out-of-reach IK.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct HaaScan {
    q1: [f64; SCAN],
    rot: [Mat3; SCAN],
    /// Whether the range is a full turn (the scan wraps around).
    full: bool,
}

pub(super) fn haa_scan(g: &IkGeometry, lower: Vec3, upper: Vec3) -> HaaScan {
    let (start, span) = range(lower[0], upper[0]);
    let full = span >= TAU;
    let divisions = if full { SCAN } else { SCAN - 1 } as f64;
    let q1: [f64; SCAN] =
        std::array::from_fn(|i| (start + span * i as f64 / divisions).clamp(lower[0], upper[0]));
    HaaScan {
        q1,
        rot: q1.map(|q| axis_angle(g.u1, -q)),
        full,
    }
}

impl PlanarArc {
    fn new(
        centre: [f64; 2],
        radius: f64,
        start: f64,
        span: f64,
        (q2_start, phi_start): (f64, f64),
        along_q2: bool,
    ) -> Self {
        let end = |o: f64| {
            let (s, c) = (start + o).sin_cos();
            [radius * c, radius * s]
        };
        Self {
            centre,
            radius,
            start,
            span,
            q2_start,
            phi_start,
            along_q2,
            ends: [end(0.0), end(span)],
        }
    }

    /// Distance [m] to the arc and the arc offset [rad] where it is attained,
    /// from `v`, the point relative to the arc's centre, and `r` = |v|.
    fn closest(&self, v: [f64; 2], r: f64) -> (f64, f64) {
        let offset = (v[1].atan2(v[0]) - self.start).rem_euclid(TAU);
        if self.span >= TAU || offset <= self.span {
            return ((r - self.radius).abs(), offset);
        }
        let end_distance = |e: [f64; 2]| (v[0] - e[0]).hypot(v[1] - e[1]);
        let (d0, d1) = (end_distance(self.ends[0]), end_distance(self.ends[1]));
        if d0 <= d1 {
            (d0, 0.0)
        } else {
            (d1, self.span)
        }
    }

    /// (q_HFE, φ) at an offset along the arc.
    fn joints(&self, offset: f64) -> (f64, f64) {
        if self.along_q2 {
            (self.q2_start + offset, self.phi_start)
        } else {
            (self.q2_start, self.phi_start + offset)
        }
    }
}

impl LegChain {
    /// Squared distance [m²] from the target to the feet reachable with HAA
    /// at the scan's `k`-th angle, and the (q_HFE, φ) attaining it. `t` is
    /// the target relative to the HAA anchor in the hip frame at q_HAA = 0.
    fn slice(&self, t: Vec3, k: usize) -> (f64, f64, f64) {
        let g = &self.ik_geometry;
        let (lower, upper) = (self.params.lower, self.params.upper);
        let t_hip = add(self.params.anchor[0], mat_vec(&self.scan.rot[k], t));
        let rel = sub(t_hip, g.hfe_anchor);
        let h = dot(rel, g.n) - g.plane_offset;
        let d = [dot(rel, g.e1), dot(rel, g.e2)];
        let (phi_lo, phi_hi) = if g.knee_axis_sign > 0.0 {
            (lower[2], upper[2])
        } else {
            (-upper[2], -lower[2])
        };
        if (-1.0..=1.0).contains(&g.cos_psi(d)) {
            for sign in [1.0, -1.0] {
                let (q2, phi) = g.planar_branch(d, sign);
                let q2 = wrap_into_limits(q2, lower[1], upper[1]);
                let phi = wrap_into_limits(phi, phi_lo, phi_hi);
                if let (Some(q2), Some(phi)) = (q2, phi) {
                    return (h * h, q2, phi);
                }
            }
        }
        let mut best = (f64::INFINITY, self.nominal()[1], 0.0);
        for arc in &self.arcs {
            // The distance to an arc is at least that to its circle: skip
            // arcs that cannot beat the best (it must be strictly less).
            let v = [d[0] - arc.centre[0], d[1] - arc.centre[1]];
            let r = v[0].hypot(v[1]);
            if (r - arc.radius).abs() >= best.0 {
                continue;
            }
            let (dist, offset) = arc.closest(v, r);
            if dist < best.0 {
                let (q2, phi) = arc.joints(offset);
                best = (dist, q2, phi);
            }
        }
        (h * h + best.0 * best.0, best.1, best.2)
    }

    /// The joint angles within limits whose foot is closest to `target` (base
    /// frame [m]). `extra_seed` (the analytic IK's clamped candidate) is
    /// refined too: the scan keeps one planar basin per HAA slice, and where
    /// two basins (the HFE at either limit, say) lie at nearly the same HAA
    /// the scan can miss the better; the extra seed makes the answer never
    /// farther than the cheap clamped answer of `ik_or_clamped`.
    pub(super) fn closest_within_limits(&self, target: Vec3, extra_seed: Option<Vec3>) -> Vec3 {
        let t = self.target_at_hip(target);
        let full = self.scan.full;
        let q1_at = |i: usize| self.scan.q1[i];
        let slices: [(f64, f64, f64); SCAN] = std::array::from_fn(|i| self.slice(t, i));
        let value = |i: usize| slices[i].0;
        let mut minima: Vec<usize> = (0..SCAN)
            .filter(|&i| {
                let before = if i > 0 {
                    Some(i - 1)
                } else {
                    full.then_some(SCAN - 1)
                };
                let after = if i + 1 < SCAN {
                    Some(i + 1)
                } else {
                    full.then_some(0)
                };
                !before.is_some_and(|j| value(i) > value(j))
                    && !after.is_some_and(|j| value(i) > value(j))
            })
            .collect();
        minima.sort_by(|&a, &b| value(a).total_cmp(&value(b)));
        let mut best = (self.nominal(), f64::INFINITY);
        let scan_seeds = minima.iter().take(REFINED).map(|&i| {
            let (_, q2, phi) = slices[i];
            [q1_at(i), q2, self.ik_geometry.knee_axis_sign * phi]
        });
        for seed in scan_seeds.chain(extra_seed) {
            let (q, err) = self.projected_newton(seed, target);
            if err < best.1 {
                best = (q, err);
            }
        }
        best.0
    }

    /// Foot FK_B(q), its Jacobian, e = target − foot, and the Hessian of ½|e|².
    ///
    /// Column k of the Jacobian, c_k = a_k × (f − o_k), is a vector carried by
    /// every joint j ≤ k, so ∂c_k/∂q_j = a_j × c_k (j ≤ k): the exact Hessian
    /// JᵀJ − Σ e_i ∇²f_i costs a few cross products. The residual term matters
    /// because an out-of-reach target leaves a large residual, where
    /// Gauss–Newton only converges linearly.
    pub(super) fn foot_newton(&self, q: Vec3, target: Vec3) -> (Vec3, Mat3, Vec3, Mat3) {
        let f = self.link_frames(q);
        let foot = add(f.pos[2], mat_vec(&f.rot[2], self.params.foot));
        let jac = Self::columns(&f, foot, 2);
        let e = sub(target, foot);
        let c = [0, 1, 2].map(|k| column(&jac, k));
        let mut hess = [[0.0; 3]; 3];
        for j in 0..3 {
            for k in j..3 {
                hess[j][k] = dot(c[j], c[k]) - dot(e, cross(f.axis[j], c[k]));
                hess[k][j] = hess[j][k];
            }
        }
        (foot, jac, e, hess)
    }

    /// Damped Newton on ½|FK(q) − target|² with the joints on an active limit
    /// (pushed outward by the gradient) held fixed, every step clamped into
    /// the box and accepted only if it reduces the distance.
    fn projected_newton(&self, seed: Vec3, target: Vec3) -> (Vec3, f64) {
        let (lower, upper) = (self.params.lower, self.params.upper);
        let mut q = clamp_to(seed, lower, upper);
        let (_, mut jac, mut e, mut hess) = self.foot_newton(q, target);
        let mut cost = dot(e, e);
        let mut lambda = 1e-6;
        for _ in 0..60 {
            // The descent direction of ½|e|² is +Jᵀe (e = target − foot).
            let grad = mat_t_vec(&jac, e);
            let free = [0, 1, 2].map(|k| {
                !((q[k] <= lower[k] && grad[k] < 0.0) || (q[k] >= upper[k] && grad[k] > 0.0))
            });
            let g = [0, 1, 2].map(|k| if free[k] { grad[k] } else { 0.0 });
            let jac_scale = norm(jac[0]) + norm(jac[1]) + norm(jac[2]);
            if norm(g) <= 1e-13 * jac_scale * (cost.sqrt() + 1e-12) {
                break;
            }
            let scale_h = (0..3)
                .map(|k| dot(column(&jac, k), column(&jac, k)))
                .sum::<f64>()
                / 3.0;
            let mut improved = false;
            while lambda < 1e8 {
                let mut damped = [[0.0; 3]; 3];
                for r in 0..3 {
                    for c in 0..3 {
                        if free[r] && free[c] {
                            damped[r][c] = hess[r][c];
                        }
                    }
                    damped[r][r] += if free[r] {
                        lambda * scale_h.max(1e-300)
                    } else {
                        1.0
                    };
                }
                let Some(dq) = solve(&damped, g).filter(|dq| dot(*dq, g) > 0.0) else {
                    lambda = lambda.max(1e-6) * 10.0;
                    continue;
                };
                let q_new = clamp_to(add(q, dq), lower, upper);
                let (_, j_new, e_new, h_new) = self.foot_newton(q_new, target);
                let cost_new = dot(e_new, e_new);
                if cost_new < cost {
                    let step = norm(sub(q_new, q));
                    let gain = cost - cost_new;
                    (q, jac, e, hess, cost) = (q_new, j_new, e_new, h_new, cost_new);
                    lambda = (lambda / 10.0).max(1e-12);
                    improved = step > 1e-13 && gain > 1e-16 * cost;
                    break;
                }
                lambda = lambda.max(1e-6) * 10.0;
            }
            if !improved {
                break;
            }
        }
        (q, cost.sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::leg::tests::{
        assert_mat_close, finite_difference, random_leg, sample_q, test_legs,
    };
    use crate::kinematics::math::scale;

    #[test]
    fn closest_point_hessian_matches_central_differences() {
        // ∇(½|t − f|²) = −Jᵀe; its finite differences must give the exact Hessian.
        let target = [0.5, -0.2, 0.1];
        for leg in test_legs() {
            let q = sample_q(&leg, [0.3, 0.6, 0.2]);
            let (_, _, _, hess) = leg.foot_newton(q, target);
            let gradient = |q: Vec3| {
                let (_, jac, e, _) = leg.foot_newton(q, target);
                scale(mat_t_vec(&jac, e), -1.0)
            };
            assert_mat_close(&hess, &finite_difference(gradient, q), 1e-6);
        }
    }

    #[test]
    fn arcs_bound_the_planar_region() {
        // Every arc point is a reachable foot (its joints are within limits and
        // the arc's formula agrees with FK).
        for leg in test_legs() {
            let g = &leg.ik_geometry;
            for arc in &leg.arcs {
                for o in [0.0, 0.3 * arc.span, arc.span] {
                    let (q2, phi) = arc.joints(o);
                    let (s, c) = (arc.start + o).sin_cos();
                    let on_arc = [
                        arc.centre[0] + arc.radius * c,
                        arc.centre[1] + arc.radius * s,
                    ];
                    let m = g.planar_foot(phi);
                    let (s2, c2) = q2.sin_cos();
                    let fk = [c2 * m[0] - s2 * m[1], s2 * m[0] + c2 * m[1]];
                    assert!((on_arc[0] - fk[0]).hypot(on_arc[1] - fk[1]) < 1e-12);
                    let q3 = g.knee_axis_sign * phi;
                    assert!(
                        leg.is_within_limits([leg.nominal()[0], q2, q3]),
                        "{q2} {q3}"
                    );
                }
            }
        }
    }

    /// Best foot-to-target distance over a dense grid of joint angles within limits.
    fn brute_force_distance(leg: &LegChain, target: Vec3, n: usize) -> f64 {
        let mut best = f64::INFINITY;
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let u = [i, j, k].map(|v| v as f64 / (n - 1) as f64);
                    best = best.min(norm(sub(leg.fk(sample_q(leg, u)), target)));
                }
            }
        }
        best
    }

    #[test]
    fn out_of_reach_targets_get_the_closest_reachable_foot() {
        let mut rng = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        let legs: Vec<LegChain> = test_legs()
            .into_iter()
            .chain((0..24).map(random_leg))
            .collect();
        for leg in legs {
            let hip = leg.haa_anchor_base;
            for _ in 0..8 {
                let dir = [next() - 0.5, next() - 0.5, next() - 0.5];
                let target = add(hip, scale(dir, (0.3 + 1.2 * next()) / norm(dir)));
                let r = leg.ik(target, None);
                let brute = brute_force_distance(&leg, target, 25);
                assert!(
                    r.error <= brute + 1e-9,
                    "{}: ik {} > brute {brute} for {target:?}",
                    leg.name(),
                    r.error
                );
                assert!(leg.is_within_limits(r.q));
                assert_eq!(r.reachable, r.error <= super::super::IK_TOLERANCE);
            }
        }
    }
}

//! Analytic inverse kinematics of the abduction–flexion–knee chain
//! (Zucker 2011, §3.1: IK_B). Valid when the HFE and KFE axes are parallel
//! and both perpendicular to the HAA axis (LittleDog, ANYmal, Go1, A1).
//!
//! Rotating about HAA moves the foot on a circle about the HAA axis, at a
//! fixed offset along the HFE axis; HFE and KFE move it in a plane ⟂ their
//! common axis. So HAA comes from the target's polar angle about its axis
//! (two solutions), then HFE/KFE from a planar two-link problem (law of
//! cosines, two knee branches).

use super::{clamp_to, unit, IkResult, LegChain, LegParams, LinkFrames, IK_TOLERANCE, LIMIT_SLACK};
use crate::error::{CoreError, CoreResult};
use crate::kinematics::math::{
    add, cross, dot, mat_t_vec, mat_vec, norm, scale, solve, sub, wrap_angle, Mat3, Vec3,
};

/// Tolerance on the axis structure the analytic IK needs: |cos| of the angle
/// between axes that must be perpendicular, |sin| between axes that must be parallel.
const STRUCTURE_TOLERANCE: f64 = 1e-6;

/// Polishing Newton steps start only this close to the target [m]: a
/// candidate of a chain within [`STRUCTURE_TOLERANCE`] of the analytic
/// structure lands within about that times the leg's length of a target it
/// can reach; one farther off is out of this candidate's reach, and the
/// steps would only be wasted on it (the other candidates cover the other
/// solutions).
const NEWTON_RANGE: f64 = 1e-5;

/// Targets farther than this from the hip [m] are pulled in along their direction
/// before solving: no leg reaches that far, and it keeps squares finite.
const FAR_TARGET: f64 = 1e3;

/// Geometry the IK needs, fixed at construction. "Hip frame" is body 1's
/// frame; vectors are in it unless stated.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct IkGeometry {
    /// HAA axis (exact, unit).
    pub u1: Vec3,
    /// HFE axis orthogonalised against u1: with u1 and w = u1 × n_perp, the
    /// basis in which HAA rotates the foot.
    pub n_perp: Vec3,
    pub w: Vec3,
    /// The foot's fixed offset along n_perp from the HAA anchor [m].
    pub lateral: f64,
    /// HFE axis (exact, unit) and the planar basis ⟂ it, e1 × e2 = n.
    pub n: Vec3,
    pub e1: Vec3,
    pub e2: Vec3,
    /// The foot's fixed offset along n from the HFE anchor [m].
    pub plane_offset: f64,
    /// +1 when the KFE axis points along the HFE axis, −1 when against it:
    /// the in-plane knee rotation is φ = knee_axis_sign · q_KFE.
    pub knee_axis_sign: f64,
    /// HFE anchor [m].
    pub hfe_anchor: Vec3,
    /// Thigh (HFE anchor → KFE anchor) and shank (KFE anchor → foot) at q = 0,
    /// in (e1, e2) [m], their lengths [m] and polar angles [rad].
    pub thigh: [f64; 2],
    pub shank: [f64; 2],
    pub l1: f64,
    pub l2: f64,
    pub alpha1: f64,
    pub alpha2: f64,
}

impl IkGeometry {
    /// Checks the axis structure and precomputes the planar chain.
    pub fn new(name: &str, p: &LegParams, body_rot: &[Mat3; 3]) -> CoreResult<Self> {
        let u1 = p.axis[0];
        let n = mat_vec(&body_rot[1], p.axis[1]);
        let knee_axis = mat_vec(&body_rot[1], mat_vec(&body_rot[2], p.axis[2]));
        let cos_haa_hfe = dot(u1, n);
        if cos_haa_hfe.abs() > STRUCTURE_TOLERANCE {
            return Err(CoreError::RobotModel(format!(
                "leg '{name}': the HFE axis must be perpendicular to the HAA axis for the analytic IK, \
                 but cos(angle) = {cos_haa_hfe:.3e} (tolerance {STRUCTURE_TOLERANCE:e})"
            )));
        }
        let sin_hfe_kfe = norm(cross(n, knee_axis));
        if sin_hfe_kfe > STRUCTURE_TOLERANCE {
            return Err(CoreError::RobotModel(format!(
                "leg '{name}': the KFE axis must be parallel to the HFE axis for the analytic IK, \
                 but sin(angle) = {sin_hfe_kfe:.3e} (tolerance {STRUCTURE_TOLERANCE:e})"
            )));
        }
        let n_perp = unit(sub(n, scale(u1, cos_haa_hfe)));
        let e1 = unit(sub(u1, scale(n, cos_haa_hfe)));
        let e2 = cross(n, e1);

        // Positions in the hip frame at q_HFE = q_KFE = 0.
        let in_hip = |v_thigh: Vec3| add(p.body_pos[1], mat_vec(&body_rot[1], v_thigh));
        let hfe_anchor = add(p.body_pos[1], mat_vec(&body_rot[1], p.anchor[1]));
        let kfe_anchor = in_hip(add(p.body_pos[2], mat_vec(&body_rot[2], p.anchor[2])));
        let foot = in_hip(add(p.body_pos[2], mat_vec(&body_rot[2], p.foot)));
        let planar = |v: Vec3| [dot(v, e1), dot(v, e2)];
        let thigh = planar(sub(kfe_anchor, hfe_anchor));
        let shank = planar(sub(foot, kfe_anchor));
        for (what, v) in [("thigh (HFE→KFE)", thigh), ("shank (KFE→foot)", shank)] {
            let len = v[0].hypot(v[1]);
            if len < 1e-6 {
                return Err(CoreError::RobotModel(format!(
                    "leg '{name}': the {what} has length {len:.3e} m in the plane of the HFE and KFE \
                     rotations; the leg cannot move its foot in that plane"
                )));
            }
        }
        Ok(Self {
            u1,
            n_perp,
            w: cross(u1, n_perp),
            lateral: dot(n_perp, sub(foot, p.anchor[0])),
            n,
            e1,
            e2,
            plane_offset: dot(n, sub(foot, hfe_anchor)),
            knee_axis_sign: dot(n, knee_axis).signum(),
            hfe_anchor,
            thigh,
            shank,
            l1: thigh[0].hypot(thigh[1]),
            l2: shank[0].hypot(shank[1]),
            alpha1: thigh[1].atan2(thigh[0]),
            alpha2: shank[1].atan2(shank[0]),
        })
    }

    /// Thigh + Rot(φ)·shank: the foot relative to the HFE anchor at q_HFE = 0, in (e1, e2) [m].
    pub fn planar_foot(&self, phi: f64) -> [f64; 2] {
        let (s, c) = phi.sin_cos();
        [
            self.thigh[0] + c * self.shank[0] - s * self.shank[1],
            self.thigh[1] + s * self.shank[0] + c * self.shank[1],
        ]
    }

    /// cos ψ of the knee angle that puts the foot at distance |d| from the
    /// HFE anchor (outside [−1, 1] out of the annulus of reach).
    #[inline]
    pub fn cos_psi(&self, d: [f64; 2]) -> f64 {
        let (l1, l2) = (self.l1, self.l2);
        (d[0] * d[0] + d[1] * d[1] - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    }

    /// The planar two-link solution (q_HFE, φ) placing the foot at `d`
    /// (relative to the HFE anchor, in (e1, e2) [m]) on the knee branch of
    /// sign `sign` (ψ > 0 for +1); out of the annulus of reach (|cos ψ| > 1),
    /// the foot points at `d`, straight or folded. One branch at a time:
    /// callers usually need only the first.
    pub fn planar_branch(&self, d: [f64; 2], sign: f64) -> (f64, f64) {
        let psi = self.cos_psi(d).clamp(-1.0, 1.0).acos();
        let phi = sign * psi + self.alpha1 - self.alpha2;
        let m = self.planar_foot(phi);
        (d[1].atan2(d[0]) - m[1].atan2(m[0]), phi)
    }
}

/// The representative q + 2πm inside [lower, upper] (the one nearest the
/// bottom of the range), clamped onto it; `None` when there is none.
pub(super) fn wrap_into_limits(q: f64, lower: f64, upper: f64) -> Option<f64> {
    let w = wrap_angle(q);
    let lo = lower - LIMIT_SLACK;
    let hi = upper + LIMIT_SLACK;
    if (lo..=hi).contains(&w) {
        return Some(w.clamp(lower, upper));
    }
    let tau = std::f64::consts::TAU;
    let v = w + tau * ((lo - w) / tau).ceil();
    (v <= hi).then(|| v.clamp(lower, upper))
}

/// What the analytic IK found: a candidate that reaches the target, or the
/// nearest one (error [m], q) if it was asked for; its link frames are
/// written where the caller asked.
enum Analytic {
    Reached(IkResult),
    Nearest(Option<(f64, Vec3)>),
}

/// The four solutions (2 HAA × 2 knee branches) of the limit-free chain,
/// most preferred first: HAA nearest its nominal angle, then the knee branch
/// `knee`. Every candidate is finite; out of reach they are only
/// approximate, which the caller detects from the foot error.
///
/// Candidate k is built on demand by [`Self::get`], with the very
/// operations an eager construction would use, so the numbers are the same.
struct AnalyticCandidates {
    t_u: f64,
    /// (v_w, q_HAA) of the two HAA solutions, preferred first.
    haa: [(f64, f64); 2],
    knee: f64,
}

impl AnalyticCandidates {
    fn new(leg: &LegChain, target: Vec3, knee: f64) -> Self {
        let g = &leg.ik_geometry;
        let t = leg.target_at_hip(target);
        let (t_u, t_n, t_w) = (dot(t, g.u1), dot(t, g.n_perp), dot(t, g.w));
        let v_w_abs = (t_n * t_n + t_w * t_w - g.lateral * g.lateral)
            .max(0.0)
            .sqrt();
        let nominal_haa = leg.nominal()[0];
        let polar = t_w.atan2(t_n);
        // atan2 is odd in its first argument (IEEE sign symmetry, exactly):
        // one call serves both solutions.
        let turn = v_w_abs.atan2(g.lateral);
        let mut haa = [(v_w_abs, polar - turn), (-v_w_abs, polar + turn)];
        if wrap_angle(haa[0].1 - nominal_haa).abs() > wrap_angle(haa[1].1 - nominal_haa).abs() {
            haa.swap(0, 1);
        }
        Self { t_u, haa, knee }
    }

    /// Candidate `k` (0..4): HAA solution k / 2, knee branch k % 2 in order
    /// of preference.
    fn get(&self, leg: &LegChain, k: usize) -> Vec3 {
        let g = &leg.ik_geometry;
        let (v_w, q1) = self.haa[k / 2];
        // Where the foot must be in the hip frame once HAA has turned it into place.
        let foot_hip = add(
            leg.params.anchor[0],
            add(
                add(scale(g.u1, self.t_u), scale(g.n_perp, g.lateral)),
                scale(g.w, v_w),
            ),
        );
        let rel = sub(foot_hip, g.hfe_anchor);
        let sign = if (self.knee > 0.0) == k.is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        let (q2, phi) = g.planar_branch([dot(rel, g.e1), dot(rel, g.e2)], sign);
        [q1, q2, g.knee_axis_sign * phi]
    }
}

impl LegChain {
    /// Inverse kinematics IK_B: joint angles placing the foot centre at
    /// `target` (base frame [m]), or, when that is impossible within the joint
    /// limits, the joint angles within limits whose foot is closest to it.
    ///
    /// `knee_sign` (±1) overrides the leg's preferred knee branch (see
    /// [`LegParams::knee_sign`]); the other branch is used only when the
    /// preferred one violates a limit. Never panics and never returns NaN.
    pub fn ik(&self, target: Vec3, knee_sign: Option<f64>) -> IkResult {
        self.ik_with_frames(target, knee_sign).0
    }

    /// [`Self::ik`] and the link frames at its joint angles, as
    /// [`Self::link_frames`] gives them: the IK's last forward kinematics
    /// already computed them, and callers that need both (the pose
    /// certificate) save a second evaluation of every joint's rotation.
    pub fn ik_with_frames(&self, target: Vec3, knee_sign: Option<f64>) -> (IkResult, LinkFrames) {
        if !target.iter().all(|v| v.is_finite()) {
            let q = self.nominal();
            let result = IkResult {
                q,
                reachable: false,
                within_limits: true,
                error: f64::INFINITY,
            };
            return (result, self.link_frames(q));
        }
        let solve_target = self.solve_target(target);
        let mut frames = LinkFrames::default();
        if let Some(found) = self.ik_exact_at(solve_target, target, knee_sign, &mut frames) {
            return (found, frames);
        }
        let clamped = match self.analytic(solve_target, target, knee_sign, true, &mut frames) {
            Analytic::Nearest(nearest) => nearest.map(|(_, q)| q),
            Analytic::Reached(_) => None,
        };
        let q = self.closest_within_limits(solve_target, clamped);
        let frames = self.link_frames(q);
        let foot = add(frames.pos[2], mat_vec(&frames.rot[2], self.params.foot));
        let error = norm(sub(foot, target));
        let reachable = error <= IK_TOLERANCE;
        let on_limit = (0..3).any(|k| {
            q[k] <= self.params.lower[k] + LIMIT_SLACK || q[k] >= self.params.upper[k] - LIMIT_SLACK
        });
        let result = IkResult {
            q,
            reachable,
            within_limits: reachable || !on_limit,
            error,
        };
        (result, frames)
    }

    /// The analytic part of [`Self::ik_with_frames`] alone: the joint angles
    /// within limits that put the foot on `target` (base frame [m]), with
    /// their link frames, or `None` without the closest-reachable search
    /// that `ik` falls back to (for callers that only ask whether a point
    /// can be reached).
    pub fn ik_exact(&self, target: Vec3, knee_sign: Option<f64>) -> Option<(IkResult, LinkFrames)> {
        let mut frames = LinkFrames::default();
        self.ik_exact_into(target, knee_sign, &mut frames)
            .map(|r| (r, frames))
    }

    /// [`Self::ik_exact`] writing the link frames into `frames` (which hold
    /// a rejected candidate's when it returns `None`): the pose certificate
    /// keeps every leg's frames in one array, and 432-byte frames returned
    /// through the IK's layers were copied three times on the way (~5 % of
    /// a certificate's instructions on the logs board).
    pub fn ik_exact_into(
        &self,
        target: Vec3,
        knee_sign: Option<f64>,
        frames: &mut LinkFrames,
    ) -> Option<IkResult> {
        if !target.iter().all(|v| v.is_finite()) {
            return None;
        }
        self.ik_exact_at(self.solve_target(target), target, knee_sign, frames)
    }

    /// The point the analytic IK solves for: `target`, pulled in to
    /// [`FAR_TARGET`] from the hip.
    fn solve_target(&self, target: Vec3) -> Vec3 {
        let from_hip = sub(target, self.haa_anchor_base);
        let dist = norm(from_hip);
        if dist > FAR_TARGET {
            add(self.haa_anchor_base, scale(from_hip, FAR_TARGET / dist))
        } else {
            target
        }
    }

    /// [`Self::ik_with_frames`] where the analytic IK places the foot;
    /// otherwise, instead of the closest-reachable search (tens of times
    /// dearer), the analytic candidate whose joint angles, clamped into their
    /// limits, put the foot nearest `target`: near the closest reachable foot
    /// but not it (`reachable` false, `error` its distance [m]). For callers
    /// that need only the direction and rough size of the foot's error, such
    /// as the pose certificate's reachability step (Zucker 2011, §3.2).
    pub fn ik_or_clamped(&self, target: Vec3, knee_sign: Option<f64>) -> (IkResult, LinkFrames) {
        let mut frames = LinkFrames::default();
        let result = self.ik_or_clamped_into(target, knee_sign, &mut frames);
        (result, frames)
    }

    /// [`Self::ik_or_clamped`] writing the link frames into `frames` (see
    /// [`Self::ik_exact_into`] for why).
    pub fn ik_or_clamped_into(
        &self,
        target: Vec3,
        knee_sign: Option<f64>,
        frames: &mut LinkFrames,
    ) -> IkResult {
        if !target.iter().all(|v| v.is_finite()) {
            let (result, f) = self.ik_with_frames(target, knee_sign);
            *frames = f;
            return result;
        }
        let solve_target = self.solve_target(target);
        let (error, q) = match self.analytic(solve_target, target, knee_sign, true, frames) {
            Analytic::Reached(result) => return result,
            Analytic::Nearest(nearest) => nearest.expect("four clamped candidates"),
        };
        let (lower, upper) = (self.params.lower, self.params.upper);
        let on_limit =
            (0..3).any(|k| q[k] <= lower[k] + LIMIT_SLACK || q[k] >= upper[k] - LIMIT_SLACK);
        let reachable = error <= IK_TOLERANCE;
        IkResult {
            q,
            reachable,
            within_limits: reachable || !on_limit,
            error,
        }
    }

    /// The knee branch to prefer, ±1.
    fn knee(&self, knee_sign: Option<f64>) -> f64 {
        if knee_sign.unwrap_or(self.params.knee_sign) < 0.0 {
            -1.0
        } else {
            1.0
        }
    }

    fn ik_exact_at(
        &self,
        solve_target: Vec3,
        target: Vec3,
        knee_sign: Option<f64>,
        frames: &mut LinkFrames,
    ) -> Option<IkResult> {
        match self.analytic(solve_target, target, knee_sign, false, frames) {
            Analytic::Reached(result) => Some(result),
            Analytic::Nearest(_) => None,
        }
    }

    /// The first analytic candidate, in order of preference, that reaches
    /// `target` within the joint limits; otherwise, with `nearest`, the
    /// candidate (clamped into the limits where it leaves them) whose foot
    /// is nearest, as (error [m], q). Each candidate's frames are built in
    /// `out`, which holds the returned candidate's frames on return (any
    /// candidate's when none is returned).
    fn analytic(
        &self,
        solve_target: Vec3,
        target: Vec3,
        knee_sign: Option<f64>,
        nearest: bool,
        out: &mut LinkFrames,
    ) -> Analytic {
        let (lower, upper) = (self.params.lower, self.params.upper);
        // Candidates are built one at a time: the first usually fits, and
        // each costs a handful of atan2/acos/sin_cos.
        let candidates = AnalyticCandidates::new(self, solve_target, self.knee(knee_sign));
        // The nearest candidate so far keeps its frames here (the rare
        // out-of-reach case); the usual first-candidate hit copies nothing.
        let mut best: Option<(f64, Vec3, LinkFrames)> = None;
        for k in 0..4 {
            let q = candidates.get(self, k);
            let wrapped = [0, 1, 2].map(|k| wrap_into_limits(q[k], lower[k], upper[k]));
            let (q, error) = if let [Some(a), Some(b), Some(c)] = wrapped {
                let (q, error) = self.polish([a, b, c], target, out);
                if error <= IK_TOLERANCE {
                    let result = IkResult {
                        q,
                        reachable: true,
                        within_limits: true,
                        error,
                    };
                    return Analytic::Reached(result);
                }
                (q, error)
            } else if nearest {
                let q = [0, 1, 2].map(|j| {
                    wrapped[j].unwrap_or_else(|| wrap_angle(q[j]).clamp(lower[j], upper[j]))
                });
                *out = self.link_frames(q);
                let foot = add(out.pos[2], mat_vec(&out.rot[2], self.params.foot));
                (q, norm(sub(foot, target)))
            } else {
                continue;
            };
            match best {
                Some((e, _, _)) if e <= error => {}
                _ if nearest => best = Some((error, q, *out)),
                _ => {}
            }
        }
        Analytic::Nearest(best.map(|(error, q, frames)| {
            *out = frames;
            (error, q)
        }))
    }

    /// The target relative to the HAA anchor, in the hip frame at q_HAA = 0 [m].
    pub(super) fn target_at_hip(&self, target: Vec3) -> Vec3 {
        mat_t_vec(&self.body_rot[0], sub(target, self.haa_anchor_base))
    }

    /// A few Newton steps from an analytic solution, to take out the error of
    /// a slightly imperfect axis structure or of acos near a straight knee.
    /// Returns the angles and the foot error [m], with the link frames at
    /// them in `frames`.
    fn polish(&self, q: Vec3, target: Vec3, frames: &mut LinkFrames) -> (Vec3, f64) {
        let (lower, upper) = (self.params.lower, self.params.upper);
        let foot_of = |f: &LinkFrames| add(f.pos[2], mat_vec(&f.rot[2], self.params.foot));
        *frames = self.link_frames(q);
        let (mut q, mut foot) = (q, foot_of(frames));
        let mut error = norm(sub(foot, target));
        for _ in 0..4 {
            if error <= 1e-14 || error > NEWTON_RANGE {
                break;
            }
            let jacobian = Self::columns(frames, foot, 2);
            let Some(dq) = solve(&jacobian, sub(target, foot)) else {
                break;
            };
            let q_new = clamp_to(add(q, dq), lower, upper);
            let frames_new = self.link_frames(q_new);
            let foot_new = foot_of(&frames_new);
            let e_new = norm(sub(foot_new, target));
            if !e_new.is_finite() || e_new >= error {
                break;
            }
            (q, foot, error) = (q_new, foot_new, e_new);
            *frames = frames_new;
        }
        (q, error)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::leg::tests::{littledog_leg, random_leg, sample_q, test_legs};
    use proptest::prelude::*;

    #[test]
    fn knee_sign_selects_the_branch() {
        // LittleDog front leg: ψ = q_KFE + 0.263 (the shin's backward offset), so
        // the mirror of q_KFE = −1.2 (ψ = −0.937) is q_KFE = 0.674, inside the limit of 1.0.
        let leg = littledog_leg(1.0, true);
        let q = [0.1, 0.4, -1.2];
        let f = leg.fk(q);
        let minus = leg.ik(f, Some(-1.0));
        assert!(minus.reachable && norm(sub(minus.q, q)) < 1e-9, "{minus:?}");
        let plus = leg.ik(f, Some(1.0));
        assert!(
            plus.reachable && (plus.q[2] - 0.674).abs() < 2e-3,
            "{plus:?}"
        );
        // The mirror of q_KFE = −2.0 would need q_KFE = 1.47 > 1.0: the preferred
        // branch is then dropped for the one that fits.
        let q = [0.1, -0.2, -2.0];
        let fallback = leg.ik(leg.fk(q), Some(1.0));
        assert!(
            fallback.reachable && norm(sub(fallback.q, q)) < 1e-9,
            "{fallback:?}"
        );
    }

    #[test]
    fn structure_check_names_the_leg() {
        let mut p = test_legs()[4].params().clone();
        p.axis[2] = [0.0, 0.0, 1.0];
        let err = LegChain::new("RH", p).unwrap_err();
        assert!(
            matches!(&err, CoreError::RobotModel(m) if m.contains("'RH'") && m.contains("KFE"))
        );
        let mut p = littledog_leg(1.0, true).params().clone();
        p.axis[1] = [1.0, 0.0, 0.0];
        p.axis[2] = [1.0, 0.0, 0.0];
        let err = LegChain::new("LF", p).unwrap_err();
        assert!(
            matches!(&err, CoreError::RobotModel(m) if m.contains("'LF'") && m.contains("perpendicular"))
        );
    }

    #[test]
    fn degenerate_targets_give_finite_answers() {
        for leg in test_legs() {
            let hip = leg.haa_anchor_base;
            for target in [
                hip,
                [0.0; 3],
                [1e300, -1e300, 1e300],
                [f64::MAX, 0.0, 0.0],
                add(hip, [0.0, 0.0, 5.0]),
                [f64::NAN, 0.0, 0.0],
                [f64::INFINITY, 0.0, 0.0],
            ] {
                let r = leg.ik(target, None);
                assert!(r.q.iter().all(|v| v.is_finite()), "{target:?} → {r:?}");
                assert!(leg.is_within_limits(r.q));
                assert!(!r.reachable);
                assert!(!r.error.is_nan());
            }
        }
    }

    proptest! {
        #[test]
        fn ik_inverts_fk_inside_the_workspace(
            u in prop::array::uniform3(0.0..=1.0f64),
            which in 0usize..6,
            knee in prop::sample::select(vec![None, Some(1.0), Some(-1.0)]),
        ) {
            let leg = &test_legs()[which];
            let q = sample_q(leg, u);
            let f = leg.fk(q);
            let r = leg.ik(f, knee);
            prop_assert!(r.reachable, "{q:?} → {r:?}");
            prop_assert!(r.within_limits);
            prop_assert!(leg.is_within_limits(r.q));
            prop_assert!(norm(sub(leg.fk(r.q), f)) <= 1e-9);
        }

        #[test]
        fn ik_inverts_fk_on_random_legs(u in prop::array::uniform3(0.0..=1.0f64), seed in 0u64..10_000) {
            let leg = random_leg(seed);
            let q = sample_q(&leg, u);
            let f = leg.fk(q);
            let r = leg.ik(f, None);
            prop_assert!(r.reachable && r.within_limits, "{q:?} → {r:?}");
            prop_assert!(norm(sub(leg.fk(r.q), f)) <= 1e-9);
        }

        #[test]
        fn ik_frames_and_exact_ik_agree_with_ik(
            u in prop::array::uniform3(0.0..=1.0f64),
            which in 0usize..6,
            push in 0.0..0.3f64,
        ) {
            // Reachable targets, and targets pushed out along their direction
            // from the hip (often out of reach).
            let leg = &test_legs()[which];
            let f = leg.fk(sample_q(leg, u));
            let out = sub(f, leg.haa_anchor_base);
            let target = add(f, scale(out, push / norm(out).max(1e-9)));
            let r = leg.ik(target, None);
            let (with, frames) = leg.ik_with_frames(target, None);
            prop_assert_eq!(with, r);
            prop_assert_eq!(frames, leg.link_frames(r.q));
            match leg.ik_exact(target, None) {
                Some((exact, frames)) => {
                    prop_assert_eq!(exact, r);
                    prop_assert_eq!(frames, leg.link_frames(r.q));
                }
                None => prop_assert!(!r.reachable, "{r:?}"),
            }
            // The cheap variant: the same where the analytic IK reaches; else
            // within limits, its frames and error consistent, never nearer
            // than the closest reachable foot, which it approximates.
            let (c, frames) = leg.ik_or_clamped(target, None);
            prop_assert_eq!(frames, leg.link_frames(c.q));
            if let Some((exact, _)) = leg.ik_exact(target, None) {
                prop_assert_eq!(c, exact);
            } else {
                prop_assert!(!c.reachable && leg.is_within_limits(c.q), "{c:?}");
                prop_assert!((norm(sub(leg.fk(c.q), target)) - c.error).abs() < 1e-12);
                prop_assert!(c.error >= r.error - 1e-9, "{c:?} vs closest {r:?}");
            }
        }
    }

    #[test]
    fn exact_ik_refuses_non_finite_targets() {
        let leg = littledog_leg(1.0, true);
        assert!(leg.ik_exact([f64::NAN, 0.0, 0.0], None).is_none());
        assert!(leg.ik_exact([0.0, f64::INFINITY, 0.0], None).is_none());
        let (r, frames) = leg.ik_with_frames([f64::NAN, 0.0, 0.0], None);
        assert_eq!(frames, leg.link_frames(r.q));
        assert!(!r.reachable);
        assert_eq!(leg.ik_or_clamped([f64::NAN, 0.0, 0.0], None), (r, frames));
    }
}

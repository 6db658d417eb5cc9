//! Cost-to-go heuristics for a footstep planner on the plane
//! (Zucker 2011, §4.1).
//!
//! The paper collapses a footstep state to the feet's centroid and heading
//! (x, y, θ) and models the robot as a Dubins car: forward only, with a
//! fixed turning radius, it first turns on an arc until it faces the goal,
//! then drives straight to it. This penalises goals beside or behind the
//! robot, which a quadruped reaches only with many small side or turning
//! steps, and so keeps the search from expanding states that point the
//! wrong way. The Euclidean distance is the admissible alternative.

use std::f64::consts::{FRAC_PI_2, TAU};

/// Length [m] of the shortest "arc, then straight line" path of a
/// forward-only car at (x, y) [m] with heading θ [rad] to the goal point
/// (goal_x, goal_y) [m], the goal heading free: the car turns left or right
/// on a circle of radius `turning_radius` [m] until it faces the goal, then
/// drives straight (whichever side is shorter).
///
/// A goal inside one side's turning circle cannot be reached by turning to
/// that side first (the tangent line from a circle never enters it), so the
/// other side is used; the two circles touch only at the car, so one side
/// always works. This is the paper's model, not the full Dubins distance to
/// a point: for a goal inside a turning circle a two-arc path can be
/// shorter, so the value may exceed the true curvature-bounded distance.
///
/// Admissibility: the value is at least the Euclidean distance, and a
/// legged robot can side-step and turn in place, so as a cost-to-go of
/// footstep plans it is **not admissible** (the paper says as much): scaled
/// by a cost per metre it estimates well but bounds nothing. Report it as
/// such (`heuristic_is_admissible() == false`).
///
/// `turning_radius` = 0 gives the Euclidean distance; a negative or NaN
/// radius gives NaN, which a search rejects as invalid input.
pub fn dubins_heuristic(
    x: f64,
    y: f64,
    theta: f64,
    goal_x: f64,
    goal_y: f64,
    turning_radius: f64,
) -> f64 {
    if turning_radius.is_nan() || turning_radius < 0.0 {
        return f64::NAN;
    }
    let (dx, dy) = (goal_x - x, goal_y - y);
    if turning_radius == 0.0 {
        return dx.hypot(dy);
    }
    // The goal in the car's frame: x ahead, y to the left.
    let (s, c) = theta.sin_cos();
    let ahead = c * dx + s * dy;
    let left = -s * dx + c * dy;
    // A right turn is a left turn in the mirrored world (y → −y).
    left_arc_then_line(ahead, left, turning_radius).min(left_arc_then_line(
        ahead,
        -left,
        turning_radius,
    ))
}

/// Length of "turn left on the circle of radius r, then straight" to the
/// point (px, py) in the car's frame (car at the origin facing +x), or ∞ if
/// the point is inside the left circle.
fn left_arc_then_line(px: f64, py: f64, r: f64) -> f64 {
    // The left circle is centred at (0, r); the car sits at angle −π/2 on it.
    let (cx, cy) = (px, py - r);
    let d = cx.hypot(cy);
    if d < r {
        return f64::INFINITY;
    }
    // Leave the circle at angle α where the tangent, followed counter-
    // clockwise, passes through the point: (p − c)·u(α) = r, ahead of it.
    let alpha = cy.atan2(cx) - (r / d).min(1.0).acos();
    let mut arc = (alpha + FRAC_PI_2).rem_euclid(TAU);
    // A goal dead ahead must not turn into a full circle by rounding.
    if arc > TAU - 1e-9 {
        arc = 0.0;
    }
    let straight = ((d - r) * (d + r)).max(0.0).sqrt();
    r * arc + straight
}

/// Straight-line cost-to-go: `cost_per_metre` [1/m] × the distance [m] from
/// (x, y) to (goal_x, goal_y).
///
/// Admissible when `cost_per_metre` is at most the least cost any plan pays
/// per metre of centroid travel (e.g. the cheapest step cost divided by the
/// longest step): then it never overestimates, and being a scaled metric it
/// is also consistent.
pub fn euclidean_heuristic(x: f64, y: f64, goal_x: f64, goal_y: f64, cost_per_metre: f64) -> f64 {
    cost_per_metre * (goal_x - x).hypot(goal_y - y)
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // zero at the goal is exact
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    fn wrap(a: f64) -> f64 {
        (a + PI).rem_euclid(TAU) - PI
    }

    /// Shortest arc-then-line path found by sweeping the arc angle φ on each
    /// side in the world frame and solving "the goal is dead ahead" for φ by
    /// bisection between sign changes of the heading error.
    fn brute_force(x: f64, y: f64, theta: f64, gx: f64, gy: f64, r: f64) -> f64 {
        let pose = |side: f64, phi: f64| {
            // Centre of the turning circle, then the car after turning φ.
            let (cx, cy) = (x - side * r * theta.sin(), y + side * r * theta.cos());
            let heading = theta + side * phi;
            let px = cx + side * r * heading.sin();
            let py = cy - side * r * heading.cos();
            (px, py, heading)
        };
        let error = |side: f64, phi: f64| {
            let (px, py, h) = pose(side, phi);
            wrap((gy - py).atan2(gx - px) - h)
        };
        let length = |side: f64, phi: f64| {
            let (px, py, _) = pose(side, phi);
            r * phi + (gx - px).hypot(gy - py)
        };
        let n = 20_000u32;
        let mut best = f64::INFINITY;
        for side in [1.0, -1.0] {
            for k in 0..n {
                let (mut a, mut b) = (
                    TAU * f64::from(k) / f64::from(n),
                    TAU * f64::from(k + 1) / f64::from(n),
                );
                let (ea, eb) = (error(side, a), error(side, b));
                if ea.abs() > 0.5 || eb.abs() > 0.5 || ea.signum() == eb.signum() && ea != 0.0 {
                    continue;
                }
                for _ in 0..60 {
                    let m = 0.5 * (a + b);
                    if error(side, m).signum() == error(side, a).signum() {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                best = best.min(length(side, 0.5 * (a + b)));
            }
        }
        best
    }

    #[test]
    fn dubins_known_values() {
        let r = 0.5;
        // Dead ahead: no turn.
        assert!((dubins_heuristic(1.0, 2.0, 0.0, 4.0, 2.0, r) - 3.0).abs() < 1e-12);
        // On top of the left circle: half a turn, no line.
        assert!((dubins_heuristic(0.0, 0.0, 0.0, 0.0, 2.0 * r, r) - PI * r).abs() < 1e-12);
        // Mirrored: half a right turn.
        assert!((dubins_heuristic(0.0, 0.0, 0.0, 0.0, -2.0 * r, r) - PI * r).abs() < 1e-12);
        // Zero radius: Euclidean.
        assert!((dubins_heuristic(0.0, 0.0, 1.0, 3.0, 4.0, 0.0) - 5.0).abs() < 1e-12);
        assert!(dubins_heuristic(0.0, 0.0, 0.0, 1.0, 1.0, -1.0).is_nan());
        assert!((euclidean_heuristic(0.0, 0.0, 3.0, 4.0, 2.0) - 10.0).abs() < 1e-12);
    }

    #[test]
    fn dubins_goal_inside_left_circle_goes_right() {
        // (0, 0.5) is inside the left circle (centre (0, 1), r = 1): the car
        // must turn right and loop round; the brute force agrees.
        let h = dubins_heuristic(0.0, 0.0, 0.0, 0.0, 0.5, 1.0);
        assert!(h.is_finite() && h > PI);
        assert!((h - brute_force(0.0, 0.0, 0.0, 0.0, 0.5, 1.0)).abs() < 1e-6);
    }

    proptest! {
        #[test]
        fn dubins_matches_brute_force_sampler(
            x in -2.0..2.0f64, y in -2.0..2.0f64, theta in -4.0..4.0f64,
            gx in -2.0..2.0f64, gy in -2.0..2.0f64, r in 0.05..1.5f64,
        ) {
            let h = dubins_heuristic(x, y, theta, gx, gy, r);
            let b = brute_force(x, y, theta, gx, gy, r);
            prop_assert!((h - b).abs() <= 1e-6 * (1.0 + b), "formula {h}, brute force {b}");
        }

        #[test]
        fn dubins_is_at_least_euclidean_and_mirror_symmetric(
            x in -5.0..5.0f64, y in -5.0..5.0f64, theta in -7.0..7.0f64,
            gx in -5.0..5.0f64, gy in -5.0..5.0f64, r in 0.0..2.0f64,
        ) {
            let h = dubins_heuristic(x, y, theta, gx, gy, r);
            let e = euclidean_heuristic(x, y, gx, gy, 1.0);
            prop_assert!(h >= e - 1e-12, "dubins {h} < euclidean {e}");
            let mirrored = dubins_heuristic(x, -y, -theta, gx, -gy, r);
            prop_assert!((h - mirrored).abs() <= 1e-9 * (1.0 + h));
            prop_assert_eq!(dubins_heuristic(gx, gy, theta, gx, gy, r), 0.0);
        }
    }
}

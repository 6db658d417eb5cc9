//! A golden deterministic plan: LittleDog across the generated rocky course
//! of the `footstep_planner` benchmark, stopped after a fixed number of
//! expansions with a cold certificate cache.
//!
//! Speed-ups of the certificate search (IK, capsule clearance, skipped
//! work) must not change what it decides. Every certificate outcome steers
//! the search, so the plan's footholds, its solutions' costs and the counts
//! of certificates computed, failed and their rounds pin it down: a change
//! to any outcome shows here. If a change of results is intended (a new
//! rule, not a faster one), re-measure the plans' quality and update the
//! numbers below with a note in the commit.

use roughwalk_core::footstep::{FootstepPlanner, SearchKind, Start};
use roughwalk_core::search::Termination;
use roughwalk_core::testing::{planner, rocky_board, test_config};

/// The benchmark's course: 60 rocks up to 8 cm, seed 4.
fn course() -> (FootstepPlanner, [f64; 2]) {
    let (height, length) = rocky_board(60, 0.08, 4);
    let p = planner(length, height, |_, _| 1.0, test_config());
    (p, [length - 0.2, 0.0])
}

const START: Start = Start::Pose {
    x: 0.2,
    y: 0.0,
    yaw: 0.0,
};
const BUDGET: u64 = 1500;

/// Footholds (lattice cells of LF, RF, LH, RH) of the plan's stances, then
/// the solutions' costs and the counters. The footholds are those measured
/// before the session 5 speed-ups (commit a14cdbd). Session 6 changed the
/// clearance check's sampling (sphere tracing with the field's measured
/// Lipschitz bound, within a stated tolerance, instead of a fixed 1-voxel
/// spacing with a √3 bound the LittleDog fields break): same plan, cost
/// 100.544 832 → 100.547 051 (a clearance penalty 0.002 higher), rounds
/// 39 999 → 39 947, failures [2 469, 159, 201] → [2 465, 158, 210]. Then
/// the planner's field became its unit-slope envelope (far-field values
/// lowered where they rose faster than a distance can): same plan, cost
/// → 100.543 881, rounds → 39 948, failures → [2 475, 162, 202].
const GOLDEN_STANCES: &[[[i16; 2]; 4]] = &[
    [[58, 72], [58, 48], [22, 72], [22, 48]],
    [[58, 72], [58, 48], [34, 72], [22, 48]],
    [[73, 72], [58, 48], [34, 72], [22, 48]],
    [[73, 72], [58, 48], [34, 72], [40, 52]],
    [[73, 72], [81, 47], [34, 72], [40, 52]],
    [[73, 72], [81, 47], [52, 77], [40, 52]],
    [[94, 73], [81, 47], [52, 77], [40, 52]],
    [[94, 73], [81, 47], [52, 77], [59, 47]],
    [[94, 73], [101, 43], [52, 77], [59, 47]],
    [[94, 73], [101, 43], [72, 77], [59, 47]],
    [[114, 72], [101, 43], [72, 77], [59, 47]],
    [[114, 72], [101, 43], [72, 77], [79, 49]],
    [[114, 72], [120, 47], [72, 77], [79, 49]],
    [[114, 72], [120, 47], [91, 78], [79, 49]],
    [[133, 74], [120, 47], [91, 78], [79, 49]],
    [[133, 74], [120, 47], [91, 78], [99, 55]],
    [[133, 74], [139, 50], [91, 78], [99, 55]],
    [[133, 74], [139, 50], [110, 73], [99, 55]],
    [[152, 77], [139, 50], [110, 73], [99, 55]],
    [[152, 77], [139, 50], [110, 73], [114, 56]],
    [[152, 77], [149, 54], [110, 73], [114, 56]],
    [[152, 77], [149, 54], [125, 73], [114, 56]],
    [[165, 74], [149, 54], [125, 73], [114, 56]],
    [[165, 74], [149, 54], [125, 73], [132, 52]],
    [[165, 74], [172, 49], [125, 73], [132, 52]],
    [[165, 74], [172, 49], [134, 70], [132, 52]],
    [[177, 74], [172, 49], [134, 70], [132, 52]],
    [[177, 74], [172, 49], [134, 70], [147, 45]],
    [[177, 74], [185, 51], [134, 70], [147, 45]],
    [[177, 74], [185, 51], [153, 71], [147, 45]],
    [[195, 73], [185, 51], [153, 71], [147, 45]],
    [[195, 73], [185, 51], [153, 71], [164, 51]],
    [[195, 73], [205, 47], [153, 71], [164, 51]],
    [[195, 73], [205, 47], [173, 69], [164, 51]],
    [[215, 72], [205, 47], [173, 69], [164, 51]],
    [[215, 72], [205, 47], [173, 69], [183, 52]],
    [[215, 72], [224, 47], [173, 69], [183, 52]],
    [[215, 72], [224, 47], [193, 72], [183, 52]],
    [[235, 70], [224, 47], [193, 72], [183, 52]],
    [[235, 70], [224, 47], [193, 72], [202, 53]],
    [[235, 70], [243, 49], [193, 72], [202, 53]],
    [[235, 70], [243, 49], [213, 73], [202, 53]],
    [[255, 70], [243, 49], [213, 73], [202, 53]],
    [[255, 70], [243, 49], [213, 73], [212, 47]],
];
const GOLDEN_COSTS: &[f64] = &[100.543_881_165_324_42];
/// certificates computed, their rounds, failures (unreachable, CoM, collision).
const GOLDEN_COUNTS: (u64, u64, [u64; 3]) = (28_418, 39_948, [2_475, 162, 202]);

#[test]
fn footstep_deterministic_plan_matches_the_golden_one() {
    let (mut p, goal) = course();
    let r = p.plan(
        &START,
        goal,
        SearchKind::AraStar,
        &mut Termination::expansions(BUDGET),
        None,
    );
    assert!(r.status.is_solved(), "{:?} {:?}", r.status, r.message);
    let stances: Vec<[[i16; 2]; 4]> = r.states.iter().map(|s| s.feet).collect();
    let costs: Vec<f64> = r.solutions.iter().map(|s| s.cost).collect();
    let counts = (
        r.model.certificates_computed,
        r.model.certificate_rounds,
        r.model.certificate_failures,
    );
    assert_eq!(stances, GOLDEN_STANCES, "footholds changed");
    assert_eq!(costs.len(), GOLDEN_COSTS.len(), "solutions {costs:?}");
    for (c, g) in costs.iter().zip(GOLDEN_COSTS) {
        assert!((c - g).abs() <= 1e-9 * g.abs(), "cost {c} vs golden {g}");
    }
    assert_eq!(counts, GOLDEN_COUNTS, "certificate outcomes changed");
}

//! Footstep planner speed without Python: actions evaluated per second and
//! time to the first plan for LittleDog on a generated rocky course (a pad,
//! a 0.6 m board of rounded rocks up to 8 cm, a pad), the shape of the
//! `roughwalk bench planner` courses. Issue 4's targets: ≥ 100,000 actions/s
//! on one core, first plan ≤ 0.1 s.
//!
//! Run: `cargo bench -p roughwalk-core --bench footstep_planner`.
//!
//! Before criterion it runs one deterministic probe (a cold certificate
//! cache, a fixed expansion budget) and prints its counts. Under
//! `valgrind --tool=callgrind --toggle-collect='*FootstepPlanner*plan*'`
//! with `-- --list` (criterion then only lists its benchmarks), the
//! collected instructions divided by the probe's actions evaluated are the
//! instructions per action: a load-independent speed figure.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, BatchSize, Criterion, Throughput};
use roughwalk_core::footstep::{FootstepPlanResult, FootstepPlanner, SearchKind, Start};
use roughwalk_core::search::Termination;
use roughwalk_core::testing::{planner, rocky_board, test_config};

const ROCKS: usize = 60;
const MAX_ROCK: f64 = 0.08;
const SEED: u64 = 4;
const START: Start = Start::Pose {
    x: 0.2,
    y: 0.0,
    yaw: 0.0,
};
/// Expansions of the probe and of the throughput benchmark.
const BUDGET: u64 = 3000;

fn course() -> (FootstepPlanner, [f64; 2]) {
    let (height, length) = rocky_board(ROCKS, MAX_ROCK, SEED);
    let p = planner(length, height, |_, _| 1.0, test_config());
    (p, [length - 0.2, 0.0])
}

/// Plans with a cold certificate cache until `termination` fires.
fn plan(
    p: &FootstepPlanner,
    goal: [f64; 2],
    termination: &mut Termination<'_>,
) -> FootstepPlanResult {
    let mut cold = p.clone();
    cold.plan(&START, goal, SearchKind::AraStar, termination, None)
}

fn probe(p: &FootstepPlanner, goal: [f64; 2]) -> u64 {
    let r = plan(p, goal, &mut Termination::expansions(BUDGET));
    let first = r.solutions.first();
    eprintln!(
        "footstep probe ({BUDGET} expansions, cold cache): status {}, {} actions evaluated \
         ({} cache hits, pruned {} geometry / {} incircle, failures {:?}), \
         {:.0} actions/s, first plan {} after {} expansions, {} solutions, cost {:.6}",
        r.status,
        r.stats.actions_evaluated,
        r.model.certificate_cache_hits,
        r.model.pruned_geometry,
        r.model.pruned_incircle,
        r.model.certificate_failures,
        r.stats.actions_per_second(),
        first.map_or("none".into(), |s| format!("{:.4} s", s.time_s)),
        first.map_or(0, |s| s.expansions),
        r.solutions.len(),
        r.cost.unwrap_or(f64::NAN),
    );
    assert!(
        r.status.is_solved(),
        "the benchmark course must be crossable within the budget"
    );
    r.stats.actions_evaluated
}

fn footstep_planner(c: &mut Criterion) {
    let (p, goal) = course();
    let actions = probe(&p, goal);
    let mut group = c.benchmark_group("footstep_rocky_course");
    group.sample_size(10);
    // Throughput in elements = actions evaluated, so criterion reports actions/s.
    group.throughput(Throughput::Elements(actions));
    group.bench_function(format!("actions_in_{BUDGET}_expansions"), |b| {
        b.iter_batched(
            || p.clone(),
            |mut cold| {
                let r = cold.plan(
                    &START,
                    goal,
                    SearchKind::AraStar,
                    &mut Termination::expansions(BUDGET),
                    None,
                );
                black_box(r.stats.actions_evaluated)
            },
            BatchSize::LargeInput,
        );
    });
    group.throughput(Throughput::Elements(1));
    group.bench_function("first_plan", |b| {
        b.iter_batched(
            || p.clone(),
            |mut cold| {
                let mut first = Termination::callback(|progress| {
                    if progress.solutions > 0 {
                        std::ops::ControlFlow::Break(())
                    } else {
                        std::ops::ControlFlow::Continue(())
                    }
                });
                let r = cold.plan(&START, goal, SearchKind::AraStar, &mut first, None);
                black_box(r.solutions.len())
            },
            BatchSize::LargeInput,
        );
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(10));
    targets = footstep_planner
}

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}

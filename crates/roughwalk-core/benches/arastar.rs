//! ARA* speed on a 500×500 grid world (expansions per second), and how far a
//! wall-clock budget overruns when successors are expensive.
//!
//! Run: `cargo bench -p roughwalk-core --bench arastar`.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{criterion_group, Criterion, Throughput};
use roughwalk_core::search::grid_world::GridWorld;
use roughwalk_core::search::{AraStar, AraStarConfig, SearchProblem, Successor, Termination};

const SIDE: usize = 500;
const OBSTACLES: f64 = 0.25;
const SEED: u64 = 1;

fn world() -> GridWorld {
    GridWorld::random(SIDE, SIDE, OBSTACLES, SEED)
}

fn grid_world(c: &mut Criterion) {
    let mut group = c.benchmark_group("arastar_500x500");
    group.sample_size(10);
    for (name, config) in [
        (
            "astar_eps1",
            AraStarConfig {
                epsilon0: 1.0,
                decrement: 0.5,
            },
        ),
        (
            "arastar_eps3_step0.5_to_optimal",
            AraStarConfig {
                epsilon0: 3.0,
                decrement: 0.5,
            },
        ),
    ] {
        let world = world();
        let probe = AraStar::new(world.clone(), (0, 0), config).solve(&mut Termination::never());
        assert!(
            probe.status.is_solved(),
            "the benchmark grid must have a path"
        );
        let first = probe.solutions[0];
        eprintln!(
            "{name}: {} expansions in {} iterations, {} states, cost {:.2}; \
             first plan after {} expansions, cost {:.2}, bound {:.3}",
            probe.stats.expansions,
            probe.stats.iterations.len(),
            probe.stats.states_generated,
            probe.cost().unwrap_or(f64::NAN),
            first.expansions,
            first.cost,
            first.epsilon_bound,
        );
        // Throughput in elements = expansions, so criterion reports expansions/s.
        group.throughput(Throughput::Elements(probe.stats.expansions));
        group.bench_function(name, |b| {
            b.iter(|| {
                let r =
                    AraStar::new(world.clone(), (0, 0), config).solve(&mut Termination::never());
                black_box(r.stats.expansions)
            });
        });
    }
    group.finish();
}

/// An endless corridor whose every action takes ~10 µs to evaluate (a
/// stand-in for pose-certificate searches), 20 actions per state.
struct Expensive;

impl SearchProblem for Expensive {
    type State = i64;
    type Action = ();
    fn successors(&mut self, &s: &i64, out: &mut Vec<Successor<i64, ()>>) -> usize {
        for k in 0..20 {
            let t = Instant::now();
            while t.elapsed() < Duration::from_micros(10) {
                std::hint::spin_loop();
            }
            out.push(Successor {
                state: 20 * s + k + 1,
                cost: 1.0,
                action: (),
            });
        }
        20
    }
    fn heuristic(&mut self, _: &i64) -> f64 {
        0.0
    }
    fn is_goal(&mut self, _: &i64) -> bool {
        false
    }
}

fn time_limit_overrun() {
    let limit = Duration::from_millis(100);
    let mut worst = 0.0f64;
    let mut rate = 0.0;
    for _ in 0..10 {
        let r = AraStar::new(Expensive, 0, AraStarConfig::default())
            .solve(&mut Termination::time_limit(limit));
        worst = worst.max(r.stats.elapsed_s / limit.as_secs_f64() - 1.0);
        rate = r.stats.actions_per_second();
    }
    eprintln!(
        "time limit {limit:?} with 20 × 10 µs actions per expansion: worst overrun {:.2} % \
         (target ≤ 10 %), {rate:.0} actions/s",
        100.0 * worst
    );
}

criterion_group!(benches, grid_world);

fn main() {
    time_limit_overrun();
    benches();
    Criterion::default().configure_from_args().final_summary();
}

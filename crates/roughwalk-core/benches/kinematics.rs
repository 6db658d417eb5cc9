//! Leg FK and IK evaluations per second on a LittleDog-sized leg (single
//! calls), the §3.4 pose Jacobians, and a batched quadruped IK.
//!
//! Run: `cargo bench -p roughwalk-core --bench kinematics`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use roughwalk_core::kinematics::{point_pose_jacobians, CollisionPoint};
use roughwalk_core::testing::{littledog, littledog_leg, STANCE_Q};

fn single_leg(c: &mut Criterion) {
    let leg = littledog_leg(1.0, true);
    let q = [0.1, 0.5, -1.2];
    let reachable = leg.fk(q);
    let out_of_reach = [0.4, 0.1, -0.3];
    let mut group = c.benchmark_group("littledog_leg");
    group.throughput(Throughput::Elements(1));
    group.bench_function("fk", |b| b.iter(|| leg.fk(black_box(q))));
    group.bench_function("fk_and_jacobian", |b| {
        b.iter(|| leg.fk_and_jacobian(black_box(q)));
    });
    group.bench_function("ik_reachable", |b| {
        b.iter(|| leg.ik(black_box(reachable), None));
    });
    group.bench_function("ik_out_of_reach", |b| {
        b.iter(|| leg.ik(black_box(out_of_reach), None));
    });
    group.finish();
}

fn quadruped(c: &mut Criterion) {
    let robot = littledog();
    let feet_base = robot.fk_base(&STANCE_Q);
    let pos = [0.0, 0.0, 0.2];
    let quat = [1.0, 0.0, 0.0, 0.0];
    let feet_world = robot.foot_positions_world(pos, quat, &STANCE_Q).unwrap();
    let batch: Vec<_> = (0..1000).map(|_| feet_base).collect();
    let mut group = c.benchmark_group("littledog_quadruped");
    group.bench_function("pose_jacobians_shank_point", |b| {
        let point = CollisionPoint::Leg {
            leg: 0,
            link: 2,
            point: [0.0, 0.0, -0.05],
        };
        b.iter(|| point_pose_jacobians(&robot, black_box(&feet_world), pos, quat, point));
    });
    group.throughput(Throughput::Elements(4 * batch.len() as u64));
    group.bench_function("ik_batch_1000x4", |b| {
        b.iter(|| robot.ik_batch(black_box(&batch)));
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    targets = single_leg, quadruped
}
criterion_main!(benches);

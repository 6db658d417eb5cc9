//! Leg FK and IK evaluations per second on a LittleDog-sized leg (single
//! calls), the §3.4 pose Jacobians, and a batched quadruped IK.
//!
//! Run: `cargo bench -p roughwalk-core --bench kinematics`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use roughwalk_core::kinematics::{
    point_pose_jacobians, CollisionPoint, LegChain, LegParams, Quadruped,
};

/// LittleDog's leg numbers (MIT's URDF): x forward, y left, z up.
fn littledog_leg(name: &str, front: bool, side: f64) -> LegChain {
    let x = if front { 0.101 } else { -0.101 };
    let shin_x = if front { -0.0265 } else { 0.0265 };
    LegChain::new(
        name,
        LegParams {
            body_pos: [
                [x, side * 0.03625, 0.0],
                [0.0, side * 0.0236, -0.0166],
                [0.0, 0.0, -0.0751],
            ],
            body_quat: [[1.0, 0.0, 0.0, 0.0]; 3],
            anchor: [[0.0; 3]; 3],
            axis: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            lower: if front {
                [-0.6, -3.5, -3.1]
            } else {
                [-0.6, -2.4, -1.0]
            },
            upper: if front {
                [0.6, 2.4, 1.0]
            } else {
                [0.6, 3.5, 3.1]
            },
            velocity_limit: [f64::INFINITY; 3],
            foot: [shin_x, 0.0, -0.0985],
            foot_radius: 0.01,
            knee_sign: if front { -1.0 } else { 1.0 },
        },
    )
    .expect("LittleDog's leg is a valid chain")
}

fn littledog() -> Quadruped {
    Quadruped::new([
        littledog_leg("LF", true, 1.0),
        littledog_leg("RF", true, -1.0),
        littledog_leg("LH", false, 1.0),
        littledog_leg("RH", false, -1.0),
    ])
}

const STANCE_Q: [f64; 12] = [
    0.05, 0.6, -1.1, -0.05, 0.6, -1.1, 0.05, -0.6, 1.1, -0.05, -0.6, 1.1,
];

fn single_leg(c: &mut Criterion) {
    let leg = littledog_leg("LF", true, 1.0);
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

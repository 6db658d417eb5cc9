//! Fixtures shared by the crate's unit tests and its criterion benches: the
//! LittleDog robot as the footstep planner sees it (legs, masses, capsules,
//! nominal stance), a LittleDog-sized planner configuration, terrains with
//! their distance fields, and a generated rocky board.
//!
//! Not part of the API: hidden from the docs and free to change. It lives in
//! the library (not under `#[cfg(test)]`) because benches are separate
//! crates that see only public items.

use crate::footstep::certificate::{CertificateSearch, LegReach};
use crate::footstep::collision::{Capsule, CollisionModel};
use crate::footstep::config::{CertificateConfig, FootstepConfig, HeuristicKind};
use crate::footstep::mass_model::MassModel;
use crate::footstep::model::FootstepRobot;
use crate::footstep::planner::FootstepPlanner;
use crate::heightfield::HeightField;
use crate::kinematics::leg::{LegChain, LegParams};
use crate::kinematics::math::Vec3;
use crate::kinematics::quadruped::Quadruped;
use crate::sdf::{Band, GridSpec, HeightFieldDistance, SignedDistanceField};

/// A LittleDog leg (MIT's URDF numbers), x forward, y left, z up: `side`
/// +1 left, −1 right; `front` or hind.
pub fn littledog_leg(side: f64, front: bool) -> LegChain {
    let x = if front { 0.101 } else { -0.101 };
    let shin_x = if front { -0.0265 } else { 0.0265 };
    LegChain::new(
        "littledog",
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

/// LittleDog's four legs, canonical order (LF, RF, LH, RH).
pub fn littledog() -> Quadruped {
    Quadruped::new([
        littledog_leg(1.0, true),
        littledog_leg(-1.0, true),
        littledog_leg(1.0, false),
        littledog_leg(-1.0, false),
    ])
}

/// A standing pose [rad], canonical leg-major order, hips slightly splayed.
pub const STANCE_Q: [f64; 12] = [
    0.05, 0.6, -1.1, -0.05, 0.6, -1.1, 0.05, -0.6, 1.1, -0.05, -0.6, 1.1,
];

/// The nominal stance the planner lays actions out from [rad].
pub const NOMINAL_Q: [f64; 12] = [
    0.0, 0.6, -1.2, 0.0, 0.6, -1.2, 0.0, -0.6, 1.2, 0.0, -0.6, 1.2,
];

/// LittleDog's masses (the shipped MJCF).
pub fn littledog_mass() -> MassModel {
    let side = |leg: usize| if leg.is_multiple_of(2) { 1.0 } else { -1.0 };
    MassModel::new(
        1.8,
        [0.0; 3],
        [[0.0623, 0.1279, 0.0464]; 4],
        std::array::from_fn(|leg| {
            [
                [0.0, side(leg) * 0.0029, 0.0],
                [0.0, 0.0, -0.0166],
                [0.0, 0.0, -0.0202],
            ]
        }),
    )
    .expect("LittleDog's masses are valid")
}

/// LittleDog's collision capsules without the feet (the shipped MJCF).
pub fn littledog_capsules() -> CollisionModel {
    let mut caps = vec![
        Capsule {
            leg: None,
            link: 0,
            a: [-0.12, -0.02, 0.0],
            b: [0.12, -0.02, 0.0],
            radius: 0.036,
        },
        Capsule {
            leg: None,
            link: 0,
            a: [-0.12, 0.02, 0.0],
            b: [0.12, 0.02, 0.0],
            radius: 0.036,
        },
    ];
    for leg in 0..4 {
        let sx = if leg < 2 { 1.0 } else { -1.0 };
        caps.push(Capsule {
            leg: Some(leg),
            link: 1,
            a: [0.0; 3],
            b: [0.0, 0.0, -0.0751],
            radius: 0.011,
        });
        caps.push(Capsule {
            leg: Some(leg),
            link: 2,
            a: [0.0; 3],
            b: [-sx * 0.0212, 0.0, -0.0788],
            radius: 0.009,
        });
    }
    CollisionModel::new(caps).expect("LittleDog's capsules are valid")
}

/// LittleDog as the footstep planner sees it.
pub fn littledog_robot() -> FootstepRobot {
    FootstepRobot {
        quadruped: littledog(),
        mass: littledog_mass(),
        collision: littledog_capsules(),
        nominal_q: NOMINAL_Q,
    }
}

/// A LittleDog-sized planner configuration (hip-to-hip length 0.2 m): the
/// Python `FootstepConfig.for_robot` defaults, scaled to 0.2 m.
pub fn test_config() -> FootstepConfig {
    let l = 0.2;
    let mut actions = Vec::new();
    for dx in [-0.1, 0.0, 0.1, 0.2, 0.3] {
        for dy in [-0.1, 0.0, 0.1] {
            actions.push([dx * l, dy * l, 0.0]);
        }
    }
    for dth in [-0.15, 0.15] {
        actions.push([0.0, 0.0, dth]);
        actions.push([0.15 * l, 0.0, dth]);
    }
    FootstepConfig {
        resolution: 0.005,
        normal_radius: 0.0,
        actions,
        walking_order: [2, 0, 3, 1],
        local_search_radius: 0.01,
        local_search_penalty: 0.1,
        max_foot_travel: 0.6 * l,
        min_foot_separation: 0.2 * l,
        crossing_margin: 0.05 * l,
        step_cost: 1.0,
        incircle_preferred: 0.18 * l,
        incircle_min: 0.08 * l,
        incircle_penalty: 1.0,
        certificate: CertificateConfig {
            max_iterations: 25,
            stall_rounds: 3,
            alpha_reach: 0.7,
            beta_reach: 0.5 / (0.5 * l * 0.5 * l),
            reach_overshoot: 0.002,
            alpha_obstacle: 0.7,
            beta_obstacle: 0.3 / (0.5 * l * 0.5 * l),
            com_margin: 0.05 * l,
            max_step: 0.1 * l,
            max_turn: 0.15,
            max_drift: 0.5 * l,
            clearance: 0.004,
            start_clearance: 0.0,
            clearance_overshoot: 0.002,
            preferred_clearance: 0.01,
            clearance_penalty: 0.5,
            singularity_margin: 0.25,
            singularity_penalty: 0.5,
            max_tilt: 0.5,
        },
        goal_radius: 0.25 * l,
        heuristic: HeuristicKind::Dubins,
        turning_radius: l,
        dubins_cost_per_metre: 0.0,
        epsilon0: 3.0,
        epsilon_decrement: 0.5,
        max_tree_edges: 10_000,
        cache_capacity: 1 << 20,
    }
}

/// The height field of z(x, y) [m] on [0, `length`] × [−0.3, 0.3] at 5 mm,
/// and its distance field from `margin_below` [m] under the lowest point to
/// `margin_above` [m] over the highest.
pub fn terrain(
    length: f64,
    height: impl Fn(f64, f64) -> f64,
    margin_below: f64,
    margin_above: f64,
) -> (HeightField, SignedDistanceField) {
    let h = 0.005;
    let (nx, ny) = ((length / h).round() as usize + 1, 121);
    let heights: Vec<f64> = (0..nx * ny)
        .map(|k| height((k / ny) as f64 * h, -0.3 + (k % ny) as f64 * h))
        .collect();
    let hf = HeightField::new(0.0, -0.3, h, h, nx, ny, heights, None).expect("finite heights");
    let (lo, hi) = hf.height_range();
    let spec = GridSpec::new(
        [0.0, -0.3, lo - margin_below],
        h,
        [
            nx,
            ny,
            ((hi - lo + margin_below + margin_above) / h) as usize + 1,
        ],
    )
    .expect("a valid distance-field grid");
    let sdf = Band::from_heightfield(HeightFieldDistance::new(hf.clone()), spec, 2.0)
        .and_then(Band::finish)
        .expect("the distance field of a finite height field");
    (hf, sdf)
}

/// A planner for LittleDog on [0, `length`] × [−0.3, 0.3] with heights
/// `height` [m], terrain costs `cost` (the same for front and hind feet)
/// and `config`.
pub fn planner(
    length: f64,
    height: impl Fn(f64, f64) -> f64,
    cost: impl Fn(f64, f64) -> f64,
    config: FootstepConfig,
) -> FootstepPlanner {
    let (hf, sdf) = terrain(length, height, 0.05, 0.3);
    let costs: Vec<f64> = (0..hf.nx * hf.ny)
        .map(|k| {
            cost(
                hf.x0 + (k / hf.ny) as f64 * hf.dx,
                hf.y0 + (k % hf.ny) as f64 * hf.dy,
            )
        })
        .collect();
    FootstepPlanner::new(littledog_robot(), &hf, sdf, &costs, &costs, config)
        .expect("a valid planner")
}

/// A LittleDog rocks course: a 0.4 m flat pad, a 0.6 m board of `rocks`
/// random rounded rocks up to `max_height` [m] tall, 0.4 m of pad again
/// (the shape of the shared boards' courses); deterministic in `seed`.
/// Returns the height function z(x, y) [m] and the course length [m].
pub fn rocky_board(rocks: usize, max_height: f64, seed: u64) -> (impl Fn(f64, f64) -> f64, f64) {
    let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    let mut uniform = move || {
        // xorshift64*: a fixed, dependency-free stream.
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    };
    let stones: Vec<[f64; 4]> = (0..rocks)
        .map(|_| {
            let x = 0.4 + 0.6 * uniform();
            let y = -0.3 + 0.6 * uniform();
            let radius = 0.02 + 0.04 * uniform();
            let top = max_height * (0.3 + 0.7 * uniform());
            [x, y, radius, top]
        })
        .collect();
    let height = move |x: f64, y: f64| {
        stones.iter().fold(0.0f64, |z, &[cx, cy, r, top]| {
            let d2 = ((x - cx).powi(2) + (y - cy).powi(2)) / (r * r);
            // A rounded cap, flat beyond its radius.
            z.max(top * (1.0 - d2).max(0.0).sqrt())
        })
    };
    (height, 1.4)
}

/// The pieces a stand-alone [`CertificateSearch`] borrows, for LittleDog
/// with [`test_config`]'s certificate settings.
#[derive(Debug, Clone)]
pub struct CertificateFixture {
    /// The legs.
    pub robot: Quadruped,
    /// Link masses.
    pub mass: MassModel,
    /// Body capsules.
    pub collision: CollisionModel,
    /// Certificate settings.
    pub config: CertificateConfig,
    /// Each leg's reach shell.
    pub reach: [LegReach; 4],
}

impl Default for CertificateFixture {
    fn default() -> Self {
        let robot = littledog();
        let reach = std::array::from_fn(|i| LegReach::of(&robot.legs()[i]));
        Self {
            robot,
            mass: littledog_mass(),
            collision: littledog_capsules(),
            config: test_config().certificate,
            reach,
        }
    }
}

impl CertificateFixture {
    /// A search on `sdf` whose clearances carry the error bound `sdf_error`
    /// [m], with LittleDog's nominal trunk height and CoM.
    pub fn search<'a>(
        &'a self,
        sdf: &'a SignedDistanceField,
        sdf_error: f64,
    ) -> CertificateSearch<'a> {
        const NOMINAL_COM: Vec3 = [0.0, 0.0, -0.02];
        CertificateSearch {
            robot: &self.robot,
            mass: &self.mass,
            collision: &self.collision,
            sdf,
            config: &self.config,
            nominal_height: 0.1685,
            nominal_feet_centroid: [0.0, 0.0],
            nominal_com: NOMINAL_COM,
            sdf_error,
            reach: &self.reach,
        }
    }
}

//! The footstep model: what the generic ARA* search needs to plan footsteps
//! (Zucker 2011, §4.1–4.4): successors, action costs, the heuristic and the
//! goal test.
//!
//! An action moves the next leg of the walking order. Its cost is the
//! terrain cost under the new foothold (plus the local search's small
//! distance charge), the pose cost of the stance it reaches (support
//! triangle incircle below the preferred radius; certificate singularity
//! and clearance penalties) and a per-step constant. An action without a
//! pose certificate is pruned.

use std::collections::HashSet;
use std::hash::{BuildHasherDefault, Hasher};

use crate::dubins::{dubins_heuristic, euclidean_heuristic};
use crate::error::{CoreError, CoreResult};
use crate::footstep::actions::{action_target, LocalSearch};
use crate::footstep::certificate::{
    CertificateFailure, CertificateSearch, LegReach, PoseCertificate,
};
use crate::footstep::certificate_cache::CertificateCache;
use crate::footstep::collision::CollisionModel;
use crate::footstep::config::{FootstepConfig, HeuristicKind};
use crate::footstep::cost_map::CostMap;
use crate::footstep::mass_model::MassModel;
use crate::footstep::state::{Cell, FootstepState, Lattice};
use crate::kinematics::leg::LinkFrames;
use crate::kinematics::math::Vec3;
use crate::kinematics::quadruped::{leg_q, BodyPose, Quadruped};
use crate::kinematics::support::support_triangle_incircle;
use crate::sdf::SignedDistanceField;
use crate::search::{SearchProblem, Successor};

/// The robot as the footstep planner sees it.
#[derive(Debug, Clone)]
pub struct FootstepRobot {
    /// Leg kinematics, canonical order.
    pub quadruped: Quadruped,
    /// Link masses.
    pub mass: MassModel,
    /// Capsules of the body, feet excluded.
    pub collision: CollisionModel,
    /// Nominal joint angles [rad], canonical order: the stance the actions
    /// and the start are laid out from.
    pub nominal_q: [f64; 12],
}

/// The payload of a footstep edge: which leg moved, and where to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FootstepAction {
    /// Canonical leg index.
    pub leg: u8,
    /// Its new foothold.
    pub cell: Cell,
}

/// One parent → child foot move of the search tree, for pictures
/// (Zucker 2011, Figure 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TreeEdge {
    /// Canonical leg index.
    pub leg: u8,
    /// Where the foot was (x, y) [m].
    pub from: [f64; 2],
    /// Where it went (x, y) [m].
    pub to: [f64; 2],
}

/// What happened to the actions a search tried.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ModelCounters {
    /// Certificate searches run (cache misses): the actions evaluated.
    pub certificates_computed: u64,
    /// Correction rounds of the certificates found (their mean is how good
    /// the guessed starting pose is).
    pub certificate_rounds: u64,
    /// Certificate outcomes taken from the cache.
    pub certificate_cache_hits: u64,
    /// Certificate searches that failed, by what was left to correct:
    /// unreachable foot, centre of mass, collision.
    pub certificate_failures: [u64; 3],
    /// Actions whose local search found no foothold passing the geometric
    /// checks (known cell, travel, separation, no crossing).
    pub pruned_geometry: u64,
    /// Actions refused for a support triangle below the minimum incircle.
    pub pruned_incircle: u64,
}

/// The Fx hash (as the search's interner uses): fast and deterministic.
#[derive(Default, Clone, Copy)]
struct FxHasher(u64);

impl Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.write_u64(u64::from(i));
    }
    #[inline]
    fn write_u16(&mut self, i: u16) {
        self.write_u64(u64::from(i));
    }
    #[inline]
    fn write_i16(&mut self, i: i16) {
        self.write_u64(u64::from(i as u16));
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// A certificate outcome as cached: the pose penalty, or the failure.
type Outcome = Result<f64, CertificateFailure>;

/// The footstep model of one robot on one terrain: precomputed once
/// (Zucker 2011, §4.5) and reused across plans and re-plans, with a cache of
/// certificate outcomes keyed by stance.
#[derive(Debug, Clone)]
pub struct FootstepModel {
    robot: FootstepRobot,
    map: CostMap,
    sdf: SignedDistanceField,
    config: FootstepConfig,
    nominal_offsets: [[f64; 2]; 4],
    nominal_feet_centroid: [f64; 2],
    nominal_feet: [Vec3; 4],
    nominal_com: Vec3,
    nominal_height: f64,
    foot_radius: [f64; 4],
    local_search: LocalSearch,
    euclidean_per_metre: f64,
    dubins_per_metre: f64,
    sdf_error: f64,
    reach: [LegReach; 4],
    cache: CertificateCache<FootstepState, Outcome, BuildHasherDefault<FxHasher>>,
    tree: Vec<TreeEdge>,
    /// States already drawn in `tree` (bounded by its cap).
    tree_seen: HashSet<FootstepState, BuildHasherDefault<FxHasher>>,
    counters: ModelCounters,
    /// Terrain part of each successor's cost in the current expansion.
    terrain_parts: Vec<f64>,
}

impl FootstepModel {
    /// Builds the lattice cost map from `heightfield`'s terrain-grid cost maps
    /// (x-major, +∞/NaN for no foothold) and checks `config`.
    pub fn new(
        robot: FootstepRobot,
        heightfield: &crate::heightfield::HeightField,
        sdf: SignedDistanceField,
        cost_front: &[f64],
        cost_hind: &[f64],
        config: FootstepConfig,
    ) -> CoreResult<Self> {
        config.validate()?;
        // The certificates' clearance march steps by the field's slope
        // bound; a band-seeded far field overestimates with slopes up to
        // 1.4 (LittleDog boards), its unit-slope envelope lowers those
        // values only, so clearances on it are never larger and the march
        // takes fewer samples (AD: 24 % fewer clearance instructions).
        let sdf = sdf.lipschitz_envelope();
        let map = CostMap::new(
            heightfield,
            cost_front,
            cost_hind,
            config.resolution,
            config.normal_radius,
        )?;
        if map.foothold_count() == 0 {
            return Err(CoreError::Planning(
                "the terrain has no foothold: every cost is +inf/NaN or every cell unknown".into(),
            ));
        }
        let legs = robot.quadruped.legs();
        let frames: [LinkFrames; 4] =
            std::array::from_fn(|i| legs[i].link_frames(leg_q(&robot.nominal_q, i)));
        let nominal_feet = robot.quadruped.fk_base(&robot.nominal_q);
        let foot_radius: [f64; 4] = std::array::from_fn(|i| legs[i].params().foot_radius);
        let mut centroid = [0.0; 2];
        let mut depth = 0.0;
        for (f, r) in nominal_feet.iter().zip(foot_radius) {
            centroid[0] += 0.25 * f[0];
            centroid[1] += 0.25 * f[1];
            // The contact point lies a foot radius below the centre on flat ground.
            depth += 0.25 * (f[2] - r);
        }
        let nominal_offsets = nominal_feet.map(|f| [f[0] - centroid[0], f[1] - centroid[1]]);
        let nominal_com = robot.mass.com_base(&frames);
        let min_step = map.min_cost() + config.step_cost;
        let euclidean_per_metre = min_step / (0.25 * config.max_foot_travel);
        let dubins_per_metre = if config.dubins_cost_per_metre > 0.0 {
            config.dubins_cost_per_metre
        } else {
            // In a steady crawl with the longest forward action dx, each foot
            // lands dx ahead of the centroid, strides 1.6·dx, and the
            // centroid advances 0.4·dx per step.
            let advance = 0.4 * config.longest_forward_action();
            if advance > 0.0 {
                (1.0 + config.step_cost) / advance
            } else {
                euclidean_per_metre
            }
        };
        let local_search = LocalSearch::new(
            config.local_search_radius,
            config.resolution,
            config.local_search_penalty,
        );
        let sdf_error = 0.5 * 3f64.sqrt() * sdf.grid().spec().resolution;
        let reach = std::array::from_fn(|i| LegReach::of(&legs[i]));
        Ok(Self {
            robot,
            map,
            sdf,
            nominal_offsets,
            nominal_feet_centroid: centroid,
            nominal_feet,
            nominal_com,
            nominal_height: -depth,
            foot_radius,
            local_search,
            euclidean_per_metre,
            dubins_per_metre,
            sdf_error,
            reach,
            cache: CertificateCache::new(config.cache_capacity),
            tree: Vec::new(),
            tree_seen: HashSet::default(),
            counters: ModelCounters::default(),
            terrain_parts: Vec::new(),
            config,
        })
    }

    /// The settings.
    pub fn config(&self) -> &FootstepConfig {
        &self.config
    }

    /// The foothold lattice.
    pub fn lattice(&self) -> &Lattice {
        self.map.lattice()
    }

    /// The lattice cost map.
    pub fn cost_map(&self) -> &CostMap {
        &self.map
    }

    /// The robot.
    pub fn robot(&self) -> &FootstepRobot {
        &self.robot
    }

    /// Nominal feet (foot centres) in the base frame [m].
    pub fn nominal_feet(&self) -> &[Vec3; 4] {
        &self.nominal_feet
    }

    /// Height of the base over the feet's contact points at the nominal stance [m].
    pub fn nominal_height(&self) -> f64 {
        self.nominal_height
    }

    /// The interpolation error bound of the distance field [m], added to
    /// every clearance the certificates certify.
    pub fn sdf_error(&self) -> f64 {
        self.sdf_error
    }

    /// Cost per metre of the Euclidean (admissible) and Dubins heuristics [cost/m].
    pub fn heuristic_scales(&self) -> (f64, f64) {
        (self.euclidean_per_metre, self.dubins_per_metre)
    }

    /// Counters since the last [`Self::take_counters`].
    pub fn counters(&self) -> ModelCounters {
        self.counters
    }

    /// Returns and resets the counters.
    pub fn take_counters(&mut self) -> ModelCounters {
        std::mem::take(&mut self.counters)
    }

    /// Returns and clears the recorded search-tree edges.
    pub fn take_tree(&mut self) -> Vec<TreeEdge> {
        self.tree_seen = HashSet::default();
        std::mem::take(&mut self.tree)
    }

    /// Number of cached certificate outcomes.
    pub fn cache_len(&self) -> usize {
        self.cache.len()
    }

    /// Foot-sphere centres and contact points of a state's feet [m].
    pub fn feet_of(&self, s: &FootstepState) -> ([Vec3; 4], [Vec3; 4]) {
        let contacts = s.feet.map(|c| self.map.contact(c));
        let centres = std::array::from_fn(|i| self.map.foot_centre(s.feet[i], self.foot_radius[i]));
        (centres, contacts)
    }

    fn certificate_search(&self) -> CertificateSearch<'_> {
        CertificateSearch {
            robot: &self.robot.quadruped,
            mass: &self.robot.mass,
            collision: &self.robot.collision,
            sdf: &self.sdf,
            config: &self.config.certificate,
            nominal_height: self.nominal_height,
            nominal_feet_centroid: self.nominal_feet_centroid,
            nominal_com: self.nominal_com,
            sdf_error: self.sdf_error,
            reach: &self.reach,
        }
    }

    /// The pose certificate of a state: its stance, with the centre of mass
    /// over the triangle of the feet that stay down for its next step.
    /// Every foothold must be on the lattice.
    pub fn certify(&self, s: &FootstepState) -> Result<PoseCertificate, CertificateFailure> {
        let (centres, contacts) = self.feet_of(s);
        let support = s.stance_legs(&self.config.walking_order);
        let heading = self.lattice().heading(s);
        self.certificate_search()
            .find(&centres, &contacts, &support, heading)
    }

    /// The certificate of a start stance the robot stands on with its trunk
    /// at `trunk` (measured): [`Self::certify`]'s, else the search started
    /// from `trunk`, else that search with the body kept only
    /// `certificate.start_clearance` off the terrain as the distance field
    /// reads it. The robot already stands there, so a shin that settled
    /// against a rock (LittleDog board Y: 3.6 mm from the rock face, where a
    /// certificate needs 8.4 mm) does not keep it from walking on; every
    /// stance the plan reaches needs the full clearance. Not cached: the
    /// outcome depends on `trunk`. The error is [`Self::certify`]'s.
    pub fn certify_start(
        &self,
        s: &FootstepState,
        trunk: BodyPose,
    ) -> Result<PoseCertificate, CertificateFailure> {
        let failure = match self.certify(s) {
            Ok(c) => return Ok(c),
            Err(f) => f,
        };
        let (centres, contacts) = self.feet_of(s);
        let support = s.stance_legs(&self.config.walking_order);
        let search = self.certificate_search();
        let cfg = &self.config.certificate;
        let full = cfg.clearance + self.sdf_error;
        let relaxed = cfg.start_clearance.min(full);
        let asked: &[f64] = if relaxed < full {
            &[full, relaxed]
        } else {
            &[full]
        };
        asked
            .iter()
            .find_map(|&required| {
                search
                    .find_from(&centres, &contacts, &support, trunk, required)
                    .ok()
            })
            .ok_or(failure)
    }

    /// The cached certificate outcome of `s`, and whether it was computed now.
    fn pose_outcome(&mut self, s: &FootstepState) -> (Outcome, bool) {
        if let Some(o) = self.cache.get(s) {
            self.counters.certificate_cache_hits += 1;
            return (o, false);
        }
        let outcome = self.certify(s).map(|c| {
            self.counters.certificate_rounds += u64::from(c.iterations);
            c.penalty
        });
        self.counters.certificates_computed += 1;
        if let Err(f) = outcome {
            self.counters.certificate_failures[f as usize] += 1;
        }
        self.cache.insert(*s, outcome);
        (outcome, true)
    }

    /// Radius [m] of the incircle of the support triangle of `s`'s next step.
    pub fn support_incircle(&self, s: &FootstepState) -> f64 {
        let tri = s
            .stance_legs(&self.config.walking_order)
            .map(|leg| self.lattice().xy(s.feet[leg]));
        support_triangle_incircle(tri[0], tri[1], tri[2]).1
    }

    /// The pose cost of the support triangle (Zucker 2011, §4.3), or `None`
    /// when its incircle is below the minimum.
    fn incircle_cost(&self, s: &FootstepState) -> Option<f64> {
        let c = &self.config;
        let r = self.support_incircle(s);
        if r < c.incircle_min {
            return None;
        }
        let band = c.incircle_preferred - c.incircle_min;
        Some(if band > 0.0 {
            c.incircle_penalty * ((c.incircle_preferred - r) / band).clamp(0.0, 1.0)
        } else {
            0.0
        })
    }

    /// Whether `leg` may stand on `cell` with the other feet of `s` where
    /// they are: travel, separation and no crossing.
    fn geometry_ok(&self, s: &FootstepState, leg: usize, cell: Cell) -> bool {
        let c = &self.config;
        let lattice = self.lattice();
        let p = lattice.xy(cell);
        let old = lattice.xy(s.feet[leg]);
        if (p[0] - old[0]).hypot(p[1] - old[1]) > c.max_foot_travel {
            return false;
        }
        let mut feet = s.feet.map(|f| lattice.xy(f));
        feet[leg] = p;
        for (k, f) in feet.iter().enumerate() {
            if k != leg && (p[0] - f[0]).hypot(p[1] - f[1]) < c.min_foot_separation {
                return false;
            }
        }
        // No crossing, in the new stance's heading frame.
        let [lf, rf, lh, rh] = feet;
        let (hx, hy) = (lf[0] + rf[0] - lh[0] - rh[0], lf[1] + rf[1] - lh[1] - rh[1]);
        let len = hx.hypot(hy);
        if len == 0.0 {
            return false;
        }
        let (cs, sn) = (hx / len, hy / len);
        let along = |f: [f64; 2]| cs * f[0] + sn * f[1];
        let across = |f: [f64; 2]| -sn * f[0] + cs * f[1];
        let m = c.crossing_margin;
        across(lf) >= across(rf) + m
            && across(lh) >= across(rh) + m
            && along(lf) >= along(lh) + m
            && along(rf) >= along(rh) + m
    }

    /// Whether every foot of `s` stands on a foothold and the stance passes
    /// the geometric checks.
    pub fn stance_ok(&self, s: &FootstepState) -> Result<(), StanceError> {
        for (leg, &cell) in s.feet.iter().enumerate() {
            if !self.map.cost(cell, leg).is_finite() {
                let [x, y] = self.lattice().xy(cell);
                return Err(StanceError::OffFoothold { leg, x, y });
            }
        }
        for leg in 0..4 {
            if !self.geometry_ok(s, leg, s.feet[leg]) {
                return Err(StanceError::Geometry);
            }
        }
        Ok(())
    }
}

/// Why a stance is not one the planner may stand in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StanceError {
    /// Foot `leg` (canonical index) stands at lattice point (`x`, `y`) [m],
    /// which is off the terrain, unknown, or of infinite cost.
    OffFoothold {
        /// Canonical leg index (LF, RF, LH, RH).
        leg: usize,
        /// Lattice point x [m].
        x: f64,
        /// Lattice point y [m].
        y: f64,
    },
    /// Feet closer than `min_foot_separation` or crossed (`crossing_margin`).
    Geometry,
}

impl std::fmt::Display for StanceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            StanceError::OffFoothold { leg, x, y } => write!(
                f,
                "foot {} at ({x:.3}, {y:.3}) m is not on a foothold (off the terrain, unknown, or infinite cost)",
                crate::kinematics::quadruped::LEG_NAMES[leg]
            ),
            StanceError::Geometry => f.write_str(
                "the feet are too close together or crossed (min_foot_separation, crossing_margin)",
            ),
        }
    }
}

/// The footstep search problem: the model and a goal point.
pub struct FootstepProblem<'a> {
    /// The model (its caches persist across problems).
    pub model: &'a mut FootstepModel,
    /// Goal point (x, y) [m].
    pub goal: [f64; 2],
}

impl SearchProblem for FootstepProblem<'_> {
    type State = FootstepState;
    type Action = FootstepAction;

    fn successors(
        &mut self,
        s: &FootstepState,
        out: &mut Vec<Successor<FootstepState, FootstepAction>>,
    ) -> usize {
        let model = &mut *self.model;
        let order = model.config.walking_order;
        let leg = s.moving_leg(&order);
        let lattice = *model.lattice();
        let centroid = lattice.centroid(s);
        let heading = lattice.heading(s);
        let nominal = model.nominal_offsets[leg];
        let next = (s.next + 1) % 4;
        let mut evaluated = 0;
        model.terrain_parts.clear();
        for k in 0..model.config.actions.len() {
            let action = model.config.actions[k];
            let target = action_target(centroid, heading, nominal, action);
            let Some(target) = lattice.cell_of(target) else {
                model.counters.pruned_geometry += 1;
                continue;
            };
            let found = model.local_search.best(&model.map, leg, target, |cell| {
                model.geometry_ok(s, leg, cell)
            });
            let Some((cell, terrain)) = found else {
                model.counters.pruned_geometry += 1;
                continue;
            };
            let mut child = *s;
            child.feet[leg] = cell;
            child.next = next;
            if let Some(i) = out.iter().position(|e| e.state == child) {
                // Another action led to the same foothold: one edge, the cheaper charge.
                if terrain < model.terrain_parts[i] {
                    out[i].cost -= model.terrain_parts[i] - terrain;
                    model.terrain_parts[i] = terrain;
                }
                continue;
            }
            let Some(incircle) = model.incircle_cost(&child) else {
                model.counters.pruned_incircle += 1;
                continue;
            };
            let (outcome, computed) = model.pose_outcome(&child);
            if computed {
                evaluated += 1;
            }
            let Ok(pose) = outcome else { continue };
            // Each state once, with the first parent that reached it: a tree,
            // whether its certificate was computed now or cached.
            if model.tree.len() < model.config.max_tree_edges && model.tree_seen.insert(child) {
                model.tree.push(TreeEdge {
                    leg: leg as u8,
                    from: lattice.xy(s.feet[leg]),
                    to: lattice.xy(cell),
                });
            }
            model.terrain_parts.push(terrain);
            out.push(Successor {
                state: child,
                cost: terrain + incircle + pose + model.config.step_cost,
                action: FootstepAction {
                    leg: leg as u8,
                    cell,
                },
            });
        }
        evaluated
    }

    fn heuristic(&mut self, s: &FootstepState) -> f64 {
        let m = &*self.model;
        let c = m.lattice().centroid(s);
        let r = m.config.goal_radius;
        match m.config.heuristic {
            HeuristicKind::Euclidean => {
                let d = euclidean_heuristic(c[0], c[1], self.goal[0], self.goal[1], 1.0);
                m.euclidean_per_metre * (d - r).max(0.0)
            }
            HeuristicKind::Dubins => {
                let theta = m.lattice().heading(s);
                let d = dubins_heuristic(
                    c[0],
                    c[1],
                    theta,
                    self.goal[0],
                    self.goal[1],
                    m.config.turning_radius,
                );
                m.dubins_per_metre * (d - r).max(0.0)
            }
        }
    }

    fn is_goal(&mut self, s: &FootstepState) -> bool {
        let c = self.model.lattice().centroid(s);
        (c[0] - self.goal[0]).hypot(c[1] - self.goal[1]) <= self.model.config.goal_radius
    }

    fn heuristic_is_admissible(&self) -> bool {
        self.model.config.heuristic == HeuristicKind::Euclidean
    }

    fn heuristic_is_consistent(&self) -> bool {
        // |c − c′| ≤ max_foot_travel/4 per step and every step costs at least
        // the least terrain cost plus the step constant, so the scaled
        // distance to the goal disc drops by at most an edge's cost.
        self.model.config.heuristic == HeuristicKind::Euclidean
    }

    fn heuristic_name(&self) -> String {
        self.model.config.heuristic.name().to_owned()
    }
}

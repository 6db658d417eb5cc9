//! The anytime footstep planner (Zucker 2011, §4.5): ARA* over the footstep
//! model, from a start stance to a goal disc, returning the footsteps with
//! their pose certificates, every improved solution and the totals.
//!
//! Bad input (a start or goal off the terrain, NaN, a start stance that
//! cannot be certified) is not an error but a result with status
//! `InvalidInput` and a reason, as every planner result is.

use std::time::Instant;

use crate::error::CoreResult;
use crate::footstep::certificate::PoseCertificate;
use crate::footstep::config::FootstepConfig;
use crate::footstep::model::{
    FootstepAction, FootstepModel, FootstepProblem, FootstepRobot, ModelCounters, StanceError,
    TreeEdge,
};
use crate::footstep::state::FootstepState;
use crate::heightfield::HeightField;
use crate::kinematics::math::Vec3;
use crate::kinematics::quadruped::{BodyPose, LEG_NAMES};
use crate::sdf::SignedDistanceField;
use crate::search::{
    dijkstra, AraStar, AraStarConfig, SearchResult, SearchStats, SearchStatus, SolutionReport,
    Termination,
};

/// Where a plan starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Start {
    /// The nominal stance under a trunk at (x, y) [m] facing `yaw` [rad],
    /// snapped to the lattice; the first leg of the walking order moves first.
    Pose {
        /// Trunk x [m].
        x: f64,
        /// Trunk y [m].
        y: f64,
        /// Trunk heading [rad].
        yaw: f64,
    },
    /// Feet where they stand (x, y) [m], canonical order (a re-plan after an
    /// execution error), and the canonical index of the leg that moves next.
    Feet {
        /// Foot contact points (x, y) [m].
        feet: [[f64; 2]; 4],
        /// Canonical index (0 LF, 1 RF, 2 LH, 3 RH) of the leg to move first.
        next_leg: usize,
        /// The trunk pose the robot stands in, measured: where the start
        /// stance has no certificate from the pose guessed from the feet,
        /// one is searched from there ([`FootstepModel::certify_start`]).
        /// Only the start's certificate changes: every planned stance is
        /// certified as before.
        trunk: Option<BodyPose>,
    },
}

/// Which search runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchKind {
    /// Anytime Repairing A*.
    AraStar,
    /// Exhaustive uniform-cost search (Dijkstra): the exact optimum, for tests
    /// on small instances.
    Exhaustive,
}

/// A foothold of the plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footstep {
    /// Canonical leg index.
    pub leg: usize,
    /// The contact point on the terrain surface [m].
    pub position: Vec3,
}

/// Everything a plan call returns.
#[derive(Debug, Clone)]
pub struct FootstepPlanResult {
    /// How the search ended.
    pub status: SearchStatus,
    /// Why the input was invalid.
    pub message: Option<String>,
    /// When the input was invalid because a start foot stands on no
    /// foothold: that foot's canonical leg index (the caller may move it to
    /// a foothold and plan again).
    pub start_off_foothold: Option<usize>,
    /// The initial stance (four footsteps, canonical order), then one
    /// footstep per step in execution order; empty without a plan.
    pub footsteps: Vec<Footstep>,
    /// One certificate per step, holding the stance that step reaches.
    pub certificates: Vec<PoseCertificate>,
    /// The certificate of the initial stance.
    pub start_certificate: Option<PoseCertificate>,
    /// The plan's states (the start first).
    pub states: Vec<FootstepState>,
    /// Cost of the plan.
    pub cost: Option<f64>,
    /// Every improved solution, in the order found.
    pub solutions: Vec<SolutionReport>,
    /// ε₀.
    pub epsilon0: f64,
    /// ε decrement.
    pub decrement: f64,
    /// ε of the last iteration.
    pub final_epsilon: f64,
    /// The suboptimality bound ε′ of the plan (∞ without one).
    pub epsilon_bound: f64,
    /// `"dubins"` or `"euclidean"`.
    pub heuristic: String,
    /// Whether ε′ is proven (admissible heuristic).
    pub bound_guaranteed: bool,
    /// Search counters.
    pub stats: SearchStats,
    /// Model counters (certificates computed, cache hits, pruning).
    pub model: ModelCounters,
    /// Search-tree foot moves, for pictures (capped).
    pub tree: Vec<TreeEdge>,
    /// Wall-clock time of the whole call [s], certificates of the plan included.
    pub elapsed_s: f64,
}

/// Why a plan's input was refused.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// What is wrong, for a person.
    pub message: String,
    /// The canonical leg index of a start foot on no foothold, when that is
    /// what is wrong.
    pub start_off_foothold: Option<usize>,
}

impl From<String> for InputError {
    fn from(message: String) -> Self {
        Self {
            message,
            start_off_foothold: None,
        }
    }
}

/// A footstep planner for one robot on one terrain.
#[derive(Debug, Clone)]
pub struct FootstepPlanner {
    model: FootstepModel,
}

impl FootstepPlanner {
    /// Precomputes the lattice cost map (see [`FootstepModel::new`]).
    pub fn new(
        robot: FootstepRobot,
        heightfield: &HeightField,
        sdf: SignedDistanceField,
        cost_front: &[f64],
        cost_hind: &[f64],
        config: FootstepConfig,
    ) -> CoreResult<Self> {
        Ok(Self {
            model: FootstepModel::new(robot, heightfield, sdf, cost_front, cost_hind, config)?,
        })
    }

    /// The footstep model.
    pub fn model(&self) -> &FootstepModel {
        &self.model
    }

    /// The start state of `start` and its certificate, or why it is invalid.
    pub fn start_state(
        &self,
        start: &Start,
    ) -> Result<(FootstepState, PoseCertificate), InputError> {
        let config = self.model.config();
        let lattice = self.model.lattice();
        let (feet, next, trunk) = match *start {
            Start::Pose { x, y, yaw } => {
                if !(x.is_finite() && y.is_finite() && yaw.is_finite()) {
                    return Err(InputError::from(format!(
                        "start ({x}, {y}, {yaw}) must be finite"
                    )));
                }
                let (s, c) = yaw.sin_cos();
                let feet = self
                    .model
                    .nominal_feet()
                    .map(|f| [x + c * f[0] - s * f[1], y + s * f[0] + c * f[1]]);
                (feet, 0, None)
            }
            Start::Feet {
                feet,
                next_leg,
                trunk,
            } => {
                if !feet.iter().flatten().all(|v| v.is_finite()) {
                    return Err(InputError::from(format!(
                        "start feet {feet:?} must be finite"
                    )));
                }
                let Some(next) = config.walking_order.iter().position(|&l| l == next_leg) else {
                    return Err(InputError::from(format!(
                        "next_leg {next_leg} is not a leg index; valid: 0..4 (LF, RF, LH, RH)"
                    )));
                };
                if let Some(t) = trunk {
                    let finite =
                        t.x.iter()
                            .chain(t.r.iter().flatten())
                            .all(|v| v.is_finite());
                    if !finite {
                        return Err(InputError::from(format!(
                            "start trunk pose {t:?} must be finite"
                        )));
                    }
                }
                (feet, next, trunk)
            }
        };
        let mut cells = [[0i16; 2]; 4];
        for (leg, f) in feet.iter().enumerate() {
            cells[leg] = lattice.cell_of(*f).ok_or_else(|| {
                format!(
                    "start foot {} at ({:.3}, {:.3}) m is off the terrain",
                    LEG_NAMES[leg], f[0], f[1]
                )
            })?;
        }
        let state = FootstepState {
            feet: cells,
            next: next as u8,
        };
        self.model.stance_ok(&state).map_err(|e| InputError {
            message: format!("start: {e}"),
            start_off_foothold: match e {
                StanceError::OffFoothold { leg, .. } => Some(leg),
                StanceError::Geometry => None,
            },
        })?;
        let certificate = match trunk {
            Some(pose) => self.model.certify_start(&state, pose),
            None => self.model.certify(&state),
        };
        match certificate {
            Ok(c) => Ok((state, c)),
            Err(f) => Err(InputError::from(format!(
                "start stance has no pose certificate (feet in collision or out of reach): {}",
                f.describe()
            ))),
        }
    }

    fn check_goal(&self, goal: [f64; 2]) -> Result<(), String> {
        if !goal.iter().all(|v| v.is_finite()) {
            return Err(format!("goal {goal:?} must be finite"));
        }
        let l = self.model.lattice();
        if !l.contains(goal) {
            return Err(format!(
                "goal ({:.3}, {:.3}) m is off the terrain: x in [{:.3}, {:.3}], y in [{:.3}, {:.3}]",
                goal[0],
                goal[1],
                l.x0,
                l.x0 + (l.nx - 1) as f64 * l.resolution,
                l.y0,
                l.y0 + (l.ny - 1) as f64 * l.resolution
            ));
        }
        Ok(())
    }

    /// Plans from `start` to the disc around `goal` (x, y) [m] until
    /// `termination` fires (a time limit, an expansion budget, ...), calling
    /// `on_solution` with every improved solution.
    pub fn plan(
        &mut self,
        start: &Start,
        goal: [f64; 2],
        search: SearchKind,
        termination: &mut Termination<'_>,
        mut on_solution: Option<&mut dyn FnMut(&SolutionReport)>,
    ) -> FootstepPlanResult {
        let started = Instant::now();
        self.model.take_counters();
        self.model.take_tree();
        let checked = self
            .check_goal(goal)
            .map_err(InputError::from)
            .and_then(|()| self.start_state(start));
        let (start_state, start_certificate) = match checked {
            Ok(s) => s,
            Err(error) => return self.invalid(error, started),
        };
        let config = self.model.config();
        let ara = AraStarConfig {
            epsilon0: config.epsilon0,
            decrement: config.epsilon_decrement,
        };
        let problem = FootstepProblem {
            model: &mut self.model,
            goal,
        };
        let result: SearchResult<FootstepState, FootstepAction> = match search {
            SearchKind::AraStar => {
                let mut planner = AraStar::new(problem, start_state, ara);
                if let Some(cb) = on_solution.as_mut() {
                    planner.on_solution(|report, _| cb(report));
                }
                planner.solve(termination)
            }
            SearchKind::Exhaustive => {
                let mut problem = problem;
                let r = dijkstra(&mut problem, start_state, termination);
                if let (Some(cb), Some(report)) = (on_solution.as_mut(), r.solutions.first()) {
                    cb(report);
                }
                r
            }
        };
        self.finish(result, start_certificate, started)
    }

    fn invalid(&mut self, error: InputError, started: Instant) -> FootstepPlanResult {
        let config = self.model.config();
        FootstepPlanResult {
            status: SearchStatus::InvalidInput,
            message: Some(error.message),
            start_off_foothold: error.start_off_foothold,
            footsteps: Vec::new(),
            certificates: Vec::new(),
            start_certificate: None,
            states: Vec::new(),
            cost: None,
            solutions: Vec::new(),
            epsilon0: config.epsilon0,
            decrement: config.epsilon_decrement,
            final_epsilon: config.epsilon0,
            epsilon_bound: f64::INFINITY,
            heuristic: config.heuristic.name().to_owned(),
            bound_guaranteed: false,
            stats: SearchStats::default(),
            model: self.model.take_counters(),
            tree: Vec::new(),
            elapsed_s: started.elapsed().as_secs_f64(),
        }
    }

    fn finish(
        &mut self,
        result: SearchResult<FootstepState, FootstepAction>,
        start: PoseCertificate,
        started: Instant,
    ) -> FootstepPlanResult {
        let mut footsteps = Vec::new();
        let mut certificates = Vec::new();
        let mut start_certificate = None;
        let mut states = Vec::new();
        if let Some(plan) = &result.plan {
            states.clone_from(&plan.states);
            let (_, contacts) = self.model.feet_of(&plan.states[0]);
            for (leg, position) in contacts.iter().enumerate() {
                footsteps.push(Footstep {
                    leg,
                    position: *position,
                });
            }
            // Certificates are a function of the stance alone, so these are
            // the ones the search found (without keeping 18 numbers per edge);
            // the start's is the one `start_state` found (maybe from the
            // measured trunk).
            start_certificate = Some(start);
            for (action, state) in plan.actions.iter().zip(&plan.states[1..]) {
                footsteps.push(Footstep {
                    leg: usize::from(action.leg),
                    position: self.model.cost_map().contact(action.cell),
                });
                if let Ok(c) = self.model.certify(state) {
                    certificates.push(c);
                }
            }
        }
        FootstepPlanResult {
            status: result.status,
            message: result.message,
            start_off_foothold: None,
            footsteps,
            certificates,
            start_certificate,
            states,
            cost: result.plan.as_ref().map(|p| p.cost),
            solutions: result.solutions,
            epsilon0: result.epsilon0,
            decrement: result.decrement,
            final_epsilon: result.final_epsilon,
            epsilon_bound: result.epsilon_bound,
            heuristic: result.heuristic,
            bound_guaranteed: result.bound_guaranteed,
            stats: result.stats,
            model: self.model.take_counters(),
            tree: self.model.take_tree(),
            elapsed_s: started.elapsed().as_secs_f64(),
        }
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
pub(crate) mod tests {
    use super::*;
    use crate::footstep::config::HeuristicKind;
    use crate::kinematics::math::{norm, sub};
    pub use crate::testing::{planner, test_config};

    fn run(
        p: &mut FootstepPlanner,
        start: Start,
        goal: [f64; 2],
        search: SearchKind,
        budget: Option<u64>,
    ) -> FootstepPlanResult {
        let mut t = budget.map_or_else(Termination::never, Termination::expansions);
        p.plan(&start, goal, search, &mut t, None)
    }

    /// Checks every step of a plan against the model's own rules.
    fn check_plan(p: &FootstepPlanner, r: &FootstepPlanResult) {
        let m = p.model();
        assert_eq!(r.footsteps.len(), 3 + r.states.len());
        assert_eq!(r.certificates.len(), r.states.len() - 1);
        for (k, (cert, state)) in r.certificates.iter().zip(&r.states[1..]).enumerate() {
            let (centres, _) = m.feet_of(state);
            let reached = m
                .robot()
                .quadruped
                .foot_positions_world(cert.base_pos, cert.base_quat, &cert.q)
                .unwrap();
            for i in 0..4 {
                assert!(norm(sub(reached[i], centres[i])) < 1e-9, "step {k} leg {i}");
            }
            assert!(cert.com_margin >= m.config().certificate.com_margin);
            let prev = &r.states[k];
            let moved: Vec<usize> = (0..4).filter(|&i| prev.feet[i] != state.feet[i]).collect();
            assert!(moved.len() <= 1);
            let step = r.footsteps[4 + k];
            let leg = prev.moving_leg(&m.config().walking_order);
            assert_eq!(step.leg, leg);
            let (a, b) = (
                m.lattice().xy(prev.feet[leg]),
                m.lattice().xy(state.feet[leg]),
            );
            assert!((a[0] - b[0]).hypot(a[1] - b[1]) <= m.config().max_foot_travel + 1e-12);
        }
    }

    #[test]
    fn footstep_planner_walks_across_flat_ground_deterministically() {
        let mut p = planner(0.8, |_, _| 0.0, |_, _| 1.0, test_config());
        let start = Start::Pose {
            x: 0.15,
            y: 0.0,
            yaw: 0.0,
        };
        let r = run(&mut p, start, [0.5, 0.0], SearchKind::AraStar, Some(3000));
        assert!(r.status.is_solved(), "{:?} {:?}", r.status, r.message);
        check_plan(&p, &r);
        let last = r.states.last().unwrap();
        let c = p.model().lattice().centroid(last);
        assert!((c[0] - 0.5).hypot(c[1]) <= p.model().config().goal_radius + 1e-12);
        assert!(r.model.certificates_computed > 0);
        assert_eq!(r.stats.actions_evaluated, r.model.certificates_computed);
        assert!(!r.tree.is_empty());
        assert!(r.solutions.windows(2).all(|w| w[1].cost < w[0].cost));
        // Same inputs and budget, same plan (the warm cache changes nothing
        // but the count of certificates computed).
        let again = run(&mut p, start, [0.5, 0.0], SearchKind::AraStar, Some(3000));
        assert_eq!(again.states, r.states);
        assert_eq!(again.cost, r.cost);
        assert!(again.model.certificates_computed < r.model.certificates_computed);
    }

    #[test]
    fn footstep_arastar_at_epsilon_one_matches_the_exhaustive_optimum() {
        // Coarse lattice, a handful of actions, uneven costs: small enough to
        // search exhaustively.
        let mut config = test_config();
        config.resolution = 0.01;
        config.local_search_radius = 0.0;
        config.actions = vec![
            [0.0, 0.0, 0.0],
            [0.02, 0.0, 0.0],
            [0.04, 0.0, 0.0],
            [0.02, 0.01, 0.0],
            [0.02, -0.01, 0.0],
        ];
        config.heuristic = HeuristicKind::Euclidean;
        config.epsilon0 = 1.0;
        let cost = |x: f64, y: f64| 1.0 + 0.8 * ((25.0 * x).sin() * (30.0 * y).cos()).abs();
        let mut p = planner(0.5, |_, _| 0.0, cost, config);
        let start = Start::Pose {
            x: 0.15,
            y: 0.0,
            yaw: 0.0,
        };
        let goal = [0.24, 0.0];
        let ara = run(&mut p, start, goal, SearchKind::AraStar, None);
        let exact = run(&mut p, start, goal, SearchKind::Exhaustive, None);
        assert_eq!(exact.status, SearchStatus::Exact);
        assert_eq!(ara.status, SearchStatus::Exact);
        assert!(ara.bound_guaranteed && ara.epsilon_bound == 1.0);
        let (a, e) = (ara.cost.unwrap(), exact.cost.unwrap());
        assert!((a - e).abs() < 1e-9, "ARA* {a} vs exhaustive {e}");
        assert!(
            exact.states.len() > 4,
            "a non-trivial optimum: {}",
            exact.states.len()
        );
        check_plan(&p, &ara);
    }

    #[test]
    fn footstep_island_is_infeasible_once_open_is_exhausted() {
        let mut config = test_config();
        config.resolution = 0.02;
        config.local_search_radius = 0.0;
        // Four 6 cm pads under the start feet in a sea of cells no foot may
        // take, wider than any step: the search must try every stance on
        // the pads before it gives up.
        let pads = |x: f64, y: f64| {
            let near = |cx: f64, cy: f64| (x - cx).abs() <= 0.031 && (y - cy).abs() <= 0.031;
            if [0.108, 0.292]
                .iter()
                .any(|&cx| near(cx, 0.06) || near(cx, -0.06))
            {
                1.0
            } else {
                f64::INFINITY
            }
        };
        let mut p = planner(0.9, |_, _| 0.0, pads, config);
        let start = Start::Pose {
            x: 0.2,
            y: 0.0,
            yaw: 0.0,
        };
        let r = run(&mut p, start, [0.75, 0.0], SearchKind::AraStar, None);
        assert_eq!(r.status, SearchStatus::Infeasible, "{:?}", r.message);
        assert_eq!(r.status.issue_status(), "infeasible");
        assert!(r.stats.expansions > 10 && r.footsteps.is_empty());
        // 9 cells per pad: at most 9⁴ stances × 4 legs to move next.
        assert!(r.stats.states_generated <= 4 * 9u64.pow(4));
    }

    #[test]
    fn footstep_bad_input_is_invalid_with_a_reason() {
        // A 16 cm post at (0.45, 0.2): a trunk standing over it collides.
        let post = |x: f64, y: f64| {
            if (x - 0.45).hypot(y - 0.2) < 0.03 {
                0.16
            } else {
                0.0
            }
        };
        let mut p = planner(0.8, post, |_, _| 1.0, test_config());
        let ok = Start::Pose {
            x: 0.2,
            y: 0.0,
            yaw: 0.0,
        };
        let cases = [
            (ok, [1.5, 0.0], "off the terrain"),
            (ok, [f64::NAN, 0.0], "finite"),
            (
                Start::Pose {
                    x: f64::NAN,
                    y: 0.0,
                    yaw: 0.0,
                },
                [0.5, 0.0],
                "finite",
            ),
            (
                Start::Pose {
                    x: 0.02,
                    y: 0.0,
                    yaw: 0.0,
                },
                [0.5, 0.0],
                "off the terrain",
            ),
            (
                Start::Pose {
                    x: 0.45,
                    y: 0.2,
                    yaw: 0.0,
                },
                [0.6, 0.0],
                "collision or out of reach",
            ),
            (
                Start::Feet {
                    feet: [[0.65, 0.06], [0.29, -0.06], [0.11, 0.06], [0.11, -0.06]],
                    next_leg: 2,
                    trunk: None,
                },
                [0.6, 0.0],
                "out of reach",
            ),
            (
                Start::Feet {
                    feet: [[0.3, 0.06], [0.3, -0.06], [0.11, 0.06], [0.11, -0.06]],
                    next_leg: 7,
                    trunk: None,
                },
                [0.6, 0.0],
                "next_leg",
            ),
        ];
        for (start, goal, reason) in cases {
            let r = run(&mut p, start, goal, SearchKind::AraStar, Some(10));
            assert_eq!(r.status, SearchStatus::InvalidInput, "{start:?} {goal:?}");
            assert_eq!(r.start_off_foothold, None, "{start:?} {goal:?}");
            let m = r.message.unwrap();
            assert!(m.contains(reason), "{m}");
        }
    }

    #[test]
    fn footstep_start_foot_on_no_foothold_is_named_by_its_leg() {
        // No foothold within 3 cm of RF's nominal spot for a start at x = 0.2
        // (the nominal stance puts RF at (0.292, -0.06)).
        let hole = |x: f64, y: f64| {
            if (x - 0.292).hypot(y + 0.06) < 0.03 {
                f64::INFINITY
            } else {
                1.0
            }
        };
        let mut p = planner(0.8, |_, _| 0.0, hole, test_config());
        let start = Start::Pose {
            x: 0.2,
            y: 0.0,
            yaw: 0.0,
        };
        let r = run(&mut p, start, [0.6, 0.0], SearchKind::AraStar, Some(10));
        assert_eq!(r.status, SearchStatus::InvalidInput);
        assert_eq!(r.start_off_foothold, Some(1), "{:?}", r.message);
        assert!(r.message.unwrap().contains("foot RF"));
        // The same start beside the hole plans: the field is only set when
        // a start foot is on no foothold.
        let beside = Start::Pose {
            x: 0.2,
            y: 0.1,
            yaw: 0.0,
        };
        let r = run(&mut p, beside, [0.6, 0.1], SearchKind::AraStar, Some(3000));
        assert!(r.status.is_solved(), "{:?} {:?}", r.status, r.message);
        assert_eq!(r.start_off_foothold, None);
    }
}

//! Every number of the footstep planner, per robot (the Python
//! `FootstepConfig.for_robot` scales the defaults to the robot's size).

use crate::error::{CoreError, CoreResult};

/// Which cost-to-go estimate guides the search (Zucker 2011, §4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeuristicKind {
    /// Arc-then-line length of a forward-only car on the feet's centroid and
    /// heading, times a typical cost per metre. Informed, not admissible.
    Dubins,
    /// Straight-line distance to the goal disc times the least cost any plan
    /// pays per metre of centroid travel: admissible and consistent.
    Euclidean,
}

impl HeuristicKind {
    /// `"dubins"` or `"euclidean"`.
    pub fn name(self) -> &'static str {
        match self {
            HeuristicKind::Dubins => "dubins",
            HeuristicKind::Euclidean => "euclidean",
        }
    }

    /// Parses `"dubins"` or `"euclidean"`.
    pub fn parse(name: &str) -> CoreResult<Self> {
        match name {
            "dubins" => Ok(HeuristicKind::Dubins),
            "euclidean" => Ok(HeuristicKind::Euclidean),
            other => Err(CoreError::Planning(format!(
                "unknown heuristic '{other}'; known: dubins, euclidean"
            ))),
        }
    }
}

/// The pose-certificate search (Zucker 2011, §4.4) and the pose penalties
/// of §4.3.
#[derive(Debug, Clone, PartialEq)]
pub struct CertificateConfig {
    /// Most trunk corrections before giving up (the paper's 25).
    pub max_iterations: usize,
    /// The search also gives up when its total violation (foot errors, CoM
    /// and clearance deficits) has not dropped a tenth below its best for
    /// this many rounds: stuck, typically a shin against a rock no trunk
    /// motion frees. On rough boards most rejected actions end this way,
    /// and running them to `max_iterations` would cost most of the time.
    pub stall_rounds: usize,
    /// Translation step α of the reachability correction (§3.2) [1].
    pub alpha_reach: f64,
    /// Rotation step β of the reachability correction [rad/m²].
    pub beta_reach: f64,
    /// How far past the closest reachable point the reachability correction
    /// aims [m], so that it ends inside the workspace instead of creeping
    /// toward its boundary.
    pub reach_overshoot: f64,
    /// Translation step α of the obstacle-avoidance correction (§3.4) [1].
    pub alpha_obstacle: f64,
    /// Rotation step β of the obstacle-avoidance correction [rad/m²].
    pub beta_obstacle: f64,
    /// The centre of mass must lie this far inside the support triangle [m].
    pub com_margin: f64,
    /// Longest trunk translation per round, all corrections together [m].
    pub max_step: f64,
    /// Largest trunk rotation per round [rad].
    pub max_turn: f64,
    /// The search gives up once the trunk is this far from its guessed
    /// position [m]: near a singular leg the §3.4 Jacobians blow up and
    /// would fling it away.
    pub max_drift: f64,
    /// Least distance between the robot (feet excluded) and the terrain [m].
    pub clearance: f64,
    /// Least body clearance [m] of a re-plan's start certificate searched
    /// from the measured trunk, as the distance field reads it (its error
    /// bound not added: the robot already stands there). Only the start:
    /// every planned stance needs `clearance`.
    pub start_clearance: f64,
    /// How far past `clearance` the obstacle correction aims [m].
    pub clearance_overshoot: f64,
    /// Clearance below which the pose cost rises [m] (≥ `clearance`).
    pub preferred_clearance: f64,
    /// Pose cost added at `clearance`, falling linearly to 0 at
    /// `preferred_clearance` [cost].
    pub clearance_penalty: f64,
    /// Legs whose normalised foot-Jacobian volume |det J| / Π|J_k| (1 far
    /// from singular, 0 singular) is below this pay a penalty [1].
    pub singularity_margin: f64,
    /// Pose cost per leg at a singular configuration, falling linearly to 0
    /// at `singularity_margin` [cost].
    pub singularity_penalty: f64,
    /// Largest roll or pitch of the heuristic starting pose [rad].
    pub max_tilt: f64,
}

/// The footstep planner's settings. Lengths [m], angles [rad], costs
/// dimensionless (a flat foothold costs 1).
#[derive(Debug, Clone, PartialEq)]
pub struct FootstepConfig {
    /// Foothold lattice spacing [m].
    pub resolution: f64,
    /// Radius [m] of the disc over which a foothold's normal is the mean
    /// slope ([`HeightField::disc_normal`](crate::heightfield::HeightField::disc_normal)),
    /// the normal along which the foot centre sits; 0 takes the bilinear
    /// normal at the contact point alone.
    pub normal_radius: f64,
    /// Footstep displacements (dx, dy, dθ) of the moving leg in the heading
    /// frame [m, m, rad] (12–25 of them in the paper).
    pub actions: Vec<[f64; 3]>,
    /// Canonical leg indices (0 LF, 1 RF, 2 LH, 3 RH) in the order they step.
    pub walking_order: [usize; 4],
    /// Radius of the local search for a cheaper foothold around each action's
    /// target [m] (Zucker 2011, footnote 1); 0 disables it.
    pub local_search_radius: f64,
    /// Cost added per `local_search_radius` of distance from the target, so
    /// that ties go to the action's own target [cost].
    pub local_search_penalty: f64,
    /// Longest horizontal move of one foot in one step [m]. Also bounds the
    /// centroid's progress per step, which makes the Euclidean heuristic
    /// admissible.
    pub max_foot_travel: f64,
    /// Least horizontal distance between two feet [m].
    pub min_foot_separation: f64,
    /// Left feet must stay this far left of right feet, and front feet this
    /// far ahead of hind feet, in the heading frame [m] (no leg crossing).
    pub crossing_margin: f64,
    /// Constant cost of every step [cost].
    pub step_cost: f64,
    /// Support-triangle incircle radius below which the pose cost rises [m].
    pub incircle_preferred: f64,
    /// Support triangles with a smaller incircle radius are refused [m].
    pub incircle_min: f64,
    /// Pose cost at `incircle_min`, falling linearly to 0 at
    /// `incircle_preferred` [cost].
    pub incircle_penalty: f64,
    /// The pose-certificate search.
    pub certificate: CertificateConfig,
    /// The goal is reached when the feet's centroid is this close to it [m].
    pub goal_radius: f64,
    /// Which heuristic guides the search.
    pub heuristic: HeuristicKind,
    /// Turning radius of the Dubins car [m].
    pub turning_radius: f64,
    /// Cost per metre of the Dubins heuristic; 0 picks the cost of a flat
    /// step over the centroid's progress per step at the longest forward
    /// action [cost/m].
    pub dubins_cost_per_metre: f64,
    /// Initial heuristic inflation ε₀ of ARA* (≥ 1).
    pub epsilon0: f64,
    /// Step by which ε decreases after each ARA* iteration (> 0).
    pub epsilon_decrement: f64,
    /// Most search-tree edges kept for pictures (0 keeps none).
    pub max_tree_edges: usize,
    /// Most certificate outcomes kept in the cache shared by plans and
    /// re-plans on the same terrain; when full, the half least recently
    /// used is dropped.
    pub cache_capacity: usize,
}

fn positive(name: &str, v: f64) -> CoreResult<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(CoreError::Planning(format!(
            "footstep config: {name} must be finite and > 0, got {v}"
        )))
    }
}

fn non_negative(name: &str, v: f64) -> CoreResult<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(CoreError::Planning(format!(
            "footstep config: {name} must be finite and >= 0, got {v}"
        )))
    }
}

impl CertificateConfig {
    /// Checks every field.
    pub fn validate(&self) -> CoreResult<()> {
        if self.max_iterations == 0 || self.stall_rounds == 0 {
            return Err(CoreError::Planning(format!(
                "footstep config: certificate.max_iterations ({}) and stall_rounds ({}) must be >= 1",
                self.max_iterations, self.stall_rounds
            )));
        }
        for (name, v) in [
            ("certificate.alpha_reach", self.alpha_reach),
            ("certificate.beta_reach", self.beta_reach),
            ("certificate.reach_overshoot", self.reach_overshoot),
            ("certificate.alpha_obstacle", self.alpha_obstacle),
            ("certificate.beta_obstacle", self.beta_obstacle),
            ("certificate.com_margin", self.com_margin),
            ("certificate.clearance", self.clearance),
            ("certificate.start_clearance", self.start_clearance),
            ("certificate.clearance_overshoot", self.clearance_overshoot),
            ("certificate.clearance_penalty", self.clearance_penalty),
            ("certificate.singularity_margin", self.singularity_margin),
            ("certificate.singularity_penalty", self.singularity_penalty),
            ("certificate.max_tilt", self.max_tilt),
        ] {
            non_negative(name, v)?;
        }
        positive("certificate.max_step", self.max_step)?;
        positive("certificate.max_turn", self.max_turn)?;
        positive("certificate.max_drift", self.max_drift)?;
        if !(self.preferred_clearance.is_finite() && self.preferred_clearance >= self.clearance) {
            return Err(CoreError::Planning(format!(
                "footstep config: certificate.preferred_clearance must be >= clearance ({}), got {}",
                self.clearance, self.preferred_clearance
            )));
        }
        if self.singularity_margin > 1.0 {
            return Err(CoreError::Planning(format!(
                "footstep config: certificate.singularity_margin is a fraction in [0, 1], got {}",
                self.singularity_margin
            )));
        }
        Ok(())
    }
}

impl FootstepConfig {
    /// Checks every field; the message names the bad one and what is valid.
    pub fn validate(&self) -> CoreResult<()> {
        positive("resolution", self.resolution)?;
        non_negative("normal_radius", self.normal_radius)?;
        if self.actions.is_empty() {
            return Err(CoreError::Planning(
                "footstep config: actions must hold at least one (dx, dy, dtheta)".into(),
            ));
        }
        if let Some(a) = self
            .actions
            .iter()
            .find(|a| !a.iter().all(|v| v.is_finite()))
        {
            return Err(CoreError::Planning(format!(
                "footstep config: action {a:?} is not finite"
            )));
        }
        let mut seen = [false; 4];
        for &leg in &self.walking_order {
            if leg > 3 || seen[leg] {
                return Err(CoreError::Planning(format!(
                    "footstep config: walking_order must be a permutation of 0..4 (LF, RF, LH, RH), got {:?}",
                    self.walking_order
                )));
            }
            seen[leg] = true;
        }
        non_negative("local_search_radius", self.local_search_radius)?;
        non_negative("local_search_penalty", self.local_search_penalty)?;
        positive("max_foot_travel", self.max_foot_travel)?;
        non_negative("min_foot_separation", self.min_foot_separation)?;
        if !self.crossing_margin.is_finite() {
            return Err(CoreError::Planning(format!(
                "footstep config: crossing_margin must be finite, got {}",
                self.crossing_margin
            )));
        }
        positive("step_cost", self.step_cost)?;
        non_negative("incircle_min", self.incircle_min)?;
        non_negative("incircle_penalty", self.incircle_penalty)?;
        if !(self.incircle_preferred.is_finite() && self.incircle_preferred >= self.incircle_min) {
            return Err(CoreError::Planning(format!(
                "footstep config: incircle_preferred must be >= incircle_min ({}), got {}",
                self.incircle_min, self.incircle_preferred
            )));
        }
        self.certificate.validate()?;
        positive("goal_radius", self.goal_radius)?;
        non_negative("turning_radius", self.turning_radius)?;
        non_negative("dubins_cost_per_metre", self.dubins_cost_per_metre)?;
        if !(self.epsilon0.is_finite() && self.epsilon0 >= 1.0) {
            return Err(CoreError::Planning(format!(
                "footstep config: epsilon0 must be finite and >= 1, got {}",
                self.epsilon0
            )));
        }
        positive("epsilon_decrement", self.epsilon_decrement)?;
        Ok(())
    }

    /// The longest forward component of any action [m] (0 if none goes forward).
    pub fn longest_forward_action(&self) -> f64 {
        self.actions.iter().map(|a| a[0]).fold(0.0, f64::max)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub use crate::testing::test_config;

    #[test]
    fn footstep_config_validation_names_the_field() {
        assert!(test_config().validate().is_ok());
        let mut c = test_config();
        c.walking_order = [0, 0, 1, 2];
        assert!(matches!(c.validate(), Err(CoreError::Planning(m)) if m.contains("walking_order")));
        let mut c = test_config();
        c.certificate.preferred_clearance = 0.0;
        assert!(
            matches!(c.validate(), Err(CoreError::Planning(m)) if m.contains("preferred_clearance"))
        );
        let mut c = test_config();
        c.resolution = f64::NAN;
        assert!(matches!(c.validate(), Err(CoreError::Planning(m)) if m.contains("resolution")));
        let mut c = test_config();
        c.epsilon0 = 0.5;
        assert!(matches!(c.validate(), Err(CoreError::Planning(m)) if m.contains("epsilon0")));
        assert_eq!(HeuristicKind::parse("dubins").unwrap().name(), "dubins");
        assert!(HeuristicKind::parse("manhattan").is_err());
    }
}

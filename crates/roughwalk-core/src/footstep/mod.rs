//! The anytime footstep planner of Zucker 2011, §4: ARA* over four-foot
//! states on a foothold lattice, with the learned terrain cost, support
//! triangle and pose-certificate costs, and the Dubins heuristic.
//!
//! The search itself is the generic [`crate::search::AraStar`]; this module
//! supplies the graph ([`FootstepProblem`]) and runs it ([`FootstepPlanner`]).
//! One concept per file: [`config`] (every number), [`state`] (states and
//! the lattice), [`actions`] (action targets and the local search),
//! [`cost_map`] (footholds and terrain costs on the lattice),
//! [`mass_model`] (whole-body centre of mass), [`collision`] (capsules vs
//! the distance field), [`certificate`] (§4.4), [`certificate_cache`]
//! (certificate outcomes kept across plans), [`model`] (successors,
//! costs, heuristic), [`planner`] (the plan call).

pub mod actions;
pub mod certificate;
pub mod certificate_cache;
pub mod collision;
pub mod config;
pub mod cost_map;
pub mod mass_model;
pub mod model;
pub mod planner;
pub mod state;

pub use certificate::{CertificateFailure, CertificateSearch, PoseCertificate};
pub use collision::{Capsule, Clearance, CollisionModel};
pub use config::{CertificateConfig, FootstepConfig, HeuristicKind};
pub use cost_map::CostMap;
pub use mass_model::MassModel;
pub use model::{
    FootstepAction, FootstepModel, FootstepProblem, FootstepRobot, ModelCounters, TreeEdge,
};
pub use planner::{Footstep, FootstepPlanResult, FootstepPlanner, SearchKind, Start};
pub use state::{Cell, FootstepState, Lattice};

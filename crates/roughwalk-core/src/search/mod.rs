//! Heuristic graph search: anytime ARA* and an exact Dijkstra, generic over
//! the graph through [`SearchProblem`] (the footstep model implements it).
//!
//! Planners share one interface: `solve(termination)` returns a
//! [`SearchResult`] holding a [`SearchStatus`], the plan, every improved
//! solution and the statistics; [`Termination`] combines time, expansion
//! and callback budgets.

mod arastar;
mod dijkstra;
pub mod grid_world;
mod interner;
mod problem;
mod result;
mod termination;

pub use arastar::{AraStar, AraStarConfig};
pub use dijkstra::{dijkstra, dijkstra_costs};
pub use problem::{SearchProblem, Successor};
pub use result::{IterationStats, Plan, SearchResult, SearchStats, SearchStatus, SolutionReport};
pub use termination::{Progress, Termination};

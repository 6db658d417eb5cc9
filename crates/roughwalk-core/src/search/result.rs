//! What a search returns: a status, the plan, every improved solution and
//! the statistics (OMPL's `PlannerStatus` + `PlannerData`, in one object).

use std::fmt;

/// How a search ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SearchStatus {
    /// Solved, and the plan is proven optimal: ε′ = 1 with a heuristic the
    /// problem declares admissible. With an inadmissible heuristic nothing
    /// is proven, so a solved search is `Approximate` even at ε = 1.
    Exact,
    /// Solved with a bound ε′ > 1, or with a bound that is not guaranteed.
    Approximate,
    /// The budget ran out before any solution was found.
    Timeout,
    /// OPEN was exhausted without reaching a goal: no goal is reachable.
    Infeasible,
    /// The configuration or the problem's numbers were invalid (see the
    /// result's message).
    InvalidInput,
}

impl SearchStatus {
    /// The status string of the footstep-planner issue's JSON results:
    /// `solved`, `no_solution`, `infeasible` or `invalid_input`.
    pub fn issue_status(self) -> &'static str {
        match self {
            SearchStatus::Exact | SearchStatus::Approximate => "solved",
            SearchStatus::Timeout => "no_solution",
            SearchStatus::Infeasible => "infeasible",
            SearchStatus::InvalidInput => "invalid_input",
        }
    }

    /// Whether a plan was found.
    pub fn is_solved(self) -> bool {
        matches!(self, SearchStatus::Exact | SearchStatus::Approximate)
    }
}

impl fmt::Display for SearchStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SearchStatus::Exact => "exact",
            SearchStatus::Approximate => "approximate",
            SearchStatus::Timeout => "timeout",
            SearchStatus::Infeasible => "infeasible",
            SearchStatus::InvalidInput => "invalid_input",
        })
    }
}

/// A path from the start to a goal.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan<S, A> {
    /// States from the start to the goal, both included.
    pub states: Vec<S>,
    /// `actions[i]` leads from `states[i]` to `states[i + 1]`.
    pub actions: Vec<A>,
    /// Sum of the edge costs along the path.
    pub cost: f64,
}

/// One improved solution of an anytime search, as it was found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolutionReport {
    /// Time since `solve` started [s].
    pub time_s: f64,
    /// Cost of the plan.
    pub cost: f64,
    /// The inflation ε of the iteration that found it.
    pub epsilon: f64,
    /// The suboptimality bound ε′ ≥ 1 of this plan: cost ≤ ε′ · optimum when
    /// the result's `bound_guaranteed` is true.
    pub epsilon_bound: f64,
    /// States expanded when it was found.
    pub expansions: u64,
    /// False for a plan taken from an iteration the budget interrupted: its
    /// bound then rests on the last finished iteration and on OPEN ∪ INCONS.
    pub iteration_complete: bool,
}

/// One ARA* iteration (one ImprovePath call).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IterationStats {
    /// Its inflation ε.
    pub epsilon: f64,
    /// States it expanded.
    pub expansions: u64,
    /// False if the budget stopped it.
    pub completed: bool,
}

/// Counters of one `solve` call.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SearchStats {
    /// States expanded, summed over iterations.
    pub expansions: u64,
    /// Distinct states generated (interned).
    pub states_generated: u64,
    /// Actions whose full cost was computed, as the problem counted them.
    pub actions_evaluated: u64,
    /// Wall-clock time of the call [s].
    pub elapsed_s: f64,
    /// Every iteration run, in order.
    pub iterations: Vec<IterationStats>,
}

impl SearchStats {
    /// Actions evaluated per second of the call [1/s].
    pub fn actions_per_second(&self) -> f64 {
        rate(self.actions_evaluated, self.elapsed_s)
    }

    /// States expanded per second of the call [1/s].
    pub fn expansions_per_second(&self) -> f64 {
        rate(self.expansions, self.elapsed_s)
    }
}

fn rate(count: u64, seconds: f64) -> f64 {
    if seconds > 0.0 {
        count as f64 / seconds
    } else {
        0.0
    }
}

/// Everything a search returns.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchResult<S, A> {
    /// How the search ended.
    pub status: SearchStatus,
    /// Why the input was invalid (`InvalidInput` only).
    pub message: Option<String>,
    /// The best plan found, if any.
    pub plan: Option<Plan<S, A>>,
    /// Every improved solution in the order found (costs strictly decrease).
    pub solutions: Vec<SolutionReport>,
    /// Initial inflation ε₀.
    pub epsilon0: f64,
    /// Step by which ε decreases after each iteration.
    pub decrement: f64,
    /// ε of the last iteration run (finished or interrupted).
    pub final_epsilon: f64,
    /// Suboptimality bound ε′ of the returned plan (∞ without a plan).
    pub epsilon_bound: f64,
    /// Which heuristic guided the search.
    pub heuristic: String,
    /// Whether `epsilon_bound` is proven: the problem declared its heuristic
    /// admissible. False means ε′ is only what ARA* would claim.
    pub bound_guaranteed: bool,
    /// Counters.
    pub stats: SearchStats,
}

impl<S, A> SearchResult<S, A> {
    /// Cost of the plan, if one was found.
    pub fn cost(&self) -> Option<f64> {
        self.plan.as_ref().map(|p| p.cost)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn search_status_maps_to_the_issue_strings() {
        assert_eq!(SearchStatus::Exact.issue_status(), "solved");
        assert_eq!(SearchStatus::Approximate.issue_status(), "solved");
        assert_eq!(SearchStatus::Timeout.issue_status(), "no_solution");
        assert_eq!(SearchStatus::Infeasible.issue_status(), "infeasible");
        assert_eq!(SearchStatus::InvalidInput.issue_status(), "invalid_input");
        assert!(SearchStatus::Approximate.is_solved());
        assert!(!SearchStatus::Timeout.is_solved());
        assert_eq!(SearchStatus::InvalidInput.to_string(), "invalid_input");
    }
}

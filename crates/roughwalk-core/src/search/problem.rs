//! The graph a search runs on, as the caller supplies it.
//!
//! Search code does not own the world: ARA* and Dijkstra only ask a
//! [`SearchProblem`] for successors, edge costs, a heuristic and a goal test,
//! so the same search runs on toy graphs in tests and on the footstep model.

use std::hash::Hash;

/// One outgoing edge produced by [`SearchProblem::successors`].
#[derive(Debug, Clone, PartialEq)]
pub struct Successor<S, A> {
    /// The state the action leads to.
    pub state: S,
    /// Edge cost: finite and > 0, or `f64::INFINITY` for a disallowed action
    /// (the search skips it). Zero, negative or NaN costs make the search
    /// stop with `InvalidInput`.
    pub cost: f64,
    /// Payload handed back in the plan for this edge (e.g. the footstep and
    /// its pose certificate), so the model need not recompute it.
    pub action: A,
}

/// A graph with positive edge costs, a heuristic and a goal predicate.
///
/// Every method takes `&mut self` so that the model can cache: a footstep
/// model's action evaluations (pose-certificate searches) are expensive and
/// a re-plan from a new start revisits many of the same states.
pub trait SearchProblem {
    /// A search state. The search interns each distinct state once, so
    /// `Clone` is called once per new state, `Hash`/`Eq` once per generated edge.
    type State: Clone + Eq + Hash;
    /// The payload of an edge, returned with the plan.
    type Action: Clone;

    /// Appends the outgoing edges of `state` to `out` (which arrives empty)
    /// and returns how many actions were *evaluated*.
    ///
    /// An action counts as evaluated when its full cost was computed,
    /// certificate search included, whether or not it was then rejected: a
    /// model that rejects an action after evaluating it either leaves it out
    /// of `out` or pushes it with an infinite cost, and counts it in the
    /// return value either way. Toy graphs simply return `out.len()`.
    fn successors(
        &mut self,
        state: &Self::State,
        out: &mut Vec<Successor<Self::State, Self::Action>>,
    ) -> usize;

    /// Estimated cost-to-go h(s) ≥ 0 from `state` to the nearest goal.
    ///
    /// `f64::INFINITY` declares a dead end: the state is never expanded. NaN
    /// or negative values stop the search with `InvalidInput`. Called once
    /// per distinct non-goal state; goal states get h = 0 without a call.
    fn heuristic(&mut self, state: &Self::State) -> f64;

    /// Whether `state` is a goal. Goals end a path and are never expanded.
    /// Called once per distinct state.
    fn is_goal(&mut self, state: &Self::State) -> bool;

    /// The caller's promise that h never overestimates the cost-to-go
    /// (h(s) ≤ h*(s)). Only then is a reported bound ε′ guaranteed and can a
    /// result be `Exact`. Defaults to `false`.
    fn heuristic_is_admissible(&self) -> bool {
        false
    }

    /// The caller's promise that h is consistent (h(s) ≤ c(s, s′) + h(s′) on
    /// every edge, which with h = 0 at goals implies admissible). ARA*'s own
    /// guarantee g(goal) ≤ ε·g* after an iteration needs it (Likhachev et al.
    /// 2004, Theorem 2); with an admissible but inconsistent h only the
    /// g(goal) / min(g + h) part of ε′ is proven. Defaults to `false`.
    fn heuristic_is_consistent(&self) -> bool {
        false
    }

    /// A name for the heuristic, reported in every result (e.g. `"dubins"`).
    fn heuristic_name(&self) -> String {
        "unspecified".to_owned()
    }
}

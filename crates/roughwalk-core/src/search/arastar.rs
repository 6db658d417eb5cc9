//! Anytime Repairing A* (Likhachev, Gordon & Thrun 2004), generic over the
//! graph: the footstep planner's search (Zucker 2011, §4.5).
//!
//! ARA* runs weighted A* with keys f = g + ε·h for a decreasing schedule
//! ε₀, ε₀ − δ, …, 1. Each iteration (ImprovePath) reuses the previous one's
//! g-values: states whose g dropped after they were closed wait in INCONS
//! and rejoin OPEN, with re-computed keys, for the next iteration, so only
//! the states the smaller ε makes relevant are expanded again. After every
//! iteration the plan's suboptimality bound is
//! ε′ = min(ε, g(goal) / min over OPEN ∪ INCONS of (g + h)),
//! usually far tighter than ε.

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::time::Instant;

use super::interner::Interner;
use super::problem::{SearchProblem, Successor};
use super::result::{
    IterationStats, Plan, SearchResult, SearchStats, SearchStatus, SolutionReport,
};
use super::termination::{Progress, Termination};

/// The ε schedule of ARA*.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AraStarConfig {
    /// Initial inflation ε₀ ≥ 1 of the heuristic. Larger finds a first plan
    /// sooner (fewer expansions) but a worse one; 1 is plain A*.
    pub epsilon0: f64,
    /// Step δ > 0 by which ε decreases after each iteration (ε ← max(1, ε − δ)).
    /// Small steps give many cheap iterations and a smooth stream of plans;
    /// large steps reach the optimal plan with less bookkeeping.
    pub decrement: f64,
}

impl Default for AraStarConfig {
    /// ε₀ = 3, δ = 0.5: a first plan quickly, five iterations to ε = 1.
    fn default() -> Self {
        Self {
            epsilon0: 3.0,
            decrement: 0.5,
        }
    }
}

impl AraStarConfig {
    /// Checks ε₀ ≥ 1 and δ > 0, both finite.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.epsilon0.is_finite() && self.epsilon0 >= 1.0) {
            return Err(format!(
                "epsilon0 must be finite and >= 1, got {}",
                self.epsilon0
            ));
        }
        if !(self.decrement.is_finite() && self.decrement > 0.0) {
            return Err(format!(
                "decrement must be finite and > 0, got {}",
                self.decrement
            ));
        }
        Ok(())
    }
}

/// What receives each improved solution.
type SolutionSink<'cb, S, A> = dyn FnMut(&SolutionReport, &Plan<S, A>) + 'cb;

/// An ARA* planner bound to a problem and a start state.
///
/// Each [`solve`](Self::solve) is a fresh search from the start; the problem
/// (and whatever it caches) is kept across calls, which is what a re-plan
/// after an execution error reuses (see [`replan`](Self::replan)).
pub struct AraStar<'cb, P: SearchProblem> {
    problem: P,
    start: P::State,
    config: AraStarConfig,
    on_solution: Option<Box<SolutionSink<'cb, P::State, P::Action>>>,
}

impl<'cb, P: SearchProblem> AraStar<'cb, P> {
    /// A planner for `problem` from `start` with the ε schedule `config`
    /// (checked when solving: an invalid one gives `InvalidInput`).
    pub fn new(problem: P, start: P::State, config: AraStarConfig) -> Self {
        Self {
            problem,
            start,
            config,
            on_solution: None,
        }
    }

    /// Calls `callback` with every improved solution as soon as it is found
    /// (the anytime stream), before `solve` returns.
    pub fn on_solution(
        &mut self,
        callback: impl FnMut(&SolutionReport, &Plan<P::State, P::Action>) + 'cb,
    ) {
        self.on_solution = Some(Box::new(callback));
    }

    /// Searches from the start until the plan is proven optimal (ε′ = 1),
    /// OPEN is exhausted, or `termination` fires.
    ///
    /// Iterations run ε₀, ε₀ − δ, … down to 1 and stop early once
    /// g(goal) ≤ min over OPEN ∪ INCONS of (g + h), which proves the plan
    /// optimal for an admissible heuristic. At ε = 1 iterations repeat while
    /// INCONS holds states that could still improve the plan (only possible
    /// with an inconsistent heuristic). If the budget interrupts an iteration
    /// that already improved the goal's g, that better plan is returned too.
    pub fn solve(
        &mut self,
        termination: &mut Termination<'_>,
    ) -> SearchResult<P::State, P::Action> {
        let search = Search::new(
            &mut self.problem,
            self.config,
            self.on_solution.as_deref_mut(),
        );
        search.run(self.start.clone(), termination)
    }

    /// Re-plans from `new_start` (e.g. after an execution error) with its own
    /// budget `termination`.
    ///
    /// This is a fresh ARA* search: g-values from the previous start are not
    /// valid from a new one, and ARA* (unlike D*-style planners, which need a
    /// single goal to search backwards from) has no repair for a moved start.
    /// The problem is kept, so its caches of evaluated actions and
    /// certificates make the second search cheaper. `new_start` becomes the
    /// start of later `solve` calls.
    pub fn replan(
        &mut self,
        new_start: P::State,
        termination: &mut Termination<'_>,
    ) -> SearchResult<P::State, P::Action> {
        self.start = new_start;
        self.solve(termination)
    }

    /// The current start state.
    pub fn start(&self) -> &P::State {
        &self.start
    }

    /// The ε schedule.
    pub fn config(&self) -> AraStarConfig {
        self.config
    }

    /// The problem.
    pub fn problem(&self) -> &P {
        &self.problem
    }

    /// The problem, mutably (e.g. to change its costs before a re-plan).
    pub fn problem_mut(&mut self) -> &mut P {
        &mut self.problem
    }

    /// Gives the problem back.
    pub fn into_problem(self) -> P {
        self.problem
    }
}

const NONE: u32 = u32::MAX;

/// Per-state search data.
struct Node {
    g: f64,
    h: f64,
    parent: u32,
    /// Cost of the edge from `parent`, to sum the plan's cost exactly.
    edge_cost: f64,
    /// Sequence number of the state's live OPEN entry (lazy deletion).
    open_seq: u64,
    /// Iteration in which the state was closed (CLOSED ← ∅ is `iter += 1`).
    closed_in: u32,
    /// Iteration in which the state was put in INCONS.
    incons_in: u32,
    goal: bool,
}

/// An OPEN entry, ordered so that `BinaryHeap` pops the least key first.
/// Ties break on smaller h (deeper states), then on insertion order, so
/// identical inputs give identical plans.
#[derive(Clone, Copy)]
struct OpenEntry {
    f: f64,
    h: f64,
    seq: u64,
    idx: u32,
}

impl Ord for OpenEntry {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .f
            .total_cmp(&self.f)
            .then(other.h.total_cmp(&self.h))
            .then(other.seq.cmp(&self.seq))
    }
}

impl PartialOrd for OpenEntry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for OpenEntry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for OpenEntry {}

enum Outcome {
    Finished,
    Interrupted,
}

/// The state of one `solve` call.
struct Search<'a, 'cb, P: SearchProblem> {
    problem: &'a mut P,
    config: AraStarConfig,
    on_solution: Option<&'a mut SolutionSink<'cb, P::State, P::Action>>,
    states: Interner<P::State>,
    nodes: Vec<Node>,
    actions: Vec<Option<P::Action>>,
    open: BinaryHeap<OpenEntry>,
    incons: Vec<u32>,
    buf: Vec<Successor<P::State, P::Action>>,
    iter: u32,
    seq: u64,
    epsilon: f64,
    /// ε of the last finished iteration (∞ before the first).
    completed_epsilon: f64,
    completed_iterations: usize,
    best_goal: u32,
    plan: Option<Plan<P::State, P::Action>>,
    bound: f64,
    solutions: Vec<SolutionReport>,
    stats: SearchStats,
    started: Instant,
    admissible: bool,
    consistent: bool,
}

impl<'a, 'cb, P: SearchProblem> Search<'a, 'cb, P> {
    fn new(
        problem: &'a mut P,
        config: AraStarConfig,
        on_solution: Option<&'a mut SolutionSink<'cb, P::State, P::Action>>,
    ) -> Self {
        let consistent = problem.heuristic_is_consistent();
        let admissible = consistent || problem.heuristic_is_admissible();
        Self {
            problem,
            config,
            on_solution,
            states: Interner::new(),
            nodes: Vec::new(),
            actions: Vec::new(),
            open: BinaryHeap::new(),
            incons: Vec::new(),
            buf: Vec::new(),
            iter: 1,
            seq: 0,
            epsilon: config.epsilon0,
            completed_epsilon: f64::INFINITY,
            completed_iterations: 0,
            best_goal: NONE,
            plan: None,
            bound: f64::INFINITY,
            solutions: Vec::new(),
            stats: SearchStats::default(),
            started: Instant::now(),
            admissible,
            consistent,
        }
    }

    fn run(
        mut self,
        start: P::State,
        termination: &mut Termination<'_>,
    ) -> SearchResult<P::State, P::Action> {
        if let Err(message) = self.config.validate() {
            return self.finish(SearchStatus::InvalidInput, Some(message));
        }
        let s = match self.intern(start) {
            Ok(s) => s,
            Err(message) => return self.finish(SearchStatus::InvalidInput, Some(message)),
        };
        self.nodes[s as usize].g = 0.0;
        if self.nodes[s as usize].goal {
            // A zero-cost plan is optimal whatever the heuristic.
            self.best_goal = s;
            self.bound = 1.0;
            self.publish(1.0, true);
            return self.finish(SearchStatus::Exact, None);
        }
        self.push_open(s);

        loop {
            self.stats.iterations.push(IterationStats {
                epsilon: self.epsilon,
                expansions: 0,
                completed: false,
            });
            match self.improve_path(termination) {
                Err(message) => return self.finish(SearchStatus::InvalidInput, Some(message)),
                Ok(Outcome::Interrupted) => return self.finish_interrupted(),
                Ok(Outcome::Finished) => {}
            }
            let iteration = self.stats.iterations.last_mut().expect("pushed above");
            iteration.completed = true;
            let expanded_nothing = iteration.expansions == 0;
            if self.best_goal == NONE {
                // ImprovePath only finishes without a goal when OPEN is empty.
                return self.finish(SearchStatus::Infeasible, None);
            }
            self.completed_epsilon = self.epsilon;
            self.completed_iterations += 1;
            let lower = self.min_open_incons();
            self.bound = self.bound.min(self.epsilon_bound(lower));
            self.publish(self.epsilon, true);
            let proven = self.goal_g() <= lower;
            let at_fixpoint = self.epsilon <= 1.0 && (self.consistent || expanded_nothing);
            if proven || at_fixpoint || termination.should_stop(&self.progress()) {
                let status = self.solved_status();
                return self.finish(status, None);
            }
            self.epsilon = (self.epsilon - self.config.decrement).max(1.0);
            self.next_iteration();
        }
    }

    /// One weighted-A* pass with the current ε; stops when no OPEN key is
    /// below f(goal) = g(goal) (h = 0 at goals).
    fn improve_path(&mut self, termination: &mut Termination<'_>) -> Result<Outcome, String> {
        loop {
            let top = loop {
                match self.open.peek() {
                    None => break None,
                    Some(&e) if self.is_live(e) => break Some(e),
                    Some(_) => {
                        self.open.pop();
                    }
                }
            };
            let Some(top) = top else {
                return Ok(Outcome::Finished);
            };
            if self.best_goal != NONE && self.goal_g() <= top.f {
                return Ok(Outcome::Finished);
            }
            if termination.should_stop(&self.progress()) {
                return Ok(Outcome::Interrupted);
            }
            self.open.pop();
            self.expand(top.idx)?;
            self.stats.expansions += 1;
            if let Some(it) = self.stats.iterations.last_mut() {
                it.expansions += 1;
            }
        }
    }

    fn expand(&mut self, s: u32) -> Result<(), String> {
        self.nodes[s as usize].closed_in = self.iter;
        let mut buf = std::mem::take(&mut self.buf);
        buf.clear();
        let evaluated = self.problem.successors(self.states.get(s), &mut buf);
        self.stats.actions_evaluated += evaluated as u64;
        let gs = self.nodes[s as usize].g;
        for Successor {
            state,
            cost,
            action,
        } in buf.drain(..)
        {
            if cost == f64::INFINITY {
                continue;
            }
            if !(cost > 0.0 && cost.is_finite()) {
                return Err(format!(
                    "edge cost {cost} returned by successors(): costs must be finite and > 0 \
                     (or +inf for a disallowed action)"
                ));
            }
            let t = self.intern(state)?;
            let new_g = gs + cost;
            let node = &mut self.nodes[t as usize];
            if new_g >= node.g {
                continue;
            }
            node.g = new_g;
            node.parent = s;
            node.edge_cost = cost;
            self.actions[t as usize] = Some(action);
            if node.goal {
                if self.best_goal == NONE || new_g < self.goal_g() {
                    self.best_goal = t;
                }
            } else if node.h == f64::INFINITY {
                // A declared dead end: never worth expanding.
            } else if node.closed_in == self.iter {
                if node.incons_in != self.iter {
                    node.incons_in = self.iter;
                    self.incons.push(t);
                }
            } else {
                self.push_open(t);
            }
        }
        self.buf = buf;
        Ok(())
    }

    /// Interns `state`, asking the problem for its goal flag and heuristic
    /// the first time it is seen.
    fn intern(&mut self, state: P::State) -> Result<u32, String> {
        let (t, new) = self.states.intern(state);
        if new {
            let st = self.states.get(t);
            let goal = self.problem.is_goal(st);
            let h = if goal {
                0.0
            } else {
                self.problem.heuristic(st)
            };
            if h.is_nan() || h < 0.0 {
                return Err(format!(
                    "heuristic value {h} is invalid: it must be >= 0 (or +inf for a dead end)"
                ));
            }
            self.nodes.push(Node {
                g: f64::INFINITY,
                h,
                parent: NONE,
                edge_cost: 0.0,
                open_seq: u64::MAX,
                closed_in: 0,
                incons_in: 0,
                goal,
            });
            self.actions.push(None);
        }
        Ok(t)
    }

    fn push_open(&mut self, t: u32) {
        self.seq += 1;
        let node = &mut self.nodes[t as usize];
        node.open_seq = self.seq;
        self.open.push(OpenEntry {
            f: node.g + self.epsilon * node.h,
            h: node.h,
            seq: self.seq,
            idx: t,
        });
    }

    fn is_live(&self, e: OpenEntry) -> bool {
        let node = &self.nodes[e.idx as usize];
        node.open_seq == e.seq && node.closed_in != self.iter
    }

    /// OPEN ← OPEN ∪ INCONS with keys for the new ε; CLOSED ← ∅.
    fn next_iteration(&mut self) {
        let old = std::mem::take(&mut self.open).into_vec();
        let mut members: Vec<u32> = old
            .into_iter()
            .filter(|&e| self.is_live(e))
            .map(|e| e.idx)
            .collect();
        members.append(&mut self.incons);
        self.iter += 1;
        let mut entries = Vec::with_capacity(members.len());
        for t in members {
            self.seq += 1;
            let node = &mut self.nodes[t as usize];
            node.open_seq = self.seq;
            entries.push(OpenEntry {
                f: node.g + self.epsilon * node.h,
                h: node.h,
                seq: self.seq,
                idx: t,
            });
        }
        self.open = BinaryHeap::from(entries);
    }

    /// min over OPEN ∪ INCONS of g + h: a lower bound on the optimal cost
    /// (with g(goal)) when h is admissible, because the first state of an
    /// optimal path that is not consistent (v ≠ g) lies in OPEN ∪ INCONS
    /// with g equal to its optimal cost-to-come.
    fn min_open_incons(&self) -> f64 {
        let open = self
            .open
            .iter()
            .filter(|&&e| self.is_live(e))
            .map(|e| e.idx);
        open.chain(self.incons.iter().copied())
            .map(|t| {
                let n = &self.nodes[t as usize];
                n.g + n.h
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn goal_g(&self) -> f64 {
        self.nodes[self.best_goal as usize].g
    }

    /// ε′ = min(ε, g(goal) / min(g(goal), min over OPEN ∪ INCONS of g + h)),
    /// at least 1. The ε term is ARA*'s per-iteration guarantee, which needs a
    /// consistent heuristic: with one declared only admissible it is left out.
    fn epsilon_bound(&self, min_open_incons: f64) -> f64 {
        let g = self.goal_g();
        let lower = g.min(min_open_incons);
        let ratio = if lower > 0.0 {
            g / lower
        } else {
            f64::INFINITY
        };
        let epsilon_term = if self.admissible && !self.consistent {
            f64::INFINITY
        } else {
            self.completed_epsilon
        };
        ratio.min(epsilon_term).max(1.0)
    }

    fn solved_status(&self) -> SearchStatus {
        if self.admissible && self.bound <= 1.0 {
            SearchStatus::Exact
        } else {
            SearchStatus::Approximate
        }
    }

    fn finish_interrupted(mut self) -> SearchResult<P::State, P::Action> {
        if self.best_goal == NONE {
            return self.finish(SearchStatus::Timeout, None);
        }
        let lower = self.min_open_incons();
        self.bound = self.bound.min(self.epsilon_bound(lower));
        self.publish(self.epsilon, false);
        let status = self.solved_status();
        self.finish(status, None)
    }

    /// Rebuilds the plan to the best goal and reports it if it is cheaper
    /// than the last one. The kept plan's cost never exceeds g(goal), so the
    /// bound computed from g(goal) holds for it.
    fn publish(&mut self, epsilon: f64, iteration_complete: bool) {
        let plan = self.trace(self.best_goal);
        if self.plan.as_ref().is_some_and(|p| p.cost <= plan.cost) {
            return;
        }
        let report = SolutionReport {
            time_s: self.started.elapsed().as_secs_f64(),
            cost: plan.cost,
            epsilon,
            epsilon_bound: self.bound,
            expansions: self.stats.expansions,
            iteration_complete,
        };
        if let Some(callback) = self.on_solution.as_mut() {
            callback(&report, &plan);
        }
        self.solutions.push(report);
        self.plan = Some(plan);
    }

    fn trace(&self, goal: u32) -> Plan<P::State, P::Action> {
        let mut chain = vec![goal];
        let mut t = goal;
        while self.nodes[t as usize].parent != NONE {
            t = self.nodes[t as usize].parent;
            chain.push(t);
        }
        chain.reverse();
        // Summed from the start, in the order g was accumulated.
        let cost = chain[1..]
            .iter()
            .fold(0.0, |c, &t| c + self.nodes[t as usize].edge_cost);
        Plan {
            states: chain.iter().map(|&t| self.states.get(t).clone()).collect(),
            actions: chain[1..]
                .iter()
                .map(|&t| {
                    self.actions[t as usize]
                        .clone()
                        .expect("every state but the start has a parent action")
                })
                .collect(),
            cost,
        }
    }

    fn progress(&self) -> Progress {
        Progress {
            expansions: self.stats.expansions,
            elapsed: self.started.elapsed(),
            iterations_completed: self.completed_iterations,
            solutions: self.solutions.len(),
            best_cost: self.plan.as_ref().map(|p| p.cost),
            epsilon: self.epsilon,
        }
    }

    fn finish(
        mut self,
        status: SearchStatus,
        message: Option<String>,
    ) -> SearchResult<P::State, P::Action> {
        self.stats.states_generated = self.states.len() as u64;
        self.stats.elapsed_s = self.started.elapsed().as_secs_f64();
        let epsilon_bound = if self.plan.is_some() {
            self.bound
        } else {
            f64::INFINITY
        };
        SearchResult {
            status,
            message,
            plan: self.plan,
            solutions: self.solutions,
            epsilon0: self.config.epsilon0,
            decrement: self.config.decrement,
            final_epsilon: self.epsilon,
            epsilon_bound,
            heuristic: self.problem.heuristic_name(),
            bound_guaranteed: self.admissible,
            stats: self.stats,
        }
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the hand-made graphs have exact answers
mod tests {
    use super::*;
    use crate::search::{SearchProblem, Successor};

    /// A hand-written graph: `edges[s]` = (target, cost), h per state,
    /// declared consistent.
    struct Table {
        edges: Vec<Vec<(usize, f64)>>,
        h: Vec<f64>,
        goal: usize,
    }

    impl SearchProblem for Table {
        type State = usize;
        type Action = usize;
        fn successors(&mut self, &s: &usize, out: &mut Vec<Successor<usize, usize>>) -> usize {
            for &(t, cost) in &self.edges[s] {
                out.push(Successor {
                    state: t,
                    cost,
                    action: 10 * s + t,
                });
            }
            out.len()
        }
        fn heuristic(&mut self, &s: &usize) -> f64 {
            self.h[s]
        }
        fn is_goal(&mut self, &s: &usize) -> bool {
            s == self.goal
        }
        fn heuristic_is_consistent(&self) -> bool {
            true
        }
        fn heuristic_name(&self) -> String {
            "table".to_owned()
        }
    }

    fn solve(
        table: Table,
        start: usize,
        termination: &mut Termination<'_>,
    ) -> SearchResult<usize, usize> {
        AraStar::new(table, start, AraStarConfig::default()).solve(termination)
    }

    /// S=0 → 1 → G=3 costs 3; S → 2 → G costs 2.5 but looks worse at ε = 3.
    fn two_routes() -> Table {
        Table {
            edges: vec![
                vec![(1, 2.0), (2, 0.5)],
                vec![(3, 1.0)],
                vec![(3, 2.0)],
                vec![],
            ],
            h: vec![0.0, 1.0, 2.0, 0.0],
            goal: 3,
        }
    }

    #[test]
    fn search_arastar_first_plan_suboptimal_then_optimal_with_tight_bounds() {
        let r = solve(two_routes(), 0, &mut Termination::never());
        assert_eq!(r.status, SearchStatus::Exact);
        let costs: Vec<_> = r
            .solutions
            .iter()
            .map(|s| (s.cost, s.epsilon, s.epsilon_bound))
            .collect();
        // At ε = 3 the route via 1 is taken; ε′ = min(3, 3 / (0.5 + 2)) = 1.2.
        assert_eq!(costs, vec![(3.0, 3.0, 1.2), (2.5, 1.0, 1.0)]);
        let eps: Vec<_> = r
            .stats
            .iterations
            .iter()
            .map(|i| (i.epsilon, i.expansions))
            .collect();
        assert_eq!(eps, vec![(3.0, 2), (2.5, 0), (2.0, 0), (1.5, 0), (1.0, 1)]);
        let plan = r.plan.unwrap();
        assert_eq!(plan.states, vec![0, 2, 3]);
        assert_eq!(plan.actions, vec![2, 23]);
        assert_eq!(r.heuristic, "table");
        assert!(r.bound_guaranteed);
        assert_eq!((r.final_epsilon, r.epsilon_bound), (1.0, 1.0));
    }

    #[test]
    fn search_arastar_stopped_after_first_plan_is_approximate() {
        let mut stop = Termination::callback(|p| {
            if p.solutions >= 1 {
                std::ops::ControlFlow::Break(())
            } else {
                std::ops::ControlFlow::Continue(())
            }
        });
        let r = solve(two_routes(), 0, &mut stop);
        assert_eq!(r.status, SearchStatus::Approximate);
        assert_eq!(r.status.issue_status(), "solved");
        assert_eq!((r.cost(), r.epsilon_bound), (Some(3.0), 1.2));
    }

    #[test]
    fn search_arastar_incons_states_are_repaired_in_the_next_iteration() {
        // S=0 → X=1 costs 3, S → B=2 → X costs 2, X → G=3 costs 4, and
        // S → Z=4 → G costs 6.5. At ε = 3, X is closed with g = 3 before B
        // finds it at g = 2, so X waits in INCONS while the iteration ends
        // with the plan via Z (6.5); the next iteration re-expands X alone
        // and finds the optimum 6. Dropping INCONS would stop at 6.5.
        let table = Table {
            edges: vec![
                vec![(1, 3.0), (2, 1.0), (4, 5.0)],
                vec![(3, 4.0)],
                vec![(1, 1.0)],
                vec![],
                vec![(3, 1.5)],
            ],
            h: vec![0.0, 0.0, 1.0, 0.0, 0.0],
            goal: 3,
        };
        let r = solve(table, 0, &mut Termination::never());
        let costs: Vec<_> = r
            .solutions
            .iter()
            .map(|s| (s.cost, s.epsilon, s.epsilon_bound))
            .collect();
        // ε′ = min(3, 6.5 / (g + h of X in INCONS = 2)) = 3.
        assert_eq!(costs, vec![(6.5, 3.0, 3.0), (6.0, 2.5, 1.0)]);
        assert_eq!(r.status, SearchStatus::Exact);
        assert_eq!(r.plan.unwrap().states, vec![0, 2, 1, 3]);
        let eps: Vec<_> = r
            .stats
            .iterations
            .iter()
            .map(|i| (i.epsilon, i.expansions))
            .collect();
        assert_eq!(eps, vec![(3.0, 4), (2.5, 1)]);
    }

    #[test]
    fn search_arastar_start_at_goal_is_an_empty_exact_plan() {
        let r = solve(two_routes(), 3, &mut Termination::expansions(0));
        assert_eq!(r.status, SearchStatus::Exact);
        let plan = r.plan.unwrap();
        assert_eq!(
            (plan.states, plan.actions, plan.cost),
            (vec![3], vec![], 0.0)
        );
        assert_eq!(r.solutions.len(), 1);
    }

    #[test]
    fn search_arastar_dead_ends_are_not_expanded_and_infeasible_means_exhausted() {
        let mut table = two_routes();
        table.h = vec![0.0, f64::INFINITY, f64::INFINITY, 0.0];
        let r = solve(table, 0, &mut Termination::never());
        assert_eq!(r.status, SearchStatus::Infeasible);
        assert_eq!(r.stats.expansions, 1);
        assert_eq!(r.stats.states_generated, 3);
        assert!(r.plan.is_none());
    }

    #[test]
    fn search_arastar_rejects_invalid_input() {
        for (epsilon0, decrement, what) in [
            (0.5, 0.5, "epsilon0"),
            (f64::NAN, 0.5, "epsilon0"),
            (2.0, 0.0, "decrement"),
        ] {
            let r = AraStar::new(
                two_routes(),
                0,
                AraStarConfig {
                    epsilon0,
                    decrement,
                },
            )
            .solve(&mut Termination::never());
            assert_eq!(r.status, SearchStatus::InvalidInput);
            assert!(r.message.unwrap().contains(what));
        }
        let mut bad_cost = two_routes();
        bad_cost.edges[0][1].1 = 0.0;
        let r = solve(bad_cost, 0, &mut Termination::never());
        assert_eq!(r.status, SearchStatus::InvalidInput);
        assert!(r.message.unwrap().contains("edge cost 0"));
        let mut bad_h = two_routes();
        bad_h.h[2] = f64::NAN;
        let r = solve(bad_h, 0, &mut Termination::never());
        assert_eq!(r.status, SearchStatus::InvalidInput);
        assert!(r.message.unwrap().contains("heuristic value NaN"));
        // A disallowed (infinite-cost) action is skipped, not an error.
        let mut blocked = two_routes();
        blocked.edges[0][1].1 = f64::INFINITY;
        let r = solve(blocked, 0, &mut Termination::never());
        assert_eq!((r.status, r.cost()), (SearchStatus::Exact, Some(3.0)));
    }
}

//! Plain Dijkstra over a [`SearchProblem`]: the exact reference ARA* is
//! tested against, and a way to tabulate costs-to-go (run it on a reversed
//! graph) for building heuristics.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;
use std::time::Instant;

use super::interner::Interner;
use super::problem::{SearchProblem, Successor};
use super::result::{IterationStats, Plan, SearchResult, SearchStats, SearchStatus};
use super::termination::{Progress, Termination};
use crate::error::{CoreError, CoreResult};

const NONE: u32 = u32::MAX;

/// A (distance, insertion order, state) entry; the order makes ties and so
/// the returned plan deterministic.
#[derive(Clone, Copy, PartialEq)]
struct Entry(f64, u64, u32);

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

struct Tree<S, A> {
    states: Interner<S>,
    dist: Vec<f64>,
    parent: Vec<u32>,
    edge_cost: Vec<f64>,
    action: Vec<Option<A>>,
    expansions: u64,
    actions_evaluated: u64,
}

enum End {
    Goal(u32),
    Exhausted,
    Stopped,
    Invalid(String),
}

/// Uniform-cost search from `start`; with `stop_at_goal` it ends at the
/// first goal popped (optimal, since costs are positive) and never expands a
/// goal, otherwise it settles every reachable state.
fn grow<P: SearchProblem>(
    problem: &mut P,
    start: P::State,
    stop_at_goal: bool,
    termination: &mut Termination<'_>,
    started: Instant,
) -> (Tree<P::State, P::Action>, End) {
    let mut tree = Tree {
        states: Interner::new(),
        dist: vec![0.0],
        parent: vec![NONE],
        edge_cost: vec![0.0],
        action: vec![None],
        expansions: 0,
        actions_evaluated: 0,
    };
    tree.states.intern(start);
    let mut heap = BinaryHeap::from([Reverse(Entry(0.0, 0, 0))]);
    let mut seq = 0u64;
    let mut buf: Vec<Successor<P::State, P::Action>> = Vec::new();
    while let Some(Reverse(Entry(d, _, s))) = heap.pop() {
        if d > tree.dist[s as usize] {
            continue;
        }
        if stop_at_goal && problem.is_goal(tree.states.get(s)) {
            return (tree, End::Goal(s));
        }
        let progress = Progress {
            expansions: tree.expansions,
            elapsed: started.elapsed(),
            iterations_completed: 0,
            solutions: 0,
            best_cost: None,
            epsilon: 1.0,
        };
        if termination.should_stop(&progress) {
            return (tree, End::Stopped);
        }
        buf.clear();
        tree.actions_evaluated += problem.successors(tree.states.get(s), &mut buf) as u64;
        tree.expansions += 1;
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
                return (
                    tree,
                    End::Invalid(format!(
                        "edge cost {cost} returned by successors(): costs must be finite and > 0 \
                         (or +inf for a disallowed action)"
                    )),
                );
            }
            let (t, new) = tree.states.intern(state);
            if new {
                tree.dist.push(f64::INFINITY);
                tree.parent.push(NONE);
                tree.edge_cost.push(0.0);
                tree.action.push(None);
            }
            let nd = d + cost;
            if nd < tree.dist[t as usize] {
                tree.dist[t as usize] = nd;
                tree.parent[t as usize] = s;
                tree.edge_cost[t as usize] = cost;
                tree.action[t as usize] = Some(action);
                seq += 1;
                heap.push(Reverse(Entry(nd, seq, t)));
            }
        }
    }
    (tree, End::Exhausted)
}

/// The cheapest plan from `start` to a goal of `problem`, or why there is none.
///
/// The heuristic is ignored, so the result is `Exact` whenever solved; the
/// ARA*-specific fields read ε₀ = ε = ε′ = 1 and `decrement` = 0.
pub fn dijkstra<P: SearchProblem>(
    problem: &mut P,
    start: P::State,
    termination: &mut Termination<'_>,
) -> SearchResult<P::State, P::Action> {
    let started = Instant::now();
    let (tree, end) = grow(problem, start, true, termination, started);
    let (status, message, plan) = match end {
        End::Goal(goal) => {
            let mut chain = vec![goal];
            while tree.parent[*chain.last().expect("non-empty") as usize] != NONE {
                chain.push(tree.parent[*chain.last().expect("non-empty") as usize]);
            }
            chain.reverse();
            let plan = Plan {
                states: chain.iter().map(|&t| tree.states.get(t).clone()).collect(),
                actions: chain[1..]
                    .iter()
                    .map(|&t| tree.action[t as usize].clone().expect("has a parent"))
                    .collect(),
                cost: chain[1..]
                    .iter()
                    .fold(0.0, |c, &t| c + tree.edge_cost[t as usize]),
            };
            (SearchStatus::Exact, None, Some(plan))
        }
        End::Exhausted => (SearchStatus::Infeasible, None, None),
        End::Stopped => (SearchStatus::Timeout, None, None),
        End::Invalid(m) => (SearchStatus::InvalidInput, Some(m), None),
    };
    let solved = plan.is_some();
    SearchResult {
        status,
        message,
        plan,
        solutions: Vec::new(),
        epsilon0: 1.0,
        decrement: 0.0,
        final_epsilon: 1.0,
        epsilon_bound: if solved { 1.0 } else { f64::INFINITY },
        heuristic: "none (dijkstra)".to_owned(),
        bound_guaranteed: true,
        stats: SearchStats {
            expansions: tree.expansions,
            states_generated: tree.states.len() as u64,
            actions_evaluated: tree.actions_evaluated,
            elapsed_s: started.elapsed().as_secs_f64(),
            iterations: vec![IterationStats {
                epsilon: 1.0,
                expansions: tree.expansions,
                completed: status != SearchStatus::Timeout,
            }],
        },
    }
}

/// The least cost from `start` to every state reachable from it, goals and
/// heuristic ignored, in the order the states were settled.
///
/// On a reversed graph this tabulates the true cost-to-go h*, the yardstick
/// of admissible heuristics.
pub fn dijkstra_costs<P: SearchProblem>(
    problem: &mut P,
    start: P::State,
) -> CoreResult<Vec<(P::State, f64)>> {
    let (tree, end) = grow(
        problem,
        start,
        false,
        &mut Termination::never(),
        Instant::now(),
    );
    if let End::Invalid(m) = end {
        return Err(CoreError::Planning(m));
    }
    let mut order: Vec<u32> = (0..tree.states.len() as u32)
        .filter(|&t| tree.dist[t as usize].is_finite())
        .collect();
    order.sort_by(|&a, &b| tree.dist[a as usize].total_cmp(&tree.dist[b as usize]));
    Ok(order
        .into_iter()
        .map(|t| (tree.states.get(t).clone(), tree.dist[t as usize]))
        .collect())
}

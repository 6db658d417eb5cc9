//! When a search must stop: wall-clock budgets, expansion budgets and user
//! callbacks, combined with "any of" (OMPL's `PlannerTerminationCondition`).

use std::fmt;
use std::ops::ControlFlow;
use std::time::Duration;

/// What a termination condition sees each time it is asked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// States expanded so far in this `solve` call (all iterations).
    pub expansions: u64,
    /// Wall-clock time since this `solve` call started.
    pub elapsed: Duration,
    /// ARA* iterations (ImprovePath calls) finished so far.
    pub iterations_completed: usize,
    /// Improved solutions reported so far.
    pub solutions: usize,
    /// Cost of the best solution so far, if any.
    pub best_cost: Option<f64>,
    /// Inflation ε of the iteration running (or about to run).
    pub epsilon: f64,
}

type StopCallback<'a> = Box<dyn FnMut(&Progress) -> ControlFlow<()> + 'a>;

enum Condition<'a> {
    TimeLimit(Duration),
    Expansions(u64),
    Callback(StopCallback<'a>),
}

/// A stopping rule: the search stops as soon as any of its conditions fires.
///
/// Conditions are asked before every expansion and between ARA* iterations,
/// so a time limit overruns by at most one expansion (one `successors` call).
/// Budgets count from the start of each `solve`/`replan` call, so that a
/// re-plan gets its own budget. A rule without a time limit is
/// deterministic: the same problem and budget give the same plan.
#[derive(Default)]
pub struct Termination<'a> {
    conditions: Vec<Condition<'a>>,
}

impl<'a> Termination<'a> {
    /// Never stops on its own: the search runs until it proves its solution
    /// optimal (ε′ = 1) or exhausts OPEN. Only for finite graphs.
    pub fn never() -> Self {
        Self::default()
    }

    /// Stops once `limit` of wall-clock time has passed since `solve` started.
    pub fn time_limit(limit: Duration) -> Self {
        Self {
            conditions: vec![Condition::TimeLimit(limit)],
        }
    }

    /// Stops before expanding more than `max_expansions` states: the
    /// deterministic budget (tests and reproducible runs use it).
    pub fn expansions(max_expansions: u64) -> Self {
        Self {
            conditions: vec![Condition::Expansions(max_expansions)],
        }
    }

    /// Stops when `callback` returns `ControlFlow::Break(())`.
    ///
    /// It is called before every expansion, so it must be cheap.
    pub fn callback(callback: impl FnMut(&Progress) -> ControlFlow<()> + 'a) -> Self {
        Self {
            conditions: vec![Condition::Callback(Box::new(callback))],
        }
    }

    /// Stops when any of `rules` would stop.
    pub fn any_of(rules: impl IntoIterator<Item = Termination<'a>>) -> Self {
        Self {
            conditions: rules.into_iter().flat_map(|t| t.conditions).collect(),
        }
    }

    /// Stops when `self` or `other` would stop.
    #[must_use]
    pub fn or(mut self, other: Termination<'a>) -> Self {
        self.conditions.extend(other.conditions);
        self
    }

    /// Whether a wall-clock limit is part of the rule (then it is not
    /// deterministic).
    pub fn has_time_limit(&self) -> bool {
        self.conditions
            .iter()
            .any(|c| matches!(c, Condition::TimeLimit(_)))
    }

    /// Asks every condition (all of them, so callbacks see every check).
    pub fn should_stop(&mut self, progress: &Progress) -> bool {
        let mut stop = false;
        for condition in &mut self.conditions {
            stop |= match condition {
                Condition::TimeLimit(limit) => progress.elapsed >= *limit,
                Condition::Expansions(n) => progress.expansions >= *n,
                Condition::Callback(f) => f(progress).is_break(),
            };
        }
        stop
    }
}

impl fmt::Debug for Termination<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut list = f.debug_list();
        for condition in &self.conditions {
            match condition {
                Condition::TimeLimit(d) => list.entry(&format_args!("time_limit({d:?})")),
                Condition::Expansions(n) => list.entry(&format_args!("expansions({n})")),
                Condition::Callback(_) => list.entry(&format_args!("callback")),
            };
        }
        list.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn progress(expansions: u64, elapsed_ms: u64) -> Progress {
        Progress {
            expansions,
            elapsed: Duration::from_millis(elapsed_ms),
            iterations_completed: 0,
            solutions: 0,
            best_cost: None,
            epsilon: 1.0,
        }
    }

    #[test]
    fn search_termination_conditions_fire_at_their_budget() {
        let mut t = Termination::expansions(10);
        assert!(!t.should_stop(&progress(9, 0)));
        assert!(t.should_stop(&progress(10, 0)));
        let mut t = Termination::time_limit(Duration::from_millis(5));
        assert!(!t.should_stop(&progress(1000, 4)));
        assert!(t.should_stop(&progress(0, 5)));
        let mut t = Termination::never();
        assert!(!t.should_stop(&progress(u64::MAX, u64::MAX)));
    }

    #[test]
    fn search_termination_any_of_stops_when_one_fires_and_asks_every_callback() {
        let mut calls = 0;
        {
            let mut t = Termination::any_of([
                Termination::expansions(3),
                Termination::callback(|p| {
                    calls += 1;
                    if p.solutions > 0 {
                        ControlFlow::Break(())
                    } else {
                        ControlFlow::Continue(())
                    }
                }),
            ])
            .or(Termination::time_limit(Duration::from_secs(1)));
            assert!(t.has_time_limit());
            assert!(!t.should_stop(&progress(2, 0)));
            assert!(t.should_stop(&progress(3, 0)));
            let mut p = progress(0, 0);
            p.solutions = 1;
            assert!(t.should_stop(&p));
            assert_eq!(
                format!("{t:?}"),
                "[expansions(3), callback, time_limit(1s)]"
            );
        }
        assert_eq!(calls, 3);
    }
}

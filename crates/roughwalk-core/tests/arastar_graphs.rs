//! ARA* against brute-force Dijkstra on random graphs and grid worlds
//! (the footstep-planner issue's §4 tests).

// Exact float equality is meant here: ε schedules, infinite bounds, and
// plans compared run against run for determinism.
#![allow(clippy::float_cmp)]

mod search {
    use std::ops::ControlFlow;
    use std::time::Duration;

    use proptest::prelude::*;
    use roughwalk_core::search::grid_world::GridWorld;
    use roughwalk_core::search::{
        dijkstra, dijkstra_costs, AraStar, AraStarConfig, Plan, SearchProblem, SearchResult,
        SearchStatus, Successor, Termination,
    };

    /// How the random graph's heuristic relates to the true cost-to-go h*.
    #[derive(Debug, Clone, Copy)]
    enum Heuristic {
        /// α·h* with one α in [0, 1]: consistent.
        Scaled(f64),
        /// A per-state fraction of h*: admissible, usually inconsistent.
        PerState,
        /// 2·h*: inadmissible.
        Inflated,
    }

    /// A directed graph with positive edge costs; state 0 is the start.
    #[derive(Debug, Clone)]
    struct Graph {
        adj: Vec<Vec<(usize, f64)>>,
        goal: Vec<bool>,
        h: Vec<f64>,
        kind: Heuristic,
    }

    impl Graph {
        fn new(n: usize, edges: &[(usize, usize, f64)], goals: &[usize]) -> Self {
            let mut adj = vec![Vec::new(); n];
            for &(u, v, c) in edges {
                adj[u].push((v, c));
            }
            let mut goal = vec![false; n];
            for &g in goals {
                goal[g] = true;
            }
            Self {
                adj,
                goal,
                h: vec![0.0; n],
                kind: Heuristic::Scaled(0.0),
            }
        }

        /// h*(s): least cost from s to any goal, by Dijkstra from each goal
        /// on the reversed graph.
        fn cost_to_go(&self) -> Vec<f64> {
            let n = self.adj.len();
            let mut reversed = Graph::new(n, &[], &[]);
            for (u, out) in self.adj.iter().enumerate() {
                for &(v, c) in out {
                    reversed.adj[v].push((u, c));
                }
            }
            let mut best = vec![f64::INFINITY; n];
            for g in (0..n).filter(|&g| self.goal[g]) {
                for (s, c) in dijkstra_costs(&mut reversed, g).unwrap() {
                    best[s] = best[s].min(c);
                }
            }
            best
        }

        fn with_heuristic(mut self, kind: Heuristic, fractions: &[f64]) -> Self {
            let h_star = self.cost_to_go();
            self.h = h_star
                .iter()
                .enumerate()
                .map(|(s, &hs)| {
                    let factor = match kind {
                        Heuristic::Scaled(a) => a,
                        Heuristic::PerState => fractions[s % fractions.len()],
                        Heuristic::Inflated => 2.0,
                    };
                    if factor == 0.0 {
                        0.0
                    } else {
                        factor * hs
                    }
                })
                .collect();
            self.kind = kind;
            self
        }
    }

    impl SearchProblem for Graph {
        type State = usize;
        type Action = (usize, usize);

        fn successors(
            &mut self,
            &s: &usize,
            out: &mut Vec<Successor<usize, (usize, usize)>>,
        ) -> usize {
            for (k, &(v, c)) in self.adj[s].iter().enumerate() {
                out.push(Successor {
                    state: v,
                    cost: c,
                    action: (s, k),
                });
            }
            out.len()
        }

        fn heuristic(&mut self, &s: &usize) -> f64 {
            self.h[s]
        }

        fn is_goal(&mut self, &s: &usize) -> bool {
            self.goal[s]
        }

        fn heuristic_is_admissible(&self) -> bool {
            !matches!(self.kind, Heuristic::Inflated)
        }

        fn heuristic_is_consistent(&self) -> bool {
            matches!(self.kind, Heuristic::Scaled(_))
        }

        fn heuristic_name(&self) -> String {
            "random fraction of h*".to_owned()
        }
    }

    /// The plan starts at 0, ends at a goal, follows real edges, and its
    /// cost is the sum of their costs.
    fn assert_valid_plan(g: &Graph, plan: &Plan<usize, (usize, usize)>) {
        assert_eq!(plan.states[0], 0);
        assert!(g.goal[*plan.states.last().unwrap()]);
        assert_eq!(plan.actions.len() + 1, plan.states.len());
        let mut cost = 0.0;
        for (i, &(from, k)) in plan.actions.iter().enumerate() {
            assert_eq!(from, plan.states[i]);
            let (to, c) = g.adj[from][k];
            assert_eq!(to, plan.states[i + 1]);
            cost += c;
        }
        assert!((cost - plan.cost).abs() <= 1e-9 * cost.max(1.0));
    }

    fn run(
        g: &Graph,
        epsilon0: f64,
        decrement: f64,
        termination: &mut Termination<'_>,
    ) -> SearchResult<usize, (usize, usize)> {
        AraStar::new(
            g.clone(),
            0,
            AraStarConfig {
                epsilon0,
                decrement,
            },
        )
        .solve(termination)
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-9 * a.abs().max(1.0)
    }

    fn graph() -> impl Strategy<Value = (usize, Vec<(usize, usize, f64)>, Vec<usize>)> {
        (5usize..60).prop_flat_map(|n| {
            (
                Just(n),
                prop::collection::vec((0..n, 0..n, 0.1f64..10.0), 0..4 * n),
                prop::collection::vec(1..n, 1..3),
            )
        })
    }

    fn heuristic() -> impl Strategy<Value = Heuristic> {
        prop_oneof![
            Just(Heuristic::Scaled(0.0)),
            (0.0f64..=1.0).prop_map(Heuristic::Scaled),
            Just(Heuristic::PerState),
        ]
    }

    /// Fewest edges from 0 to a goal (breadth-first), if reachable.
    fn hops_to_goal(g: &Graph) -> Option<u64> {
        let mut depth = vec![u64::MAX; g.adj.len()];
        depth[0] = 0;
        let mut queue = std::collections::VecDeque::from([0usize]);
        while let Some(s) = queue.pop_front() {
            if g.goal[s] {
                return Some(depth[s]);
            }
            for &(v, _) in &g.adj[s] {
                if depth[v] == u64::MAX {
                    depth[v] = depth[s] + 1;
                    queue.push_back(v);
                }
            }
        }
        None
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        #[test]
        fn epsilon_one_returns_the_dijkstra_optimum(
            (n, edges, goals) in graph(),
            kind in heuristic(),
            fractions in prop::collection::vec(0.0f64..=1.0, 1..8),
        ) {
            let g = Graph::new(n, &edges, &goals).with_heuristic(kind, &fractions);
            let reference = dijkstra(&mut g.clone(), 0, &mut Termination::never());
            let result = run(&g, 1.0, 0.5, &mut Termination::never());
            if let Some(optimum) = reference.cost() {
                prop_assert_eq!(result.status, SearchStatus::Exact);
                let plan = result.plan.as_ref().unwrap();
                assert_valid_plan(&g, plan);
                prop_assert!(close(plan.cost, optimum), "ARA* {} vs Dijkstra {}", plan.cost, optimum);
                prop_assert_eq!(result.epsilon_bound, 1.0);
            } else {
                prop_assert_eq!(reference.status, SearchStatus::Infeasible);
                prop_assert_eq!(result.status, SearchStatus::Infeasible);
                prop_assert!(result.plan.is_none());
                if matches!(kind, Heuristic::Scaled(a) if a == 0.0) {
                    // Infeasible only once OPEN is exhausted: every reachable state expanded.
                    prop_assert_eq!(result.stats.expansions, reference.stats.expansions);
                }
            }
        }

        #[test]
        fn anytime_solutions_are_within_their_bounds(
            (n, edges, goals) in graph(),
            kind in heuristic(),
            fractions in prop::collection::vec(0.0f64..=1.0, 1..8),
        ) {
            let g = Graph::new(n, &edges, &goals).with_heuristic(kind, &fractions);
            let Some(optimum) = dijkstra(&mut g.clone(), 0, &mut Termination::never()).cost() else {
                return Ok(());
            };
            let mut streamed = Vec::new();
            let result = {
                let mut planner = AraStar::new(g.clone(), 0, AraStarConfig { epsilon0: 3.0, decrement: 0.5 });
                planner.on_solution(|report, plan| streamed.push((*report, plan.cost)));
                planner.solve(&mut Termination::never())
            };
            prop_assert!(!result.solutions.is_empty());
            prop_assert_eq!(streamed.len(), result.solutions.len());
            for (i, report) in result.solutions.iter().enumerate() {
                prop_assert_eq!(streamed[i].0, *report);
                prop_assert!(report.cost <= report.epsilon_bound * optimum * (1.0 + 1e-12),
                    "cost {} > bound {} × optimum {}", report.cost, report.epsilon_bound, optimum);
                prop_assert!(report.epsilon_bound >= 1.0);
                if g.heuristic_is_consistent() {
                    // ARA*'s own guarantee, and ε′ never looser than it.
                    prop_assert!(report.cost <= report.epsilon * optimum * (1.0 + 1e-12));
                    prop_assert!(report.epsilon_bound <= report.epsilon);
                }
                if i > 0 {
                    prop_assert!(report.cost < result.solutions[i - 1].cost);
                    prop_assert!(report.epsilon_bound <= result.solutions[i - 1].epsilon_bound);
                    prop_assert!(report.epsilon <= result.solutions[i - 1].epsilon);
                }
            }
            prop_assert_eq!(result.status, SearchStatus::Exact);
            prop_assert!(close(result.cost().unwrap(), optimum));
            assert_valid_plan(&g, result.plan.as_ref().unwrap());
            prop_assert_eq!(result.epsilon0, 3.0);
            prop_assert_eq!(result.decrement, 0.5);
            // The schedule: 3, 2.5, 2, … (stopping early once proven optimal).
            for (i, it) in result.stats.iterations.iter().enumerate() {
                prop_assert_eq!(it.epsilon, (3.0 - 0.5 * i as f64).max(1.0));
                prop_assert!(it.completed);
            }
            prop_assert_eq!(result.stats.expansions, result.stats.iterations.iter().map(|i| i.expansions).sum::<u64>());
            prop_assert!(result.bound_guaranteed);
        }

        #[test]
        fn inadmissible_heuristic_solves_but_guarantees_nothing(
            (n, edges, goals) in graph(),
        ) {
            let g = Graph::new(n, &edges, &goals).with_heuristic(Heuristic::Inflated, &[1.0]);
            let reference = dijkstra(&mut g.clone(), 0, &mut Termination::never());
            let result = run(&g, 2.0, 0.5, &mut Termination::never());
            prop_assert!(!result.bound_guaranteed);
            if let Some(optimum) = reference.cost() {
                prop_assert_eq!(result.status, SearchStatus::Approximate);
                assert_valid_plan(&g, result.plan.as_ref().unwrap());
                prop_assert!(result.cost().unwrap() >= optimum * (1.0 - 1e-12));
            } else {
                prop_assert_eq!(result.status, SearchStatus::Infeasible);
            }
        }

        #[test]
        fn same_inputs_same_plan_and_expansions(
            (n, edges, goals) in graph(),
            kind in heuristic(),
            fractions in prop::collection::vec(0.0f64..=1.0, 1..8),
            budget in 0u64..40,
        ) {
            let g = Graph::new(n, &edges, &goals).with_heuristic(kind, &fractions);
            for mut termination in [Termination::never(), Termination::expansions(budget)] {
                let a = run(&g, 3.0, 0.5, &mut termination);
                let b = run(&g, 3.0, 0.5, &mut termination);
                prop_assert_eq!(&a.plan, &b.plan);
                prop_assert_eq!(a.status, b.status);
                prop_assert_eq!(&a.stats.iterations, &b.stats.iterations);
                let costs = |r: &SearchResult<usize, (usize, usize)>| r.solutions.iter().map(|s| (s.cost, s.epsilon_bound)).collect::<Vec<_>>();
                prop_assert_eq!(costs(&a), costs(&b));
            }
        }

        #[test]
        fn too_small_an_expansion_budget_times_out_without_a_plan(
            (n, edges, goals) in graph(),
            kind in heuristic(),
            fractions in prop::collection::vec(0.0f64..=1.0, 1..8),
        ) {
            let g = Graph::new(n, &edges, &goals).with_heuristic(kind, &fractions);
            let Some(hops) = hops_to_goal(&g) else { return Ok(()) };
            // A goal is generated no sooner than after `hops` expansions.
            let result = run(&g, 3.0, 0.5, &mut Termination::expansions(hops - 1));
            prop_assert_eq!(result.status, SearchStatus::Timeout);
            prop_assert_eq!(result.status.issue_status(), "no_solution");
            prop_assert!(result.plan.is_none() && result.solutions.is_empty());
            prop_assert_eq!(result.stats.expansions, hops - 1);
            prop_assert_eq!(result.epsilon_bound, f64::INFINITY);
        }

        #[test]
        fn a_callback_can_stop_after_the_first_solution(
            (n, edges, goals) in graph(),
            kind in heuristic(),
            fractions in prop::collection::vec(0.0f64..=1.0, 1..8),
        ) {
            let g = Graph::new(n, &edges, &goals).with_heuristic(kind, &fractions);
            let full = run(&g, 3.0, 0.5, &mut Termination::never());
            let Some(first) = full.solutions.first().copied() else { return Ok(()) };
            let mut stop = Termination::callback(|p| if p.solutions >= 1 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) });
            let result = run(&g, 3.0, 0.5, &mut stop);
            prop_assert_eq!(result.solutions.len(), 1);
            prop_assert_eq!(result.cost(), Some(first.cost));
            prop_assert_eq!(result.epsilon_bound, first.epsilon_bound);
            let expected = if first.epsilon_bound > 1.0 { SearchStatus::Approximate } else { SearchStatus::Exact };
            prop_assert_eq!(result.status, expected);
        }
    }

    /// A grid world with the optimal cost checked by Dijkstra; ARA* reuses
    /// search effort: its iterations together expand fewer states than a
    /// fresh weighted A* for each ε of its schedule.
    #[test]
    fn grid_world_optimum_and_reuse_of_search_effort() {
        for seed in [1, 2, 3] {
            let world = GridWorld::random(200, 200, 0.3, seed);
            let goal = world.goal();
            let reference = dijkstra(&mut world.clone(), (0, 0), &mut Termination::never());
            let optimum = reference.cost().expect("these seeds have a path");
            let config = AraStarConfig {
                epsilon0: 3.0,
                decrement: 0.5,
            };
            let result =
                AraStar::new(world.clone(), (0, 0), config).solve(&mut Termination::never());
            assert_eq!(result.status, SearchStatus::Exact, "seed {seed}");
            assert!(
                close(result.cost().unwrap(), optimum),
                "seed {seed}: {:?} vs {optimum}",
                result.cost()
            );
            let plan = result.plan.as_ref().unwrap();
            assert_eq!(*plan.states.last().unwrap(), goal);
            for report in &result.solutions {
                assert!(report.cost <= report.epsilon * optimum * (1.0 + 1e-12));
                assert!(report.cost <= report.epsilon_bound * optimum * (1.0 + 1e-12));
            }
            assert!(
                result.stats.iterations.len() >= 2,
                "seed {seed}: {:?}",
                result.stats.iterations
            );

            let mut from_scratch = 0;
            for it in &result.stats.iterations {
                let mut one_iteration = Termination::callback(|p| {
                    if p.iterations_completed >= 1 {
                        ControlFlow::Break(())
                    } else {
                        ControlFlow::Continue(())
                    }
                });
                let fresh = AraStar::new(
                    world.clone(),
                    (0, 0),
                    AraStarConfig {
                        epsilon0: it.epsilon,
                        decrement: 0.5,
                    },
                )
                .solve(&mut one_iteration);
                assert_eq!(fresh.stats.iterations.len(), 1);
                from_scratch += fresh.stats.expansions;
            }
            eprintln!(
                "seed {seed}: ARA* {} expansions over {} iterations, from scratch {from_scratch}",
                result.stats.expansions,
                result.stats.iterations.len()
            );
            assert!(
                result.stats.expansions < from_scratch,
                "seed {seed}: {} >= {from_scratch}",
                result.stats.expansions
            );
        }
    }

    #[test]
    fn replan_is_a_fresh_search_from_the_new_start() {
        let world = GridWorld::random(60, 60, 0.25, 7);
        let mut planner = AraStar::new(world.clone(), (0, 0), AraStarConfig::default());
        let first = planner.solve(&mut Termination::never());
        assert!(first.status.is_solved());
        let new_start = first.plan.as_ref().unwrap().states[10];
        let replanned = planner.replan(new_start, &mut Termination::expansions(1_000_000));
        assert_eq!(*planner.start(), new_start);
        let fresh = AraStar::new(world.clone(), new_start, AraStarConfig::default())
            .solve(&mut Termination::never());
        assert_eq!(replanned.plan, fresh.plan);
        assert_eq!(replanned.stats.iterations, fresh.stats.iterations);
        let optimum = dijkstra(&mut world.clone(), new_start, &mut Termination::never())
            .cost()
            .unwrap();
        assert!(close(replanned.cost().unwrap(), optimum));
        assert_eq!(replanned.plan.unwrap().states[0], new_start);
    }

    /// A problem whose every successor call takes ~`delay`, on an endless
    /// corridor with no goal: only the time limit can stop it.
    struct SlowCorridor {
        delay: Duration,
    }

    impl SearchProblem for SlowCorridor {
        type State = i64;
        type Action = ();
        fn successors(&mut self, &s: &i64, out: &mut Vec<Successor<i64, ()>>) -> usize {
            let t = std::time::Instant::now();
            while t.elapsed() < self.delay {}
            out.push(Successor {
                state: s + 1,
                cost: 1.0,
                action: (),
            });
            1
        }
        fn heuristic(&mut self, _: &i64) -> f64 {
            0.0
        }
        fn is_goal(&mut self, _: &i64) -> bool {
            false
        }
    }

    #[test]
    fn time_limit_stops_within_about_one_expansion() {
        let limit = Duration::from_millis(50);
        let problem = SlowCorridor {
            delay: Duration::from_micros(200),
        };
        let result = AraStar::new(problem, 0, AraStarConfig::default())
            .solve(&mut Termination::time_limit(limit));
        assert_eq!(result.status, SearchStatus::Timeout);
        assert!(result.stats.elapsed_s >= limit.as_secs_f64());
        // Loose: the machine is shared; the benchmark measures the real overrun.
        assert!(
            result.stats.elapsed_s < limit.as_secs_f64() + 0.5,
            "{}",
            result.stats.elapsed_s
        );
        assert!(result.stats.expansions > 10);
        assert_eq!(result.stats.actions_evaluated, result.stats.expansions);
        assert!(result.stats.actions_per_second() > 0.0);
    }
}

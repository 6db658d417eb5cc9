//! Bindings for `roughwalk_core::footstep`: the footstep planner of one
//! robot on one terrain, built once and planned with many times. Type
//! conversion only: arrays and a config dict in, a result dict out.

use std::cell::Cell;
use std::ops::ControlFlow;
use std::time::Duration;

use numpy::{
    AllowTypeChange, PyArray1, PyArrayLikeDyn, PyArrayMethods, PyReadonlyArray3,
    PyUntypedArrayMethods,
};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use roughwalk_core::footstep::{
    Capsule, CertificateConfig, CollisionModel, FootstepConfig, FootstepPlanResult,
    FootstepPlanner, FootstepRobot, HeuristicKind, MassModel, PoseCertificate, SearchKind, Start,
};
use roughwalk_core::kinematics::math::Vec3;
use roughwalk_core::kinematics::quadruped::BodyPose;
use roughwalk_core::sdf::{DistanceGrid, GridSpec, HeightFieldDistance, SignedDistanceField};
use roughwalk_core::search::{SolutionReport, Termination};
use roughwalk_core::CoreError;

use crate::errors::{to_py, IntoPyResult};
use crate::heightfield::PyHeightField;
use crate::robot::PyQuadruped;

type ArrayIn<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// Python is asked for pending signals (Ctrl-C) every this many search checks.
const SIGNAL_CHECK_PERIOD: u32 = 1024;

fn invalid(msg: String) -> PyErr {
    to_py(CoreError::InvalidArgument(msg))
}

/// Reads `arr` as exactly `shape` (values may be ±inf or NaN).
fn read(arr: &ArrayIn<'_>, name: &str, shape: &[usize]) -> PyResult<Vec<f64>> {
    if arr.shape() != shape {
        return Err(invalid(format!(
            "{name} must have shape {shape:?}, got {:?}",
            arr.shape()
        )));
    }
    Ok(arr.as_array().iter().copied().collect())
}

fn vec3_rows(v: &[f64]) -> Vec<Vec3> {
    v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

fn item<'py, T: FromPyObjectOwned<'py>>(config: &Bound<'py, PyDict>, key: &str) -> PyResult<T> {
    let value = config.get_item(key)?.ok_or_else(|| {
        to_py(CoreError::Planning(format!(
            "footstep config dict lacks '{key}'"
        )))
    })?;
    value.extract::<T>().map_err(|_| {
        to_py(CoreError::Planning(format!(
            "footstep config '{key}' has the wrong type: {value}"
        )))
    })
}

fn parse_config(d: &Bound<'_, PyDict>) -> PyResult<FootstepConfig> {
    let c: Bound<'_, PyDict> = item(d, "certificate")?;
    let certificate = CertificateConfig {
        max_iterations: item(&c, "max_iterations")?,
        stall_rounds: item(&c, "stall_rounds")?,
        alpha_reach: item(&c, "alpha_reach")?,
        beta_reach: item(&c, "beta_reach")?,
        reach_overshoot: item(&c, "reach_overshoot")?,
        alpha_obstacle: item(&c, "alpha_obstacle")?,
        beta_obstacle: item(&c, "beta_obstacle")?,
        com_margin: item(&c, "com_margin")?,
        max_step: item(&c, "max_step")?,
        max_turn: item(&c, "max_turn")?,
        max_drift: item(&c, "max_drift")?,
        clearance: item(&c, "clearance")?,
        start_clearance: item(&c, "start_clearance")?,
        clearance_overshoot: item(&c, "clearance_overshoot")?,
        preferred_clearance: item(&c, "preferred_clearance")?,
        clearance_penalty: item(&c, "clearance_penalty")?,
        singularity_margin: item(&c, "singularity_margin")?,
        singularity_penalty: item(&c, "singularity_penalty")?,
        max_tilt: item(&c, "max_tilt")?,
    };
    let actions: Vec<(f64, f64, f64)> = item(d, "actions")?;
    let heuristic: String = item(d, "heuristic")?;
    let config = FootstepConfig {
        resolution: item(d, "resolution")?,
        normal_radius: item(d, "normal_radius")?,
        actions: actions.into_iter().map(|(a, b, c)| [a, b, c]).collect(),
        walking_order: item(d, "walking_order")?,
        local_search_radius: item(d, "local_search_radius")?,
        local_search_penalty: item(d, "local_search_penalty")?,
        max_foot_travel: item(d, "max_foot_travel")?,
        min_foot_separation: item(d, "min_foot_separation")?,
        crossing_margin: item(d, "crossing_margin")?,
        step_cost: item(d, "step_cost")?,
        incircle_preferred: item(d, "incircle_preferred")?,
        incircle_min: item(d, "incircle_min")?,
        incircle_penalty: item(d, "incircle_penalty")?,
        certificate,
        goal_radius: item(d, "goal_radius")?,
        heuristic: HeuristicKind::parse(&heuristic).py()?,
        turning_radius: item(d, "turning_radius")?,
        dubins_cost_per_metre: item(d, "dubins_cost_per_metre")?,
        epsilon0: item(d, "epsilon0")?,
        epsilon_decrement: item(d, "epsilon_decrement")?,
        max_tree_edges: item(d, "max_tree_edges")?,
        cache_capacity: item(d, "cache_capacity")?,
    };
    config.validate().py()?;
    Ok(config)
}

fn certificate_dict<'py>(py: Python<'py>, c: &PoseCertificate) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("base_pos", c.base_pos.to_vec())?;
    d.set_item("base_quat", c.base_quat.to_vec())?;
    d.set_item("q", c.q.to_vec())?;
    d.set_item("com", c.com.to_vec())?;
    d.set_item("com_margin", c.com_margin)?;
    d.set_item("clearance", c.clearance)?;
    d.set_item("singularity", c.singularity)?;
    d.set_item("penalty", c.penalty)?;
    d.set_item("iterations", c.iterations)?;
    Ok(d)
}

fn report_dict<'py>(py: Python<'py>, r: &SolutionReport) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("time_s", r.time_s)?;
    d.set_item("cost", r.cost)?;
    d.set_item("epsilon", r.epsilon)?;
    d.set_item("epsilon_bound", r.epsilon_bound)?;
    d.set_item("expansions", r.expansions)?;
    d.set_item("iteration_complete", r.iteration_complete)?;
    Ok(d)
}

fn result_dict<'py>(py: Python<'py>, r: &FootstepPlanResult) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("status", r.status.issue_status())?;
    d.set_item("search_status", r.status.to_string())?;
    d.set_item("message", r.message.clone())?;
    d.set_item("start_off_foothold", r.start_off_foothold)?;
    let steps: Vec<(usize, f64, f64, f64)> = r
        .footsteps
        .iter()
        .map(|f| (f.leg, f.position[0], f.position[1], f.position[2]))
        .collect();
    d.set_item("footsteps", steps)?;
    let certs = PyList::empty(py);
    for c in &r.certificates {
        certs.append(certificate_dict(py, c)?)?;
    }
    d.set_item("certificates", certs)?;
    match &r.start_certificate {
        Some(c) => d.set_item("start_certificate", certificate_dict(py, c)?)?,
        None => d.set_item("start_certificate", py.None())?,
    }
    let states: Vec<(Vec<[i16; 2]>, u8)> =
        r.states.iter().map(|s| (s.feet.to_vec(), s.next)).collect();
    d.set_item("states", states)?;
    d.set_item("cost", r.cost)?;
    let solutions = PyList::empty(py);
    for s in &r.solutions {
        solutions.append(report_dict(py, s)?)?;
    }
    d.set_item("solutions", solutions)?;
    d.set_item("epsilon0", r.epsilon0)?;
    d.set_item("epsilon_decrement", r.decrement)?;
    d.set_item("final_epsilon", r.final_epsilon)?;
    d.set_item("epsilon_bound", r.epsilon_bound)?;
    d.set_item("heuristic", r.heuristic.clone())?;
    d.set_item("bound_guaranteed", r.bound_guaranteed)?;
    d.set_item("states_expanded", r.stats.expansions)?;
    d.set_item("states_generated", r.stats.states_generated)?;
    d.set_item("actions_evaluated", r.stats.actions_evaluated)?;
    d.set_item("search_s", r.stats.elapsed_s)?;
    d.set_item("elapsed_s", r.elapsed_s)?;
    let iterations: Vec<(f64, u64, bool)> = r
        .stats
        .iterations
        .iter()
        .map(|i| (i.epsilon, i.expansions, i.completed))
        .collect();
    d.set_item("iterations", iterations)?;
    d.set_item("certificates_computed", r.model.certificates_computed)?;
    d.set_item("certificate_rounds", r.model.certificate_rounds)?;
    d.set_item("certificate_cache_hits", r.model.certificate_cache_hits)?;
    d.set_item(
        "certificate_failures",
        r.model.certificate_failures.to_vec(),
    )?;
    d.set_item("pruned_geometry", r.model.pruned_geometry)?;
    d.set_item("pruned_incircle", r.model.pruned_incircle)?;
    let tree: Vec<f64> = r
        .tree
        .iter()
        .flat_map(|e| [f64::from(e.leg), e.from[0], e.from[1], e.to[0], e.to[1]])
        .collect();
    let n = r.tree.len();
    d.set_item("tree", PyArray1::from_vec(py, tree).reshape([n, 5])?)?;
    Ok(d)
}

/// The footstep planner of one robot on one terrain (Zucker 2011, §4).
#[pyclass(name = "FootstepPlanner", module = "roughwalk._core")]
pub struct PyFootstepPlanner {
    inner: FootstepPlanner,
}

#[pymethods]
impl PyFootstepPlanner {
    /// Builds the planner: the robot (legs, nominal joint angles, masses,
    /// capsules without feet), the terrain (height field, SDF lattice values,
    /// terrain-grid cost maps for front and hind feet) and the config dict.
    #[new]
    #[pyo3(signature = (
        quadruped, nominal_q, base_mass, base_com, link_mass, link_com,
        capsule_leg, capsule_link, capsule_a, capsule_b, capsule_radius,
        heightfield, sdf_values, sdf_origin, sdf_resolution, cost_front, cost_hind, config
    ))]
    fn new(
        py: Python<'_>,
        quadruped: PyRef<'_, PyQuadruped>,
        nominal_q: ArrayIn<'_>,
        base_mass: f64,
        base_com: ArrayIn<'_>,
        link_mass: ArrayIn<'_>,
        link_com: ArrayIn<'_>,
        capsule_leg: Vec<i64>,
        capsule_link: Vec<i64>,
        capsule_a: ArrayIn<'_>,
        capsule_b: ArrayIn<'_>,
        capsule_radius: Vec<f64>,
        heightfield: PyRef<'_, PyHeightField>,
        sdf_values: PyReadonlyArray3<'_, f32>,
        sdf_origin: [f64; 3],
        sdf_resolution: f64,
        cost_front: ArrayIn<'_>,
        cost_hind: ArrayIn<'_>,
        config: Bound<'_, PyDict>,
    ) -> PyResult<Self> {
        let config = parse_config(&config)?;
        let q = read(&nominal_q, "nominal_q", &[12])?;
        let base_com = read(&base_com, "base_com", &[3])?;
        let link_mass = read(&link_mass, "link_mass", &[4, 3])?;
        let link_com = vec3_rows(&read(&link_com, "link_com", &[4, 3, 3])?);
        let mass = MassModel::new(
            base_mass,
            [base_com[0], base_com[1], base_com[2]],
            std::array::from_fn(|l| std::array::from_fn(|k| link_mass[3 * l + k])),
            std::array::from_fn(|l| std::array::from_fn(|k| link_com[3 * l + k])),
        )
        .py()?;
        let n = capsule_radius.len();
        if capsule_leg.len() != n || capsule_link.len() != n {
            return Err(invalid(format!(
                "capsules: {n} radii but {} legs and {} links",
                capsule_leg.len(),
                capsule_link.len()
            )));
        }
        let a = vec3_rows(&read(&capsule_a, "capsule_a", &[n, 3])?);
        let b = vec3_rows(&read(&capsule_b, "capsule_b", &[n, 3])?);
        let capsules = (0..n)
            .map(|k| Capsule {
                leg: usize::try_from(capsule_leg[k]).ok(),
                link: usize::try_from(capsule_link[k]).unwrap_or(0),
                a: a[k],
                b: b[k],
                radius: capsule_radius[k],
            })
            .collect();
        let robot = FootstepRobot {
            quadruped: quadruped.inner.clone(),
            mass,
            collision: CollisionModel::new(capsules).py()?,
            nominal_q: std::array::from_fn(|i| q[i]),
        };
        let hf = heightfield.inner.clone();
        let shape = [hf.nx, hf.ny];
        let front = read(&cost_front, "cost_front", &shape)?;
        let hind = read(&cost_hind, "cost_hind", &shape)?;
        let s = sdf_values.shape();
        let spec = GridSpec::new(sdf_origin, sdf_resolution, [s[0], s[1], s[2]]).py()?;
        let values: Vec<f32> = sdf_values.as_array().iter().copied().collect();
        let grid = DistanceGrid::new(spec, values).py()?;
        let inner = py
            .detach(|| {
                let sdf = SignedDistanceField::new(grid, HeightFieldDistance::new(hf.clone()));
                FootstepPlanner::new(robot, &hf, sdf, &front, &hind, config)
            })
            .py()?;
        Ok(Self { inner })
    }

    /// Plans from `start_pose` (x, y, yaw) [m, m, rad] — the nominal stance
    /// there — or from `start_feet` (4, 2) [m] with `next_leg` moving first
    /// (and optionally `start_trunk`, the measured trunk position [m] and
    /// quaternion (w, x, y, z) the start certificate's search starts from),
    /// to the disc around `goal` (x, y) [m]. Stops after `time_limit` [s]
    /// and/or `expansions` states; `callback(report)` is called with every
    /// improved solution and stops the search by returning True. `search` is
    /// "arastar" or "exhaustive" (Dijkstra, small instances only).
    #[pyo3(signature = (goal, start_pose=None, start_feet=None, next_leg=2, time_limit=None, expansions=None, callback=None, search="arastar", start_trunk=None))]
    fn plan<'py>(
        &mut self,
        py: Python<'py>,
        goal: (f64, f64),
        start_pose: Option<(f64, f64, f64)>,
        start_feet: Option<ArrayIn<'py>>,
        next_leg: usize,
        time_limit: Option<f64>,
        expansions: Option<u64>,
        callback: Option<Py<PyAny>>,
        search: &str,
        start_trunk: Option<([f64; 3], [f64; 4])>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let start = match (start_pose, start_feet) {
            (Some((x, y, yaw)), None) if start_trunk.is_none() => Start::Pose { x, y, yaw },
            (None, Some(f)) => {
                let v = read(&f, "start_feet", &[4, 2])?;
                let trunk = start_trunk
                    .map(|(pos, quat)| BodyPose::new(pos, quat))
                    .transpose()
                    .py()?;
                Start::Feet {
                    feet: std::array::from_fn(|i| [v[2 * i], v[2 * i + 1]]),
                    next_leg,
                    trunk,
                }
            }
            _ => {
                return Err(invalid(
                    "give exactly one of start_pose (x, y, yaw) and start_feet (4, 2), \
                     and start_trunk only with start_feet"
                        .into(),
                ))
            }
        };
        let kind = match search {
            "arastar" => SearchKind::AraStar,
            "exhaustive" => SearchKind::Exhaustive,
            other => {
                return Err(invalid(format!(
                    "unknown search '{other}'; known: arastar, exhaustive"
                )))
            }
        };
        if let Some(t) = time_limit {
            if !(t.is_finite() && t >= 0.0) {
                return Err(invalid(format!(
                    "time_limit must be a finite number of seconds >= 0, got {t}"
                )));
            }
        }
        let planner = &mut self.inner;
        let (result, error) = py.detach(move || {
            let stop = Cell::new(false);
            let error: Cell<Option<PyErr>> = Cell::new(None);
            let checks = Cell::new(0u32);
            let mut rules = vec![Termination::callback(|_| {
                checks.set(checks.get().wrapping_add(1));
                if checks.get().is_multiple_of(SIGNAL_CHECK_PERIOD) {
                    if let Err(e) = Python::attach(|py: Python<'_>| py.check_signals()) {
                        error.set(Some(e));
                        stop.set(true);
                    }
                }
                if stop.get() {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            })];
            if let Some(t) = time_limit {
                rules.push(Termination::time_limit(Duration::from_secs_f64(t)));
            }
            if let Some(n) = expansions {
                rules.push(Termination::expansions(n));
            }
            let mut termination = Termination::any_of(rules);
            let mut on_solution = |report: &SolutionReport| {
                let Some(cb) = callback.as_ref() else { return };
                Python::attach(|py| {
                    let outcome = report_dict(py, report)
                        .and_then(|d| cb.call1(py, (d,)))
                        .and_then(|r| r.is_truthy(py));
                    match outcome {
                        Ok(true) => stop.set(true),
                        Ok(false) => {}
                        Err(e) => {
                            error.set(Some(e));
                            stop.set(true);
                        }
                    }
                });
            };
            let result = planner.plan(
                &start,
                [goal.0, goal.1],
                kind,
                &mut termination,
                Some(&mut on_solution),
            );
            drop(termination);
            (result, error.take())
        });
        if let Some(e) = error {
            return Err(e);
        }
        result_dict(py, &result)
    }

    /// The foothold lattice: (x0, y0, resolution, nx, ny) [m, m, m, -, -].
    #[getter]
    fn lattice(&self) -> (f64, f64, f64, usize, usize) {
        let l = self.inner.model().lattice();
        (l.x0, l.y0, l.resolution, l.nx, l.ny)
    }

    /// Cost per metre of the Euclidean and the Dubins heuristic [cost/m].
    #[getter]
    fn heuristic_scales(&self) -> (f64, f64) {
        self.inner.model().heuristic_scales()
    }

    /// The SDF interpolation error bound added to every certified clearance [m].
    #[getter]
    fn sdf_error(&self) -> f64 {
        self.inner.model().sdf_error()
    }

    /// Height of the trunk over the feet at the nominal stance [m].
    #[getter]
    fn nominal_height(&self) -> f64 {
        self.inner.model().nominal_height()
    }

    /// Number of foothold cells of the lattice.
    #[getter]
    fn foothold_count(&self) -> usize {
        self.inner.model().cost_map().foothold_count()
    }

    /// Number of cached certificate outcomes.
    #[getter]
    fn cache_len(&self) -> usize {
        self.inner.model().cache_len()
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyFootstepPlanner>()?;
    Ok(())
}

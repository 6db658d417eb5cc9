//! Bindings for `roughwalk_core::trajectory`: one CHOMP pass (trunk or swing
//! leg) of one footstep, set up once and evaluated once per iteration. Arrays
//! in (any array-like, converted to float64), a dict of arrays out.

use numpy::{AllowTypeChange, PyArray1, PyArrayLikeDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use roughwalk_core::kinematics::math::{Mat3, Vec3};
use roughwalk_core::trajectory::body_pass::BodyPassSetup;
use roughwalk_core::trajectory::swing_pass::SwingPassSetup;
use roughwalk_core::trajectory::{
    capsule_clearances, center_of_mass_batch, reach_by_height_and_tilt, BodyPass, BodyPoints,
    GradientMode, LinkCapsules, MassDistribution, ObstacleTerm, SwingPass, ZmpSupport,
};
use roughwalk_core::CoreError;

use crate::errors::{to_py, IntoPyResult};
use crate::robot::PyQuadruped;
use crate::sdf::PySdfField;

type ArrayIn<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

fn invalid(msg: String) -> PyErr {
    to_py(CoreError::InvalidArgument(msg))
}

/// Reads `arr` with shape `shape`, where `None` takes any length; refuses non-finite values.
fn read(arr: &ArrayIn<'_>, name: &str, shape: &[Option<usize>]) -> PyResult<Vec<f64>> {
    let got = arr.shape();
    let fits = got.len() == shape.len()
        && got
            .iter()
            .zip(shape)
            .all(|(g, s)| s.is_none_or(|s| s == *g));
    if !fits {
        let want: Vec<String> = shape
            .iter()
            .map(|s| s.map_or("N".to_string(), |v| v.to_string()))
            .collect();
        return Err(invalid(format!(
            "{name} must have shape ({}), got {got:?}",
            want.join(", ")
        )));
    }
    let v: Vec<f64> = arr.as_array().iter().copied().collect();
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(invalid(format!(
            "{name} must be finite, got {} at flat index {i}",
            v[i]
        )));
    }
    Ok(v)
}

fn rows<const N: usize>(v: &[f64]) -> Vec<[f64; N]> {
    v.chunks_exact(N)
        .map(|c| std::array::from_fn(|i| c[i]))
        .collect()
}

fn vec3_rows(v: &[f64]) -> Vec<Vec3> {
    rows::<3>(v)
}

fn array<'py>(py: Python<'py>, flat: Vec<f64>, shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, flat).reshape(shape)?.into_any())
}

fn bools<'py>(py: Python<'py>, flat: Vec<bool>, shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, flat).reshape(shape)?.into_any())
}

/// Body points from their per-point arrays (leg −1 for the trunk).
fn body_points(
    leg: &ArrayIn<'_>,
    link: &ArrayIn<'_>,
    local: &ArrayIn<'_>,
    radius: &ArrayIn<'_>,
    is_foot: &ArrayIn<'_>,
) -> PyResult<BodyPoints> {
    let leg = read(leg, "point legs", &[None])?;
    let u = leg.len();
    let link = read(link, "point links", &[Some(u)])?;
    let local = read(local, "point positions", &[Some(u), Some(3)])?;
    let radius = read(radius, "point radii", &[Some(u)])?;
    let is_foot = read(is_foot, "point foot flags", &[Some(u)])?;
    BodyPoints::new(
        &leg.iter().map(|&v| v as i64).collect::<Vec<_>>(),
        &link.iter().map(|&v| v as i64).collect::<Vec<_>>(),
        vec3_rows(&local),
        radius,
        is_foot.iter().map(|&v| v != 0.0).collect(),
    )
    .py()
}

/// The trunk block of one footstep's CHOMP (Zucker 2011, §5.3), evaluated in one call.
#[pyclass(name = "BodyPassEvaluator", module = "roughwalk._core", frozen)]
pub struct PyBodyPassEvaluator {
    inner: BodyPass,
    sdf: Py<PySdfField>,
    points: usize,
}

#[pymethods]
impl PyBodyPassEvaluator {
    #[new]
    #[pyo3(signature = (
        quadruped, sdf, point_leg, point_link, point_local, point_radius, point_is_foot,
        body, feet, support, held_q, active, hips, max_reach, velocity_limit,
        polygons, polygon_index, com_offset, com_offset_acceleration, *,
        dt, reach_margin, reach_weight, damping, zmp_k, zmp_margin, support_weight,
        obstacle_epsilon, obstacle_weight, gradient
    ))]
    fn new(
        quadruped: PyRef<'_, PyQuadruped>,
        sdf: Py<PySdfField>,
        point_leg: ArrayIn<'_>,
        point_link: ArrayIn<'_>,
        point_local: ArrayIn<'_>,
        point_radius: ArrayIn<'_>,
        point_is_foot: ArrayIn<'_>,
        body: ArrayIn<'_>,
        feet: ArrayIn<'_>,
        support: ArrayIn<'_>,
        held_q: ArrayIn<'_>,
        active: ArrayIn<'_>,
        hips: ArrayIn<'_>,
        max_reach: ArrayIn<'_>,
        velocity_limit: ArrayIn<'_>,
        polygons: Vec<ArrayIn<'_>>,
        polygon_index: ArrayIn<'_>,
        com_offset: ArrayIn<'_>,
        com_offset_acceleration: ArrayIn<'_>,
        dt: f64,
        reach_margin: f64,
        reach_weight: f64,
        damping: f64,
        zmp_k: f64,
        zmp_margin: f64,
        support_weight: f64,
        obstacle_epsilon: f64,
        obstacle_weight: f64,
        gradient: &str,
    ) -> PyResult<Self> {
        let points = body_points(
            &point_leg,
            &point_link,
            &point_local,
            &point_radius,
            &point_is_foot,
        )?;
        let u = points.len();
        let body = rows::<6>(&read(&body, "body", &[None, Some(6)])?);
        let t = body.len();
        let feet = read(&feet, "feet", &[Some(t), Some(4), Some(3)])?;
        let support = read(&support, "support", &[Some(t), Some(4)])?;
        let held_q = read(&held_q, "held_q", &[Some(t), Some(4), Some(3)])?;
        let active = read(&active, "active", &[Some(t), Some(u)])?;
        let hips = read(&hips, "hips", &[Some(4), Some(3)])?;
        let max_reach = read(&max_reach, "max_reach", &[Some(4)])?;
        let limit = read(&velocity_limit, "velocity_limit", &[Some(4), Some(3)])?;
        let polygons = polygons
            .iter()
            .map(|p| Ok(rows::<2>(&read(p, "support polygon", &[None, Some(2)])?)))
            .collect::<PyResult<Vec<_>>>()?;
        let index = read(&polygon_index, "polygon_index", &[Some(t)])?;
        let offset = read(&com_offset, "com_offset", &[Some(t), Some(2)])?;
        let offset_acc = read(
            &com_offset_acceleration,
            "com_offset_acceleration",
            &[Some(t), Some(2)],
        )?;
        let setup = BodyPassSetup {
            body,
            feet: rows::<12>(&feet)
                .iter()
                .map(|r| std::array::from_fn(|l| [r[3 * l], r[3 * l + 1], r[3 * l + 2]]))
                .collect(),
            support: rows::<4>(&support)
                .iter()
                .map(|r| r.map(|v| v != 0.0))
                .collect(),
            held_q: rows::<12>(&held_q),
            active: active.iter().map(|&v| v != 0.0).collect(),
            hips: std::array::from_fn(|l| [hips[3 * l], hips[3 * l + 1], hips[3 * l + 2]]),
            max_reach: std::array::from_fn(|l| max_reach[l]),
            reach_margin,
            reach_weight,
            velocity_limit: std::array::from_fn(|j| limit[j]),
            dt,
            damping,
        };
        let support = ZmpSupport::new(
            polygons,
            index.iter().map(|&v| v as usize).collect(),
            rows::<2>(&offset),
            rows::<2>(&offset_acc),
            zmp_k,
            dt,
            zmp_margin,
            support_weight,
        )
        .py()?;
        let obstacle = ObstacleTerm::new(
            obstacle_epsilon,
            obstacle_weight,
            GradientMode::parse(gradient).py()?,
        )
        .py()?;
        let inner =
            BodyPass::new(quadruped.inner.clone(), points, setup, obstacle, support).py()?;
        Ok(Self {
            inner,
            sdf,
            points: u,
        })
    }

    /// Terms, gradient (n, 6), clearances (T, U), points (T, U, 3), q (T, 4, 3),
    /// reached (T, 4), ZMP margins (T − 2,) and the velocity excess at ξ (n, 6).
    fn evaluate<'py>(&self, py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Bound<'py, PyDict>> {
        let n = self.inner.samples() - 2;
        let xi = rows::<6>(&read(&xi, "xi", &[Some(n), Some(6)])?);
        let field = &self.sdf.get().inner;
        let ev = py.detach(|| self.inner.evaluate(&xi, field)).py()?;
        let t = n + 2;
        let u = self.points;
        let out = PyDict::new(py);
        out.set_item("obstacle", ev.obstacle)?;
        out.set_item("reachability", ev.reachability)?;
        out.set_item("support", ev.support)?;
        out.set_item("velocity_excess", ev.velocity_excess)?;
        out.set_item("gradient", array(py, ev.gradient.concat(), &[n, 6])?)?;
        out.set_item("clearance", array(py, ev.clearance, &[t, u])?)?;
        out.set_item("points", array(py, ev.points.concat(), &[t, u, 3])?)?;
        out.set_item("q", array(py, ev.q.concat(), &[t, 4, 3])?)?;
        out.set_item("reached", bools(py, ev.reached.concat(), &[t, 4])?)?;
        out.set_item("margins", array(py, ev.margins, &[n])?)?;
        Ok(out)
    }
}

/// The swing-leg block of one footstep's CHOMP (Zucker 2011, §5.3), evaluated in one call.
#[pyclass(name = "SwingPassEvaluator", module = "roughwalk._core", frozen)]
pub struct PySwingPassEvaluator {
    inner: SwingPass,
    sdf: Py<PySdfField>,
    samples: usize,
}

#[pymethods]
impl PySwingPassEvaluator {
    #[new]
    #[pyo3(signature = (
        quadruped, sdf, point_leg, point_link, point_local, point_radius, point_is_foot,
        leg, base_pos, rotation, ends, active, velocity_limit, *,
        dt, speed_fraction, speed_weight, obstacle_epsilon, obstacle_weight, gradient
    ))]
    fn new(
        quadruped: PyRef<'_, PyQuadruped>,
        sdf: Py<PySdfField>,
        point_leg: ArrayIn<'_>,
        point_link: ArrayIn<'_>,
        point_local: ArrayIn<'_>,
        point_radius: ArrayIn<'_>,
        point_is_foot: ArrayIn<'_>,
        leg: usize,
        base_pos: ArrayIn<'_>,
        rotation: ArrayIn<'_>,
        ends: ArrayIn<'_>,
        active: ArrayIn<'_>,
        velocity_limit: ArrayIn<'_>,
        dt: f64,
        speed_fraction: f64,
        speed_weight: f64,
        obstacle_epsilon: f64,
        obstacle_weight: f64,
        gradient: &str,
    ) -> PyResult<Self> {
        let points = body_points(
            &point_leg,
            &point_link,
            &point_local,
            &point_radius,
            &point_is_foot,
        )?;
        let base_pos = vec3_rows(&read(&base_pos, "base_pos", &[None, Some(3)])?);
        let w = base_pos.len();
        let rotation: Vec<Mat3> =
            rows::<9>(&read(&rotation, "rotation", &[Some(w), Some(3), Some(3)])?)
                .iter()
                .map(|r| [[r[0], r[1], r[2]], [r[3], r[4], r[5]], [r[6], r[7], r[8]]])
                .collect();
        let ends = read(&ends, "ends", &[Some(2), Some(3)])?;
        let active = read(&active, "active", &[Some(w), None])?;
        let limit = read(&velocity_limit, "velocity_limit", &[Some(3)])?;
        let setup = SwingPassSetup {
            base_pos,
            rotation,
            ends: [[ends[0], ends[1], ends[2]], [ends[3], ends[4], ends[5]]],
            active: active.iter().map(|&v| v != 0.0).collect(),
            velocity_limit: [limit[0], limit[1], limit[2]],
            speed_fraction,
            speed_weight,
            dt,
        };
        let obstacle = ObstacleTerm::new(
            obstacle_epsilon,
            obstacle_weight,
            GradientMode::parse(gradient).py()?,
        )
        .py()?;
        let inner = SwingPass::new(&quadruped.inner, &points, leg, setup, obstacle).py()?;
        Ok(Self {
            inner,
            sdf,
            samples: w,
        })
    }

    /// Terms, gradient (n, 3), the leg's clearances (W, U_leg) and points
    /// (W, U_leg, 3), and the velocity excess at the airborne angles ξ (n, 3).
    fn evaluate<'py>(&self, py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Bound<'py, PyDict>> {
        let n = self.samples - 2;
        let xi = vec3_rows(&read(&xi, "xi", &[Some(n), Some(3)])?);
        let field = &self.sdf.get().inner;
        let ev = py.detach(|| self.inner.evaluate(&xi, field)).py()?;
        let u = self.inner.point_index().len();
        let out = PyDict::new(py);
        out.set_item("obstacle", ev.obstacle)?;
        out.set_item("joint_speed", ev.joint_speed)?;
        out.set_item("velocity_excess", ev.velocity_excess)?;
        out.set_item("gradient", array(py, ev.gradient.concat(), &[n, 3])?)?;
        out.set_item("clearance", array(py, ev.clearance, &[self.samples, u])?)?;
        out.set_item(
            "points",
            array(py, ev.points.concat(), &[self.samples, u, 3])?,
        )?;
        Ok(out)
    }
}

/// Whole-robot CoM (N, 3) in the base frame [m] for joint angles (N, 4, 3) [rad],
/// from link masses (4, 3) [kg], link CoMs (4, 3, 3) in their link frames [m]
/// and the trunk's mass [kg] and CoM (3,) [m].
#[pyfunction]
#[pyo3(name = "center_of_mass_batch")]
fn center_of_mass_batch_py<'py>(
    py: Python<'py>,
    quadruped: PyRef<'py, PyQuadruped>,
    q: ArrayIn<'py>,
    link_mass: ArrayIn<'py>,
    link_com: ArrayIn<'py>,
    base_mass: f64,
    base_com: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let q = rows::<12>(&read(&q, "q", &[None, Some(4), Some(3)])?);
    let lm = read(&link_mass, "link_mass", &[Some(4), Some(3)])?;
    let lc = read(&link_com, "link_com", &[Some(4), Some(3), Some(3)])?;
    let bc = read(&base_com, "base_com", &[Some(3)])?;
    let mass = MassDistribution {
        link_mass: std::array::from_fn(|l| [lm[3 * l], lm[3 * l + 1], lm[3 * l + 2]]),
        link_com: std::array::from_fn(|l| {
            std::array::from_fn(|k| {
                let i = 9 * l + 3 * k;
                [lc[i], lc[i + 1], lc[i + 2]]
            })
        }),
        base_mass,
        base_com: [bc[0], bc[1], bc[2]],
    };
    let robot = &quadruped.inner;
    let com = py.detach(|| center_of_mass_batch(robot, &mass, &q)).py()?;
    array(py, com.concat(), &[q.len(), 3])
}

/// Clearances (N, P) [m] of P collision capsules (leg −1 = trunk, link, ends
/// a and b (P, 3) in their link's frame [m], radii (P,)) at N configurations:
/// joint angles (N, 4, 3) [rad], trunk positions (N, 3) [m], orientations (N, 3, 3).
#[pyfunction]
#[pyo3(name = "capsule_clearances")]
fn capsule_clearances_py<'py>(
    py: Python<'py>,
    quadruped: PyRef<'py, PyQuadruped>,
    sdf: PyRef<'py, PySdfField>,
    leg: ArrayIn<'py>,
    link: ArrayIn<'py>,
    a: ArrayIn<'py>,
    b: ArrayIn<'py>,
    radius: ArrayIn<'py>,
    q: ArrayIn<'py>,
    base_pos: ArrayIn<'py>,
    rotation: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let leg = read(&leg, "capsule legs", &[None])?;
    let p = leg.len();
    let link = read(&link, "capsule links", &[Some(p)])?;
    let a = vec3_rows(&read(&a, "capsule ends a", &[Some(p), Some(3)])?);
    let b = vec3_rows(&read(&b, "capsule ends b", &[Some(p), Some(3)])?);
    let radius = read(&radius, "capsule radii", &[Some(p)])?;
    let capsules = LinkCapsules::new(
        &leg.iter().map(|&v| v as i64).collect::<Vec<_>>(),
        &link.iter().map(|&v| v as i64).collect::<Vec<_>>(),
        a,
        b,
        radius,
    )
    .py()?;
    let q = rows::<12>(&read(&q, "q", &[None, Some(4), Some(3)])?);
    let n = q.len();
    let base_pos = vec3_rows(&read(&base_pos, "base_pos", &[Some(n), Some(3)])?);
    let rotation: Vec<Mat3> =
        rows::<9>(&read(&rotation, "rotation", &[Some(n), Some(3), Some(3)])?)
            .iter()
            .map(|r| [[r[0], r[1], r[2]], [r[3], r[4], r[5]], [r[6], r[7], r[8]]])
            .collect();
    let robot = &quadruped.inner;
    let field = &sdf.inner;
    let d = py
        .detach(|| capsule_clearances(robot, &capsules, field, &q, &base_pos, &rotation))
        .py()?;
    array(py, d, &[n, p])
}

/// The trunk's position (3,) [m] and orientation (3, 3) moved by height and tilt
/// until the feet (4, 3) [m, world] are reached (hips (4, 3): the hip anchors in
/// the base frame [m]); None when they all are from the start.
#[pyfunction]
#[pyo3(name = "reach_by_height_and_tilt")]
fn reach_by_height_and_tilt_py<'py>(
    py: Python<'py>,
    quadruped: PyRef<'py, PyQuadruped>,
    hips: ArrayIn<'py>,
    feet: ArrayIn<'py>,
    base_pos: ArrayIn<'py>,
    rotation: ArrayIn<'py>,
    iterations: usize,
) -> PyResult<Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)>> {
    let hips = vec3_rows(&read(&hips, "hips", &[Some(4), Some(3)])?);
    let feet = vec3_rows(&read(&feet, "feet", &[Some(4), Some(3)])?);
    let x = read(&base_pos, "base_pos", &[Some(3)])?;
    let r = read(&rotation, "rotation", &[Some(3), Some(3)])?;
    let hips: [Vec3; 4] = std::array::from_fn(|l| hips[l]);
    let feet: [Vec3; 4] = std::array::from_fn(|l| feet[l]);
    let rot: Mat3 = [[r[0], r[1], r[2]], [r[3], r[4], r[5]], [r[6], r[7], r[8]]];
    let moved = reach_by_height_and_tilt(
        &quadruped.inner,
        &hips,
        &feet,
        [x[0], x[1], x[2]],
        rot,
        iterations,
    );
    moved
        .map(|(x, rot)| {
            Ok((
                array(py, x.to_vec(), &[3])?,
                array(py, rot.concat(), &[3, 3])?,
            ))
        })
        .transpose()
}

/// Adds the pass evaluators and the CoM and clearance batches to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(capsule_clearances_py, m)?)?;
    m.add_class::<PyBodyPassEvaluator>()?;
    m.add_class::<PySwingPassEvaluator>()?;
    m.add_function(wrap_pyfunction!(center_of_mass_batch_py, m)?)?;
    m.add_function(wrap_pyfunction!(reach_by_height_and_tilt_py, m)?)?;
    Ok(())
}

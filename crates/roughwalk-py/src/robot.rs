//! Bindings for `roughwalk_core::kinematics`: leg chains, the quadruped's
//! FK/IK (single and batched), the body-pose steps and the support-polygon
//! helpers. Arrays in and out are float64 numpy arrays; any array-like is accepted.

// PyO3 extracts every argument by value; borrowing them is not an option.
#![allow(clippy::needless_pass_by_value)]

use numpy::{AllowTypeChange, PyArray1, PyArrayLikeDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyList;
use roughwalk_core::kinematics::math::{Mat3, Quat, Vec3};
use roughwalk_core::kinematics::{
    self as kin, BodyPoseStep, CollisionPoint, LegChain, LegParams, Quadruped,
};
use roughwalk_core::CoreError;

use crate::errors::{to_py, IntoPyResult};

type ArrayIn<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

fn invalid(msg: String) -> PyErr {
    to_py(CoreError::InvalidArgument(msg))
}

/// A shape as Python prints it: (3,), (4, 3).
fn shape_str(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Reads `arr` as exactly `shape`, refusing other shapes and non-finite values.
fn read(arr: &ArrayIn<'_>, name: &str, shape: &[usize]) -> PyResult<Vec<f64>> {
    if arr.shape() != shape {
        return Err(invalid(format!(
            "{name} must have shape {}, got {}",
            shape_str(shape),
            shape_str(arr.shape())
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

/// Reads `arr` as (N, *row): the row count and the flat values.
fn read_rows(arr: &ArrayIn<'_>, name: &str, row: &[usize]) -> PyResult<(usize, Vec<f64>)> {
    let shape = arr.shape();
    if shape.len() != row.len() + 1 || &shape[1..] != row {
        return Err(invalid(format!(
            "{name} must have shape (N, {}), got {}",
            row.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            shape_str(shape)
        )));
    }
    let n = shape[0];
    let mut full = vec![n];
    full.extend_from_slice(row);
    Ok((n, read(arr, name, &full)?))
}

fn vec3(arr: &ArrayIn<'_>, name: &str) -> PyResult<Vec3> {
    let v = read(arr, name, &[3])?;
    Ok([v[0], v[1], v[2]])
}

fn quat(arr: &ArrayIn<'_>, name: &str) -> PyResult<Quat> {
    let v = read(arr, name, &[4])?;
    Ok([v[0], v[1], v[2], v[3]])
}

fn rows3<const N: usize>(arr: &ArrayIn<'_>, name: &str) -> PyResult<[Vec3; N]> {
    let v = read(arr, name, &[N, 3])?;
    Ok(std::array::from_fn(|i| {
        [v[3 * i], v[3 * i + 1], v[3 * i + 2]]
    }))
}

fn rows4<const N: usize>(arr: &ArrayIn<'_>, name: &str) -> PyResult<[Quat; N]> {
    let v = read(arr, name, &[N, 4])?;
    Ok(std::array::from_fn(|i| {
        [v[4 * i], v[4 * i + 1], v[4 * i + 2], v[4 * i + 3]]
    }))
}

/// A point in the x–y plane from a (2,) or (3,) array (z ignored).
fn xy(arr: &ArrayIn<'_>, name: &str) -> PyResult<[f64; 2]> {
    let n = arr.shape().first().copied().unwrap_or(0);
    if arr.ndim() != 1 || !(n == 2 || n == 3) {
        return Err(invalid(format!(
            "{name} must have shape (2,) or (3,), got {}",
            shape_str(arr.shape())
        )));
    }
    let v = read(arr, name, &[n])?;
    Ok([v[0], v[1]])
}

/// Points in the x–y plane from a (k, 2) or (k, 3) array (z ignored).
fn xy_rows(arr: &ArrayIn<'_>, name: &str) -> PyResult<Vec<[f64; 2]>> {
    let shape = arr.shape().to_vec();
    if shape.len() != 2 || !(shape[1] == 2 || shape[1] == 3) {
        return Err(invalid(format!(
            "{name} must have shape (k, 2) or (k, 3), got {}",
            shape_str(&shape)
        )));
    }
    let v = read(arr, name, &shape)?;
    Ok(v.chunks(shape[1]).map(|r| [r[0], r[1]]).collect())
}

fn array<'py>(py: Python<'py>, flat: Vec<f64>, shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, flat).reshape(shape)?.into_any())
}

fn mat<'py>(py: Python<'py>, m: &Mat3) -> PyResult<Bound<'py, PyAny>> {
    array(py, m.iter().flatten().copied().collect(), &[3, 3])
}

fn vec_out<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyAny> {
    PyArray1::from_vec(py, v.to_vec()).into_any()
}

/// One leg: three hinge joints (HAA, HFE, KFE) from the trunk frame to a spherical foot.
#[pyclass(name = "LegChain", module = "roughwalk._core", frozen)]
#[derive(Clone)]
pub struct PyLegChain {
    pub inner: LegChain,
}

#[pymethods]
impl PyLegChain {
    #[new]
    #[pyo3(signature = (body_pos, body_quat, anchor, axis, lower, upper, velocity_limit, foot, foot_radius, knee_sign, name="leg"))]
    fn new(
        body_pos: ArrayIn<'_>,
        body_quat: ArrayIn<'_>,
        anchor: ArrayIn<'_>,
        axis: ArrayIn<'_>,
        lower: ArrayIn<'_>,
        upper: ArrayIn<'_>,
        velocity_limit: ArrayIn<'_>,
        foot: ArrayIn<'_>,
        foot_radius: f64,
        knee_sign: f64,
        name: &str,
    ) -> PyResult<Self> {
        // Limits may be ±inf (unlimited joints), so they skip the finiteness check.
        let limits = |arr: &ArrayIn<'_>, what: &str| -> PyResult<Vec3> {
            if arr.shape() != [3] {
                return Err(invalid(format!(
                    "{what} must have shape (3,), got {}",
                    shape_str(arr.shape())
                )));
            }
            let v: Vec<f64> = arr.as_array().iter().copied().collect();
            Ok([v[0], v[1], v[2]])
        };
        let params = LegParams {
            body_pos: rows3(&body_pos, "body_pos")?,
            body_quat: rows4(&body_quat, "body_quat")?,
            anchor: rows3(&anchor, "anchor")?,
            axis: rows3(&axis, "axis")?,
            lower: limits(&lower, "lower")?,
            upper: limits(&upper, "upper")?,
            velocity_limit: limits(&velocity_limit, "velocity_limit")?,
            foot: vec3(&foot, "foot")?,
            foot_radius,
            knee_sign,
        };
        Ok(Self {
            inner: LegChain::new(name, params).py()?,
        })
    }

    /// Foot centre in the base frame, FK_B(q) [m], shape (3,).
    fn fk<'py>(&self, py: Python<'py>, q: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(vec_out(py, &self.inner.fk(vec3(&q, "q")?)))
    }

    /// ∂FK_B/∂q [m/rad], shape (3, 3), column k for joint k.
    fn jacobian<'py>(&self, py: Python<'py>, q: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.inner.jacobian(vec3(&q, "q")?))
    }

    /// Base-frame position (3,) [m] and Jacobian (3, 3) [m/rad] of a point on link 0, 1 or 2.
    fn point_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: ArrayIn<'py>,
        link: usize,
        point: ArrayIn<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (p, j) = self
            .inner
            .point_jacobian(vec3(&q, "q")?, link, vec3(&point, "point")?)
            .py()?;
        Ok((vec_out(py, &p), mat(py, &j)?))
    }

    /// Origins (3, 3) [m] and rotation matrices (3, 3, 3) of the three joint bodies, base frame.
    fn link_frames<'py>(
        &self,
        py: Python<'py>,
        q: ArrayIn<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let f = self.inner.link_frames(vec3(&q, "q")?);
        let pos = array(py, f.pos.iter().flatten().copied().collect(), &[3, 3])?;
        let rot = array(
            py,
            f.rot.iter().flatten().flatten().copied().collect(),
            &[3, 3, 3],
        )?;
        Ok((pos, rot))
    }

    /// IK_B: (q (3,) [rad], reachable, within_limits, error [m]) for a base-frame target [m].
    #[pyo3(signature = (target, knee_sign=None))]
    fn ik<'py>(
        &self,
        py: Python<'py>,
        target: ArrayIn<'py>,
        knee_sign: Option<f64>,
    ) -> PyResult<(Bound<'py, PyAny>, bool, bool, f64)> {
        if let Some(k) = knee_sign {
            if !(k.is_finite() && k != 0.0) {
                return Err(invalid(format!("knee_sign must be +1 or -1, got {k}")));
            }
        }
        let r = self.inner.ik(vec3(&target, "target")?, knee_sign);
        Ok((vec_out(py, &r.q), r.reachable, r.within_limits, r.error))
    }

    #[getter]
    fn name(&self) -> &str {
        self.inner.name()
    }
    #[getter]
    fn body_pos<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.inner.params().body_pos)
    }
    #[getter]
    fn body_quat<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let q = &self.inner.params().body_quat;
        array(py, q.iter().flatten().copied().collect(), &[3, 4])
    }
    #[getter]
    fn anchor<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.inner.params().anchor)
    }
    #[getter]
    fn axis<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.inner.params().axis)
    }
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec_out(py, &self.inner.params().lower)
    }
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec_out(py, &self.inner.params().upper)
    }
    #[getter]
    fn velocity_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec_out(py, &self.inner.params().velocity_limit)
    }
    #[getter]
    fn foot<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec_out(py, &self.inner.params().foot)
    }
    #[getter]
    fn foot_radius(&self) -> f64 {
        self.inner.params().foot_radius
    }
    #[getter]
    fn knee_sign(&self) -> f64 {
        self.inner.params().knee_sign
    }

    fn __repr__(&self) -> String {
        let p = self.inner.params();
        format!(
            "LegChain(name={:?}, lower={:?}, upper={:?}, knee_sign={})",
            self.inner.name(),
            p.lower,
            p.upper,
            p.knee_sign
        )
    }
}

/// The result of one body-pose step: the new trunk pose and what moved it.
#[pyclass(name = "BodyPoseStep", module = "roughwalk._core", frozen)]
pub struct PyBodyPoseStep {
    step: BodyPoseStep,
    ik: Option<([f64; 12], [bool; 4])>,
}

#[pymethods]
impl PyBodyPoseStep {
    /// Trunk position after the step [m], shape (3,).
    #[getter]
    fn base_pos<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec_out(py, &self.step.base_pos)
    }
    /// Trunk orientation (w, x, y, z) after the step, shape (4,).
    #[getter]
    fn base_quat<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec_out(py, &self.step.base_quat)
    }
    /// Translation applied (world) [m], shape (3,).
    #[getter]
    fn delta_x<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec_out(py, &self.step.delta_x)
    }
    /// Rotation applied (world rotation vector) [rad], shape (3,).
    #[getter]
    fn omega<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec_out(py, &self.step.omega)
    }
    /// The objective before the step [m] (foot error, distance or CoM margin).
    #[getter]
    fn value_before(&self) -> f64 {
        self.step.value_before
    }
    /// Reachability step only: IK joint angles (12,) [rad] at the old pose, else None.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyAny>> {
        self.ik.map(|(q, _)| vec_out(py, &q))
    }
    /// Reachability step only: whether each foot was reached at the old pose (4,), else None.
    #[getter]
    fn reachable<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyAny>> {
        self.ik
            .map(|(_, r)| PyArray1::from_vec(py, r.to_vec()).into_any())
    }

    fn __repr__(&self) -> String {
        format!(
            "BodyPoseStep(delta_x={:?}, omega={:?}, value_before={})",
            self.step.delta_x, self.step.omega, self.step.value_before
        )
    }
}

fn collision_point(leg: Option<usize>, link: usize, point: Vec3) -> CollisionPoint {
    match leg {
        None => CollisionPoint::Trunk(point),
        Some(leg) => CollisionPoint::Leg { leg, link, point },
    }
}

/// Four legs on a trunk, canonical order LF, RF, LH, RH; q is leg-major (HAA, HFE, KFE).
#[pyclass(name = "Quadruped", module = "roughwalk._core", frozen)]
pub struct PyQuadruped {
    pub inner: Quadruped,
}

#[pymethods]
impl PyQuadruped {
    #[new]
    fn new(legs: Vec<PyRef<'_, PyLegChain>>) -> PyResult<Self> {
        if legs.len() != 4 {
            return Err(to_py(CoreError::RobotModel(format!(
                "a quadruped needs 4 legs in the order {}, got {}",
                kin::LEG_NAMES.join(", "),
                legs.len()
            ))));
        }
        let legs: [LegChain; 4] = std::array::from_fn(|i| legs[i].inner.clone());
        Ok(Self {
            inner: Quadruped::new(legs),
        })
    }

    /// The four legs, canonical order.
    #[getter]
    fn legs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let legs: Vec<PyLegChain> = self
            .inner
            .legs()
            .iter()
            .map(|l| PyLegChain { inner: l.clone() })
            .collect();
        PyList::new(py, legs)
    }

    /// World feet (4, 3) [m]: FK_W(x, R, q_i) = R·FK_B(q_i) + x.
    #[pyo3(signature = (q, base_pos=None, base_quat=None))]
    fn foot_positions<'py>(
        &self,
        py: Python<'py>,
        q: ArrayIn<'py>,
        base_pos: Option<ArrayIn<'py>>,
        base_quat: Option<ArrayIn<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let q = q12(&q)?;
        let (pos, quat) = pose(base_pos.as_ref(), base_quat.as_ref())?;
        let feet = self.inner.foot_positions_world(pos, quat, &q).py()?;
        array(py, feet.iter().flatten().copied().collect(), &[4, 3])
    }

    /// IK_W: joint angles (12,) [rad] and per-leg reached flags (4,) for world feet (4, 3) [m].
    #[pyo3(signature = (feet, base_pos=None, base_quat=None))]
    fn inverse_kinematics<'py>(
        &self,
        py: Python<'py>,
        feet: ArrayIn<'py>,
        base_pos: Option<ArrayIn<'py>>,
        base_quat: Option<ArrayIn<'py>>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let feet = rows3::<4>(&feet, "feet")?;
        let (pos, quat) = pose(base_pos.as_ref(), base_quat.as_ref())?;
        let (q, ok) = self.inner.ik_world(pos, quat, &feet).py()?;
        Ok((
            vec_out(py, &q),
            PyArray1::from_vec(py, ok.to_vec()).into_any(),
        ))
    }

    /// Base-frame feet (N, 4, 3) [m] of joint angles (N, 12) [rad].
    fn fk_batch<'py>(&self, py: Python<'py>, q: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (n, flat) = read_rows(&q, "q", &[12])?;
        let rows: Vec<[f64; 12]> = flat
            .chunks_exact(12)
            .map(|r| std::array::from_fn(|k| r[k]))
            .collect();
        let feet = py.detach(|| self.inner.fk_batch(&rows));
        array(
            py,
            feet.iter().flatten().flatten().copied().collect(),
            &[n, 4, 3],
        )
    }

    /// IK_B of base-frame feet (N, 4, 3) [m]: joint angles (N, 12) [rad] and reached flags (N, 4).
    fn ik_batch<'py>(
        &self,
        py: Python<'py>,
        feet: ArrayIn<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (n, flat) = read_rows(&feet, "feet", &[4, 3])?;
        let rows: Vec<[Vec3; 4]> = flat
            .chunks_exact(12)
            .map(|r| std::array::from_fn(|i| [r[3 * i], r[3 * i + 1], r[3 * i + 2]]))
            .collect();
        let (q, ok) = py.detach(|| self.inner.ik_batch(&rows));
        let q = array(py, q.iter().flatten().copied().collect(), &[n, 12])?;
        let ok = PyArray1::from_vec(py, ok.iter().flatten().copied().collect::<Vec<bool>>())
            .reshape([n, 4])?
            .into_any();
        Ok((q, ok))
    }

    /// Zucker 2011 §3.2: Δx = α Σ e_i, ω = β Σ (f'_i − x) × e_i; value_before = Σ|e_i| [m].
    fn reachability_step(
        &self,
        feet: ArrayIn<'_>,
        base_pos: ArrayIn<'_>,
        base_quat: ArrayIn<'_>,
        alpha: f64,
        beta: f64,
    ) -> PyResult<PyBodyPoseStep> {
        let feet = rows3::<4>(&feet, "feet")?;
        let (step, q, ok) = kin::reachability_step(
            &self.inner,
            &feet,
            vec3(&base_pos, "base_pos")?,
            quat(&base_quat, "base_quat")?,
            alpha,
            beta,
        )
        .py()?;
        Ok(PyBodyPoseStep {
            step,
            ik: Some((q, ok)),
        })
    }

    /// Zucker 2011 §3.4: p (3,) [m], J_p(x) (3, 3) and J_p(R) (3, 3) with the feet held by IK.
    #[pyo3(signature = (feet, base_pos, base_quat, leg, link, point))]
    fn point_pose_jacobians<'py>(
        &self,
        py: Python<'py>,
        feet: ArrayIn<'py>,
        base_pos: ArrayIn<'py>,
        base_quat: ArrayIn<'py>,
        leg: Option<usize>,
        link: usize,
        point: ArrayIn<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let jac = kin::point_pose_jacobians(
            &self.inner,
            &rows3::<4>(&feet, "feet")?,
            vec3(&base_pos, "base_pos")?,
            quat(&base_quat, "base_quat")?,
            collision_point(leg, link, vec3(&point, "point")?),
        )
        .py()?;
        Ok((vec_out(py, &jac.p), mat(py, &jac.j_x)?, mat(py, &jac.j_r)?))
    }

    /// Zucker 2011 §3.4: Δx = α(c − d)·J_p(x)ᵀg, ω = β(c − d)·J_p(R)ᵀg while d < c; value_before = d.
    #[pyo3(signature = (feet, base_pos, base_quat, leg, link, point, distance, gradient, alpha, beta, clearance=0.0))]
    fn obstacle_avoidance_step(
        &self,
        feet: ArrayIn<'_>,
        base_pos: ArrayIn<'_>,
        base_quat: ArrayIn<'_>,
        leg: Option<usize>,
        link: usize,
        point: ArrayIn<'_>,
        distance: f64,
        gradient: ArrayIn<'_>,
        alpha: f64,
        beta: f64,
        clearance: f64,
    ) -> PyResult<PyBodyPoseStep> {
        let (step, _) = kin::obstacle_avoidance_step(
            &self.inner,
            &rows3::<4>(&feet, "feet")?,
            vec3(&base_pos, "base_pos")?,
            quat(&base_quat, "base_quat")?,
            collision_point(leg, link, vec3(&point, "point")?),
            distance,
            vec3(&gradient, "gradient")?,
            clearance,
            alpha,
            beta,
        )
        .py()?;
        Ok(PyBodyPoseStep { step, ik: None })
    }

    /// Zucker 2011 §4.4: move the CoM (x + R·com_offset) horizontally toward `margin` inside the stance feet.
    #[staticmethod]
    fn com_support_step(
        stance_feet: ArrayIn<'_>,
        base_pos: ArrayIn<'_>,
        base_quat: ArrayIn<'_>,
        com_offset: ArrayIn<'_>,
        margin: f64,
        max_step: f64,
    ) -> PyResult<PyBodyPoseStep> {
        let (_, flat) = read_rows(&stance_feet, "stance_feet", &[3])?;
        let feet: Vec<Vec3> = flat.chunks_exact(3).map(|r| [r[0], r[1], r[2]]).collect();
        let step = kin::com_support_step(
            &feet,
            vec3(&base_pos, "base_pos")?,
            quat(&base_quat, "base_quat")?,
            vec3(&com_offset, "com_offset")?,
            margin,
            max_step,
        )
        .py()?;
        Ok(PyBodyPoseStep { step, ik: None })
    }
}

fn q12(q: &ArrayIn<'_>) -> PyResult<[f64; 12]> {
    let v = read(q, "q", &[12])?;
    Ok(std::array::from_fn(|k| v[k]))
}

fn pose(base_pos: Option<&ArrayIn<'_>>, base_quat: Option<&ArrayIn<'_>>) -> PyResult<(Vec3, Quat)> {
    let pos = base_pos.map_or(Ok([0.0; 3]), |p| vec3(p, "base_pos"))?;
    let quat = base_quat.map_or(Ok([1.0, 0.0, 0.0, 0.0]), |q| quat(q, "base_quat"))?;
    Ok((pos, quat))
}

/// Incircle centre (2,) [m] and radius [m] of the x–y triangle (a, b, c); points (2,) or (3,).
#[pyfunction]
fn support_triangle_incircle<'py>(
    py: Python<'py>,
    a: ArrayIn<'py>,
    b: ArrayIn<'py>,
    c: ArrayIn<'py>,
) -> PyResult<(Bound<'py, PyAny>, f64)> {
    let (centre, r) = kin::support_triangle_incircle(xy(&a, "a")?, xy(&b, "b")?, xy(&c, "c")?);
    Ok((vec_out(py, &centre), r))
}

/// Signed x–y distance [m] from `point` to the convex hull of `feet` (k, 2|3): positive inside.
#[pyfunction]
fn support_polygon_margin(point: ArrayIn<'_>, feet: ArrayIn<'_>) -> PyResult<f64> {
    let feet = xy_rows(&feet, "feet")?;
    if feet.is_empty() {
        return Err(invalid(
            "feet must hold at least one point, got none".into(),
        ));
    }
    Ok(kin::support_polygon_margin(xy(&point, "point")?, &feet))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyLegChain>()?;
    m.add_class::<PyQuadruped>()?;
    m.add_class::<PyBodyPoseStep>()?;
    m.add_function(wrap_pyfunction!(support_triangle_incircle, m)?)?;
    m.add_function(wrap_pyfunction!(support_polygon_margin, m)?)?;
    Ok(())
}

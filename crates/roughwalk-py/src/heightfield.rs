//! Bindings for `roughwalk_core::HeightField`: batched height and normal queries.

use numpy::{PyArray1, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use roughwalk_core::{HeightField, Interpolation};

use crate::errors::IntoPyResult;

pub fn parse_interp(name: &str) -> PyResult<Interpolation> {
    match name {
        "bilinear" => Ok(Interpolation::Bilinear),
        "bicubic" => Ok(Interpolation::Bicubic),
        other => Err(crate::errors::to_py(
            roughwalk_core::CoreError::InvalidArgument(format!(
                "unknown interpolation '{other}'; known: bilinear, bicubic"
            )),
        )),
    }
}

/// A regular-grid height field held in Rust (x-major heights [m]).
#[pyclass(name = "HeightField", module = "roughwalk._core", frozen)]
pub struct PyHeightField {
    pub inner: HeightField,
}

#[pymethods]
impl PyHeightField {
    #[new]
    #[pyo3(signature = (x0, y0, dx, dy, heights, known=None))]
    fn new(
        x0: f64,
        y0: f64,
        dx: f64,
        dy: f64,
        heights: PyReadonlyArray2<'_, f64>,
        known: Option<PyReadonlyArray2<'_, bool>>,
    ) -> PyResult<Self> {
        let shape = heights.shape();
        let (nx, ny) = (shape[0], shape[1]);
        let h = heights.as_array().iter().copied().collect();
        let k = match known {
            Some(k) => {
                if k.shape() != shape {
                    return Err(crate::errors::to_py(roughwalk_core::CoreError::Terrain(
                        format!(
                            "known mask shape {:?} differs from heights shape {:?}",
                            k.shape(),
                            shape
                        ),
                    )));
                }
                Some(k.as_array().iter().copied().collect())
            }
            None => None,
        };
        Ok(Self {
            inner: HeightField::new(x0, y0, dx, dy, nx, ny, h, k).py()?,
        })
    }

    /// Heights [m] at the (N, 2) points `xy`.
    #[pyo3(signature = (xy, interpolation="bilinear"))]
    fn height<'py>(
        &self,
        py: Python<'py>,
        xy: PyReadonlyArray2<'py, f64>,
        interpolation: &str,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let interp = parse_interp(interpolation)?;
        let pts = xy_rows(&xy)?;
        let out: Vec<f64> = py.detach(|| {
            pts.iter()
                .map(|&(x, y)| self.inner.height(x, y, interp))
                .collect()
        });
        Ok(PyArray1::from_vec(py, out))
    }

    /// Heights [m] and gradients (∂z/∂x, ∂z/∂y) at the (N, 2) points `xy`.
    #[pyo3(signature = (xy, interpolation="bilinear"))]
    fn height_and_gradient<'py>(
        &self,
        py: Python<'py>,
        xy: PyReadonlyArray2<'py, f64>,
        interpolation: &str,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>)> {
        let interp = parse_interp(interpolation)?;
        let pts = xy_rows(&xy)?;
        let (h, g): (Vec<f64>, Vec<[f64; 2]>) = py.detach(|| {
            pts.iter()
                .map(|&(x, y)| {
                    let (h, gx, gy) = self.inner.height_and_gradient(x, y, interp);
                    (h, [gx, gy])
                })
                .unzip()
        });
        let g = PyArray2::from_vec2(py, &g.iter().map(|r| r.to_vec()).collect::<Vec<_>>())?;
        Ok((PyArray1::from_vec(py, h), g))
    }

    /// Unit upward normals (N, 3) of the mean slope over the disc of
    /// `radius` [m] around each (N, 2) point (`HeightField::disc_normal`).
    fn disc_normal<'py>(
        &self,
        py: Python<'py>,
        xy: PyReadonlyArray2<'py, f64>,
        radius: f64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(crate::errors::to_py(
                roughwalk_core::CoreError::InvalidArgument(format!(
                    "radius must be finite and >= 0, got {radius}"
                )),
            ));
        }
        let pts = xy_rows(&xy)?;
        let n: Vec<Vec<f64>> = py.detach(|| {
            pts.iter()
                .map(|&(x, y)| self.inner.disc_normal(x, y, radius).to_vec())
                .collect()
        });
        if n.is_empty() {
            return Ok(PyArray2::zeros(py, [0, 3], false));
        }
        PyArray2::from_vec2(py, &n).map_err(Into::into)
    }

    /// Whether each (N, 2) point lies over a fully measured grid cell.
    fn is_known<'py>(
        &self,
        py: Python<'py>,
        xy: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let pts = xy_rows(&xy)?;
        let out: Vec<bool> = pts
            .iter()
            .map(|&(x, y)| self.inner.is_known(x, y))
            .collect();
        Ok(PyArray1::from_vec(py, out))
    }

    /// Shape (nx, ny) of the grid.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        (self.inner.nx, self.inner.ny)
    }
}

/// Reads an (N, 2) float array into (x, y) pairs, refusing other shapes and non-finite values.
pub fn xy_rows(xy: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<(f64, f64)>> {
    let a = xy.as_array();
    if a.ncols() != 2 {
        return Err(crate::errors::to_py(
            roughwalk_core::CoreError::InvalidArgument(format!(
                "expected points of shape (N, 2), got {:?}",
                a.shape()
            )),
        ));
    }
    let mut out = Vec::with_capacity(a.nrows());
    for (i, r) in a.rows().into_iter().enumerate() {
        if !(r[0].is_finite() && r[1].is_finite()) {
            return Err(crate::errors::to_py(
                roughwalk_core::CoreError::InvalidArgument(format!(
                    "point {i} is not finite: ({}, {})",
                    r[0], r[1]
                )),
            ));
        }
        out.push((r[0], r[1]));
    }
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyHeightField>()
}

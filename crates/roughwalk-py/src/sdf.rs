//! Bindings for `roughwalk_core::sdf`: building a signed distance field in
//! stages and batched point, sphere and capsule queries.

// PyO3 hands arguments over by value (readonly array views, PyRef guards);
// borrowing them instead is not an option the macro offers.
#![allow(clippy::needless_pass_by_value)]

use std::borrow::Cow;

use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use roughwalk_core::sdf::edt::NO_SEED;
use roughwalk_core::sdf::{
    Band, DistanceGrid, GridSpec, HeightFieldDistance, SignedDistanceField, TriangleMesh,
};
use roughwalk_core::CoreError;

use crate::errors::{to_py, IntoPyResult};
use crate::heightfield::PyHeightField;

fn invalid(msg: String) -> PyErr {
    to_py(CoreError::InvalidArgument(msg))
}

/// A borrowed (or, if not C-contiguous, copied) (N, 3) float array, flattened.
fn rows3<'a>(what: &str, a: &'a PyReadonlyArray2<'_, f64>) -> PyResult<Cow<'a, [f64]>> {
    if a.shape()[1] != 3 {
        return Err(invalid(format!(
            "{what}: expected shape (N, 3), got {:?}",
            a.shape()
        )));
    }
    Ok(match a.as_slice() {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => Cow::Owned(a.as_array().iter().copied().collect()),
    })
}

fn vec1<'a>(a: &'a PyReadonlyArray1<'_, f64>) -> Cow<'a, [f64]> {
    match a.as_slice() {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => Cow::Owned(a.as_array().iter().copied().collect()),
    }
}

type Outputs<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>);
type CapsuleOutputs<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
);

fn outputs(py: Python<'_>, d: Vec<f64>, g: Vec<f64>) -> PyResult<Outputs<'_>> {
    let n = d.len();
    Ok((d.into_pyarray(py), g.into_pyarray(py).reshape([n, 3])?))
}

fn spec(origin: [f64; 3], resolution: f64, shape: [usize; 3]) -> PyResult<GridSpec> {
    GridSpec::new(origin, resolution, shape).py()
}

/// A signed distance field half built: occupancy and exact band done, far
/// voxels still to fill by one of the `finish*` methods (each consumes it).
#[pyclass(name = "SdfBand", module = "roughwalk._core")]
pub struct PySdfBand {
    inner: Option<Band>,
}

impl PySdfBand {
    fn take(&mut self) -> PyResult<Band> {
        self.inner.take().ok_or_else(|| {
            to_py(CoreError::Terrain(
                "this SDF band was already finished".into(),
            ))
        })
    }
    fn get(&self) -> PyResult<&Band> {
        self.inner.as_ref().ok_or_else(|| {
            to_py(CoreError::Terrain(
                "this SDF band was already finished".into(),
            ))
        })
    }
}

#[pymethods]
impl PySdfBand {
    /// Occupancy and exact band of a height-field terrain.
    #[staticmethod]
    fn from_heightfield(
        py: Python<'_>,
        heightfield: PyRef<'_, PyHeightField>,
        origin: [f64; 3],
        resolution: f64,
        shape: [usize; 3],
        band_cells: f64,
    ) -> PyResult<Self> {
        let spec = spec(origin, resolution, shape)?;
        let hf = heightfield.inner.clone();
        let band =
            py.detach(|| Band::from_heightfield(HeightFieldDistance::new(hf), spec, band_cells));
        Ok(Self {
            inner: Some(band.py()?),
        })
    }

    /// Occupancy and exact band of a mesh terrain; `heightfield` (its upper
    /// envelope) is the fall-back outside the lattice.
    #[staticmethod]
    fn from_mesh(
        py: Python<'_>,
        heightfield: PyRef<'_, PyHeightField>,
        vertices: PyReadonlyArray2<'_, f64>,
        faces: PyReadonlyArray2<'_, i64>,
        origin: [f64; 3],
        resolution: f64,
        shape: [usize; 3],
        band_cells: f64,
    ) -> PyResult<Self> {
        let spec = spec(origin, resolution, shape)?;
        let v = rows3("mesh vertices", &vertices)?;
        if faces.shape()[1] != 3 {
            return Err(invalid(format!(
                "mesh faces: expected shape (F, 3), got {:?}",
                faces.shape()
            )));
        }
        let mut f = Vec::with_capacity(faces.shape()[0]);
        for (n, row) in faces.as_array().rows().into_iter().enumerate() {
            let mut t = [0u32; 3];
            for (c, &idx) in t.iter_mut().zip(row.iter()) {
                *c = u32::try_from(idx).map_err(|_| {
                    to_py(CoreError::Terrain(format!(
                        "mesh face {n} has vertex index {idx}"
                    )))
                })?;
            }
            f.push(t);
        }
        let verts = v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let hf = heightfield.inner.clone();
        let band = py.detach(|| -> Result<Band, CoreError> {
            let mesh = TriangleMesh::new(verts, f)?;
            Band::from_mesh(HeightFieldDistance::new(hf), &mesh, spec, band_cells)
        });
        Ok(Self {
            inner: Some(band.py()?),
        })
    }

    /// (nx, ny, nz) flags of the far-field seeds: band voxels with
    /// |distance| ≤ `max_distance` [m] (every band voxel if None).
    #[pyo3(signature = (max_distance=None))]
    fn seed_mask<'py>(
        &self,
        py: Python<'py>,
        max_distance: Option<f64>,
    ) -> PyResult<Bound<'py, PyArray3<bool>>> {
        let band = self.get()?;
        let shape = band.spec().shape;
        band.seed_mask(max_distance).into_pyarray(py).reshape(shape)
    }

    /// Number of voxels with an exact distance.
    #[getter]
    fn exact_count(&self) -> PyResult<usize> {
        Ok(self.get()?.exact_count())
    }

    /// Far voxels by the Rust Felzenszwalb–Huttenlocher feature transform.
    fn finish(&mut self, py: Python<'_>) -> PyResult<PySdfField> {
        let band = self.take()?;
        let field = py.detach(|| band.finish()).py()?;
        Ok(PySdfField { inner: field })
    }

    /// Far voxels from a feature transform computed elsewhere: `nearest`
    /// holds, per voxel, the linear index of a nearest seed voxel.
    fn finish_with_nearest_voxel(
        &mut self,
        py: Python<'_>,
        nearest: PyReadonlyArray1<'_, i64>,
    ) -> PyResult<PySdfField> {
        let band = self.take()?;
        let idx: Vec<i64> = match nearest.as_slice() {
            Ok(s) => s.to_vec(),
            Err(_) => nearest.as_array().iter().copied().collect(),
        };
        let field = py.detach(|| band.finish_with_nearest_voxel(&idx)).py()?;
        Ok(PySdfField { inner: field })
    }

    /// Far voxels from distances alone: `seed_distance` [voxels] to the seeds
    /// of `seed_mask(offset)`, plus `offset` [m].
    fn finish_with_seed_distance(
        &mut self,
        py: Python<'_>,
        seed_distance: PyReadonlyArray3<'_, f32>,
        offset: f64,
    ) -> PyResult<PySdfField> {
        let band = self.take()?;
        let d: Vec<f32> = match seed_distance.as_slice() {
            Ok(s) => s.to_vec(),
            Err(_) => seed_distance.as_array().iter().copied().collect(),
        };
        let field = py
            .detach(|| band.finish_with_seed_distance(&d, offset))
            .py()?;
        Ok(PySdfField { inner: field })
    }
}

/// A built signed distance field: lattice values [m] and the exact
/// height-field fall-back outside the lattice.
#[pyclass(name = "SdfField", module = "roughwalk._core", frozen)]
pub struct PySdfField {
    pub(crate) inner: SignedDistanceField,
}

#[pymethods]
impl PySdfField {
    /// Rebuilds a field from saved lattice values (nx, ny, nz) [m].
    #[new]
    fn new(
        py: Python<'_>,
        heightfield: PyRef<'_, PyHeightField>,
        origin: [f64; 3],
        resolution: f64,
        values: PyReadonlyArray3<'_, f32>,
    ) -> PyResult<Self> {
        let s = values.shape();
        let spec = spec(origin, resolution, [s[0], s[1], s[2]])?;
        let v: Vec<f32> = match values.as_slice() {
            Ok(s) => s.to_vec(),
            Err(_) => values.as_array().iter().copied().collect(),
        };
        let grid = DistanceGrid::new(spec, v).py()?;
        let hf = heightfield.inner.clone();
        let surface = py.detach(|| HeightFieldDistance::new(hf));
        Ok(Self {
            inner: SignedDistanceField::new(grid, surface),
        })
    }

    /// Signed distances [m] (N,) and gradients (N, 3) at (N, 3) points [m].
    fn query<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Outputs<'py>> {
        let p = rows3("points", &points)?;
        let n = p.len() / 3;
        let (mut d, mut g) = (vec![0.0; n], vec![0.0; 3 * n]);
        py.detach(|| self.inner.query_points(&p, &mut d, &mut g))
            .py()?;
        outputs(py, d, g)
    }

    /// Exact signed distances [m] and gradients to the height-field surface
    /// (the fall-back), ignoring the lattice.
    fn surface_query<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Outputs<'py>> {
        let p = rows3("points", &points)?;
        if let Some(i) = p.iter().position(|v| !v.is_finite()) {
            return Err(invalid(format!("point {} is not finite", i / 3)));
        }
        let (d, g): (Vec<f64>, Vec<[f64; 3]>) = py.detach(|| {
            p.chunks_exact(3)
                .map(|c| self.inner.surface().signed_distance([c[0], c[1], c[2]]))
                .unzip()
        });
        outputs(py, d, g.concat())
    }

    /// Sphere distances [m] (centre distance − radius) and centre gradients.
    fn query_spheres<'py>(
        &self,
        py: Python<'py>,
        centers: PyReadonlyArray2<'py, f64>,
        radii: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Outputs<'py>> {
        let c = rows3("centers", &centers)?;
        let r = vec1(&radii);
        let n = c.len() / 3;
        let (mut d, mut g) = (vec![0.0; n], vec![0.0; 3 * n]);
        py.detach(|| self.inner.query_spheres(&c, &r, &mut d, &mut g))
            .py()?;
        outputs(py, d, g)
    }

    /// Capsule distances [m], gradients at the minimising sample, and that
    /// sample's fraction t along a→b.
    #[pyo3(signature = (a, b, radii, samples=None))]
    fn query_capsules<'py>(
        &self,
        py: Python<'py>,
        a: PyReadonlyArray2<'py, f64>,
        b: PyReadonlyArray2<'py, f64>,
        radii: PyReadonlyArray1<'py, f64>,
        samples: Option<usize>,
    ) -> PyResult<CapsuleOutputs<'py>> {
        let pa = rows3("a", &a)?;
        let pb = rows3("b", &b)?;
        let r = vec1(&radii);
        let n = pa.len() / 3;
        let (mut d, mut g, mut t) = (vec![0.0; n], vec![0.0; 3 * n], vec![0.0; n]);
        py.detach(|| {
            self.inner
                .query_capsules(&pa, &pb, &r, samples, &mut d, &mut g, &mut t)
        })
        .py()?;
        let (d, g) = outputs(py, d, g)?;
        Ok((d, g, t.into_pyarray(py)))
    }

    /// A copy of the lattice values (nx, ny, nz) [m], float32.
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let grid = self.inner.grid();
        grid.values()
            .to_vec()
            .into_pyarray(py)
            .reshape(grid.spec().shape)
    }

    /// Position [m] of lattice node (0, 0, 0).
    #[getter]
    fn origin(&self) -> [f64; 3] {
        self.inner.grid().spec().origin
    }

    /// Node spacing [m].
    #[getter]
    fn resolution(&self) -> f64 {
        self.inner.grid().spec().resolution
    }

    /// Number of nodes (nx, ny, nz).
    #[getter]
    fn shape(&self) -> [usize; 3] {
        self.inner.grid().spec().shape
    }
}

/// Felzenszwalb–Huttenlocher feature transform of a 3-D boolean array:
/// for every voxel, the C-order linear index of a Euclidean-nearest True
/// voxel (−1 everywhere if there is none).
#[pyfunction]
fn feature_transform<'py>(
    py: Python<'py>,
    seeds: PyReadonlyArray3<'py, bool>,
) -> PyResult<Bound<'py, PyArray3<i64>>> {
    let s = seeds.shape();
    let shape = [s[0], s[1], s[2]];
    let n = shape[0] * shape[1] * shape[2];
    if n >= u32::MAX as usize {
        return Err(invalid(format!(
            "feature_transform: {n} voxels is more than {} allowed",
            u32::MAX - 1
        )));
    }
    let mut labels: Vec<u32> = seeds
        .as_array()
        .iter()
        .enumerate()
        .map(|(i, &b)| if b { i as u32 } else { NO_SEED })
        .collect();
    py.detach(|| roughwalk_core::sdf::edt::feature_transform(shape, &mut labels));
    let out: Vec<i64> = labels
        .into_iter()
        .map(|l| if l == NO_SEED { -1 } else { i64::from(l) })
        .collect();
    out.into_pyarray(py).reshape(shape)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySdfBand>()?;
    m.add_class::<PySdfField>()?;
    m.add_function(wrap_pyfunction!(feature_transform, m)?)?;
    Ok(())
}

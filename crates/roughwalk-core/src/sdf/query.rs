//! Batched distance queries against a built signed distance field: points,
//! spheres and capsules (Zucker 2011, §3.3).
//!
//! Inside the lattice's node box a query is the trilinear interpolant of the
//! stored values and its analytic gradient. Outside it falls back to the
//! exact signed distance to the height-field surface (see
//! [`HeightFieldDistance`]), which is slower but never wrong: for mesh
//! terrain that surface is the mesh's upper envelope, so overhangs beyond
//! the lattice are not seen.

use rayon::prelude::*;

use crate::error::{CoreError, CoreResult};
use crate::sdf::grid::DistanceGrid;
use crate::sdf::heightfield_distance::HeightFieldDistance;

/// Batches at least this long are split across threads.
const PARALLEL_MIN: usize = 1 << 15;
const CHUNK: usize = 1 << 12;

/// A signed distance field: lattice values plus the exact fall-back surface.
#[derive(Debug, Clone)]
pub struct SignedDistanceField {
    grid: DistanceGrid,
    surface: HeightFieldDistance,
}

fn check_points(what: &str, flat: &[f64]) -> CoreResult<usize> {
    if !flat.len().is_multiple_of(3) {
        return Err(CoreError::InvalidArgument(format!(
            "{what}s: expected 3 coordinates per point, got {} numbers",
            flat.len()
        )));
    }
    match flat.iter().position(|v| !v.is_finite()) {
        None => Ok(flat.len() / 3),
        Some(i) => {
            let r = i / 3;
            Err(CoreError::InvalidArgument(format!(
                "{what} {r} is not finite: {:?}",
                &flat[3 * r..3 * r + 3]
            )))
        }
    }
}

fn check_radii(radii: &[f64], n: usize) -> CoreResult<()> {
    if radii.len() != n {
        return Err(CoreError::InvalidArgument(format!(
            "expected {n} radii (one per shape), got {}",
            radii.len()
        )));
    }
    match radii.iter().position(|r| !(r.is_finite() && *r >= 0.0)) {
        None => Ok(()),
        Some(i) => Err(CoreError::InvalidArgument(format!(
            "radius {i} is {}; radii must be finite and ≥ 0 [m]",
            radii[i]
        ))),
    }
}

fn check_outputs(n: usize, d: &[f64], g: &[f64]) -> CoreResult<()> {
    if d.len() == n && g.len() == 3 * n {
        Ok(())
    } else {
        Err(CoreError::InvalidArgument(format!(
            "output buffers for {n} queries must hold {n} distances and {} gradient numbers, got {} and {}",
            3 * n,
            d.len(),
            g.len()
        )))
    }
}

#[inline]
fn point(flat: &[f64], i: usize) -> [f64; 3] {
    [flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]]
}

impl SignedDistanceField {
    /// Pairs lattice values with the surface used outside the lattice.
    pub fn new(grid: DistanceGrid, surface: HeightFieldDistance) -> Self {
        Self { grid, surface }
    }

    /// The same field with its lattice values lowered to their unit-slope
    /// envelope (see [`DistanceGrid::lipschitz_envelope`]).
    #[must_use]
    pub fn lipschitz_envelope(self) -> Self {
        Self {
            grid: self.grid.lipschitz_envelope(),
            surface: self.surface,
        }
    }

    /// The lattice values.
    pub fn grid(&self) -> &DistanceGrid {
        &self.grid
    }

    /// The fall-back surface.
    pub fn surface(&self) -> &HeightFieldDistance {
        &self.surface
    }

    /// Signed distance [m] at `p` [m] and its gradient.
    #[inline]
    pub fn distance_and_gradient(&self, p: [f64; 3]) -> (f64, [f64; 3]) {
        match self.grid.trilinear(p) {
            Some(r) => r,
            None => self.surface.signed_distance(p),
        }
    }

    /// Writes `d[i]` = field at `at(i)` − `minus(i)` and `g[3i..3i + 3]` =
    /// its gradient for every query i, on several threads when the batch is
    /// large.
    fn batch(
        &self,
        d: &mut [f64],
        g: &mut [f64],
        at: impl Fn(usize) -> [f64; 3] + Sync,
        minus: impl Fn(usize) -> f64 + Sync,
    ) {
        let run = |offset: usize, d: &mut [f64], g: &mut [f64]| {
            // Gather a block's corner values before interpolating any, so the
            // cache misses of a block overlap instead of queueing one by one
            // (random queries run ~1.5× faster this way).
            const BLOCK: usize = 16;
            let mut cells = [(0usize, [0.0f64; 3], [0.0f32; 8], false); BLOCK];
            for (b, (db, gb)) in d.chunks_mut(BLOCK).zip(g.chunks_mut(3 * BLOCK)).enumerate() {
                let first = offset + b * BLOCK;
                for (m, cell) in cells.iter_mut().enumerate().take(db.len()) {
                    *cell = match self.grid.locate(at(first + m)) {
                        Some((base, t)) => (base, t, self.grid.corners(base), true),
                        None => (0, [0.0; 3], [0.0; 8], false),
                    };
                }
                for (m, (dm, gm)) in db.iter_mut().zip(gb.chunks_exact_mut(3)).enumerate() {
                    let (_, t, c, inside) = cells[m];
                    let (v, grad) = if inside {
                        self.grid.interpolate(&c, t)
                    } else {
                        self.surface.signed_distance(at(first + m))
                    };
                    *dm = v - minus(first + m);
                    gm.copy_from_slice(&grad);
                }
            }
        };
        if d.len() < PARALLEL_MIN {
            run(0, d, g);
        } else {
            d.par_chunks_mut(CHUNK)
                .zip(g.par_chunks_mut(3 * CHUNK))
                .enumerate()
                .for_each(|(c, (d, g))| run(c * CHUNK, d, g));
        }
    }

    /// Signed distances [m] and gradients at the points `points` [m]
    /// (x, y, z per point, flattened), written to `d` and `g` (flattened).
    pub fn query_points(&self, points: &[f64], d: &mut [f64], g: &mut [f64]) -> CoreResult<()> {
        let n = check_points("point", points)?;
        check_outputs(n, d, g)?;
        self.batch(d, g, |i| point(points, i), |_| 0.0);
        Ok(())
    }

    /// Sphere distances: centre distance minus radius [m]; the gradient is
    /// that of the centre. Layout as in [`Self::query_points`].
    pub fn query_spheres(
        &self,
        centers: &[f64],
        radii: &[f64],
        d: &mut [f64],
        g: &mut [f64],
    ) -> CoreResult<()> {
        let n = check_points("sphere centre", centers)?;
        check_radii(radii, n)?;
        check_outputs(n, d, g)?;
        self.batch(d, g, |i| point(centers, i), |i| radii[i]);
        Ok(())
    }

    /// Number of samples a capsule of segment length `length` [m] gets by
    /// default: spacing at most one voxel, and both ends.
    pub fn default_capsule_samples(&self, length: f64) -> usize {
        ((length / self.grid.spec().resolution).ceil() as usize + 1).max(2)
    }

    /// Capsule distances: the minimum of the field over `samples` evenly
    /// spaced points of segment a–b (both ends included; by default one per
    /// voxel of length), minus the radius [m]. Writes the distance, the
    /// gradient at the minimising sample, and that sample's fraction
    /// t ∈ [0, 1] along a→b (so ∂d/∂a = (1 − t)·g and ∂d/∂b = t·g).
    pub fn query_capsules(
        &self,
        a: &[f64],
        b: &[f64],
        radii: &[f64],
        samples: Option<usize>,
        d: &mut [f64],
        g: &mut [f64],
        t: &mut [f64],
    ) -> CoreResult<()> {
        let n = check_points("capsule end a", a)?;
        let nb = check_points("capsule end b", b)?;
        if n != nb {
            return Err(CoreError::InvalidArgument(format!(
                "capsule ends: got {n} a-points and {nb} b-points"
            )));
        }
        check_radii(radii, n)?;
        check_outputs(n, d, g)?;
        if t.len() != n {
            return Err(CoreError::InvalidArgument(format!(
                "capsule fractions: output must hold {n} values, got {}",
                t.len()
            )));
        }
        if let Some(s) = samples {
            if s < 2 {
                return Err(CoreError::InvalidArgument(format!(
                    "capsule samples must be ≥ 2 (both ends), got {s}"
                )));
            }
        }
        let capsule = |i: usize| -> (f64, [f64; 3], f64) {
            let (pa, pb) = (point(a, i), point(b, i));
            let ab = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
            let length = (ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]).sqrt();
            let m = samples.unwrap_or_else(|| self.default_capsule_samples(length));
            let mut best = (f64::INFINITY, [0.0; 3], 0.0);
            for s in 0..m {
                let f = s as f64 / (m - 1) as f64;
                let p = [pa[0] + f * ab[0], pa[1] + f * ab[1], pa[2] + f * ab[2]];
                let (v, grad) = self.distance_and_gradient(p);
                if v < best.0 {
                    best = (v, grad, f);
                }
            }
            (best.0 - radii[i], best.1, best.2)
        };
        let run = |offset: usize, d: &mut [f64], g: &mut [f64], t: &mut [f64]| {
            for (i, ((di, gi), ti)) in d
                .iter_mut()
                .zip(g.chunks_exact_mut(3))
                .zip(t.iter_mut())
                .enumerate()
            {
                let (v, grad, f) = capsule(offset + i);
                *di = v;
                gi.copy_from_slice(&grad);
                *ti = f;
            }
        };
        if n < PARALLEL_MIN {
            run(0, d, g, t);
        } else {
            d.par_chunks_mut(CHUNK)
                .zip(g.par_chunks_mut(3 * CHUNK))
                .zip(t.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(|(c, ((d, g), t))| run(c * CHUNK, d, g, t));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sdf::build::Band;
    use crate::sdf::grid::GridSpec;
    use crate::HeightField;

    fn field() -> SignedDistanceField {
        let (nx, ny, d) = (26usize, 21usize, 0.004);
        let h = (0..nx * ny)
            .map(|n| 0.01 * ((n / ny) as f64 * 0.3).sin() * ((n % ny) as f64 * 0.2).cos())
            .collect();
        let hf = HeightField::new(0.0, 0.0, d, d, nx, ny, h, None).unwrap();
        let spec = GridSpec::new([0.0, 0.0, -0.03], 0.005, [21, 17, 13]).unwrap();
        Band::from_heightfield(HeightFieldDistance::new(hf), spec, 2.0)
            .unwrap()
            .finish()
            .unwrap()
    }

    fn one(f: &SignedDistanceField, p: [f64; 3]) -> (f64, [f64; 3]) {
        let (mut d, mut g) = ([0.0], [0.0; 3]);
        f.query_points(&p, &mut d, &mut g).unwrap();
        (d[0], g)
    }

    #[test]
    fn batched_points_equal_single_queries_inside_and_outside_the_lattice() {
        let f = field();
        let pts = [
            0.05, 0.04, 0.01, // inside
            0.2, 0.03, 0.02, // beyond x
            0.05, 0.04, 0.08, // above the lattice
            -0.1, -0.1, -0.1, // far below a corner
        ];
        let (mut d, mut g) = (vec![0.0; 4], vec![0.0; 12]);
        f.query_points(&pts, &mut d, &mut g).unwrap();
        for i in 0..4 {
            let p = [pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]];
            let (e, eg) = f.distance_and_gradient(p);
            assert!((d[i] - e).abs() < 1e-15 && (g[3 * i] - eg[0]).abs() < 1e-15);
            if f.grid().spec().contains(p) {
                continue;
            }
            // Outside: the exact height-field distance.
            let (s, _) = f.surface().signed_distance(p);
            assert!((d[i] - s).abs() < 1e-15, "{p:?}: {} vs {s}", d[i]);
        }
        assert!(d[3] < -0.09, "far below is deep inside, got {}", d[3]);
    }

    #[test]
    fn spheres_are_points_minus_radius() {
        let f = field();
        let c = [0.03, 0.05, 0.012, 0.07, 0.02, -0.004];
        let r = [0.002, 0.01];
        let (mut d, mut g) = (vec![0.0; 2], vec![0.0; 6]);
        f.query_spheres(&c, &r, &mut d, &mut g).unwrap();
        for i in 0..2 {
            let (e, eg) = one(&f, [c[3 * i], c[3 * i + 1], c[3 * i + 2]]);
            assert!((d[i] - (e - r[i])).abs() < 1e-15);
            assert!((0..3).all(|a| (g[3 * i + a] - eg[a]).abs() < 1e-15));
        }
    }

    #[test]
    fn capsules_are_the_minimum_over_their_samples_minus_radius() {
        let f = field();
        let a = [0.01, 0.01, 0.02, 0.02, 0.07, 0.0];
        let b = [0.09, 0.06, 0.0, 0.021, 0.071, 0.001];
        let r = [0.003, 0.0];
        for samples in [None, Some(2), Some(7)] {
            let (mut d, mut g, mut t) = (vec![0.0; 2], vec![0.0; 6], vec![0.0; 2]);
            f.query_capsules(&a, &b, &r, samples, &mut d, &mut g, &mut t)
                .unwrap();
            for i in 0..2 {
                let pa = [a[3 * i], a[3 * i + 1], a[3 * i + 2]];
                let pb = [b[3 * i], b[3 * i + 1], b[3 * i + 2]];
                let len = crate::sdf::mesh::dist2(pa, pb).sqrt();
                let n = samples.unwrap_or_else(|| f.default_capsule_samples(len));
                assert!(n >= 2 && (samples.is_some() || len / (n - 1) as f64 <= 0.005 + 1e-12));
                let (mut best, mut best_t) = (f64::INFINITY, 0.0);
                for s in 0..n {
                    let u = s as f64 / (n - 1) as f64;
                    let p = [0, 1, 2].map(|k| pa[k] + u * (pb[k] - pa[k]));
                    let (e, _) = one(&f, p);
                    if e < best {
                        (best, best_t) = (e, u);
                    }
                }
                assert!(
                    (d[i] - (best - r[i])).abs() < 1e-15,
                    "{} vs {}",
                    d[i],
                    best - r[i]
                );
                assert!((t[i] - best_t).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn refuses_bad_input() {
        let f = field();
        let (mut d, mut g) = (vec![0.0; 1], vec![0.0; 3]);
        assert!(f
            .query_points(&[0.0, f64::NAN, 0.0], &mut d, &mut g)
            .is_err());
        assert!(f.query_points(&[0.0, 0.0], &mut d, &mut g).is_err());
        assert!(f.query_spheres(&[0.0; 3], &[-1.0], &mut d, &mut g).is_err());
        assert!(f
            .query_spheres(&[0.0; 3], &[1.0, 2.0], &mut d, &mut g)
            .is_err());
        let mut t = vec![0.0; 1];
        assert!(f
            .query_capsules(
                &[0.0; 3],
                &[0.0; 3],
                &[0.0],
                Some(1),
                &mut d,
                &mut g,
                &mut t
            )
            .is_err());
        assert!(f
            .query_capsules(&[0.0; 3], &[0.0; 6], &[0.0], None, &mut d, &mut g, &mut t)
            .is_err());
    }
}

//! The voxel lattice of a signed distance field and trilinear interpolation
//! of the values stored at its nodes.
//!
//! Values live at lattice nodes `origin + (i, j, k)·resolution`, stored
//! C-order with z fastest: `index = (i·ny + j)·nz + k`. A query inside the
//! node box is the trilinear interpolant of the cell's eight corners; its
//! gradient is the interpolant's own analytic gradient, so that finite
//! differences of the field reproduce it.

use crate::error::{CoreError, CoreResult};

/// Position, spacing and size of a uniform voxel lattice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridSpec {
    /// Position [m] of node (0, 0, 0).
    pub origin: [f64; 3],
    /// Node spacing [m], the same along x, y and z.
    pub resolution: f64,
    /// Number of nodes along x, y and z.
    pub shape: [usize; 3],
}

impl GridSpec {
    /// Checks and builds a lattice: finite origin, positive resolution, at
    /// least two nodes per axis, and few enough nodes to index with `u32`.
    pub fn new(origin: [f64; 3], resolution: f64, shape: [usize; 3]) -> CoreResult<Self> {
        if !origin.iter().all(|v| v.is_finite()) {
            return Err(CoreError::Terrain(format!(
                "SDF grid origin must be finite, got {origin:?}"
            )));
        }
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(CoreError::Terrain(format!(
                "SDF resolution must be a positive number of metres, got {resolution}"
            )));
        }
        if shape.iter().any(|&n| n < 2) {
            return Err(CoreError::Terrain(format!(
                "SDF grid needs at least 2 nodes along each axis, got shape {shape:?}"
            )));
        }
        let total = shape
            .iter()
            .try_fold(1usize, |acc, &n| acc.checked_mul(n))
            .filter(|&t| t < u32::MAX as usize);
        if total.is_none() {
            return Err(CoreError::Terrain(format!(
                "SDF grid of shape {shape:?} has more than {} voxels; use a coarser resolution",
                u32::MAX - 1
            )));
        }
        Ok(Self {
            origin,
            resolution,
            shape,
        })
    }

    /// Number of nodes.
    #[inline]
    pub fn len(&self) -> usize {
        self.shape[0] * self.shape[1] * self.shape[2]
    }

    /// Whether the lattice has no nodes (never true for a checked spec).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Linear index of node (i, j, k).
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (i * self.shape[1] + j) * self.shape[2] + k
    }

    /// Node (i, j, k) of a linear index.
    #[inline]
    pub fn unravel(&self, index: usize) -> [usize; 3] {
        let k = index % self.shape[2];
        let ij = index / self.shape[2];
        [ij / self.shape[1], ij % self.shape[1], k]
    }

    /// Position [m] of node (i, j, k).
    #[inline]
    pub fn node(&self, i: usize, j: usize, k: usize) -> [f64; 3] {
        [
            self.origin[0] + i as f64 * self.resolution,
            self.origin[1] + j as f64 * self.resolution,
            self.origin[2] + k as f64 * self.resolution,
        ]
    }

    /// Position [m] of the last node, the upper corner of the node box.
    pub fn upper(&self) -> [f64; 3] {
        self.node(self.shape[0] - 1, self.shape[1] - 1, self.shape[2] - 1)
    }

    /// Whether `p` [m] lies in the closed node box, where interpolation applies.
    #[inline]
    pub fn contains(&self, p: [f64; 3]) -> bool {
        (0..3).all(|a| {
            let g = (p[a] - self.origin[a]) / self.resolution;
            g >= 0.0 && g <= (self.shape[a] - 1) as f64
        })
    }
}

/// Signed distances [m] stored at the nodes of a [`GridSpec`].
#[derive(Debug, Clone)]
pub struct DistanceGrid {
    spec: GridSpec,
    values: Vec<f32>,
    inv_resolution: f64,
    /// Index of the last node along each axis, as a float: the node box in
    /// lattice units is [0, top]³.
    top: [f64; 3],
    /// Index of the last full cell along each axis (shape − 2).
    last_cell: [u32; 3],
    /// Linear-index strides of x and y (z is 1).
    stride: [usize; 2],
    /// Largest |difference| of neighbouring node values along x, y and z,
    /// over the resolution: see [`Self::axis_slopes`].
    axis_slopes: [f64; 3],
}

/// Largest |v(n + e_a) − v(n)| / `resolution` over the nodes, per axis a.
fn max_axis_slopes(values: &[f32], shape: [usize; 3], resolution: f64) -> [f64; 3] {
    let [nx, ny, nz] = shape;
    let mut worst = [0.0f64; 3];
    for i in 0..nx {
        for j in 0..ny {
            let at = (i * ny + j) * nz;
            let column = &values[at..at + nz];
            for (k, &v) in column.iter().enumerate() {
                let v = f64::from(v);
                if k + 1 < nz {
                    worst[2] = worst[2].max((f64::from(column[k + 1]) - v).abs());
                }
                if j + 1 < ny {
                    worst[1] = worst[1].max((f64::from(values[at + nz + k]) - v).abs());
                }
                if i + 1 < nx {
                    worst[0] = worst[0].max((f64::from(values[at + ny * nz + k]) - v).abs());
                }
            }
        }
    }
    worst.map(|w| w / resolution)
}

impl DistanceGrid {
    /// Wraps node values (z fastest); every value must be finite.
    pub fn new(spec: GridSpec, values: Vec<f32>) -> CoreResult<Self> {
        if values.len() != spec.len() {
            return Err(CoreError::Terrain(format!(
                "SDF grid of shape {:?} needs {} values, got {}",
                spec.shape,
                spec.len(),
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::Terrain(format!(
                "SDF value at node {:?} is not finite ({})",
                spec.unravel(i),
                values[i]
            )));
        }
        let [nx, ny, nz] = spec.shape;
        let axis_slopes = max_axis_slopes(&values, spec.shape, spec.resolution);
        // GridSpec::new keeps every count below u32::MAX, so these fit.
        Ok(Self {
            spec,
            values,
            axis_slopes,
            inv_resolution: 1.0 / spec.resolution,
            top: [nx, ny, nz].map(|n| (n - 1) as f64),
            last_cell: [nx, ny, nz].map(|n| (n - 2) as u32),
            stride: [ny * nz, nz],
        })
    }

    /// The lattice.
    pub fn spec(&self) -> &GridSpec {
        &self.spec
    }

    /// Largest |difference| of neighbouring node values along x, y and z,
    /// divided by the resolution (S_x, S_y, S_z) [m/m].
    ///
    /// They bound the trilinear interpolant's partial derivatives: ∂d/∂x at
    /// any point of a cell is a convex combination of the cell's four
    /// x-edge differences over the resolution, and likewise for y and z. So
    /// along a unit direction u, |∇d·u| ≤ S_x|u_x| + S_y|u_y| + S_z|u_z|
    /// everywhere in the node box. Measured from the stored values, not
    /// assumed: the far field of a distance transform that starts from a
    /// band is not exactly 1-Lipschitz (up to 1.4 on the LittleDog boards,
    /// 2 cm and more off the surface), so √3 — the bound for node values
    /// of a true distance — would not be one.
    pub fn axis_slopes(&self) -> [f64; 3] {
        self.axis_slopes
    }

    /// The greatest field at or below this one whose neighbouring nodes
    /// differ by at most one resolution: d'(n) = min over nodes m of
    /// d(m) + h·|n − m|₁ (a forward and a backward sweep along each axis,
    /// the L1 distance being separable), so its axis slopes are 1.
    ///
    /// Only lowers values, and only where neighbours differ by more than
    /// a true distance can (the far field of a band-seeded transform, which
    /// overestimates): a clearance measured on it is never larger. Sphere
    /// tracing on it may step by ‖u‖₁ instead of up to 1.4·‖u‖₁.
    #[must_use]
    pub fn lipschitz_envelope(mut self) -> Self {
        let [nx, ny, nz] = self.spec.shape;
        let h = self.spec.resolution as f32;
        let v = &mut self.values;
        // Along z (stride 1), then y (stride nz), then x (stride ny·nz).
        for (stride, count, lines) in [(1, nz, nx * ny), (nz, ny, nx), (ny * nz, nx, 1)] {
            let inner = if stride == 1 { 1 } else { stride };
            for line in 0..lines {
                let block = if stride == 1 {
                    line * nz
                } else {
                    line * count * stride
                };
                for offset in 0..inner {
                    let first = block + offset;
                    for k in 1..count {
                        let (prev, at) = (first + (k - 1) * stride, first + k * stride);
                        v[at] = v[at].min(v[prev] + h);
                    }
                    for k in (0..count - 1).rev() {
                        let (next, at) = (first + (k + 1) * stride, first + k * stride);
                        v[at] = v[at].min(v[next] + h);
                    }
                }
            }
        }
        self.axis_slopes = max_axis_slopes(&self.values, self.spec.shape, self.spec.resolution);
        self
    }

    /// The bound of [`Self::axis_slopes`] on |∇d·u| along the direction
    /// `u` (any length; the bound is for unit speed along it) [m/m].
    #[inline]
    pub fn directional_lipschitz(&self, u: [f64; 3]) -> f64 {
        let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        if n == 0.0 {
            return 0.0;
        }
        let s = self.axis_slopes;
        (s[0] * u[0].abs() + s[1] * u[1].abs() + s[2] * u[2].abs()) / n
    }

    /// Node values [m], z fastest.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The cell holding `p` [m]: linear index of its lowest corner and the
    /// fractions (t_x, t_y, t_z) ∈ [0, 1]³, or None outside the node box.
    // Measured: LLVM left these out of the capsule-marching loop, ~6 % of a
    // certificate's instructions on the rocky probe.
    #[allow(clippy::inline_always)]
    #[inline(always)]
    pub fn locate(&self, p: [f64; 3]) -> Option<(usize, [f64; 3])> {
        let o = &self.spec.origin;
        let g = [0, 1, 2].map(|a| (p[a] - o[a]) * self.inv_resolution);
        // One test for the box; NaN fails it.
        let inside = |a: usize| g[a] >= 0.0 && g[a] <= self.top[a];
        if !(inside(0) && inside(1) && inside(2)) {
            return None;
        }
        // Truncation is floor for g ≥ 0 (and far cheaper than a libm call);
        // min keeps the last node inside a full cell. 32-bit indices convert
        // to and from floats in one instruction each (usize does not).
        let cell = [0, 1, 2].map(|a| (g[a] as u32).min(self.last_cell[a]));
        let t = [0, 1, 2].map(|a| g[a] - f64::from(cell[a]));
        let base = cell[0] as usize * self.stride[0] + cell[1] as usize * self.stride[1];
        Some((base + cell[2] as usize, t))
    }

    /// The trilinear value [m] at `p` [m] without its gradient, or None
    /// outside the node box: the same number as [`Self::trilinear`]'s value,
    /// for the hot loops that need only values (capsule marching).
    // Measured: LLVM left these out of the capsule-marching loop, ~6 % of a
    // certificate's instructions on the rocky probe.
    #[allow(clippy::inline_always)]
    #[inline(always)]
    pub fn value(&self, p: [f64; 3]) -> Option<f64> {
        let (base, [tx, ty, tz]) = self.locate(p)?;
        let c = self.corners(base).map(f64::from);
        // The operations and their order are those of `interpolate`.
        let e00 = c[0] + (c[1] - c[0]) * tz;
        let e01 = c[2] + (c[3] - c[2]) * tz;
        let e10 = c[4] + (c[5] - c[4]) * tz;
        let e11 = c[6] + (c[7] - c[6]) * tz;
        let f0 = e00 + (e01 - e00) * ty;
        let f1 = e10 + (e11 - e10) * ty;
        Some(f0 + (f1 - f0) * tx)
    }

    /// The eight corner values of the cell whose lowest corner is `base`,
    /// ordered (x, y, z) = 000, 001, 010, 011, 100, 101, 110, 111.
    // Measured: LLVM left these out of the capsule-marching loop, ~6 % of a
    // certificate's instructions on the rocky probe.
    #[allow(clippy::inline_always)]
    #[inline(always)]
    pub fn corners(&self, base: usize) -> [f32; 8] {
        let [sx, nz] = self.stride;
        // Two x-planes of the cell as fixed-size pairs: the slicing checks
        // the bounds once per pair, the pairs' own indexing not at all
        // (indexing the cell's slice checked each of the eight corners).
        let pair = |i: usize| -> [f32; 2] {
            let p: &[f32; 2] = self.values[i..i + 2].try_into().expect("two nodes");
            *p
        };
        let ([c0, c1], [c2, c3]) = (pair(base), pair(base + nz));
        let ([c4, c5], [c6, c7]) = (pair(base + sx), pair(base + sx + nz));
        [c0, c1, c2, c3, c4, c5, c6, c7]
    }

    /// Trilinear value [m] and gradient from a cell's corners and fractions.
    #[inline]
    pub fn interpolate(&self, c: &[f32; 8], t: [f64; 3]) -> (f64, [f64; 3]) {
        let c = c.map(f64::from);
        let [tx, ty, tz] = t;
        // Along z first: the four edge values and their z-slopes.
        let (s00, s01, s10, s11) = (c[1] - c[0], c[3] - c[2], c[5] - c[4], c[7] - c[6]);
        let (e00, e01, e10, e11) = (
            c[0] + s00 * tz,
            c[2] + s01 * tz,
            c[4] + s10 * tz,
            c[6] + s11 * tz,
        );
        let f0 = e00 + (e01 - e00) * ty;
        let f1 = e10 + (e11 - e10) * ty;
        let d = f0 + (f1 - f0) * tx;
        let gx = f1 - f0;
        let gy = (e01 - e00) * (1.0 - tx) + (e11 - e10) * tx;
        let sz0 = s00 + (s01 - s00) * ty;
        let sz1 = s10 + (s11 - s10) * ty;
        let gz = sz0 + (sz1 - sz0) * tx;
        let k = self.inv_resolution;
        (d, [gx * k, gy * k, gz * k])
    }

    /// Trilinear value [m] and its gradient at `p` [m], or None outside the
    /// node box (the caller decides what outside means, see
    /// `SignedDistanceField`).
    #[inline]
    pub fn trilinear(&self, p: [f64; 3]) -> Option<(f64, [f64; 3])> {
        let (base, t) = self.locate(p)?;
        Some(self.interpolate(&self.corners(base), t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn affine_grid() -> DistanceGrid {
        let spec = GridSpec::new([-0.1, 0.2, -0.05], 0.01, [4, 5, 6]).unwrap();
        let mut values = Vec::new();
        for i in 0..4 {
            for j in 0..5 {
                for k in 0..6 {
                    let p = spec.node(i, j, k);
                    values.push((0.3 * p[0] - 0.2 * p[1] + 0.9 * p[2] + 0.01) as f32);
                }
            }
        }
        DistanceGrid::new(spec, values).unwrap()
    }

    #[test]
    fn trilinear_reproduces_an_affine_field_and_its_gradient() {
        let g = affine_grid();
        for p in [
            [-0.095, 0.213, -0.031],
            [-0.07, 0.24, 0.0],
            [-0.0712, 0.2011, -0.0499],
        ] {
            let (d, grad) = g.trilinear(p).unwrap();
            let exact = 0.3 * p[0] - 0.2 * p[1] + 0.9 * p[2] + 0.01;
            assert!((d - exact).abs() < 1e-6, "{d} vs {exact}");
            for (a, e) in grad.iter().zip([0.3, -0.2, 0.9]) {
                assert!((a - e).abs() < 1e-4, "{grad:?}");
            }
        }
    }

    #[test]
    fn gradient_matches_finite_differences_of_a_nonlinear_field() {
        let spec = GridSpec::new([0.0; 3], 0.1, [3, 3, 3]).unwrap();
        let values = (0..27).map(|i| ((i * 7919) % 13) as f32 * 0.01).collect();
        let g = DistanceGrid::new(spec, values).unwrap();
        let e = 1e-6;
        for p in [[0.037, 0.151, 0.088], [0.123, 0.041, 0.177]] {
            let (_, grad) = g.trilinear(p).unwrap();
            for a in 0..3 {
                let (mut hi, mut lo) = (p, p);
                hi[a] += e;
                lo[a] -= e;
                let fd = (g.trilinear(hi).unwrap().0 - g.trilinear(lo).unwrap().0) / (2.0 * e);
                assert!((fd - grad[a]).abs() < 1e-6, "axis {a}: {fd} vs {}", grad[a]);
            }
        }
    }

    #[test]
    fn axis_slopes_bound_the_interpolant_along_every_direction() {
        // Random values: far from Lipschitz, so the bound is doing the work.
        let spec = GridSpec::new([0.0; 3], 0.01, [6, 5, 4]).unwrap();
        let values: Vec<f32> = (0..spec.len())
            .map(|i| ((i * 7919) % 23) as f32 * 0.002 + (i % 4) as f32 * 0.004)
            .collect();
        let g = DistanceGrid::new(spec, values.clone()).unwrap();
        let s = g.axis_slopes();
        // The slopes are attained: each is some edge's difference.
        let mut brute = [0.0f64; 3];
        for i in 0..6 {
            for j in 0..5 {
                for k in 0..4 {
                    let v = |i, j, k| f64::from(values[spec.index(i, j, k)]);
                    let here = v(i, j, k);
                    for (a, n) in [(0, (i + 1, j, k)), (1, (i, j + 1, k)), (2, (i, j, k + 1))] {
                        if n.0 < 6 && n.1 < 5 && n.2 < 4 {
                            brute[a] = brute[a].max((v(n.0, n.1, n.2) - here).abs() / 0.01);
                        }
                    }
                }
            }
        }
        assert!(
            (0..3).all(|a| (s[a] - brute[a]).abs() <= 1e-12 * brute[a]),
            "{s:?} vs {brute:?}"
        );
        let (mut worst, e) = (0.0f64, 1e-7);
        for k in 0..4000usize {
            let f = k as f64;
            let p =
                [0.618_033_9, 0.414_213_5, 0.732_050_8].map(|m| 0.001 + (f * m).fract() * 0.028);
            let u = [0.302_775_6, 0.236_067_9, 0.645_751_3].map(|m| (f * m).fract() * 2.0 - 1.0);
            let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            let q = [0, 1, 2].map(|a| p[a] + e * u[a] / n);
            let slope = (g.value(q).unwrap() - g.value(p).unwrap()).abs() / e;
            worst = worst.max(slope / g.directional_lipschitz(u));
        }
        assert!(worst <= 1.0 + 1e-6, "{worst}");
        assert!(
            worst > 0.5,
            "the bound should be near tight somewhere: {worst}"
        );
    }

    #[test]
    fn lipschitz_envelope_is_the_greatest_unit_slope_field_below() {
        let spec = GridSpec::new([0.0; 3], 0.01, [5, 4, 6]).unwrap();
        let values: Vec<f32> = (0..spec.len())
            .map(|i| ((i * 7919) % 23) as f32 * 0.004)
            .collect();
        let g = DistanceGrid::new(spec, values.clone()).unwrap();
        assert!(g.axis_slopes().iter().all(|&s| s > 1.5));
        let e = g.lipschitz_envelope();
        assert!(
            e.axis_slopes().iter().all(|&s| s <= 1.0 + 1e-5),
            "{:?}",
            e.axis_slopes()
        );
        // Brute force: min over every node m of d(m) + h·|n − m|₁.
        for i in 0..5usize {
            for j in 0..4usize {
                for k in 0..6usize {
                    let mut best = f64::INFINITY;
                    for a in 0..5usize {
                        for b in 0..4usize {
                            for c in 0..6usize {
                                let l1 = i.abs_diff(a) + j.abs_diff(b) + k.abs_diff(c);
                                best = best
                                    .min(f64::from(values[spec.index(a, b, c)]) + 0.01 * l1 as f64);
                            }
                        }
                    }
                    let got = f64::from(e.values()[spec.index(i, j, k)]);
                    assert!(
                        (got - best).abs() < 1e-6,
                        "({i}, {j}, {k}): {got} vs {best}"
                    );
                }
            }
        }
    }

    #[test]
    fn value_is_exactly_the_trilinear_value_and_none_outside() {
        let spec = GridSpec::new([-0.1, 0.05, -0.2], 0.01, [5, 4, 6]).unwrap();
        let values = (0..spec.len())
            .map(|i| ((i * 7919) % 17) as f32 * 0.003 - 0.02)
            .collect();
        let g = DistanceGrid::new(spec, values).unwrap();
        let upper = spec.upper();
        let mut inside = 0u32;
        for k in 0..3000usize {
            let f = k as f64;
            // Beyond the box by up to a cell on every side, and its faces and corners exactly.
            let u = [0.618_033_9, 0.414_213_5, 0.732_050_8].map(|m| (f * m).fract() * 1.4 - 0.2);
            let mut p = [0, 1, 2].map(|a| spec.origin[a] + u[a] * (upper[a] - spec.origin[a]));
            if k % 7 == 0 {
                p[k % 3] = if k % 2 == 0 {
                    upper[k % 3]
                } else {
                    spec.origin[k % 3]
                };
            }
            match (g.value(p), g.trilinear(p)) {
                (Some(v), Some((d, _))) => {
                    assert_eq!(v.to_bits(), d.to_bits(), "{p:?}");
                    inside += 1;
                }
                (None, None) => assert!(!spec.contains(p), "{p:?}"),
                other => panic!("value and trilinear disagree at {p:?}: {other:?}"),
            }
        }
        assert!(inside > 1000, "{inside}");
        // The top corner node is its own value (up to the interpolation's
        // rounding at t = 1); NaN is outside.
        let last = f64::from(g.values()[spec.len() - 1]);
        assert!((g.value(upper).unwrap() - last).abs() < 1e-15);
        assert_eq!(g.value([f64::NAN, 0.07, -0.18]), None);
    }

    #[test]
    fn refuses_bad_specs() {
        assert!(GridSpec::new([0.0; 3], 0.0, [2, 2, 2]).is_err());
        assert!(GridSpec::new([f64::NAN, 0.0, 0.0], 0.1, [2, 2, 2]).is_err());
        assert!(GridSpec::new([0.0; 3], 0.1, [1, 2, 2]).is_err());
        assert!(GridSpec::new([0.0; 3], 0.1, [70_000, 70_000, 2]).is_err());
        let spec = GridSpec::new([0.0; 3], 0.1, [2, 2, 2]).unwrap();
        assert!(DistanceGrid::new(spec, vec![0.0; 7]).is_err());
        assert!(DistanceGrid::new(spec, vec![f32::NAN; 8]).is_err());
    }
}

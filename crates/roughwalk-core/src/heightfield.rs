//! A height field on a regular x–y grid: the terrain model every other part
//! of the core queries.
//!
//! Storage is x-major: `heights[ix * ny + iy]` is the height [m] at
//! `(x0 + ix·dx, y0 + iy·dy)`. Unknown cells (NaN in the source data) are
//! filled before they reach the core (see the Python `Terrain` docs) and
//! flagged in `known`, so that every query here returns a finite value.
//! Outside the grid, queries clamp to the nearest edge cell.

use crate::error::{CoreError, CoreResult};

/// How heights between grid points are interpolated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// Piecewise bilinear: exact at grid points, continuous, kinks at cell edges.
    Bilinear,
    /// Catmull–Rom bicubic: exact at grid points and C¹, for optimisers.
    Bicubic,
}

/// A regular-grid height field with a known-cell mask.
#[derive(Debug, Clone)]
pub struct HeightField {
    /// x of the first grid column [m].
    pub x0: f64,
    /// y of the first grid row [m].
    pub y0: f64,
    /// Grid spacing along x [m].
    pub dx: f64,
    /// Grid spacing along y [m].
    pub dy: f64,
    /// Number of grid points along x.
    pub nx: usize,
    /// Number of grid points along y.
    pub ny: usize,
    heights: Vec<f64>,
    known: Vec<bool>,
}

impl HeightField {
    /// Builds a height field from x-major heights [m]; every height must be finite.
    pub fn new(
        x0: f64,
        y0: f64,
        dx: f64,
        dy: f64,
        nx: usize,
        ny: usize,
        heights: Vec<f64>,
        known: Option<Vec<bool>>,
    ) -> CoreResult<Self> {
        if nx < 2 || ny < 2 {
            return Err(CoreError::Terrain(format!(
                "a height field needs at least 2×2 grid points, got {nx}×{ny}"
            )));
        }
        if !(dx.is_finite() && dy.is_finite() && dx > 0.0 && dy > 0.0) {
            return Err(CoreError::Terrain(format!(
                "grid spacing must be finite and positive, got dx={dx}, dy={dy}"
            )));
        }
        if !(x0.is_finite() && y0.is_finite()) {
            return Err(CoreError::Terrain(format!(
                "grid origin must be finite, got ({x0}, {y0})"
            )));
        }
        if heights.len() != nx * ny {
            return Err(CoreError::Terrain(format!(
                "expected {} heights for a {nx}×{ny} grid, got {}",
                nx * ny,
                heights.len()
            )));
        }
        if let Some(i) = heights.iter().position(|h| !h.is_finite()) {
            return Err(CoreError::Terrain(format!(
                "height at grid index ({}, {}) is not finite ({}); fill unknown cells first",
                i / ny,
                i % ny,
                heights[i]
            )));
        }
        let known = known.unwrap_or_else(|| vec![true; nx * ny]);
        if known.len() != nx * ny {
            return Err(CoreError::Terrain(format!(
                "expected {} known flags, got {}",
                nx * ny,
                known.len()
            )));
        }
        Ok(Self {
            x0,
            y0,
            dx,
            dy,
            nx,
            ny,
            heights,
            known,
        })
    }

    /// Height [m] stored at grid index (ix, iy), clamped to the grid.
    #[inline]
    pub fn at(&self, ix: isize, iy: isize) -> f64 {
        let ix = ix.clamp(0, self.nx as isize - 1) as usize;
        let iy = iy.clamp(0, self.ny as isize - 1) as usize;
        self.heights[ix * self.ny + iy]
    }

    /// Height [m] at grid index (ix, iy), extrapolated linearly one cell past
    /// the edge so that bicubic interpolation reproduces planes in edge cells.
    #[inline]
    fn at_extrapolated(&self, ix: isize, iy: isize) -> f64 {
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        if ix < 0 {
            return 2.0 * self.at_extrapolated(0, iy) - self.at_extrapolated(1, iy);
        }
        if ix >= nx {
            return 2.0 * self.at_extrapolated(nx - 1, iy) - self.at_extrapolated(nx - 2, iy);
        }
        if iy < 0 {
            return 2.0 * self.at(ix, 0) - self.at(ix, 1);
        }
        if iy >= ny {
            return 2.0 * self.at(ix, ny - 1) - self.at(ix, ny - 2);
        }
        self.at(ix, iy)
    }

    /// Whether grid point (ix, iy) was measured (false outside the grid).
    #[inline]
    pub fn is_known_index(&self, ix: isize, iy: isize) -> bool {
        if ix < 0 || iy < 0 || ix >= self.nx as isize || iy >= self.ny as isize {
            return false;
        }
        self.known[ix as usize * self.ny + iy as usize]
    }

    /// The x-major height array [m].
    pub fn heights(&self) -> &[f64] {
        &self.heights
    }

    /// The x-major known-cell mask.
    pub fn known(&self) -> &[bool] {
        &self.known
    }

    /// Largest x of the grid [m].
    pub fn x_max(&self) -> f64 {
        self.x0 + (self.nx - 1) as f64 * self.dx
    }

    /// Largest y of the grid [m].
    pub fn y_max(&self) -> f64 {
        self.y0 + (self.ny - 1) as f64 * self.dy
    }

    /// Whether (x, y) lies inside the grid's rectangle.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x0 && x <= self.x_max() && y >= self.y0 && y <= self.y_max()
    }

    /// Continuous grid coordinates of (x, y), clamped to the grid: cell index and fraction.
    #[inline]
    fn cell(&self, x: f64, y: f64) -> (isize, f64, isize, f64) {
        let gx = ((x - self.x0) / self.dx).clamp(0.0, (self.nx - 1) as f64);
        let gy = ((y - self.y0) / self.dy).clamp(0.0, (self.ny - 1) as f64);
        let ix = (gx.floor() as isize).min(self.nx as isize - 2);
        let iy = (gy.floor() as isize).min(self.ny as isize - 2);
        (ix, gx - ix as f64, iy, gy - iy as f64)
    }

    /// Whether the grid cell under (x, y) has all four corners measured.
    pub fn is_known(&self, x: f64, y: f64) -> bool {
        if !self.contains(x, y) {
            return false;
        }
        let (ix, _, iy, _) = self.cell(x, y);
        self.is_known_index(ix, iy)
            && self.is_known_index(ix + 1, iy)
            && self.is_known_index(ix, iy + 1)
            && self.is_known_index(ix + 1, iy + 1)
    }

    /// Height [m] and its gradient (∂z/∂x, ∂z/∂y) at (x, y).
    ///
    /// Outside the grid the height is that of the nearest edge and the
    /// gradient is zero along the clamped direction.
    pub fn height_and_gradient(&self, x: f64, y: f64, interp: Interpolation) -> (f64, f64, f64) {
        let inside_x = x > self.x0 && x < self.x_max();
        let inside_y = y > self.y0 && y < self.y_max();
        let (ix, tx, iy, ty) = self.cell(x, y);
        let (h, mut gx, mut gy) = match interp {
            Interpolation::Bilinear => {
                let z00 = self.at(ix, iy);
                let z10 = self.at(ix + 1, iy);
                let z01 = self.at(ix, iy + 1);
                let z11 = self.at(ix + 1, iy + 1);
                let h = z00 * (1.0 - tx) * (1.0 - ty)
                    + z10 * tx * (1.0 - ty)
                    + z01 * (1.0 - tx) * ty
                    + z11 * tx * ty;
                let gx = ((z10 - z00) * (1.0 - ty) + (z11 - z01) * ty) / self.dx;
                let gy = ((z01 - z00) * (1.0 - tx) + (z11 - z10) * tx) / self.dy;
                (h, gx, gy)
            }
            Interpolation::Bicubic => {
                let (wx, dwx) = catmull_rom(tx);
                let (wy, dwy) = catmull_rom(ty);
                let mut h = 0.0;
                let mut gx = 0.0;
                let mut gy = 0.0;
                for (a, (wxa, dwxa)) in wx.iter().zip(dwx.iter()).enumerate() {
                    for (b, (wyb, dwyb)) in wy.iter().zip(dwy.iter()).enumerate() {
                        let z = self.at_extrapolated(ix + a as isize - 1, iy + b as isize - 1);
                        h += wxa * wyb * z;
                        gx += dwxa * wyb * z;
                        gy += wxa * dwyb * z;
                    }
                }
                (h, gx / self.dx, gy / self.dy)
            }
        };
        if !inside_x {
            gx = 0.0;
        }
        if !inside_y {
            gy = 0.0;
        }
        (h, gx, gy)
    }

    /// Height [m] at (x, y).
    pub fn height(&self, x: f64, y: f64, interp: Interpolation) -> f64 {
        self.height_and_gradient(x, y, interp).0
    }

    /// Unit upward surface normal at (x, y).
    pub fn normal(&self, x: f64, y: f64, interp: Interpolation) -> [f64; 3] {
        let (_, gx, gy) = self.height_and_gradient(x, y, interp);
        let n = (gx * gx + gy * gy + 1.0).sqrt();
        [-gx / n, -gy / n, 1.0 / n]
    }

    /// Unit upward normal of the mean slope over the disc of `radius` [m]
    /// around (x, y): the bilinear gradient averaged over the points of a
    /// square grid of spacing r / ⌈r / min(dx, dy)⌉ within the disc: about
    /// the mean gradient the foothold slope checks judge a foot's disc by
    /// (they average central differences at the grid points).
    /// `radius` ≤ 0 gives [`normal`](Self::normal) at the point.
    pub fn disc_normal(&self, x: f64, y: f64, radius: f64) -> [f64; 3] {
        if radius <= 0.0 {
            return self.normal(x, y, Interpolation::Bilinear);
        }
        let n = ((radius / self.dx.min(self.dy)).ceil() as i64).max(1);
        let step = radius / n as f64;
        let (mut gx, mut gy, mut count) = (0.0, 0.0, 0usize);
        for i in -n..=n {
            for j in -n..=n {
                let (ox, oy) = (i as f64 * step, j as f64 * step);
                if ox * ox + oy * oy > radius * radius + 1e-15 {
                    continue;
                }
                let (_, a, b) = self.height_and_gradient(x + ox, y + oy, Interpolation::Bilinear);
                gx += a;
                gy += b;
                count += 1;
            }
        }
        gx /= count as f64;
        gy /= count as f64;
        let norm = (gx * gx + gy * gy + 1.0).sqrt();
        [-gx / norm, -gy / norm, 1.0 / norm]
    }

    /// Minimum and maximum stored height [m].
    pub fn height_range(&self) -> (f64, f64) {
        self.heights
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &h| {
                (lo.min(h), hi.max(h))
            })
    }
}

/// Catmull–Rom weights for the four samples around a fraction t ∈ [0, 1],
/// and their derivatives with respect to t.
#[inline]
fn catmull_rom(t: f64) -> ([f64; 4], [f64; 4]) {
    let t2 = t * t;
    let t3 = t2 * t;
    let w = [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ];
    let dw = [
        0.5 * (-3.0 * t2 + 4.0 * t - 1.0),
        0.5 * (9.0 * t2 - 10.0 * t),
        0.5 * (-9.0 * t2 + 8.0 * t + 1.0),
        0.5 * (3.0 * t2 - 2.0 * t),
    ];
    (w, dw)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(a: f64, b: f64, c: f64) -> HeightField {
        let (nx, ny) = (11, 7);
        let mut h = Vec::new();
        for ix in 0..nx {
            for iy in 0..ny {
                let x = -0.5 + ix as f64 * 0.1;
                let y = 0.2 + iy as f64 * 0.05;
                h.push(a * x + b * y + c);
            }
        }
        HeightField::new(-0.5, 0.2, 0.1, 0.05, nx, ny, h, None).unwrap()
    }

    #[test]
    fn both_interpolations_reproduce_a_plane() {
        let hf = plane(0.3, -0.2, 0.1);
        for interp in [Interpolation::Bilinear, Interpolation::Bicubic] {
            for &(x, y) in &[(0.0, 0.3), (0.123, 0.41), (-0.31, 0.22)] {
                let (h, gx, gy) = hf.height_and_gradient(x, y, interp);
                assert!((h - (0.3 * x - 0.2 * y + 0.1)).abs() < 1e-12);
                assert!((gx - 0.3).abs() < 1e-12 && (gy + 0.2).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn disc_normal_is_the_plane_normal_on_a_plane_and_the_point_normal_at_zero_radius() {
        let hf = plane(0.3, -0.2, 0.1);
        for &(x, y) in &[(0.0, 0.3), (0.123, 0.41)] {
            let n = hf.normal(x, y, Interpolation::Bilinear);
            for r in [0.0, 0.01, 0.07] {
                let d = hf.disc_normal(x, y, r);
                assert!((0..3).all(|k| (d[k] - n[k]).abs() < 1e-12), "{d:?} {n:?}");
            }
        }
    }

    #[test]
    fn disc_normal_averages_a_ridge_that_the_point_normal_sees_one_side_of() {
        // A roof h = 0.2 - |x| on a 1 cm grid: 1 mm off the ridge the point
        // normal leans 45°, the mean over a 3 cm disc 14°.
        let (nx, ny) = (41, 21);
        let mut h = Vec::new();
        for ix in 0..nx {
            for _ in 0..ny {
                h.push(0.2 - (-0.2 + ix as f64 * 0.01_f64).abs());
            }
        }
        let hf = HeightField::new(-0.2, -0.1, 0.01, 0.01, nx, ny, h, None).unwrap();
        let point = hf.normal(0.001, 0.0, Interpolation::Bilinear);
        assert!((point[2] - 0.5_f64.sqrt()).abs() < 1e-12);
        let disc = hf.disc_normal(0.001, 0.0, 0.03);
        // Brute force over the same 29 points within 3 cm, at x = 0.001 +
        // 0.01·i: the 18 with i ≥ 0 lie right of the ridge (slope −1), the
        // 11 with i < 0 left of it (+1).
        let (mut gx, mut count) = (0.0_f64, 0.0_f64);
        for i in -3i32..=3 {
            for j in -3i32..=3 {
                if i * i + j * j <= 9 {
                    gx += if 0.001 + 0.01 * f64::from(i) > 0.0 {
                        -1.0
                    } else {
                        1.0
                    };
                    count += 1.0;
                }
            }
        }
        gx /= count;
        let want = [
            -gx / (gx * gx + 1.0).sqrt(),
            0.0,
            1.0 / (gx * gx + 1.0).sqrt(),
        ];
        assert!(
            (0..3).all(|k| (disc[k] - want[k]).abs() < 1e-12),
            "{disc:?} {want:?}"
        );
        assert!(disc[2] > 0.95); // 14° against the point normal's 45°
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let mut h = Vec::new();
        for ix in 0..9 {
            for iy in 0..9 {
                h.push(f64::from((ix * 7 + iy * 3) % 5) * 0.01);
            }
        }
        let hf = HeightField::new(0.0, 0.0, 0.01, 0.01, 9, 9, h, None).unwrap();
        let e = 1e-7;
        for interp in [Interpolation::Bilinear, Interpolation::Bicubic] {
            for &(x, y) in &[(0.0234, 0.0517), (0.0612, 0.0155)] {
                let (_, gx, gy) = hf.height_and_gradient(x, y, interp);
                let fx = (hf.height(x + e, y, interp) - hf.height(x - e, y, interp)) / (2.0 * e);
                let fy = (hf.height(x, y + e, interp) - hf.height(x, y - e, interp)) / (2.0 * e);
                assert!((gx - fx).abs() < 1e-5, "{gx} vs {fx}");
                assert!((gy - fy).abs() < 1e-5, "{gy} vs {fy}");
            }
        }
    }

    #[test]
    fn refuses_bad_input() {
        assert!(HeightField::new(0.0, 0.0, 0.1, 0.1, 1, 5, vec![0.0; 5], None).is_err());
        assert!(HeightField::new(0.0, 0.0, -0.1, 0.1, 2, 2, vec![0.0; 4], None).is_err());
        assert!(HeightField::new(0.0, 0.0, 0.1, 0.1, 2, 2, vec![0.0; 3], None).is_err());
        assert!(HeightField::new(0.0, 0.0, 0.1, 0.1, 2, 2, vec![f64::NAN; 4], None).is_err());
    }
}

//! Stability as a CHOMP term: the cart-table ZMP kept inside the support polygon (Zucker 2011, §5.3).
//!
//! With the CoM's offset o from the trunk held, c = x + o and c̈ from central
//! differences, the ZMP p = c − (z_c/g)·c̈ pays ½·w·Σ_t max(0, m* − margin(p_t))²
//! over the interior samples; its gradient w.r.t. the trunk's x–y is exact.

// Samples and legs index several parallel arrays at once.
#![allow(clippy::needless_range_loop)]

use crate::error::{CoreError, CoreResult};

/// A 2-vector (x, y).
pub type Vec2 = [f64; 2];

/// Signed margin [m] of `p` to a CCW convex polygon, and ∂margin/∂p.
///
/// Inside: the distance to the nearest edge line, gradient its inward normal.
/// Outside: minus the distance to the nearest boundary point, gradient the
/// unit vector toward it. A polygon of fewer than three corners (or with a
/// zero-length edge) is the segment from its first to its last corner.
pub fn polygon_margin(p: Vec2, poly: &[Vec2]) -> (f64, Vec2) {
    let k = poly.len();
    let edge = |i: usize| {
        let (a, b) = (poly[i], poly[(i + 1) % k]);
        [b[0] - a[0], b[1] - a[1]]
    };
    let degenerate = k < 3 || (0..k).any(|i| edge(i)[0].hypot(edge(i)[1]) < 1e-12);
    if degenerate {
        let (a, b) = (poly[0], poly[k - 1]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let dd = (d[0] * d[0] + d[1] * d[1]).max(1e-24);
        let t = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / dd).clamp(0.0, 1.0);
        let diff = [a[0] + t * d[0] - p[0], a[1] + t * d[1] - p[1]];
        let dist = diff[0].hypot(diff[1]);
        let s = 1.0 / dist.max(1e-12);
        return (-dist, [diff[0] * s, diff[1] * s]);
    }
    let mut inside = true;
    let (mut best, mut normal_best) = (f64::INFINITY, [0.0; 2]);
    for i in 0..k {
        let e = edge(i);
        let len = e[0].hypot(e[1]);
        let n = [-e[1] / len, e[0] / len];
        let s = (p[0] - poly[i][0]) * n[0] + (p[1] - poly[i][1]) * n[1];
        if s < 0.0 {
            inside = false;
        }
        if s < best {
            best = s;
            normal_best = n;
        }
    }
    if inside {
        return (best, normal_best);
    }
    let (mut dist_best, mut toward) = (f64::INFINITY, [0.0; 2]);
    for i in 0..k {
        let e = edge(i);
        let len2 = e[0] * e[0] + e[1] * e[1];
        let a = poly[i];
        let t = (((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / len2).clamp(0.0, 1.0);
        let c = [a[0] + t * e[0], a[1] + t * e[1]];
        let dist = (c[0] - p[0]).hypot(c[1] - p[1]);
        if dist < dist_best {
            dist_best = dist;
            toward = [c[0] - p[0], c[1] - p[1]];
        }
    }
    let s = 1.0 / dist_best.max(1e-12);
    (-dist_best, [toward[0] * s, toward[1] * s])
}

/// The support term of a trunk path sampled every `dt` [s].
#[derive(Debug, Clone, PartialEq)]
pub struct ZmpSupport {
    polygons: Vec<Vec<Vec2>>,
    index: Vec<usize>,
    offset: Vec<Vec2>,
    offset_acceleration: Vec<Vec2>,
    k: f64,
    dt: f64,
    margin: f64,
    weight: f64,
}

/// Value, gradient w.r.t. the interior trunk x–y, and the interior margins.
pub type SupportEvaluation = (f64, Vec<Vec2>, Vec<f64>);

impl ZmpSupport {
    /// The term for CCW polygons [m], the polygon of each sample, the CoM's
    /// offset from the trunk (T) [m] and its acceleration [m/s²], z_c/g [s²],
    /// the period [s], the margin m* [m] and the factor w·h.
    pub fn new(
        polygons: Vec<Vec<Vec2>>,
        index: Vec<usize>,
        offset: Vec<Vec2>,
        offset_acceleration: Vec<Vec2>,
        k: f64,
        dt: f64,
        margin: f64,
        weight: f64,
    ) -> CoreResult<Self> {
        if let Some(i) = index.iter().find(|&&i| i >= polygons.len()) {
            return Err(CoreError::InvalidArgument(format!(
                "polygon index {i} refers to a polygon that was not given ({} given)",
                polygons.len()
            )));
        }
        if polygons.iter().any(Vec::is_empty) {
            return Err(CoreError::InvalidArgument(
                "a support polygon needs at least one corner".into(),
            ));
        }
        let t = index.len();
        if offset.len() != t || offset_acceleration.len() != t {
            return Err(CoreError::InvalidArgument(format!(
                "CoM offsets must have one row per sample ({t}), got {} and {}",
                offset.len(),
                offset_acceleration.len()
            )));
        }
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(CoreError::InvalidArgument(format!(
                "sample period must be positive [s], got {dt}"
            )));
        }
        Ok(Self {
            polygons,
            index,
            offset,
            offset_acceleration,
            k,
            dt,
            margin,
            weight,
        })
    }

    /// Number of samples T.
    pub fn len(&self) -> usize {
        self.index.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.index.is_empty()
    }

    /// Value, gradient (T − 2) and margins (T − 2) of a trunk x–y path (T) [m].
    pub fn evaluate(&self, xy: &[Vec2]) -> SupportEvaluation {
        let t_len = xy.len();
        let n = t_len.saturating_sub(2);
        let dt2 = self.dt * self.dt;
        let mut value = 0.0;
        let mut margins = vec![0.0; n];
        // ∂f/∂p at every sample (zero at the ends), then through p's stencil.
        let mut g_p = vec![[0.0; 2]; t_len];
        for i in 0..n {
            let t = i + 1;
            let p: Vec2 = std::array::from_fn(|a| {
                let acc = (xy[t + 1][a] - 2.0 * xy[t][a] + xy[t - 1][a]) / dt2
                    + self.offset_acceleration[t][a];
                xy[t][a] + self.offset[t][a] - self.k * acc
            });
            let (m, gm) = polygon_margin(p, &self.polygons[self.index[t]]);
            margins[i] = m;
            let short = (self.margin - m).max(0.0);
            value += short * short;
            g_p[t] = [-self.weight * short * gm[0], -self.weight * short * gm[1]];
        }
        let c = self.k / dt2;
        let grad = (0..n)
            .map(|i| {
                std::array::from_fn(|a| {
                    g_p[i + 1][a] - c * (g_p[i][a] - 2.0 * g_p[i + 1][a] + g_p[i + 2][a])
                })
            })
            .collect();
        (0.5 * self.weight * value, grad, margins)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn margin_inside_outside_and_degenerate() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let (m, g) = polygon_margin([0.2, 0.5], &square);
        assert!((m - 0.2).abs() < 1e-12 && (g[0] - 1.0).abs() < 1e-12);
        let (m, g) = polygon_margin([2.0, 2.0], &square);
        assert!((m + 2f64.sqrt()).abs() < 1e-12);
        assert!((g[0] + 0.5f64.sqrt()).abs() < 1e-12);
        let (m, _) = polygon_margin([0.5, 1.0], &[[0.0, 0.0], [1.0, 0.0]]);
        assert!((m + 1.0).abs() < 1e-12);
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let tri = vec![[0.0, 0.0], [0.2, 0.0], [0.1, 0.15]];
        let t = 9;
        let off: Vec<Vec2> = (0..t).map(|i| [0.001 * i as f64, -0.002]).collect();
        let acc = vec![[0.01, 0.0]; t];
        let s =
            ZmpSupport::new(vec![tri], vec![0; t], off, acc, 0.2 / 9.81, 0.02, 0.03, 5.0).unwrap();
        let xy: Vec<Vec2> = (0..t)
            .map(|i| [0.02 + 0.02 * i as f64, 0.01 + 0.003 * (i as f64).sin()])
            .collect();
        let (v, g, _) = s.evaluate(&xy);
        assert!(v > 0.0);
        let h = 1e-7;
        for i in 1..t - 1 {
            for a in 0..2 {
                let mut p = xy.clone();
                p[i][a] += h;
                let mut m = xy.clone();
                m[i][a] -= h;
                let fd = (s.evaluate(&p).0 - s.evaluate(&m).0) / (2.0 * h);
                assert!(
                    (fd - g[i - 1][a]).abs() < 1e-5 * (1.0 + fd.abs()),
                    "{fd} {:?}",
                    g[i - 1]
                );
            }
        }
    }
}

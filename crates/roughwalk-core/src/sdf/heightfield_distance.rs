//! Exact Euclidean distance from a point to a height-field surface.
//!
//! The surface is the height field's triangulation, two triangles per grid
//! cell split along the (i, j)–(i+1, j+1) diagonal (the same triangles as
//! `Terrain.to_mesh()` in Python), extended beyond the grid the way every
//! height query is: the height outside is that of the nearest edge point.
//! The extension is made of strips (an edge profile swept outward) and four
//! flat corner quadrants, so the surface is a closed-form, continuous graph
//! z = h(x, y) over the whole plane, and "below the surface" is inside.
//!
//! Queries are a branch-and-bound over a min/max pyramid of cell heights:
//! a block whose horizontal distance and height gap to the point already
//! exceed the best distance found cannot hold a closer point.

use crate::heightfield::HeightField;
use crate::sdf::mesh::{closest_point_on_triangle, dist2};

/// A point on the surface and its distance [m] from the query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Unsigned distance [m] from the query point.
    pub distance: f64,
    /// The closest surface point [m].
    pub point: [f64; 3],
}

/// Height range of every block of 2^l × 2^l cells.
#[derive(Debug, Clone)]
struct MinMaxLevel {
    n: [usize; 2],
    /// (min, max) height [m] per block, row-major over (i, j).
    range: Vec<[f64; 2]>,
}

/// A height field prepared for exact distance queries.
#[derive(Debug, Clone)]
pub struct HeightFieldDistance {
    hf: HeightField,
    levels: Vec<MinMaxLevel>,
    /// Heights along the four edges: x = x_min, x = x_max (over j), y = y_min, y = y_max (over i).
    edges: [Vec<f64>; 4],
    /// 1/dx and 1/dy [1/m]: multiplications are cheaper than divisions in hot loops.
    inv: [f64; 2],
}

/// Stack capacity of the branch-and-bound: ≤ 9 start blocks plus 3 per
/// level is enough for grids up to 2^18 cells a side; a full stack falls
/// back to an exhaustive visit, so this only bounds speed, not correctness.
const STACK: usize = 64;

#[inline]
fn gap(v: f64, lo: f64, hi: f64) -> f64 {
    (lo - v).max(v - hi).max(0.0)
}

impl HeightFieldDistance {
    /// Builds the min/max pyramid of `hf` (a few MB for a LittleDog board).
    pub fn new(hf: HeightField) -> Self {
        let (nx, ny) = (hf.nx, hf.ny);
        let h = hf.heights();
        let mut levels = Vec::new();
        let mut n = [nx - 1, ny - 1];
        let mut range = Vec::with_capacity(n[0] * n[1]);
        for i in 0..n[0] {
            for j in 0..n[1] {
                let c = [
                    h[i * ny + j],
                    h[(i + 1) * ny + j],
                    h[i * ny + j + 1],
                    h[(i + 1) * ny + j + 1],
                ];
                range.push([
                    c.iter().copied().fold(f64::INFINITY, f64::min),
                    c.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                ]);
            }
        }
        levels.push(MinMaxLevel { n, range });
        while n[0] > 1 || n[1] > 1 {
            let below = levels.last().expect("level 0 exists");
            let m = [n[0].div_ceil(2), n[1].div_ceil(2)];
            let mut range = vec![[f64::INFINITY, f64::NEG_INFINITY]; m[0] * m[1]];
            for i in 0..n[0] {
                for j in 0..n[1] {
                    let r = below.range[i * n[1] + j];
                    let t = &mut range[(i / 2) * m[1] + j / 2];
                    t[0] = t[0].min(r[0]);
                    t[1] = t[1].max(r[1]);
                }
            }
            levels.push(MinMaxLevel { n: m, range });
            n = m;
        }
        let edges = [
            (0..ny).map(|j| h[j]).collect(),
            (0..ny).map(|j| h[(nx - 1) * ny + j]).collect(),
            (0..nx).map(|i| h[i * ny]).collect(),
            (0..nx).map(|i| h[i * ny + ny - 1]).collect(),
        ];
        let inv = [1.0 / hf.dx, 1.0 / hf.dy];
        Self {
            hf,
            levels,
            edges,
            inv,
        }
    }

    /// The height field behind the surface.
    pub fn heightfield(&self) -> &HeightField {
        &self.hf
    }

    #[inline]
    fn h(&self, i: usize, j: usize) -> f64 {
        self.hf.heights()[i * self.hf.ny + j]
    }

    /// Height [m] of the triangulated, edge-extended surface at (x, y).
    #[inline]
    pub fn surface_height(&self, x: f64, y: f64) -> f64 {
        self.surface_height_and_slope(x, y).0
    }

    /// Height [m] and slope (∂z/∂x, ∂z/∂y) of the surface at (x, y).
    #[inline]
    pub fn surface_height_and_slope(&self, x: f64, y: f64) -> (f64, f64, f64) {
        let hf = &self.hf;
        let gx = ((x - hf.x0) * self.inv[0]).clamp(0.0, (hf.nx - 1) as f64);
        let gy = ((y - hf.y0) * self.inv[1]).clamp(0.0, (hf.ny - 1) as f64);
        let i = (gx as usize).min(hf.nx - 2);
        let j = (gy as usize).min(hf.ny - 2);
        let (tx, ty) = (gx - i as f64, gy - j as f64);
        let za = self.h(i, j);
        let zc = self.h(i + 1, j + 1);
        let (sx, sy) = if tx >= ty {
            let zb = self.h(i + 1, j);
            (zb - za, zc - zb)
        } else {
            let zd = self.h(i, j + 1);
            (zc - zd, zd - za)
        };
        let inside_x = x > hf.x0 && x < hf.x_max();
        let inside_y = y > hf.y0 && y < hf.y_max();
        (
            za + sx * tx + sy * ty,
            if inside_x { sx * self.inv[0] } else { 0.0 },
            if inside_y { sy * self.inv[1] } else { 0.0 },
        )
    }

    /// Whether `p` [m] lies strictly below the surface (inside the terrain).
    #[inline]
    pub fn is_inside(&self, p: [f64; 3]) -> bool {
        p[2] < self.surface_height(p[0], p[1])
    }

    /// Heights [m] between which every point (x, y, z) within `tau` [m]
    /// of the surface lies (a conservative superset: the union over nearby
    /// 2×2-cell blocks of their height range widened by √(τ² − dh²), dh the
    /// block's horizontal distance).
    pub fn band_range(&self, x: f64, y: f64, tau: f64) -> (f64, f64) {
        let hf = &self.hf;
        // Beyond the grid the surface repeats the edge profile, which the
        // edge blocks bound when seen from the clamped point.
        let x = x.clamp(hf.x0, hf.x_max());
        let y = y.clamp(hf.y0, hf.y_max());
        let l = 1.min(self.levels.len() - 1);
        let lev = &self.levels[l];
        let (sx, sy) = (hf.dx * (1usize << l) as f64, hf.dy * (1usize << l) as f64);
        let idx = |v: f64, n: usize, s: f64| ((v / s).max(0.0) as usize).min(n - 1);
        let (i0, i1) = (
            idx(x - tau - hf.x0, lev.n[0], sx),
            idx(x + tau - hf.x0, lev.n[0], sx),
        );
        let (j0, j1) = (
            idx(y - tau - hf.y0, lev.n[1], sy),
            idx(y + tau - hf.y0, lev.n[1], sy),
        );
        let (ncx, ncy) = (hf.nx - 1, hf.ny - 1);
        let tau2 = tau * tau;
        let mut out = (f64::INFINITY, f64::NEG_INFINITY);
        for i in i0..=i1 {
            let xa = hf.x0 + (i << l) as f64 * hf.dx;
            let xb = hf.x0 + (((i + 1) << l).min(ncx)) as f64 * hf.dx;
            let gx = gap(x, xa, xb);
            for j in j0..=j1 {
                let ya = hf.y0 + (j << l) as f64 * hf.dy;
                let yb = hf.y0 + (((j + 1) << l).min(ncy)) as f64 * hf.dy;
                let gy = gap(y, ya, yb);
                let left = tau2 - gx * gx - gy * gy;
                if left < 0.0 {
                    continue;
                }
                let w = left.sqrt();
                let r = lev.range[i * lev.n[1] + j];
                out = (out.0.min(r[0] - w), out.1.max(r[1] + w));
            }
        }
        out
    }

    /// Lower bound of the squared distance from `p` to block (l, i, j).
    #[inline]
    fn block_bound2(&self, l: usize, i: usize, j: usize, p: [f64; 3]) -> f64 {
        let hf = &self.hf;
        let lev = &self.levels[l];
        let (ncx, ncy) = (hf.nx - 1, hf.ny - 1);
        let xa = hf.x0 + (i << l) as f64 * hf.dx;
        let xb = hf.x0 + (((i + 1) << l).min(ncx)) as f64 * hf.dx;
        let ya = hf.y0 + (j << l) as f64 * hf.dy;
        let yb = hf.y0 + (((j + 1) << l).min(ncy)) as f64 * hf.dy;
        let r = lev.range[i * lev.n[1] + j];
        let gx = gap(p[0], xa, xb);
        let gy = gap(p[1], ya, yb);
        let gz = gap(p[2], r[0], r[1]);
        gx * gx + gy * gy + gz * gz
    }

    /// Tests the two triangles of grid cell (i, j) against the best so far.
    #[inline]
    fn visit_cell(&self, i: usize, j: usize, p: [f64; 3], best: &mut (f64, [f64; 3])) {
        let hf = &self.hf;
        let (xa, ya) = (hf.x0 + i as f64 * hf.dx, hf.y0 + j as f64 * hf.dy);
        let (xb, yb) = (xa + hf.dx, ya + hf.dy);
        let a = [xa, ya, self.h(i, j)];
        let b = [xb, ya, self.h(i + 1, j)];
        let c = [xb, yb, self.h(i + 1, j + 1)];
        let d = [xa, yb, self.h(i, j + 1)];
        let gx = gap(p[0], xa, xb);
        let gy = gap(p[1], ya, yb);
        let h2 = gx * gx + gy * gy;
        for [a, b, c] in [[a, b, c], [a, c, d]] {
            // Each triangle's own height range bounds it tighter than the cell's.
            let gz = gap(p[2], a[2].min(b[2]).min(c[2]), a[2].max(b[2]).max(c[2]));
            if h2 + gz * gz >= best.0 {
                continue;
            }
            let q = closest_point_on_triangle(p, a, b, c);
            let e = dist2(p, q);
            if e < best.0 {
                *best = (e, q);
            }
        }
    }

    /// Branch-and-bound over the grid's triangles.
    fn search_grid(&self, p: [f64; 3], best: &mut (f64, [f64; 3])) {
        let hf = &self.hf;
        let r = best.0.sqrt();
        let cell = hf.dx.min(hf.dy);
        let top = self.levels.len() - 1;
        let mut l = 0;
        while l < top && ((1usize << l) as f64) * cell < r {
            l += 1;
        }
        let lev = &self.levels[l];
        let span = |v: f64, o: f64, d: f64, n: usize| {
            let s = d * (1usize << l) as f64;
            let lo = ((v - r - o) / s).max(0.0) as usize;
            let hi = ((v + r - o) / s).max(0.0) as usize;
            (lo.min(n - 1), hi.min(n - 1))
        };
        let (i0, i1) = span(p[0], hf.x0, hf.dx, lev.n[0]);
        let (j0, j1) = span(p[1], hf.y0, hf.dy, lev.n[1]);
        let mut stack = [(0u32, 0u32, 0u32, 0.0f64); STACK];
        let mut top_of = 0usize;
        let push = |stack: &mut [(u32, u32, u32, f64); STACK],
                    top_of: &mut usize,
                    l: usize,
                    i: usize,
                    j: usize,
                    b: f64,
                    best: &mut (f64, [f64; 3])| {
            if *top_of < STACK {
                stack[*top_of] = (l as u32, i as u32, j as u32, b);
                *top_of += 1;
            } else {
                self.search_block_exhaustive(l, i, j, p, best);
            }
        };
        for i in i0..=i1 {
            for j in j0..=j1 {
                let b = self.block_bound2(l, i, j, p);
                if b < best.0 {
                    push(&mut stack, &mut top_of, l, i, j, b, best);
                }
            }
        }
        while top_of > 0 {
            top_of -= 1;
            let (l, i, j, b) = stack[top_of];
            let (l, i, j) = (l as usize, i as usize, j as usize);
            if b >= best.0 {
                continue;
            }
            if l == 0 {
                self.visit_cell(i, j, p, best);
                continue;
            }
            let below = &self.levels[l - 1];
            let mut kids = [(0usize, 0usize, f64::INFINITY); 4];
            let mut nk = 0;
            for ci in (2 * i)..(2 * i + 2).min(below.n[0]) {
                for cj in (2 * j)..(2 * j + 2).min(below.n[1]) {
                    let cb = self.block_bound2(l - 1, ci, cj, p);
                    if cb < best.0 {
                        kids[nk] = (ci, cj, cb);
                        nk += 1;
                    }
                }
            }
            // Push farthest first so the nearest block is searched first.
            kids[..nk].sort_unstable_by(|a, b| b.2.total_cmp(&a.2));
            for &(ci, cj, cb) in &kids[..nk] {
                push(&mut stack, &mut top_of, l - 1, ci, cj, cb, best);
            }
        }
    }

    fn search_block_exhaustive(
        &self,
        l: usize,
        i: usize,
        j: usize,
        p: [f64; 3],
        best: &mut (f64, [f64; 3]),
    ) {
        let hf = &self.hf;
        for ci in (i << l)..((i + 1) << l).min(hf.nx - 1) {
            for cj in (j << l)..((j + 1) << l).min(hf.ny - 1) {
                self.visit_cell(ci, cj, p, best);
            }
        }
    }

    /// Searches one edge strip: the edge profile `e` (samples at u0 + s·du)
    /// swept outward from the edge. `across` is the point's distance [m] to
    /// the strip's half-plane and `pu` its coordinate along the edge; returns
    /// the best (u, z) on the profile if it beats `best`.
    fn search_strip(
        e: &[f64],
        u0: f64,
        du: f64,
        pu: f64,
        pz: f64,
        across: f64,
        best: f64,
    ) -> Option<(f64, f64, f64)> {
        let a2 = across * across;
        if a2 >= best {
            return None;
        }
        let n = e.len();
        let sc = (((pu - u0) / du).max(0.0) as usize).min(n - 2);
        let mut found: Option<(f64, f64, f64)> = None;
        let mut best = best;
        let mut test = |s: usize, best: &mut f64| -> bool {
            let (ua, ub) = (u0 + s as f64 * du, u0 + (s + 1) as f64 * du);
            let gu = gap(pu, ua, ub);
            if a2 + gu * gu >= *best {
                return false;
            }
            let (za, zb) = (e[s], e[s + 1]);
            let gz = gap(pz, za.min(zb), za.max(zb));
            if a2 + gu * gu + gz * gz < *best {
                let q = crate::sdf::mesh::closest_point_on_segment(
                    [pu, pz, 0.0],
                    [ua, za, 0.0],
                    [ub, zb, 0.0],
                );
                let d = a2 + (pu - q[0]).powi(2) + (pz - q[1]).powi(2);
                if d < *best {
                    *best = d;
                    found = Some((d, q[0], q[1]));
                }
            }
            true
        };
        for s in (0..=sc).rev() {
            if !test(s, &mut best) {
                break;
            }
        }
        for s in (sc + 1)..(n - 1) {
            if !test(s, &mut best) {
                break;
            }
        }
        found
    }

    /// The closest point of the surface to `p` [m]. `hint`, if given, must
    /// be a point on the surface (e.g. the answer for a neighbouring point):
    /// it only speeds the search up.
    pub fn closest_point(&self, p: [f64; 3], hint: Option<[f64; 3]>) -> SurfacePoint {
        self.closest_point_within(p, hint, f64::INFINITY)
            .expect("the point straight below or above is always closer than infinity")
    }

    /// The closest point of the surface to `p` [m] if it is within
    /// `max_distance` [m], else None; a finite bound prunes the search.
    pub fn closest_point_within(
        &self,
        p: [f64; 3],
        hint: Option<[f64; 3]>,
        max_distance: f64,
    ) -> Option<SurfacePoint> {
        let hf = &self.hf;
        let below = [p[0], p[1], self.surface_height(p[0], p[1])];
        let mut best = (max_distance * max_distance, [f64::NAN; 3]);
        for q in [Some(below), hint].into_iter().flatten() {
            let e = dist2(p, q);
            if e <= best.0 {
                best = (e, q);
            }
        }
        if best.0 > 0.0 {
            self.search_grid(p, &mut best);
        }
        let (xmin, xmax, ymin, ymax) = (hf.x0, hf.x_max(), hf.y0, hf.y_max());
        // Well inside the grid the extension is farther than the best point.
        let margin = (p[0] - xmin)
            .min(xmax - p[0])
            .min(p[1] - ymin)
            .min(ymax - p[1]);
        if margin > 0.0 && margin * margin >= best.0 {
            return (!best.1[0].is_nan()).then(|| SurfacePoint {
                distance: best.0.sqrt(),
                point: best.1,
            });
        }
        // Edge strips: the x = x_min and x = x_max profiles (along y) swept
        // outward along x, then the y = y_min and y = y_max profiles (along x).
        if best.0 > 0.0 {
            for (e, across, at) in [
                (0usize, (p[0] - xmin).max(0.0), p[0].min(xmin)),
                (1, (xmax - p[0]).max(0.0), p[0].max(xmax)),
            ] {
                if let Some((d, u, z)) =
                    Self::search_strip(&self.edges[e], ymin, hf.dy, p[1], p[2], across, best.0)
                {
                    best = (d, [at, u, z]);
                }
            }
            for (e, across, at) in [
                (2usize, (p[1] - ymin).max(0.0), p[1].min(ymin)),
                (3, (ymax - p[1]).max(0.0), p[1].max(ymax)),
            ] {
                if let Some((d, u, z)) =
                    Self::search_strip(&self.edges[e], xmin, hf.dx, p[0], p[2], across, best.0)
                {
                    best = (d, [u, at, z]);
                }
            }
            // Corner quadrants: flat at the corner heights.
            for (cx, cy) in [(false, false), (true, false), (false, true), (true, true)] {
                let x = if cx { p[0].max(xmax) } else { p[0].min(xmin) };
                let y = if cy { p[1].max(ymax) } else { p[1].min(ymin) };
                let z = self.h(
                    if cx { hf.nx - 1 } else { 0 },
                    if cy { hf.ny - 1 } else { 0 },
                );
                let q = [x, y, z];
                let e = dist2(p, q);
                if e < best.0 {
                    best = (e, q);
                }
            }
        }
        (!best.1[0].is_nan()).then(|| SurfacePoint {
            distance: best.0.sqrt(),
            point: best.1,
        })
    }

    /// Signed distance [m] (negative below the surface) and its gradient.
    /// On the surface itself the gradient is the upward unit normal.
    pub fn signed_distance(&self, p: [f64; 3]) -> (f64, [f64; 3]) {
        let sp = self.closest_point(p, None);
        let (h, sx, sy) = self.surface_height_and_slope(p[0], p[1]);
        let sign = if p[2] < h { -1.0 } else { 1.0 };
        if sp.distance > 1e-12 {
            let g = [
                sign * (p[0] - sp.point[0]) / sp.distance,
                sign * (p[1] - sp.point[1]) / sp.distance,
                sign * (p[2] - sp.point[2]) / sp.distance,
            ];
            (sign * sp.distance, g)
        } else {
            let n = (sx * sx + sy * sy + 1.0).sqrt();
            (0.0, [-sx / n, -sy / n, 1.0 / n])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Lcg(u64);
    impl Lcg {
        fn uniform(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn bumpy(nx: usize, ny: usize, rng: &mut Lcg) -> HeightField {
        let h = (0..nx * ny).map(|_| 0.03 * rng.uniform()).collect();
        HeightField::new(-0.05, 0.1, 0.01, 0.013, nx, ny, h, None).unwrap()
    }

    /// The same surface with `pad` extra cells of clamped heights on every
    /// side: its triangles are exactly the edge extension within the pad.
    fn padded_triangles(hf: &HeightField, pad: usize) -> Vec<[[f64; 3]; 3]> {
        let (nx, ny) = (hf.nx + 2 * pad, hf.ny + 2 * pad);
        let x = |i: usize| hf.x0 + (i as f64 - pad as f64) * hf.dx;
        let y = |j: usize| hf.y0 + (j as f64 - pad as f64) * hf.dy;
        let z = |i: usize, j: usize| hf.at(i as isize - pad as isize, j as isize - pad as isize);
        let mut out = Vec::new();
        for i in 0..nx - 1 {
            for j in 0..ny - 1 {
                let a = [x(i), y(j), z(i, j)];
                let b = [x(i + 1), y(j), z(i + 1, j)];
                let c = [x(i + 1), y(j + 1), z(i + 1, j + 1)];
                let d = [x(i), y(j + 1), z(i, j + 1)];
                out.push([a, b, c]);
                out.push([a, c, d]);
            }
        }
        out
    }

    #[test]
    fn closest_point_matches_brute_force_inside_and_beyond_the_grid() {
        let mut rng = Lcg(11);
        let hf = bumpy(9, 7, &mut rng);
        let pad = 40;
        let tris = padded_triangles(&hf, pad);
        let surf = HeightFieldDistance::new(hf.clone());
        for n in 0..400 {
            // Points over the grid and up to ~15 cells beyond each edge.
            let p = [
                -0.2 + 0.38 * rng.uniform(),
                -0.05 + 0.4 * rng.uniform(),
                -0.08 + 0.2 * rng.uniform(),
            ];
            let brute = tris
                .iter()
                .map(|t| dist2(p, closest_point_on_triangle(p, t[0], t[1], t[2])))
                .fold(f64::INFINITY, f64::min)
                .sqrt();
            let got = surf.closest_point(p, None);
            assert!(
                (got.distance - brute).abs() < 1e-12,
                "point {n} {p:?}: {} vs brute force {brute}",
                got.distance
            );
            // The answer is a point on the surface at that distance.
            assert!((dist2(p, got.point).sqrt() - got.distance).abs() < 1e-12);
            let h = surf.surface_height(got.point[0], got.point[1]);
            assert!(
                (h - got.point[2]).abs() < 1e-9,
                "{got:?} is off the surface ({h})"
            );
        }
    }

    #[test]
    fn hints_do_not_change_the_answer() {
        let mut rng = Lcg(5);
        let hf = bumpy(12, 12, &mut rng);
        let surf = HeightFieldDistance::new(hf);
        let mut hint = None;
        for k in 0..30 {
            let p = [0.03, 0.16, -0.02 + 0.003 * f64::from(k)];
            let a = surf.closest_point(p, None);
            let b = surf.closest_point(p, hint);
            assert!((a.distance - b.distance).abs() < 1e-14);
            hint = Some(b.point);
        }
    }

    #[test]
    fn signed_distance_is_negative_below_and_its_gradient_is_a_unit_vector() {
        let mut rng = Lcg(8);
        let surf = HeightFieldDistance::new(bumpy(10, 10, &mut rng));
        for _ in 0..100 {
            let x = -0.05 + 0.09 * rng.uniform();
            let y = 0.1 + 0.117 * rng.uniform();
            let h = surf.surface_height(x, y);
            let dz = 0.05 * (rng.uniform() - 0.5);
            let (d, g) = surf.signed_distance([x, y, h + dz]);
            assert_eq!(d < 0.0, dz < 0.0, "dz {dz} gave {d}");
            assert!(d.abs() <= dz.abs() + 1e-12);
            let norm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            assert!((norm - 1.0).abs() < 1e-9);
        }
        let (d, g) = surf.signed_distance([0.0, 0.15, surf.surface_height(0.0, 0.15)]);
        assert!(d.abs() < 1e-15);
        assert!(g[2] > 0.0);
    }

    #[test]
    fn band_range_holds_every_point_near_the_surface() {
        let mut rng = Lcg(2);
        let surf = HeightFieldDistance::new(bumpy(40, 30, &mut rng));
        let tau = 0.012;
        let mut inside = 0;
        for _ in 0..3000 {
            // Columns over the grid and a little beyond its edges.
            let (x, y) = (-0.08 + 0.47 * rng.uniform(), 0.07 + 0.44 * rng.uniform());
            let z = -0.02 + 0.07 * rng.uniform();
            let (lo, hi) = surf.band_range(x, y, tau);
            if surf.closest_point([x, y, z], None).distance <= tau {
                inside += 1;
                assert!(
                    lo <= z && z <= hi,
                    "({x}, {y}, {z}) within τ but outside [{lo}, {hi}]"
                );
            }
            assert!(
                surf.closest_point_within([x, y, z], None, tau).is_some()
                    == (surf.closest_point([x, y, z], None).distance <= tau)
            );
        }
        assert!(inside > 300, "only {inside} samples near the surface");
    }
}

//! Triangle soups: the closest point on a triangle, and inside/outside of a
//! mesh by vertical-ray parity, for terrain that is not 2.5-D (overhangs,
//! arches, tunnels).

use crate::error::{CoreError, CoreResult};

#[inline]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn axpy(a: [f64; 3], s: f64, b: [f64; 3]) -> [f64; 3] {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

/// Squared distance between two points.
#[inline]
pub fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(d, d)
}

/// The point of triangle (a, b, c) closest to `p` (Ericson, Real-Time
/// Collision Detection, §5.1.5: Voronoi regions of vertices, edges, face).
/// Degenerate triangles are handled: the result always lies on the triangle.
#[inline]
pub fn closest_point_on_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return axpy(a, v, ab);
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return axpy(a, w, ac);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return axpy(b, w, sub(c, b));
    }
    let denom = va + vb + vc;
    if denom.abs() <= f64::MIN_POSITIVE {
        // Collinear corners that passed every region test: fall back to the
        // nearest of the three edges.
        return [(a, b), (b, c), (c, a)]
            .iter()
            .map(|&(s, e)| closest_point_on_segment(p, s, e))
            .min_by(|x, y| dist2(p, *x).total_cmp(&dist2(p, *y)))
            .unwrap_or(a);
    }
    let v = vb / denom;
    let w = vc / denom;
    axpy(axpy(a, v, ab), w, ac)
}

/// The point of segment [a, b] closest to `p`.
#[inline]
pub fn closest_point_on_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    if l2 <= 0.0 {
        return a;
    }
    let t = (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0);
    axpy(a, t, ab)
}

/// A triangle soup with a 2-D bucket grid over x–y for vertical rays.
#[derive(Debug, Clone)]
pub struct TriangleMesh {
    vertices: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
    lo: [f64; 3],
    hi: [f64; 3],
    cell: f64,
    cols: [usize; 2],
    /// CSR lists of faces whose x–y bounding box touches each bucket.
    start: Vec<u32>,
    members: Vec<u32>,
}

impl TriangleMesh {
    /// Checks vertices (finite) and faces (valid indices) and buckets the faces.
    pub fn new(vertices: Vec<[f64; 3]>, faces: Vec<[u32; 3]>) -> CoreResult<Self> {
        if faces.is_empty() {
            return Err(CoreError::Terrain(
                "terrain mesh has no faces; nothing to measure a distance to".into(),
            ));
        }
        if let Some(i) = vertices
            .iter()
            .position(|v| !v.iter().all(|c| c.is_finite()))
        {
            return Err(CoreError::Terrain(format!(
                "terrain mesh vertex {i} is not finite: {:?}",
                vertices[i]
            )));
        }
        if let Some(f) = faces
            .iter()
            .position(|f| f.iter().any(|&v| v as usize >= vertices.len()))
        {
            return Err(CoreError::Terrain(format!(
                "terrain mesh face {f} = {:?} refers to a vertex beyond the {} given",
                faces[f],
                vertices.len()
            )));
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for f in &faces {
            for &v in f {
                for a in 0..3 {
                    lo[a] = lo[a].min(vertices[v as usize][a]);
                    hi[a] = hi[a].max(vertices[v as usize][a]);
                }
            }
        }
        // About two faces per bucket, at most 1024 buckets a side.
        let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(1e-12);
        let cell = (area / faces.len() as f64 * 2.0)
            .sqrt()
            .max((hi[0] - lo[0]).max(hi[1] - lo[1]) / 1024.0)
            .max(1e-9);
        let cols = [
            ((hi[0] - lo[0]) / cell) as usize + 1,
            ((hi[1] - lo[1]) / cell) as usize + 1,
        ];
        let mut mesh = Self {
            vertices,
            faces,
            lo,
            hi,
            cell,
            cols,
            start: Vec::new(),
            members: Vec::new(),
        };
        let mut count = vec![0u32; cols[0] * cols[1] + 1];
        for f in 0..mesh.faces.len() {
            let (i0, i1, j0, j1) = mesh.face_buckets(f);
            for i in i0..=i1 {
                for j in j0..=j1 {
                    count[i * cols[1] + j + 1] += 1;
                }
            }
        }
        for b in 1..count.len() {
            count[b] += count[b - 1];
        }
        let mut fill = count.clone();
        let mut members = vec![0u32; count[count.len() - 1] as usize];
        for f in 0..mesh.faces.len() {
            let (i0, i1, j0, j1) = mesh.face_buckets(f);
            for i in i0..=i1 {
                for j in j0..=j1 {
                    let b = i * cols[1] + j;
                    members[fill[b] as usize] = f as u32;
                    fill[b] += 1;
                }
            }
        }
        mesh.start = count;
        mesh.members = members;
        Ok(mesh)
    }

    fn bucket(&self, x: f64, y: f64) -> (usize, usize) {
        let i = ((x - self.lo[0]) / self.cell).max(0.0) as usize;
        let j = ((y - self.lo[1]) / self.cell).max(0.0) as usize;
        (i.min(self.cols[0] - 1), j.min(self.cols[1] - 1))
    }

    fn face_buckets(&self, f: usize) -> (usize, usize, usize, usize) {
        let [a, b, c] = self.triangle(f);
        let (i0, j0) = self.bucket(a[0].min(b[0]).min(c[0]), a[1].min(b[1]).min(c[1]));
        let (i1, j1) = self.bucket(a[0].max(b[0]).max(c[0]), a[1].max(b[1]).max(c[1]));
        (i0, i1, j0, j1)
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        self.faces.len()
    }

    /// Whether the mesh has no faces (never true for a checked mesh).
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Corners [m] of face `f`.
    #[inline]
    pub fn triangle(&self, f: usize) -> [[f64; 3]; 3] {
        let [a, b, c] = self.faces[f];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// Lower and upper corners [m] of the mesh's bounding box.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        (self.lo, self.hi)
    }

    /// Heights [m] where the vertical line through (x, y) crosses the mesh,
    /// sorted. Edges and vertices follow a half-open rule so that a line
    /// through a shared edge counts one crossing, not two or none.
    pub fn vertical_crossings(&self, x: f64, y: f64, out: &mut Vec<f64>) {
        out.clear();
        if x < self.lo[0] || x > self.hi[0] || y < self.lo[1] || y > self.hi[1] {
            return;
        }
        let (i, j) = self.bucket(x, y);
        let b = i * self.cols[1] + j;
        for &f in &self.members[self.start[b] as usize..self.start[b + 1] as usize] {
            let [a, b, c] = self.triangle(f as usize);
            if let Some(z) = vertical_hit(x, y, a, b, c) {
                out.push(z);
            }
        }
        out.sort_by(f64::total_cmp);
    }
}

/// Height [m] at which the vertical line through (x, y) crosses triangle
/// (a, b, c), if it does. Uses edge functions with a top-left style
/// tie-break, so shared edges belong to exactly one of their two triangles.
#[inline]
fn vertical_hit(x: f64, y: f64, a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Option<f64> {
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area == 0.0 {
        return None;
    }
    let s = area.signum();
    let edge = |p: [f64; 3], q: [f64; 3]| -> Option<f64> {
        let w = s * ((q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]));
        if w > 0.0 {
            return Some(w);
        }
        if w < 0.0 {
            return None;
        }
        // On the edge line: keep it only for "top-left" edges of the
        // counter-clockwise-oriented triangle.
        let (ex, ey) = (s * (q[0] - p[0]), s * (q[1] - p[1]));
        (ey < 0.0 || (ey == 0.0 && ex > 0.0)).then_some(0.0)
    };
    let wa = edge(b, c)?;
    let wb = edge(c, a)?;
    let wc = edge(a, b)?;
    let total = wa + wb + wc;
    if total <= 0.0 {
        return None;
    }
    Some((wa * a[2] + wb * b[2] + wc * c[2]) / total)
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
        fn point(&mut self, scale: f64) -> [f64; 3] {
            [
                (self.uniform() - 0.5) * scale,
                (self.uniform() - 0.5) * scale,
                (self.uniform() - 0.5) * scale,
            ]
        }
    }

    #[test]
    fn closest_point_on_triangle_beats_a_dense_sampler() {
        let mut rng = Lcg(3);
        for _ in 0..200 {
            let (a, b, c) = (rng.point(1.0), rng.point(1.0), rng.point(1.0));
            let p = rng.point(2.0);
            let q = closest_point_on_triangle(p, a, b, c);
            let got = dist2(p, q).sqrt();
            let n = 200;
            let mut best = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=(n - i) {
                    let (u, v) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
                    let s = axpy(axpy(a, u, sub(b, a)), v, sub(c, a));
                    best = best.min(dist2(p, s));
                }
            }
            let best = best.sqrt();
            // The answer lies on the triangle, so it is never better than
            // the true minimum, and the sampler is within its spacing of it.
            assert!(got <= best + 1e-12, "{got} > {best}");
            assert!(best - got < 0.02, "{got} vs sampled {best}");
        }
    }

    #[test]
    fn degenerate_triangles_return_a_point_on_them() {
        let p = [0.3, 0.7, -0.2];
        let (a, b) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let q = closest_point_on_triangle(p, a, b, [2.0, 0.0, 0.0]);
        assert!((q[0] - 0.3).abs() < 1e-12 && q[1].abs() < 1e-12 && q[2].abs() < 1e-12);
        let q = closest_point_on_triangle(p, a, a, a);
        assert!(dist2(q, a) < 1e-30);
    }

    #[test]
    fn a_vertical_line_through_a_shared_edge_crosses_once() {
        // Unit square split along its diagonal, both triangles at z = 1.
        let v = vec![
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        let mesh = TriangleMesh::new(v, vec![[0, 1, 2], [0, 2, 3]]).unwrap();
        let mut out = Vec::new();
        for &(x, y) in &[(0.5, 0.5), (0.25, 0.25), (0.3, 0.6), (0.9, 0.1)] {
            mesh.vertical_crossings(x, y, &mut out);
            assert_eq!(out.len(), 1, "({x}, {y}) gave {out:?}");
            assert!((out[0] - 1.0).abs() < 1e-12);
        }
        mesh.vertical_crossings(1.5, 0.5, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn refuses_bad_meshes() {
        assert!(TriangleMesh::new(vec![[0.0; 3]; 3], vec![]).is_err());
        assert!(TriangleMesh::new(vec![[0.0; 3]; 3], vec![[0, 1, 3]]).is_err());
        assert!(TriangleMesh::new(vec![[f64::NAN, 0.0, 0.0]; 3], vec![[0, 1, 2]]).is_err());
    }
}

//! Support-polygon geometry in the x–y plane: the incircle of a support
//! triangle (Zucker 2011, §4.3 rates footholds by it), the signed margin of a
//! point to the convex hull of the stance feet, and the point that keeps a
//! margin from every edge (where §4.4 nudges the centre of mass).

use crate::kinematics::math::solve;

/// A point or vector in the x–y plane [m].
pub type Vec2 = [f64; 2];

fn sub2(a: Vec2, b: Vec2) -> Vec2 {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross2(a: Vec2, b: Vec2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn len2(a: Vec2) -> f64 {
    a[0].hypot(a[1])
}

/// Incircle of the triangle (a, b, c): its centre [m] and radius [m].
///
/// The centre is the side-length-weighted mean of the vertices, the radius
/// twice the area over the perimeter. Collinear vertices give radius 0;
/// coincident ones the centre `a`.
pub fn support_triangle_incircle(a: Vec2, b: Vec2, c: Vec2) -> (Vec2, f64) {
    let (la, lb, lc) = (len2(sub2(b, c)), len2(sub2(c, a)), len2(sub2(a, b)));
    let perimeter = la + lb + lc;
    if perimeter <= 0.0 || !perimeter.is_finite() {
        return (a, 0.0);
    }
    let centre = [
        (la * a[0] + lb * b[0] + lc * c[0]) / perimeter,
        (la * a[1] + lb * b[1] + lc * c[1]) / perimeter,
    ];
    let area = 0.5 * cross2(sub2(b, a), sub2(c, a)).abs();
    (centre, 2.0 * area / perimeter)
}

/// Convex hull, counter-clockwise, without collinear points (Andrew's monotone chain).
pub fn convex_hull(points: &[Vec2]) -> Vec<Vec2> {
    let mut p: Vec<Vec2> = points.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vec2>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &pt in iter {
            while hull.len() >= start + 2
                && cross2(
                    sub2(hull[hull.len() - 1], hull[hull.len() - 2]),
                    sub2(pt, hull[hull.len() - 2]),
                ) <= 0.0
            {
                hull.pop();
            }
            hull.push(pt);
        }
        hull.pop();
    }
    hull
}

/// Distance from `p` to the segment a–b [m].
fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> (f64, Vec2) {
    let ab = sub2(b, a);
    let l2 = ab[0] * ab[0] + ab[1] * ab[1];
    let t = if l2 > 0.0 {
        ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / l2
    } else {
        0.0
    };
    let t = t.clamp(0.0, 1.0);
    let c = [a[0] + t * ab[0], a[1] + t * ab[1]];
    (len2(sub2(p, c)), c)
}

/// Inward unit normal and offset of each hull edge: n·p − b is the distance inside it.
fn edge_half_planes(hull: &[Vec2]) -> Vec<(Vec2, f64)> {
    (0..hull.len())
        .map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
            let e = sub2(b, a);
            let l = len2(e);
            let n = [-e[1] / l, e[0] / l];
            (n, n[0] * a[0] + n[1] * a[1])
        })
        .collect()
}

/// Closest point of the hull's boundary to `p` and its distance [m].
fn boundary_closest(p: Vec2, hull: &[Vec2]) -> (f64, Vec2) {
    if hull.len() == 1 {
        return (len2(sub2(p, hull[0])), hull[0]);
    }
    (0..hull.len())
        .map(|i| segment_distance(p, hull[i], hull[(i + 1) % hull.len()]))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap_or((f64::INFINITY, p))
}

/// Signed distance [m] from `point` to the boundary of the convex hull of
/// `feet` (x–y): positive inside, negative outside. Fewer than three
/// non-collinear feet span no area, so every point is outside (≤ 0).
/// Empty `feet` give −∞.
pub fn support_polygon_margin(point: Vec2, feet: &[Vec2]) -> f64 {
    let hull = convex_hull(feet);
    if hull.is_empty() {
        return f64::NEG_INFINITY;
    }
    let (dist, _) = boundary_closest(point, &hull);
    let inside = hull.len() >= 3
        && edge_half_planes(&hull)
            .iter()
            .all(|(n, b)| n[0] * point[0] + n[1] * point[1] - b >= 0.0);
    if inside {
        dist
    } else {
        -dist
    }
}

/// The point of the polygon farthest inside it (Chebyshev centre) and its
/// margin [m]. For a triangle this is the incircle.
pub fn chebyshev_centre(hull: &[Vec2]) -> (Vec2, f64) {
    if hull.len() < 3 {
        let n = hull.len().max(1) as f64;
        let c = hull
            .iter()
            .fold([0.0, 0.0], |s, p| [s[0] + p[0] / n, s[1] + p[1] / n]);
        return (c, 0.0);
    }
    let planes = edge_half_planes(hull);
    let mut best = (hull[0], f64::NEG_INFINITY);
    // The optimum of max t s.t. n_j·p − t ≥ b_j is a vertex of the (p, t)
    // polytope: three edges tight. Feet polygons have ≤ 4 edges, so enumerate.
    let m = planes.len();
    for i in 0..m {
        for j in i + 1..m {
            for k in j + 1..m {
                let rows = [i, j, k].map(|e| [planes[e].0[0], planes[e].0[1], -1.0]);
                let Some(sol) = solve(&rows, [planes[i].1, planes[j].1, planes[k].1]) else {
                    continue;
                };
                let (c, t) = ([sol[0], sol[1]], sol[2]);
                let feasible = planes
                    .iter()
                    .all(|(n, b)| n[0] * c[0] + n[1] * c[1] - b >= t - 1e-12);
                if feasible && t > best.1 {
                    best = (c, t);
                }
            }
        }
    }
    best
}

/// The point at least `margin` [m] inside every edge of the convex hull of
/// `feet` that is closest to `point`; when no point keeps that margin, the
/// Chebyshev centre (the incircle centre for three feet).
pub fn closest_point_with_margin(point: Vec2, feet: &[Vec2], margin: f64) -> Vec2 {
    let hull = convex_hull(feet);
    if hull.len() < 3 {
        return chebyshev_centre(&hull).0;
    }
    let planes = edge_half_planes(&hull);
    if planes
        .iter()
        .all(|(n, b)| n[0] * point[0] + n[1] * point[1] - b >= margin)
    {
        return point;
    }
    // Shrink the polygon by clipping it with each edge moved inward by the margin.
    let mut poly = hull.clone();
    for (n, b) in &planes {
        let side = |p: Vec2| n[0] * p[0] + n[1] * p[1] - b - margin;
        let mut next = Vec::with_capacity(poly.len() + 1);
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                next.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                let t = sp / (sp - sq);
                next.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
        poly = next;
        if poly.is_empty() {
            return chebyshev_centre(&hull).0;
        }
    }
    boundary_closest(point, &poly).1
}

#[cfg(test)]
// Exact float equality is what these tests mean where they use it.
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn incircle_of_the_3_4_5_triangle_has_radius_one() {
        let (c, r) = support_triangle_incircle([0.0, 0.0], [3.0, 0.0], [0.0, 4.0]);
        assert!(
            (r - 1.0).abs() < 1e-15 && (c[0] - 1.0).abs() < 1e-15 && (c[1] - 1.0).abs() < 1e-15
        );
        // Equilateral with side s: r = s/(2√3), centre at the centroid.
        let s = 0.3;
        let (c, r) =
            support_triangle_incircle([0.0, 0.0], [s, 0.0], [s / 2.0, s * 3f64.sqrt() / 2.0]);
        assert!((r - s / (2.0 * 3f64.sqrt())).abs() < 1e-15);
        assert!((c[1] - s / (2.0 * 3f64.sqrt())).abs() < 1e-15);
        assert_eq!(
            support_triangle_incircle([1.0, 1.0], [2.0, 2.0], [3.0, 3.0]).1,
            0.0
        );
        assert_eq!(
            support_triangle_incircle([1.0, 1.0], [1.0, 1.0], [1.0, 1.0]),
            ([1.0, 1.0], 0.0)
        );
    }

    #[test]
    fn margin_is_a_signed_distance() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]];
        assert!((support_polygon_margin([0.5, 0.5], &square) - 0.5).abs() < 1e-15);
        assert!((support_polygon_margin([0.2, 0.7], &square) - 0.2).abs() < 1e-15);
        assert!((support_polygon_margin([2.0, 0.5], &square) + 1.0).abs() < 1e-15);
        assert!((support_polygon_margin([2.0, 2.0], &square) + 2f64.sqrt()).abs() < 1e-15);
        assert!(
            (support_polygon_margin([0.5, 1.0], &[[0.0, 0.0], [1.0, 0.0]]) + 1.0).abs() < 1e-15
        );
        // The triangle's incircle centre is where the margin peaks, at the inradius.
        let tri = [[0.0, 0.0], [3.0, 0.0], [0.0, 4.0]];
        assert!((support_polygon_margin([1.0, 1.0], &tri) - 1.0).abs() < 1e-15);
        let (c, r) = chebyshev_centre(&convex_hull(&tri));
        assert!(
            (r - 1.0).abs() < 1e-12 && (c[0] - 1.0).abs() < 1e-12 && (c[1] - 1.0).abs() < 1e-12
        );
    }

    #[test]
    fn closest_point_with_margin_keeps_the_margin() {
        let tri = [[0.0, 0.0], [3.0, 0.0], [0.0, 4.0]];
        let p = closest_point_with_margin([5.0, -1.0], &tri, 0.25);
        assert!(
            (support_polygon_margin(p, &tri) - 0.25).abs() < 1e-12,
            "{p:?}"
        );
        assert_eq!(closest_point_with_margin([1.0, 1.0], &tri, 0.5), [1.0, 1.0]);
        // Margin wider than the inradius: the incircle centre.
        let p = closest_point_with_margin([5.0, -1.0], &tri, 2.0);
        assert!((p[0] - 1.0).abs() < 1e-12 && (p[1] - 1.0).abs() < 1e-12);
        // Brute force: no grid point with the margin is closer.
        let target = [-0.7, 1.9];
        let p = closest_point_with_margin(target, &tri, 0.3);
        let d = len2(sub2(p, target));
        for i in 0..200 {
            for j in 0..200 {
                let g = [f64::from(i) * 0.02 - 0.5, f64::from(j) * 0.025 - 0.5];
                if support_polygon_margin(g, &tri) >= 0.3 {
                    assert!(len2(sub2(g, target)) >= d - 1e-12);
                }
            }
        }
    }
}

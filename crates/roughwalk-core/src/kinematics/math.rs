//! Small fixed-size 3-vector, 3×3-matrix and quaternion helpers.
//!
//! The kinematics only ever needs 3-vectors, 3×3 rotations and 3×3 linear
//! solves, so plain arrays and a page of functions keep the core free of a
//! linear-algebra dependency (and its compile time) while staying
//! allocation-free. Matrices are row-major: `m[r][c]`. Quaternions are
//! (w, x, y, z) as MuJoCo orders them.

/// A 3-vector.
pub type Vec3 = [f64; 3];
/// A row-major 3×3 matrix.
pub type Mat3 = [[f64; 3]; 3];
/// A quaternion (w, x, y, z).
pub type Quat = [f64; 4];

/// The 3×3 identity.
pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// a + b.
#[inline]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a − b.
#[inline]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// s·a.
#[inline]
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// a·b.
#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// a × b.
#[inline]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean norm, without overflow or underflow for extreme components.
#[inline]
pub fn norm(a: Vec3) -> f64 {
    let m = a[0].abs().max(a[1].abs()).max(a[2].abs());
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    if (1e-150..1e150).contains(&m) {
        return dot(a, a).sqrt();
    }
    let s = scale(a, 1.0 / m);
    m * dot(s, s).sqrt()
}

/// Whether all three components are finite.
#[inline]
pub fn is_finite(a: Vec3) -> bool {
    a.iter().all(|v| v.is_finite())
}

/// m·v.
#[inline]
pub fn mat_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// mᵀ·v.
#[inline]
pub fn mat_t_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

/// a·b.
#[inline]
pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
        }
    }
    out
}

/// mᵀ.
#[inline]
pub fn transpose(m: &Mat3) -> Mat3 {
    [
        [m[0][0], m[1][0], m[2][0]],
        [m[0][1], m[1][1], m[2][1]],
        [m[0][2], m[1][2], m[2][2]],
    ]
}

/// a + b for matrices.
#[inline]
pub fn mat_add(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = *a;
    for (r, row) in out.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v += b[r][c];
        }
    }
    out
}

/// a − b for matrices.
#[inline]
pub fn mat_sub(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = *a;
    for (r, row) in out.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v -= b[r][c];
        }
    }
    out
}

/// The matrix whose columns are `c0, c1, c2`.
#[inline]
pub fn from_columns(c0: Vec3, c1: Vec3, c2: Vec3) -> Mat3 {
    [
        [c0[0], c1[0], c2[0]],
        [c0[1], c1[1], c2[1]],
        [c0[2], c1[2], c2[2]],
    ]
}

/// Column `c` of `m`.
#[inline]
pub fn column(m: &Mat3, c: usize) -> Vec3 {
    [m[0][c], m[1][c], m[2][c]]
}

/// [u]×, the matrix with [u]× v = u × v.
#[inline]
pub fn skew(u: Vec3) -> Mat3 {
    [[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]]
}

/// det(m).
#[inline]
pub fn det(m: &Mat3) -> f64 {
    dot(m[0], cross(m[1], m[2]))
}

/// Solves m·x = b by Cramer's rule; `None` when m is singular relative to its scale.
pub fn solve(m: &Mat3, b: Vec3) -> Option<Vec3> {
    let d = det(m);
    let scale3 = norm(m[0]) * norm(m[1]) * norm(m[2]);
    if !d.is_finite() || d.abs() <= 1e-14 * scale3 || scale3 == 0.0 {
        return None;
    }
    let c0 = column(m, 0);
    let c1 = column(m, 1);
    let c2 = column(m, 2);
    Some([
        det(&from_columns(b, c1, c2)) / d,
        det(&from_columns(c0, b, c2)) / d,
        det(&from_columns(c0, c1, b)) / d,
    ])
}

/// m⁻¹, `None` when m is singular relative to its scale.
pub fn inverse(m: &Mat3) -> Option<Mat3> {
    let c0 = solve(m, [1.0, 0.0, 0.0])?;
    let c1 = solve(m, [0.0, 1.0, 0.0])?;
    let c2 = solve(m, [0.0, 0.0, 1.0])?;
    Some(from_columns(c0, c1, c2))
}

/// Unit quaternion `q / |q|`; `None` for a zero or non-finite quaternion.
pub fn quat_normalize(q: Quat) -> Option<Quat> {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if !n.is_finite() || n < 1e-12 {
        return None;
    }
    Some([q[0] / n, q[1] / n, q[2] / n, q[3] / n])
}

/// Rotation matrix of a unit quaternion (w, x, y, z).
pub fn quat_to_mat(q: Quat) -> Mat3 {
    let [w, x, y, z] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// Unit quaternion (w ≥ 0) of a rotation matrix (Shepperd's method).
pub fn mat_to_quat(m: &Mat3) -> Quat {
    let tr = m[0][0] + m[1][1] + m[2][2];
    let q = if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        [
            0.25 * s,
            (m[2][1] - m[1][2]) / s,
            (m[0][2] - m[2][0]) / s,
            (m[1][0] - m[0][1]) / s,
        ]
    } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
        let s = (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt() * 2.0;
        [
            (m[2][1] - m[1][2]) / s,
            0.25 * s,
            (m[0][1] + m[1][0]) / s,
            (m[0][2] + m[2][0]) / s,
        ]
    } else if m[1][1] > m[2][2] {
        let s = (1.0 + m[1][1] - m[0][0] - m[2][2]).sqrt() * 2.0;
        [
            (m[0][2] - m[2][0]) / s,
            (m[0][1] + m[1][0]) / s,
            0.25 * s,
            (m[1][2] + m[2][1]) / s,
        ]
    } else {
        let s = (1.0 + m[2][2] - m[0][0] - m[1][1]).sqrt() * 2.0;
        [
            (m[1][0] - m[0][1]) / s,
            (m[0][2] + m[2][0]) / s,
            (m[1][2] + m[2][1]) / s,
            0.25 * s,
        ]
    };
    let q = quat_normalize(q).unwrap_or([1.0, 0.0, 0.0, 0.0]);
    if q[0] < 0.0 {
        [-q[0], -q[1], -q[2], -q[3]]
    } else {
        q
    }
}

/// Rotation by `angle` [rad] about the unit `axis` (Rodrigues).
pub fn axis_angle(axis: Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let [x, y, z] = axis;
    [
        [c + t * x * x, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, c + t * y * y, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, c + t * z * z],
    ]
}

/// exp([ω]×): rotation by |ω| [rad] about ω/|ω|.
pub fn exp_so3(omega: Vec3) -> Mat3 {
    let angle = norm(omega);
    if angle < 1e-300 {
        return IDENTITY;
    }
    axis_angle(scale(omega, 1.0 / angle), angle)
}

/// Angle wrapped to (−π, π].
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    let two_pi = std::f64::consts::TAU;
    let w = a - two_pi * ((a + std::f64::consts::PI) / two_pi).floor();
    // floor puts exactly −π at −π; keep the half-open interval (−π, π].
    if w <= -std::f64::consts::PI {
        w + two_pi
    } else {
        w
    }
}

#[cfg(test)]
// Exact float equality is what these tests mean where they use it.
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    fn close(a: &Mat3, b: &Mat3, tol: f64) -> bool {
        (0..3).all(|r| (0..3).all(|c| (a[r][c] - b[r][c]).abs() <= tol))
    }

    #[test]
    fn quaternion_round_trip_and_axis_angle_agree() {
        let axis = {
            let a = [0.3, -0.5, 0.8];
            scale(a, 1.0 / norm(a))
        };
        let angle = 2.1;
        let m = axis_angle(axis, angle);
        let (s, c) = (angle / 2.0_f64).sin_cos();
        let q = [c, s * axis[0], s * axis[1], s * axis[2]];
        assert!(close(&quat_to_mat(q), &m, 1e-14));
        assert!(close(&quat_to_mat(mat_to_quat(&m)), &m, 1e-14));
        assert!(close(&mat_mul(&m, &transpose(&m)), &IDENTITY, 1e-14));
        assert!((det(&m) - 1.0).abs() < 1e-14);
    }

    #[test]
    fn solve_and_inverse_invert() {
        let m = [[2.0, 1.0, 0.5], [-1.0, 3.0, 0.2], [0.1, 0.4, 1.5]];
        let inv = inverse(&m).unwrap();
        assert!(close(&mat_mul(&m, &inv), &IDENTITY, 1e-14));
        assert!(solve(
            &[[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]],
            [1.0, 0.0, 0.0]
        )
        .is_none());
    }

    #[test]
    fn skew_is_cross_product_and_norm_survives_extremes() {
        let u = [0.2, -1.3, 0.7];
        let v = [1.1, 0.4, -0.6];
        let a = mat_vec(&skew(u), v);
        let b = cross(u, v);
        assert!((0..3).all(|i| (a[i] - b[i]).abs() < 1e-15));
        assert_eq!(norm([3e300, 4e300, 0.0]), 5e300);
        assert!((norm([3e-300, 4e-300, 0.0]) - 5e-300).abs() < 1e-314);
    }

    #[test]
    fn wrap_angle_lands_in_half_open_interval() {
        use std::f64::consts::PI;
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.5 - 4.0 * PI) - 0.5).abs() < 1e-12);
    }
}

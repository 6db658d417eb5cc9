//! Roll–pitch–yaw (ZYX) trunk coordinates: R = R_z(ψ)·R_y(θ)·R_x(φ).

use crate::kinematics::math::Mat3;

/// R of roll–pitch–yaw (φ, θ, ψ) [rad].
pub fn rpy_to_matrix(rpy: [f64; 3]) -> Mat3 {
    let (sr, cr) = rpy[0].sin_cos();
    let (sp, cp) = rpy[1].sin_cos();
    let (sy, cy) = rpy[2].sin_cos();
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// E with ω_world = E·d(rpy)/dt: columns R_z·R_y·e_x, R_z·e_y, e_z.
pub fn rpy_rate_matrix(rpy: [f64; 3]) -> Mat3 {
    let (sp, cp) = rpy[1].sin_cos();
    let (sy, cy) = rpy[2].sin_cos();
    [[cy * cp, -sy, 0.0], [sy * cp, cy, 0.0], [-sp, 0.0, 1.0]]
}

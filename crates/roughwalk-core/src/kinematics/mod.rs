//! Leg kinematics and body-pose routines (Zucker 2011, §3.1–3.4).
//!
//! [`LegChain`] is one three-hinge leg (FK, Jacobians, analytic IK);
//! [`Quadruped`] is four of them on a trunk; [`body_pose`] holds the
//! gradient steps that move the trunk while the feet stay put; [`support`]
//! the support-polygon geometry.

pub mod body_pose;
pub mod leg;
pub mod math;
pub mod quadruped;
pub mod support;

pub use body_pose::{
    com_support_step, obstacle_avoidance_step, point_pose_jacobians, point_pose_jacobians_at,
    reachability_step, BodyPoseStep, CollisionPoint, PointPoseJacobians,
};
pub use leg::{IkResult, LegChain, LegParams, LinkFrames, IK_TOLERANCE};
pub use quadruped::{leg_q, BodyPose, Configuration, Quadruped, LEG_NAMES};
pub use support::{support_polygon_margin, support_triangle_incircle};

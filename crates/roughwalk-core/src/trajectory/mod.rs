//! One CHOMP pass evaluated over a whole footstep trajectory (Zucker 2011, §5.1, §5.3).
//!
//! CHOMP's update needs, per iteration, every term but smoothness at every
//! sample: the body points of the collision capsules in the world, their
//! clearances from the terrain's signed distance field, the arc-length
//! weighted obstacle cost and its gradient projected orthogonal to each
//! point's path, pulled back to the optimised coordinates through the
//! kinematics; plus reachability and ZMP support (the trunk pass) or joint
//! speed (the swing pass). [`BodyPass`] and [`SwingPass`] do that in one call
//! per evaluation; the covariant update itself stays with the caller.

pub mod body_pass;
pub mod body_points;
pub mod capsule_clearance;
pub mod center_of_mass;
pub mod obstacle;
pub mod reach_adjust;
pub mod rpy;
pub mod swing_pass;
pub mod zmp_support;

pub use body_pass::{BodyPass, BodyPassEvaluation};
pub use body_points::BodyPoints;
pub use capsule_clearance::{capsule_clearances, LinkCapsules};
pub use center_of_mass::{center_of_mass_batch, MassDistribution};
pub use obstacle::{obstacle_potential, DistanceQuery, GradientMode, ObstacleTerm};
pub use reach_adjust::reach_by_height_and_tilt;
pub use swing_pass::{SwingPass, SwingPassEvaluation};
pub use zmp_support::{polygon_margin, ZmpSupport};

//! Signed distance fields of terrain (Zucker 2011, §3.3).
//!
//! A uniform voxel lattice over the terrain stores the signed distance [m]
//! to its surface (negative inside); queries interpolate it trilinearly and
//! return the interpolant's gradient. Building it ([`Band`]) computes exact
//! distances near the surface and fills the rest from a linear-time feature
//! transform ([`edt`]); queries outside the lattice fall back to the exact
//! height-field distance ([`HeightFieldDistance`]).

pub mod build;
pub mod edt;
pub mod grid;
pub mod heightfield_distance;
pub mod mesh;
pub mod query;

pub use build::Band;
pub use grid::{DistanceGrid, GridSpec};
pub use heightfield_distance::{HeightFieldDistance, SurfacePoint};
pub use mesh::TriangleMesh;
pub use query::SignedDistanceField;

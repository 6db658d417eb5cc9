//! roughwalk-core: the pure-Rust hot loops of roughwalk.
//!
//! Knows no Python. Every public function takes plain slices and returns
//! plain vectors or [`CoreError`], so that it is tested with `cargo test`
//! and bound to Python by the thin `roughwalk-py` crate.

pub mod dubins;
pub mod error;
pub mod footstep;
pub mod heightfield;
pub mod kinematics;
pub mod sdf;
pub mod search;
#[doc(hidden)]
pub mod testing;
pub mod trajectory;

pub use error::{CoreError, CoreResult};
pub use heightfield::{HeightField, Interpolation};

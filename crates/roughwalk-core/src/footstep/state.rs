//! A footstep state and the foothold lattice it lives on (Zucker 2011, §4.1:
//! "a state is the 2D (x, y) location for each foot").

use std::hash::{Hash, Hasher};

use crate::error::{CoreError, CoreResult};

/// A lattice cell (i, j): the foothold at (x0 + i·h, y0 + j·h).
///
/// i16 rather than i32: states are stored three times (the search's table
/// and index, and the certificate cache), and 32,767 cells per axis is
/// 160 m at LittleDog's 5 mm.
pub type Cell = [i16; 2];

/// Where the four feet stand, in canonical leg order (LF, RF, LH, RH), and
/// which step of the fixed walking order comes next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FootstepState {
    /// Foothold cell of each leg, canonical order.
    pub feet: [Cell; 4],
    /// Index into the walking order of the leg that moves next (0..4).
    pub next: u8,
}

impl FootstepState {
    /// Two legs' cell indices packed into one word (16 bits each).
    #[inline]
    fn packed(cells: &[Cell]) -> u64 {
        cells
            .iter()
            .flatten()
            .fold(0u64, |w, &i| (w << 16) | u64::from(i as u16))
    }
}

impl Hash for FootstepState {
    /// Three words, not the derived 22 (a length and four bytes per cell):
    /// states are hashed once per successor in the search's table and the
    /// certificate cache.
    #[inline]
    fn hash<H: Hasher>(&self, state: &mut H) {
        state.write_u64(Self::packed(&self.feet[..2]));
        state.write_u64(Self::packed(&self.feet[2..]));
        state.write_u8(self.next);
    }
}

impl FootstepState {
    /// The canonical index of the leg that moves next.
    #[inline]
    pub fn moving_leg(&self, walking_order: &[usize; 4]) -> usize {
        walking_order[self.next as usize]
    }

    /// The three legs that stay down while the next leg swings.
    #[inline]
    pub fn stance_legs(&self, walking_order: &[usize; 4]) -> [usize; 3] {
        let moving = self.moving_leg(walking_order);
        let mut out = [0; 3];
        let mut k = 0;
        for leg in 0..4 {
            if leg != moving {
                out[k] = leg;
                k += 1;
            }
        }
        out
    }
}

/// The regular foothold lattice over the terrain's x–y extent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    /// x of cell (0, ·) [m].
    pub x0: f64,
    /// y of cell (·, 0) [m].
    pub y0: f64,
    /// Cell spacing [m].
    pub resolution: f64,
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
}

impl Lattice {
    /// The lattice of spacing `resolution` [m] whose cells cover
    /// [x0, x_max] × [y0, y_max] [m].
    pub fn covering(x0: f64, y0: f64, x_max: f64, y_max: f64, resolution: f64) -> CoreResult<Self> {
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(CoreError::Planning(format!(
                "lattice resolution must be finite and > 0, got {resolution}"
            )));
        }
        let count = |span: f64| ((span / resolution) + 1e-9).floor() as usize + 1;
        let (nx, ny) = (count(x_max - x0), count(y_max - y0));
        let limit = i16::MAX as usize;
        if nx > limit || ny > limit {
            return Err(CoreError::Planning(format!(
                "a {nx}×{ny} foothold lattice exceeds {limit} cells per axis; \
                 use a coarser resolution than {resolution} m"
            )));
        }
        Ok(Self {
            x0,
            y0,
            resolution,
            nx,
            ny,
        })
    }

    /// The (x, y) of a cell [m].
    #[inline]
    pub fn xy(&self, c: Cell) -> [f64; 2] {
        [
            self.x0 + f64::from(c[0]) * self.resolution,
            self.y0 + f64::from(c[1]) * self.resolution,
        ]
    }

    /// The nearest cell to (x, y) [m], or `None` outside the lattice.
    #[inline]
    pub fn cell_of(&self, xy: [f64; 2]) -> Option<Cell> {
        let i = ((xy[0] - self.x0) / self.resolution).round();
        let j = ((xy[1] - self.y0) / self.resolution).round();
        if i >= 0.0 && j >= 0.0 && i < self.nx as f64 && j < self.ny as f64 {
            Some([i as i16, j as i16])
        } else {
            None
        }
    }

    /// Flat x-major index of a cell, or `None` outside.
    #[inline]
    pub fn index(&self, c: Cell) -> Option<usize> {
        let (i, j) = (c[0], c[1]);
        if i >= 0 && j >= 0 && (i as usize) < self.nx && (j as usize) < self.ny {
            Some(i as usize * self.ny + j as usize)
        } else {
            None
        }
    }

    /// Whether (x, y) [m] lies within the lattice's extent.
    pub fn contains(&self, xy: [f64; 2]) -> bool {
        let x_max = self.x0 + (self.nx - 1) as f64 * self.resolution;
        let y_max = self.y0 + (self.ny - 1) as f64 * self.resolution;
        xy[0] >= self.x0 && xy[0] <= x_max && xy[1] >= self.y0 && xy[1] <= y_max
    }

    /// Centroid of a state's feet (x, y) [m].
    #[inline]
    pub fn centroid(&self, s: &FootstepState) -> [f64; 2] {
        let mut c = [0.0; 2];
        for f in &s.feet {
            let p = self.xy(*f);
            c[0] += 0.25 * p[0];
            c[1] += 0.25 * p[1];
        }
        c
    }

    /// Heading of a state [rad]: the direction from the hind feet's midpoint
    /// to the front feet's midpoint.
    #[inline]
    pub fn heading(&self, s: &FootstepState) -> f64 {
        let [lf, rf, lh, rh] = s.feet.map(|f| self.xy(f));
        let dx = lf[0] + rf[0] - lh[0] - rh[0];
        let dy = lf[1] + rf[1] - lh[1] - rh[1];
        dy.atan2(dx)
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn footstep_lattice_round_trips_cells_and_refuses_outside() {
        let l = Lattice::covering(-0.4, 0.0, 1.0, 0.6, 0.005).unwrap();
        assert_eq!((l.nx, l.ny), (281, 121));
        let c = l.cell_of([0.2031, 0.3]).unwrap();
        assert_eq!(c, [121, 60]);
        assert!((l.xy(c)[0] - 0.205).abs() < 1e-12);
        assert!(l.cell_of([-0.41, 0.3]).is_none());
        assert!(l.cell_of([1.003, 0.3]).is_none());
        assert_eq!(l.index([280, 120]), Some(280 * 121 + 120));
        assert_eq!(l.index([281, 0]), None);
        assert!(Lattice::covering(0.0, 0.0, 400.0, 1.0, 0.005).is_err());
    }

    #[test]
    fn footstep_state_heading_centroid_and_stance() {
        let l = Lattice::covering(0.0, 0.0, 1.0, 1.0, 0.01).unwrap();
        // A 0.2 × 0.1 stance facing +y.
        let s = FootstepState {
            feet: [[40, 60], [50, 60], [40, 40], [50, 40]],
            next: 1,
        };
        assert!((l.heading(&s) - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        let c = l.centroid(&s);
        assert!((c[0] - 0.45).abs() < 1e-12 && (c[1] - 0.5).abs() < 1e-12);
        let order = [2, 0, 3, 1];
        assert_eq!(s.moving_leg(&order), 0);
        assert_eq!(s.stance_legs(&order), [1, 2, 3]);
    }
}

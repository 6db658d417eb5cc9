//! The terrain as the footstep search sees it: per lattice cell, whether it
//! can be a foothold, its terrain cost for a front and a hind foot
//! (Zucker 2011, §4.2: c = exp(−w·f), learned separately for front and
//! hind feet), and the contact point and surface normal.
//!
//! Built once per terrain and lattice (§4.5: precomputation), so that the
//! search only indexes arrays.

use crate::error::{CoreError, CoreResult};
use crate::footstep::state::{Cell, Lattice};
use crate::heightfield::{HeightField, Interpolation};

/// Front (LF, RF) or hind (LH, RH) foot.
#[inline]
pub fn is_front(leg: usize) -> bool {
    leg < 2
}

/// Foothold data on the lattice, x-major.
#[derive(Debug, Clone)]
pub struct CostMap {
    lattice: Lattice,
    /// Terrain cost [front, hind] per cell; +∞ where the cell is no foothold.
    cost: Vec<[f64; 2]>,
    /// Contact height [m].
    z: Vec<f64>,
    /// Unit upward surface normal at the contact point.
    normal: Vec<[f64; 3]>,
    min_cost: f64,
}

impl CostMap {
    /// Samples `heightfield` and the terrain-grid cost maps `cost_front` and
    /// `cost_hind` (x-major, the height field's grid; +∞ or NaN where a foot
    /// may not go) on the lattice of spacing `resolution` [m] covering the
    /// height field.
    ///
    /// A cell is a foothold when the height field's cell under it is known
    /// and the nearest grid point's cost is finite and > 0. Heights are
    /// bilinear, as `Terrain.height`; normals are the mean slope's over the
    /// disc of `normal_radius` [m] ([`HeightField::disc_normal`]), or with
    /// 0 the bilinear normal at the point, as `Terrain.normal`.
    pub fn new(
        heightfield: &HeightField,
        cost_front: &[f64],
        cost_hind: &[f64],
        resolution: f64,
        normal_radius: f64,
    ) -> CoreResult<Self> {
        let n = heightfield.nx * heightfield.ny;
        for (name, grid) in [("front", cost_front), ("hind", cost_hind)] {
            if grid.len() != n {
                return Err(CoreError::Planning(format!(
                    "the {name} cost map has {} values; the terrain grid needs {n} ({}×{})",
                    grid.len(),
                    heightfield.nx,
                    heightfield.ny
                )));
            }
            if let Some(v) = grid.iter().find(|v| **v <= 0.0) {
                return Err(CoreError::Planning(format!(
                    "the {name} cost map holds {v}; terrain costs must be > 0 (+inf or NaN for no foothold)"
                )));
            }
        }
        let lattice = Lattice::covering(
            heightfield.x0,
            heightfield.y0,
            heightfield.x_max(),
            heightfield.y_max(),
            resolution,
        )?;
        let cells = lattice.nx * lattice.ny;
        let (mut cost, mut z, mut normal) = (
            Vec::with_capacity(cells),
            Vec::with_capacity(cells),
            Vec::with_capacity(cells),
        );
        let mut min_cost = f64::INFINITY;
        for i in 0..lattice.nx {
            for j in 0..lattice.ny {
                let [x, y] = lattice.xy([i as i16, j as i16]);
                let gi = (((x - heightfield.x0) / heightfield.dx).round() as usize)
                    .min(heightfield.nx - 1);
                let gj = (((y - heightfield.y0) / heightfield.dy).round() as usize)
                    .min(heightfield.ny - 1);
                let known = heightfield.is_known(x, y);
                let pick = |grid: &[f64]| {
                    let v = grid[gi * heightfield.ny + gj];
                    if known && v.is_finite() {
                        v
                    } else {
                        f64::INFINITY
                    }
                };
                let c = [pick(cost_front), pick(cost_hind)];
                min_cost = min_cost.min(c[0]).min(c[1]);
                cost.push(c);
                z.push(heightfield.height(x, y, Interpolation::Bilinear));
                normal.push(heightfield.disc_normal(x, y, normal_radius));
            }
        }
        Ok(Self {
            lattice,
            cost,
            z,
            normal,
            min_cost,
        })
    }

    /// The lattice.
    #[inline]
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    /// Terrain cost of `cell` for `leg` (+∞ off the lattice or where no foothold).
    #[inline]
    pub fn cost(&self, cell: Cell, leg: usize) -> f64 {
        match self.lattice.index(cell) {
            Some(k) => self.cost[k][usize::from(!is_front(leg))],
            None => f64::INFINITY,
        }
    }

    /// Whether `cell` can be a foothold for some foot.
    #[inline]
    pub fn is_foothold(&self, cell: Cell) -> bool {
        self.lattice
            .index(cell)
            .is_some_and(|k| self.cost[k][0].is_finite() || self.cost[k][1].is_finite())
    }

    /// The contact point (x, y, z) of `cell` [m] (must be on the lattice).
    #[inline]
    pub fn contact(&self, cell: Cell) -> [f64; 3] {
        let k = self.lattice.index(cell).expect("cell on the lattice");
        let [x, y] = self.lattice.xy(cell);
        [x, y, self.z[k]]
    }

    /// The foot-sphere centre of a foot of radius `radius` [m] on `cell`:
    /// the contact point plus `radius` along the surface normal [m].
    #[inline]
    pub fn foot_centre(&self, cell: Cell, radius: f64) -> [f64; 3] {
        let k = self.lattice.index(cell).expect("cell on the lattice");
        let [x, y] = self.lattice.xy(cell);
        let n = self.normal[k];
        [
            x + radius * n[0],
            y + radius * n[1],
            self.z[k] + radius * n[2],
        ]
    }

    /// Least finite terrain cost over the lattice (+∞ if there is none).
    pub fn min_cost(&self) -> f64 {
        self.min_cost
    }

    /// Number of foothold cells.
    pub fn foothold_count(&self) -> usize {
        self.cost
            .iter()
            .filter(|c| c[0].is_finite() || c[1].is_finite())
            .count()
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // costs are copied, not computed
mod tests {
    use super::*;

    #[test]
    fn footstep_cost_map_samples_costs_heights_and_unknown_cells() {
        // A 0.2 m × 0.1 m ramp z = 0.1·x on a 1 cm grid, with one unknown corner.
        let (nx, ny) = (21, 11);
        let heights: Vec<f64> = (0..nx * ny).map(|k| 0.1 * 0.01 * (k / ny) as f64).collect();
        let mut known = vec![true; nx * ny];
        known[0] = false;
        let hf = HeightField::new(0.0, 0.0, 0.01, 0.01, nx, ny, heights, Some(known)).unwrap();
        let mut front = vec![1.0; nx * ny];
        front[10 * ny + 5] = 3.0;
        let mut hind = vec![2.0; nx * ny];
        hind[20 * ny + 10] = f64::INFINITY;
        let map = CostMap::new(&hf, &front, &hind, 0.005, 0.0).unwrap();
        assert_eq!((map.lattice().nx, map.lattice().ny), (41, 21));
        assert_eq!(map.cost([20, 10], 0), 3.0);
        assert_eq!(map.cost([20, 10], 2), 2.0);
        assert_eq!(map.cost([40, 20], 3), f64::INFINITY);
        assert_eq!(map.cost([40, 20], 1), 1.0);
        // The unknown corner poisons the grid cell under (0, 0).
        assert!(!map.is_foothold([0, 0]) && !map.is_foothold([1, 1]));
        assert!(map.is_foothold([2, 2]));
        assert_eq!(map.cost([-1, 0], 0), f64::INFINITY);
        assert_eq!(map.min_cost(), 1.0);
        let c = map.contact([30, 4]);
        assert!((c[2] - 0.1 * 0.15).abs() < 1e-12, "{c:?}");
        // The foot centre sits along the ramp's normal.
        let f = map.foot_centre([30, 4], 0.01);
        let n = 1.0 / (1.0f64 + 0.01).sqrt();
        assert!((f[0] - (0.15 - 0.01 * 0.1 * n)).abs() < 1e-12);
        assert!((f[2] - (c[2] + 0.01 * n)).abs() < 1e-12);
        assert!(CostMap::new(&hf, &front[1..], &hind, 0.005, 0.0).is_err());
        let mut zero = front.clone();
        zero[3] = 0.0;
        assert!(CostMap::new(&hf, &zero, &hind, 0.005, 0.0).is_err());
    }
}

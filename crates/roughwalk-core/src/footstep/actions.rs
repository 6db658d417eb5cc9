//! Footstep actions: where the moving leg is aimed, and the local search for
//! a cheaper foothold around that target (Zucker 2011, §4.1 and footnote 1,
//! after Chestnutt 2007).
//!
//! An action (dx, dy, dθ) places the moving leg L at
//! target = c + R(θ + dθ)·n_L + R(θ)·(dx, dy),
//! with c the centroid of the four feet, θ the stance's heading and n_L the
//! leg's nominal offset from the centroid of the nominal stance: forward
//! and sideways steps, and turns about the centroid.

use crate::footstep::cost_map::CostMap;
use crate::footstep::state::Cell;

/// Where action `action` aims leg `leg` (x, y) [m] from a stance with
/// centroid `centroid` [m] and heading `heading` [rad], given the leg's
/// nominal offset `nominal` (x, y) [m] in the base frame.
#[inline]
pub fn action_target(
    centroid: [f64; 2],
    heading: f64,
    nominal: [f64; 2],
    action: [f64; 3],
) -> [f64; 2] {
    let (s, c) = heading.sin_cos();
    let (s2, c2) = (heading + action[2]).sin_cos();
    [
        centroid[0] + c2 * nominal[0] - s2 * nominal[1] + c * action[0] - s * action[1],
        centroid[1] + s2 * nominal[0] + c2 * nominal[1] + s * action[0] + c * action[1],
    ]
}

/// The lattice offsets within a disc, nearest first (ties in a fixed order),
/// with their distance [m].
#[derive(Debug, Clone, PartialEq)]
pub struct LocalSearch {
    offsets: Vec<([i16; 2], f64)>,
    radius: f64,
    penalty: f64,
}

impl LocalSearch {
    /// The disc of radius `radius` [m] on a lattice of spacing
    /// `resolution` [m]; `penalty` [cost] is charged per `radius` of distance
    /// from the target.
    pub fn new(radius: f64, resolution: f64, penalty: f64) -> Self {
        let reach = (radius / resolution + 1e-9).floor() as i16;
        let mut offsets = Vec::new();
        for di in -reach..=reach {
            for dj in -reach..=reach {
                let d = f64::from(di).hypot(f64::from(dj)) * resolution;
                if d <= radius + 1e-12 {
                    offsets.push(([di, dj], d));
                }
            }
        }
        offsets.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        Self {
            offsets,
            radius,
            penalty,
        }
    }

    /// Number of cells searched.
    pub fn len(&self) -> usize {
        self.offsets.len()
    }

    /// Whether the search disc is empty (never: it holds the target itself).
    pub fn is_empty(&self) -> bool {
        self.offsets.is_empty()
    }

    /// The cheapest foothold for `leg` around `target`: the cell minimising
    /// terrain cost + penalty·distance/radius among those `accept` allows,
    /// with that sum; `None` when no cell qualifies.
    #[inline]
    pub fn best(
        &self,
        map: &CostMap,
        leg: usize,
        target: Cell,
        mut accept: impl FnMut(Cell) -> bool,
    ) -> Option<(Cell, f64)> {
        let per_metre = if self.radius > 0.0 {
            self.penalty / self.radius
        } else {
            0.0
        };
        let mut best: Option<(Cell, f64)> = None;
        for &([di, dj], d) in &self.offsets {
            let distance_cost = per_metre * d;
            if best.is_some_and(|(_, c)| distance_cost >= c) {
                // Offsets come nearest first and terrain costs are > 0.
                break;
            }
            let cell = [target[0].saturating_add(di), target[1].saturating_add(dj)];
            let cost = map.cost(cell, leg) + distance_cost;
            if cost.is_finite() && best.is_none_or(|(_, c)| cost < c) && accept(cell) {
                best = Some((cell, cost));
            }
        }
        best
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use crate::heightfield::HeightField;

    #[test]
    fn footstep_action_target_turns_about_the_centroid() {
        let n = [0.1, 0.05];
        // Heading 0, no turn: nominal offset plus the displacement.
        let t = action_target([1.0, 2.0], 0.0, n, [0.03, -0.01, 0.0]);
        assert!((t[0] - 1.13).abs() < 1e-12 && (t[1] - 2.04).abs() < 1e-12);
        // Heading π/2: forward is +y, left is −x.
        let t = action_target([0.0, 0.0], std::f64::consts::FRAC_PI_2, n, [0.03, 0.0, 0.0]);
        assert!((t[0] + 0.05).abs() < 1e-12 && (t[1] - 0.13).abs() < 1e-12);
        // A pure turn keeps the distance to the centroid.
        let t = action_target([0.0, 0.0], 0.4, n, [0.0, 0.0, 0.2]);
        assert!((t[0].hypot(t[1]) - n[0].hypot(n[1])).abs() < 1e-12);
        assert!((t[1].atan2(t[0]) - (0.6 + n[1].atan2(n[0]))).abs() < 1e-12);
    }

    #[test]
    fn footstep_local_search_finds_the_cheapest_cell_against_brute_force() {
        let (nx, ny) = (41, 41);
        let hf =
            HeightField::new(0.0, 0.0, 0.005, 0.005, nx, ny, vec![0.0; nx * ny], None).unwrap();
        // Pseudo-random costs in [1, 3).
        let costs: Vec<f64> = (0..nx * ny)
            .map(|k| 1.0 + 2.0 * (((k * 7919) % 1013) as f64 / 1013.0))
            .collect();
        let map = CostMap::new(&hf, &costs, &costs, 0.005, 0.0).unwrap();
        let search = LocalSearch::new(0.012, 0.005, 0.3);
        assert_eq!(search.len(), 21);
        for target in [[20i16, 20i16], [1, 1], [0, 40], [39, 3]] {
            let forbidden = [target[0] + 1, target[1]];
            let got = search.best(&map, 0, target, |c| c != forbidden);
            let mut brute: Option<(Cell, f64)> = None;
            for di in -3i16..=3 {
                for dj in -3i16..=3 {
                    let d = f64::from(di).hypot(f64::from(dj)) * 0.005;
                    let cell = [target[0] + di, target[1] + dj];
                    if d > 0.012 || cell == forbidden {
                        continue;
                    }
                    let c = map.cost(cell, 0) + 0.3 / 0.012 * d;
                    if c.is_finite() && brute.is_none_or(|(_, b)| c < b) {
                        brute = Some((cell, c));
                    }
                }
            }
            let (g, b) = (got.unwrap(), brute.unwrap());
            assert!((g.1 - b.1).abs() < 1e-12, "{g:?} vs {b:?}");
        }
        // Radius 0: the target only.
        let only = LocalSearch::new(0.0, 0.005, 0.3);
        assert_eq!(only.best(&map, 0, [5, 5], |_| true).unwrap().0, [5, 5]);
        assert_eq!(only.best(&map, 0, [-3, 5], |_| true), None);
    }
}

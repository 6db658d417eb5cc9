//! An 8-connected grid world with obstacles: the toy [`SearchProblem`] the
//! search tests and benchmarks run on (the MovingAI benchmark convention:
//! straight moves cost 1, diagonal moves √2 and may not cut corners).

use super::problem::{SearchProblem, Successor};
use crate::error::{CoreError, CoreResult};

/// A grid cell (x, y).
pub type Cell = (i32, i32);

/// The eight moves, indexed by the action payload.
pub const MOVES: [Cell; 8] = [
    (1, 0),
    (0, 1),
    (-1, 0),
    (0, -1),
    (1, 1),
    (-1, 1),
    (-1, -1),
    (1, -1),
];

/// An obstacle grid with one goal cell and the octile-distance heuristic.
#[derive(Debug, Clone)]
pub struct GridWorld {
    width: i32,
    height: i32,
    /// x-major: `blocked[x * height + y]`.
    blocked: Vec<bool>,
    goal: Cell,
    /// Multiplies the octile heuristic; 1 keeps it consistent.
    heuristic_scale: f64,
}

impl GridWorld {
    /// A grid of `width × height` cells, `blocked` x-major
    /// (`blocked[x * height + y]`), with goal cell `goal`.
    pub fn new(width: usize, height: usize, blocked: Vec<bool>, goal: Cell) -> CoreResult<Self> {
        if width == 0 || height == 0 || width > i32::MAX as usize || height > i32::MAX as usize {
            return Err(CoreError::InvalidArgument(format!(
                "grid size must be positive and fit in i32, got {width}×{height}"
            )));
        }
        if blocked.len() != width * height {
            return Err(CoreError::InvalidArgument(format!(
                "expected {} blocked flags for a {width}×{height} grid, got {}",
                width * height,
                blocked.len()
            )));
        }
        let world = Self {
            width: width as i32,
            height: height as i32,
            blocked,
            goal,
            heuristic_scale: 1.0,
        };
        if !world.is_free(goal) {
            return Err(CoreError::InvalidArgument(format!(
                "goal cell {goal:?} is outside the {width}×{height} grid or blocked"
            )));
        }
        Ok(world)
    }

    /// A grid whose cells are blocked independently with probability
    /// `obstacle_fraction` (deterministic in `seed`), except the start corner
    /// (0, 0) and the goal corner (width − 1, height − 1).
    pub fn random(width: usize, height: usize, obstacle_fraction: f64, seed: u64) -> Self {
        let mut state = seed;
        let mut blocked: Vec<bool> = (0..width * height)
            .map(|_| {
                (splitmix64(&mut state) >> 11) as f64 / (1u64 << 53) as f64 <= obstacle_fraction
            })
            .collect();
        blocked[0] = false;
        blocked[width * height - 1] = false;
        Self::new(
            width,
            height,
            blocked,
            (width as i32 - 1, height as i32 - 1),
        )
        .expect("a random grid is well formed")
    }

    /// The same world with the heuristic multiplied by `scale` (> 1 makes it
    /// inadmissible, in [0, 1] keeps it consistent).
    #[must_use]
    pub fn with_heuristic_scale(mut self, scale: f64) -> Self {
        self.heuristic_scale = scale;
        self
    }

    /// Whether `cell` is inside the grid and not blocked.
    pub fn is_free(&self, (x, y): Cell) -> bool {
        x >= 0
            && y >= 0
            && x < self.width
            && y < self.height
            && !self.blocked[(x * self.height + y) as usize]
    }

    /// The goal cell.
    pub fn goal(&self) -> Cell {
        self.goal
    }

    /// Octile distance: the cost of the cheapest obstacle-free path.
    pub fn octile(a: Cell, b: Cell) -> f64 {
        let dx = f64::from((a.0 - b.0).abs());
        let dy = f64::from((a.1 - b.1).abs());
        dx.max(dy) + (std::f64::consts::SQRT_2 - 1.0) * dx.min(dy)
    }
}

fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl SearchProblem for GridWorld {
    type State = Cell;
    type Action = u8;

    fn successors(&mut self, &(x, y): &Cell, out: &mut Vec<Successor<Cell, u8>>) -> usize {
        for (k, &(dx, dy)) in MOVES.iter().enumerate() {
            let to = (x + dx, y + dy);
            if !self.is_free(to) {
                continue;
            }
            let diagonal = dx != 0 && dy != 0;
            if diagonal && !(self.is_free((x + dx, y)) && self.is_free((x, y + dy))) {
                continue;
            }
            out.push(Successor {
                state: to,
                cost: if diagonal {
                    std::f64::consts::SQRT_2
                } else {
                    1.0
                },
                action: k as u8,
            });
        }
        out.len()
    }

    fn heuristic(&mut self, &cell: &Cell) -> f64 {
        self.heuristic_scale * Self::octile(cell, self.goal)
    }

    fn is_goal(&mut self, &cell: &Cell) -> bool {
        cell == self.goal
    }

    fn heuristic_is_admissible(&self) -> bool {
        self.heuristic_scale <= 1.0
    }

    fn heuristic_is_consistent(&self) -> bool {
        self.heuristic_scale <= 1.0
    }

    fn heuristic_name(&self) -> String {
        "octile".to_owned()
    }
}

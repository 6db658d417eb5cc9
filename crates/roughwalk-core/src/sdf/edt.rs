//! Linear-time Euclidean distance transform with a feature transform
//! (Felzenszwalb and Huttenlocher 2004, "Distance transforms of sampled
//! functions"), as Zucker 2011 §3.3 uses it.
//!
//! The transform is separable: one pass of 1-D lower envelopes of parabolas
//! along each axis. Each pass carries, beside the squared distance, the label
//! of the seed that attains it, so the result names the nearest seed of every
//! voxel (the feature transform), not only its distance. Squared distances
//! are integers in voxel units and stay exact in `u32`.

use rayon::prelude::*;

/// Label of a voxel that is not a seed (and, in the output, of every voxel
/// when there is no seed at all).
pub const NO_SEED: u32 = u32::MAX;

const FAR: u32 = u32::MAX;

/// Work buffers of one 1-D lower-envelope computation, reused across lines.
///
/// Breakpoints between parabolas are kept as exact fractions num/den
/// (den > 0) of integers, so every comparison is a cross-multiplication:
/// no division, no rounding.
struct Envelope {
    /// f(q) + q², the parabola's value at 0 shifted to make breakpoints linear; −1 = no sample.
    g: Vec<i64>,
    label: Vec<u32>,
    v: Vec<usize>,
    z: Vec<(i64, i64)>,
}

impl Envelope {
    fn new(n: usize) -> Self {
        Self {
            g: vec![-1; n],
            label: vec![NO_SEED; n],
            v: vec![0; n],
            z: vec![(0, 1); n + 1],
        }
    }

    /// Loads sample q of the line: squared distance `d2` (FAR = none) and its label.
    #[inline]
    fn set(&mut self, q: usize, d2: u32, label: u32) {
        self.g[q] = if d2 == FAR {
            -1
        } else {
            i64::from(d2) + (q * q) as i64
        };
        self.label[q] = label;
    }

    /// Replaces the loaded line by min over p of f(p) + (q − p)², calling
    /// `out(q, d2, label)` for every q.
    fn solve(&mut self, n: usize, mut out: impl FnMut(usize, u32, u32)) {
        let (g, v, z) = (&self.g, &mut self.v, &mut self.z);
        // Parabolas p and q (p < q) meet at s = (g_q − g_p) / (2(q − p)).
        // v[0..=k] are the parabolas of the envelope; z[i] (i ≥ 1) is where
        // v[i] takes over from v[i − 1].
        let mut k = 0usize;
        let mut any = false;
        for q in 0..n {
            if g[q] < 0 {
                continue;
            }
            if !any {
                v[0] = q;
                any = true;
                continue;
            }
            loop {
                let p = v[k];
                let s = (g[q] - g[p], 2 * (q - p) as i64);
                // s ≤ z[k] (z[0] is −∞, so k = 0 always takes the else branch).
                if k > 0 && s.0 * z[k].1 <= z[k].0 * s.1 {
                    k -= 1;
                } else {
                    k += 1;
                    v[k] = q;
                    z[k] = s;
                    break;
                }
            }
        }
        if !any {
            for q in 0..n {
                out(q, FAR, NO_SEED);
            }
            return;
        }
        let last = k;
        k = 0;
        for q in 0..n {
            // Advance while z[k + 1] < q.
            while k < last && z[k + 1].0 < q as i64 * z[k + 1].1 {
                k += 1;
            }
            let p = v[k];
            let d = q as i64 - p as i64;
            out(q, (g[p] - (p * p) as i64 + d * d) as u32, self.label[p]);
        }
    }
}

/// Feature transform of a voxel lattice of `shape` (C-order, z fastest).
///
/// `labels[i]` is the seed's label at seed voxels and [`NO_SEED`] elsewhere;
/// on return it holds, for every voxel, the label of a Euclidean-nearest seed
/// (ties broken arbitrarily), or [`NO_SEED`] everywhere if there is no seed.
/// Extra memory: 8 bytes per voxel.
pub fn feature_transform(shape: [usize; 3], labels: &mut [u32]) {
    let [nx, ny, nz] = shape;
    let n = nx * ny * nz;
    assert_eq!(labels.len(), n, "labels must have one entry per voxel");
    if n == 0 {
        return;
    }
    let mut d2: Vec<u32> = labels
        .par_iter()
        .map(|&l| if l == NO_SEED { FAR } else { 0 })
        .collect();

    // Along z: lines are contiguous.
    d2.par_chunks_mut(nz)
        .zip(labels.par_chunks_mut(nz))
        .for_each_init(
            || Envelope::new(nz),
            |env, (dl, ll)| {
                for q in 0..nz {
                    env.set(q, dl[q], ll[q]);
                }
                env.solve(nz, |q, d, l| {
                    dl[q] = d;
                    ll[q] = l;
                });
            },
        );

    // Along y: within one x-slab, gathered plane by plane so reads stay contiguous.
    let slab = ny * nz;
    d2.par_chunks_mut(slab)
        .zip(labels.par_chunks_mut(slab))
        .for_each_init(
            || (Envelope::new(ny), vec![FAR; slab], vec![NO_SEED; slab]),
            |(env, pd, pl), (ds, ls)| {
                // Transpose the slab to (k, j) so each y-line is contiguous.
                for j in 0..ny {
                    for k in 0..nz {
                        pd[k * ny + j] = ds[j * nz + k];
                        pl[k * ny + j] = ls[j * nz + k];
                    }
                }
                for k in 0..nz {
                    for j in 0..ny {
                        env.set(j, pd[k * ny + j], pl[k * ny + j]);
                    }
                    env.solve(ny, |j, d, l| {
                        ds[j * nz + k] = d;
                        ls[j * nz + k] = l;
                    });
                }
            },
        );

    // Along x: lines cross every slab, so each task owns one y-plane and
    // writes it to a (j, i, k) buffer, transposed back below.
    let plane = nx * nz;
    let mut by_y = vec![NO_SEED; n];
    {
        let (d2, labels) = (&d2, &*labels);
        by_y.par_chunks_mut(plane).enumerate().for_each_init(
            || (Envelope::new(nx), vec![FAR; plane], vec![NO_SEED; plane]),
            |(env, pd, pl), (j, out)| {
                for i in 0..nx {
                    let src = (i * ny + j) * nz;
                    for k in 0..nz {
                        pd[k * nx + i] = d2[src + k];
                        pl[k * nx + i] = labels[src + k];
                    }
                }
                for k in 0..nz {
                    for i in 0..nx {
                        env.set(i, pd[k * nx + i], pl[k * nx + i]);
                    }
                    env.solve(nx, |i, _, l| out[i * nz + k] = l);
                }
            },
        );
    }
    drop(d2);
    labels.par_chunks_mut(slab).enumerate().for_each(|(i, ls)| {
        for j in 0..ny {
            let src = (j * nx + i) * nz;
            ls[j * nz..(j + 1) * nz].copy_from_slice(&by_y[src..src + nz]);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (no external crates in the core).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> u64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            self.0 >> 33
        }
    }

    fn d2(a: [usize; 3], b: [usize; 3]) -> usize {
        (0..3).map(|i| a[i].abs_diff(b[i]).pow(2)).sum()
    }

    #[test]
    fn nearest_seed_matches_brute_force_on_random_grids() {
        let mut rng = Lcg(7);
        for trial in 0..40 {
            let shape = [
                1 + (rng.next() % 9) as usize,
                1 + (rng.next() % 9) as usize,
                1 + (rng.next() % 9) as usize,
            ];
            let n = shape[0] * shape[1] * shape[2];
            let density = 1 + rng.next() % 30;
            let mut seeds = Vec::new();
            let mut labels = vec![NO_SEED; n];
            for (idx, l) in labels.iter_mut().enumerate() {
                if rng.next() % 100 < density {
                    *l = seeds.len() as u32;
                    seeds.push(idx);
                }
            }
            let spec = |idx: usize| {
                let k = idx % shape[2];
                let ij = idx / shape[2];
                [ij / shape[1], ij % shape[1], k]
            };
            let mut out = labels.clone();
            feature_transform(shape, &mut out);
            for (idx, &l) in out.iter().enumerate() {
                if seeds.is_empty() {
                    assert_eq!(l, NO_SEED);
                    continue;
                }
                let best = seeds.iter().map(|&s| d2(spec(idx), spec(s))).min().unwrap();
                assert_ne!(l, NO_SEED, "trial {trial}: voxel {idx} got no seed");
                let got = d2(spec(idx), spec(seeds[l as usize]));
                assert_eq!(got, best, "trial {trial} shape {shape:?} voxel {idx}");
                if labels[idx] != NO_SEED {
                    assert_eq!(got, 0);
                }
            }
        }
    }
}

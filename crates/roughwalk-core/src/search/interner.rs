//! States interned into dense indices, so that the searches keep their
//! per-state data in flat vectors instead of hash maps.

use std::collections::hash_map::Entry;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};

/// The Fx hash of rustc: much faster than SipHash for the small keys search
/// states are, and deterministic (no random seed), which keeps runs
/// reproducible. Not DoS-resistant, which a planner does not need.
#[derive(Default, Clone, Copy)]
pub(crate) struct FxHasher {
    hash: u64,
}

const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

impl FxHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.hash = (self.hash.rotate_left(5) ^ word).wrapping_mul(SEED);
    }
}

impl Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for chunk in &mut chunks {
            let mut word = [0u8; 8];
            word.copy_from_slice(chunk);
            self.add(u64::from_le_bytes(word));
        }
        for &b in chunks.remainder() {
            self.add(u64::from(b));
        }
    }
    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.add(u64::from(i));
    }
    #[inline]
    fn write_u16(&mut self, i: u16) {
        self.add(u64::from(i));
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.add(u64::from(i));
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        self.hash
    }
}

/// A state ↔ index table.
pub(crate) struct Interner<S> {
    states: Vec<S>,
    index: HashMap<S, u32, BuildHasherDefault<FxHasher>>,
}

impl<S: Clone + Eq + Hash> Interner<S> {
    pub(crate) fn new() -> Self {
        Self {
            states: Vec::new(),
            index: HashMap::default(),
        }
    }

    /// The index of `state`, and whether it was new.
    pub(crate) fn intern(&mut self, state: S) -> (u32, bool) {
        match self.index.entry(state) {
            Entry::Occupied(e) => (*e.get(), false),
            Entry::Vacant(e) => {
                let i = self.states.len() as u32;
                self.states.push(e.key().clone());
                e.insert(i);
                (i, true)
            }
        }
    }

    pub(crate) fn get(&self, i: u32) -> &S {
        &self.states[i as usize]
    }

    pub(crate) fn len(&self) -> usize {
        self.states.len()
    }
}

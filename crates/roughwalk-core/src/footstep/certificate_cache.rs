//! The bounded cache of certificate outcomes shared by plans and re-plans
//! (Zucker 2011, §4.5: precomputation and reuse are key to planning fast).
//!
//! Two generations: outcomes go into the young map; when it holds half the
//! capacity it becomes the old map (the previous old one is dropped) and a
//! new young map starts. A hit in the old map moves the entry to the young
//! one. So a full cache forgets only the half it has not used for longest,
//! where emptying it whole (as before) made the planner recompute every
//! certificate of the stances it was still expanding.

use std::collections::HashMap;
use std::hash::{BuildHasher, Hash};

/// At most `capacity` entries, the least recently used half evicted at once.
#[derive(Debug, Clone)]
pub struct CertificateCache<K, V, S> {
    young: HashMap<K, V, S>,
    old: HashMap<K, V, S>,
    capacity: usize,
}

impl<K: Hash + Eq, V: Copy, S: BuildHasher + Default> CertificateCache<K, V, S> {
    /// An empty cache of at most `capacity` entries (0 caches nothing).
    pub fn new(capacity: usize) -> Self {
        Self {
            young: HashMap::default(),
            old: HashMap::default(),
            capacity,
        }
    }

    /// Entries a generation holds before it ages.
    fn generation(&self) -> usize {
        self.capacity.div_ceil(2)
    }

    /// The cached value of `key`, renewing it.
    pub fn get(&mut self, key: &K) -> Option<V> {
        if let Some(&v) = self.young.get(key) {
            return Some(v);
        }
        let (k, v) = self.old.remove_entry(key)?;
        self.insert(k, v);
        Some(v)
    }

    /// Caches `value` for `key`.
    pub fn insert(&mut self, key: K, value: V) {
        if self.capacity == 0 {
            return;
        }
        if self.young.len() >= self.generation() {
            self.old = std::mem::take(&mut self.young);
        }
        self.young.insert(key, value);
    }

    /// Number of cached entries (at most the capacity).
    pub fn len(&self) -> usize {
        self.young.len() + self.old.len()
    }

    /// Whether nothing is cached.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::hash_map::RandomState;

    type Cache = CertificateCache<u32, u32, RandomState>;

    #[test]
    fn footstep_cache_keeps_the_recent_half_when_full() {
        let mut c = Cache::new(10);
        for k in 0..10 {
            c.insert(k, 10 * k);
        }
        assert_eq!(c.len(), 10);
        // Full: the next insert drops the 5 oldest, not all 10.
        c.insert(10, 100);
        assert_eq!(c.len(), 6);
        for k in 0..5 {
            assert_eq!(c.get(&k), None, "{k}");
        }
        for k in 5..=10 {
            assert_eq!(c.get(&k), Some(10 * k), "{k}");
        }
        assert!(c.len() <= 10);
    }

    #[test]
    fn footstep_cache_renews_an_entry_that_is_used() {
        let mut c = Cache::new(4);
        for k in 0..4 {
            c.insert(k, k);
        }
        // 0 and 1 are old; using 0 moves it to the young generation.
        assert_eq!(c.get(&0), Some(0));
        c.insert(4, 4);
        c.insert(5, 5);
        assert_eq!(c.get(&0), Some(0));
        assert_eq!(c.get(&1), None);
        for k in 0..100 {
            c.insert(k, k);
            assert!(c.len() <= 4);
        }
    }

    #[test]
    fn footstep_cache_of_capacity_zero_keeps_nothing() {
        let mut c = Cache::new(0);
        c.insert(1, 1);
        assert!(c.is_empty());
        assert_eq!(c.get(&1), None);
    }
}

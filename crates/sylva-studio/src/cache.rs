//! What the studio keeps in memory: values by key, the least recently used going first when
//! there are more than a count or their bytes pass a total. Keys are always real plants' (a
//! plant is read from the archive before anything of it is made), each with a handful of
//! forms (pictures: any view and size, but bounded like the rest), so nothing a request makes
//! up can enter a cache.

use std::collections::{HashMap, VecDeque};
use std::hash::Hash;
use std::sync::{Arc, Mutex};

/// A bounded cache of shared values.
pub struct Bounded<K, V> {
    inner: Mutex<Entries<K, V>>,
    max_items: usize,
    max_bytes: usize,
}

/// The values with their sizes, least recently used first, and the bytes in all.
struct Entries<K, V> {
    values: HashMap<K, (Arc<V>, usize)>,
    order: VecDeque<K>,
    bytes: usize,
}

impl<K: Copy + Eq + Hash, V> Bounded<K, V> {
    /// A cache of at most `max_items` values and `max_bytes` bytes (one value is kept
    /// whatever its size).
    pub fn new(max_items: usize, max_bytes: usize) -> Self {
        Bounded {
            inner: Mutex::new(Entries {
                values: HashMap::new(),
                order: VecDeque::new(),
                bytes: 0,
            }),
            max_items,
            max_bytes,
        }
    }

    /// The value of `key`, now the most recently used.
    pub fn get(&self, key: K) -> Option<Arc<V>> {
        let mut inner = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        let value = inner.values.get(&key)?.0.clone();
        if let Some(at) = inner.order.iter().position(|k| *k == key) {
            inner.order.remove(at);
        }
        inner.order.push_back(key);
        Some(value)
    }

    /// Keeps `value`, of `bytes` bytes, under `key`.
    pub fn put(&self, key: K, value: Arc<V>, bytes: usize) {
        let mut inner = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        let Entries {
            values,
            order,
            bytes: total,
        } = &mut *inner;
        *total += bytes;
        if let Some((_, old)) = values.insert(key, (value, bytes)) {
            *total -= old;
            if let Some(at) = order.iter().position(|k| *k == key) {
                order.remove(at);
            }
        }
        order.push_back(key);
        while order.len() > self.max_items || (*total > self.max_bytes && order.len() > 1) {
            if let Some(old) = order.pop_front()
                && let Some((_, size)) = values.remove(&old)
            {
                *total -= size;
            }
        }
    }

    /// The values and bytes kept.
    pub fn len_and_bytes(&self) -> (usize, usize) {
        let inner = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        (inner.values.len(), inner.bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_recently_used_go_first_and_bytes_stay_bounded() {
        let cache: Bounded<u32, Vec<u8>> = Bounded::new(3, 100);
        for k in 0..3 {
            cache.put(k, Arc::new(vec![0; 10]), 10);
        }
        assert!(cache.get(0).is_some()); // 0 is now the most recent
        cache.put(3, Arc::new(vec![0; 10]), 10);
        assert!(cache.get(1).is_none() && cache.get(0).is_some());
        cache.put(4, Arc::new(vec![0; 90]), 90);
        let (items, bytes) = cache.len_and_bytes();
        assert!(items <= 3 && bytes <= 100, "{items} {bytes}");
        assert!(cache.get(4).is_some());
        // One value larger than the bound is still kept, alone.
        cache.put(5, Arc::new(vec![0; 500]), 500);
        assert_eq!(cache.len_and_bytes(), (1, 500));
        // Putting a key again replaces its value and size.
        cache.put(5, Arc::new(vec![0; 5]), 5);
        assert_eq!(cache.len_and_bytes(), (1, 5));
    }
}

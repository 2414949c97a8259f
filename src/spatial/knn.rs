//! The bounded max-heap that holds a k-nearest search's current best candidates, so the search
//! can prune with the k-th distance (Jensen, "Realistic Image Synthesis Using Photon Mapping",
//! 2001, §6.3 / Friedman, Bentley & Finkel, ACM TOMS 3(3), 1977). Allocated once by the caller and
//! reused for every query.

/// One search result: the item's slot in [`KdTree::items`](super::KdTree::items) and its squared
/// distance to the query point (computed by [`distance2`](super::distance2)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbor {
    /// Index into the tree's item array (tree order, not build-input order).
    pub index: u32,
    /// Squared Euclidean distance to the query point, in squared scene units.
    pub dist2: f32,
}

/// Total order of candidates: by squared distance, then by slot. Squared distances are
/// non-negative, so their IEEE bits order like the values and the pair packs into one `u64`.
#[inline]
pub(super) fn key(dist2: f32, slot: u32) -> u64 {
    (u64::from(dist2.to_bits()) << 32) | u64::from(slot)
}

#[inline]
fn neighbor(key: u64) -> Neighbor {
    Neighbor {
        index: key as u32,
        dist2: f32::from_bits((key >> 32) as u32),
    }
}

/// The `k` best candidates of a k-nearest search, as a binary max-heap of packed
/// `(distance², slot)` keys; the root is the current k-th nearest, the pruning distance.
///
/// Create one per thread with [`KnnHeap::new`] and pass it to every
/// [`KdTree::nearest`](super::KdTree::nearest) call: a query clears it and never allocates
/// (beyond the first time the heap grows to `min(k, tree size)` entries).
#[derive(Debug, Clone)]
pub struct KnnHeap {
    k: usize,
    keys: Vec<u64>,
    /// True once [`KnnHeap::sort`] has turned the heap into an ascending list.
    sorted: bool,
}

impl KnnHeap {
    /// A heap for searches of the `k` nearest items. `k = 0` is allowed and finds nothing.
    /// Reserves at most 4096 entries up front; a larger `k` grows on first use.
    #[must_use]
    pub fn new(k: usize) -> Self {
        Self {
            k,
            keys: Vec::with_capacity(k.min(4096)),
            sorted: false,
        }
    }

    /// The number of neighbours this heap collects.
    #[must_use]
    pub fn k(&self) -> usize {
        self.k
    }

    /// Changes the number of neighbours collected by the next search (and clears the heap).
    pub fn set_k(&mut self, k: usize) {
        self.k = k;
        self.clear();
    }

    /// Number of neighbours found by the last search (at most `k`).
    #[must_use]
    pub fn len(&self) -> usize {
        self.keys.len()
    }

    /// True when the last search found nothing.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }

    /// Empties the heap.
    pub fn clear(&mut self) {
        self.keys.clear();
        self.sorted = false;
    }

    /// Squared distance of the farthest neighbour found (the estimate's radius²), or `None`
    /// when nothing was found.
    #[must_use]
    pub fn max_dist2(&self) -> Option<f32> {
        let k = if self.sorted {
            self.keys.last()
        } else {
            self.keys.first()
        };
        k.map(|&k| neighbor(k).dist2)
    }

    /// The neighbours found, in heap order (or ascending order after [`KnnHeap::sort`]).
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Neighbor> + '_ {
        self.keys.iter().map(|&k| neighbor(k))
    }

    /// Orders the found neighbours by ascending `(dist2, index)`, in place (no allocation).
    pub fn sort(&mut self) {
        self.keys.sort_unstable();
        self.sorted = true;
    }

    /// The limit a candidate's key must be below to enter: the root while full, else `open`.
    #[inline]
    pub(super) fn limit(&self, open: u64) -> u64 {
        if self.keys.len() >= self.k {
            self.keys.first().copied().unwrap_or(0)
        } else {
            open
        }
    }

    /// Inserts `key` (which the caller has checked is below [`KnnHeap::limit`]), evicting the
    /// largest when full.
    #[inline]
    pub(super) fn push(&mut self, key: u64) {
        let keys = &mut self.keys;
        if keys.len() < self.k {
            // Sift up.
            let mut i = keys.len();
            keys.push(key);
            while i > 0 {
                let parent = (i - 1) / 2;
                if keys[parent] >= key {
                    break;
                }
                keys[i] = keys[parent];
                i = parent;
            }
            keys[i] = key;
        } else {
            // Replace the root and sift down.
            let n = keys.len();
            let mut i = 0;
            loop {
                let l = 2 * i + 1;
                if l >= n {
                    break;
                }
                let r = l + 1;
                let c = if r < n && keys[r] > keys[l] { r } else { l };
                if keys[c] <= key {
                    break;
                }
                keys[i] = keys[c];
                i = c;
            }
            if n > 0 {
                keys[i] = key;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_k_smallest_keys() {
        // Against sorting: feed a scrambled sequence, keep 5.
        let values: Vec<u64> = (0..100u64).map(|i| (i * 37) % 101).collect();
        let mut h = KnnHeap::new(5);
        for &v in &values {
            if v < h.limit(u64::MAX) {
                h.push(v);
            }
        }
        let mut expect = values.clone();
        expect.sort_unstable();
        h.sort();
        let got: Vec<u64> = h.keys.clone();
        assert_eq!(got, expect[..5]);
    }

    #[test]
    fn zero_k_takes_nothing() {
        let mut h = KnnHeap::new(0);
        assert_eq!(h.limit(u64::MAX), 0);
        assert!(h.is_empty());
        assert_eq!(h.max_dist2(), None);
        h.set_k(1);
        assert_eq!(h.limit(7), 7);
    }

    #[test]
    fn keys_order_by_distance_then_slot() {
        assert!(key(1.0, 5) < key(1.0, 6));
        assert!(key(1.0, u32::MAX) < key(1.0000001, 0));
        assert!(key(0.0, 9) < key(f32::MIN_POSITIVE, 0));
        assert_eq!(
            neighbor(key(2.5, 7)),
            Neighbor {
                index: 7,
                dist2: 2.5
            }
        );
    }
}

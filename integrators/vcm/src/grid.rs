//! The range search over one iteration's light vertices: a hashed uniform grid (SmallVCM's
//! `HashGrid`, Teschner et al. 2003). Cells are 2r wide, so the disc of radius r around a
//! query point touches at most the 2 x 2 x 2 block of cells nearest to it; cells are hashed into
//! a table of as many buckets as vertices, filled by a counting sort (stable: a bucket lists
//! its vertices in the order they were given). A query visits its buckets in increasing order
//! (two cells of the block may share a bucket: visited once) and each bucket's vertices in
//! order, so the sum a pixel makes of its merges is the same whatever the thread count.

use foton_core::api::Vec3;
use rayon::prelude::*;

pub struct HashGrid {
    min: Vec3,
    inv_cell: f32,
    radius: f32,
    radius2: f32,
    /// Bucket b holds `indices[starts[b]..starts[b + 1]]`.
    starts: Vec<u32>,
    indices: Vec<u32>,
    positions: Vec<Vec3>,
    /// The build's scratch: each vertex's bucket, then its slot.
    keys: Vec<u32>,
}

impl HashGrid {
    /// A grid over `positions` for queries of radius `radius`.
    pub fn build(positions: Vec<Vec3>, radius: f32) -> HashGrid {
        let mut grid = HashGrid::empty();
        grid.rebuild(positions.into_par_iter(), radius);
        grid
    }

    /// The bytes the grid holds on the heap: buckets, indices, positions and the build's keys.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        (self.starts.capacity() + self.indices.capacity() + self.keys.capacity()) * size_of::<u32>()
            + self.positions.capacity() * size_of::<Vec3>()
    }

    /// A grid over nothing, to be rebuilt.
    pub fn empty() -> HashGrid {
        HashGrid {
            min: Vec3::ZERO,
            inv_cell: 0.0,
            radius: 0.0,
            radius2: 0.0,
            starts: Vec::new(),
            indices: Vec::new(),
            positions: Vec::new(),
            keys: Vec::new(),
        }
    }

    /// The grid over `positions` for queries of radius `radius`, in this grid's memory (an
    /// iteration's grid reuses the last one's: no allocation once it is large enough). The
    /// positions, their box and their buckets in parallel; the counting sort in order.
    pub fn rebuild(&mut self, positions: impl IndexedParallelIterator<Item = Vec3>, radius: f32) {
        self.positions.clear();
        self.positions.par_extend(positions);
        self.min = self
            .positions
            .par_iter()
            .copied()
            .reduce(|| Vec3::splat(f32::INFINITY), Vec3::min);
        let buckets = self.positions.len().max(1);
        self.inv_cell = 1.0 / (2.0 * radius);
        self.radius = radius;
        self.radius2 = radius * radius;
        self.starts.clear();
        self.starts.resize(buckets + 1, 0);
        let mut keys = std::mem::take(&mut self.keys);
        keys.clear();
        let this = &*self;
        keys.par_extend(
            this.positions
                .par_iter()
                .map(|p| this.bucket(this.cell(*p))),
        );
        for &k in &keys {
            self.starts[k as usize + 1] += 1;
        }
        for b in 0..buckets {
            self.starts[b + 1] += self.starts[b];
        }
        // Counting sort; each key then counts its bucket's next free slot.
        self.indices.clear();
        self.indices.resize(self.positions.len(), 0);
        for (i, k) in keys.iter_mut().enumerate() {
            let slot = &mut self.starts[*k as usize];
            *k = *slot;
            *slot += 1;
            self.indices[*k as usize] = i as u32;
        }
        // The slots moved each start to its bucket's end, the next bucket's start: back.
        for b in (1..=buckets).rev() {
            self.starts[b] = self.starts[b - 1];
        }
        self.starts[0] = 0;
        self.keys = keys;
    }

    /// The query radius the grid was built for.
    #[inline]
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The (continuous) cell coordinates of `p`.
    #[inline]
    fn cell(&self, p: Vec3) -> Vec3 {
        (p - self.min) * self.inv_cell
    }

    #[inline]
    fn bucket(&self, c: Vec3) -> u32 {
        let (x, y, z) = (c.x.floor() as i32, c.y.floor() as i32, c.z.floor() as i32);
        self.bucket_of(x, y, z)
    }

    /// Teschner et al.'s spatial hash of cell (x, y, z).
    #[inline]
    fn bucket_of(&self, x: i32, y: i32, z: i32) -> u32 {
        let h = (x as u32).wrapping_mul(73_856_093)
            ^ (y as u32).wrapping_mul(19_349_663)
            ^ (z as u32).wrapping_mul(83_492_791);
        h % (self.starts.len() as u32 - 1)
    }

    /// Calls `f(index, squared distance)` for every vertex within the radius of `p`, in a
    /// fixed order.
    pub fn within(&self, p: Vec3, mut f: impl FnMut(usize, f32)) {
        if self.positions.is_empty() {
            return;
        }
        let c = self.cell(p);
        let base = c.floor();
        let frac = c - base;
        let (x, y, z) = (base.x as i32, base.y as i32, base.z as i32);
        // The neighbour on the side of the point within its cell, along each axis.
        let step = |f: f32| if f < 0.5 { -1 } else { 1 };
        let (dx, dy, dz) = (step(frac.x), step(frac.y), step(frac.z));
        let mut buckets = [0u32; 8];
        for (i, b) in buckets.iter_mut().enumerate() {
            let (ox, oy, oz) = (i & 1, (i >> 1) & 1, (i >> 2) & 1);
            *b = self.bucket_of(x + dx * ox as i32, y + dy * oy as i32, z + dz * oz as i32);
        }
        buckets.sort_unstable();
        let mut last = u32::MAX;
        for b in buckets {
            if b == last {
                continue;
            }
            last = b;
            let (lo, hi) = (self.starts[b as usize], self.starts[b as usize + 1]);
            for &i in &self.indices[lo as usize..hi as usize] {
                let d2 = self.positions[i as usize].distance_squared(p);
                if d2 <= self.radius2 {
                    f(i as usize, d2);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use foton_core::api::Rng;

    /// The grid finds exactly the points a brute-force search finds, each once.
    #[test]
    fn the_grid_finds_what_brute_force_finds() {
        let mut rng = Rng::new(&[7]);
        let points: Vec<Vec3> = (0..3000)
            .map(|_| Vec3::new(rng.next_f32(), rng.next_f32() * 0.5, rng.next_f32() * 2.0))
            .collect();
        for r in [0.01f32, 0.05, 0.3] {
            let grid = HashGrid::build(points.clone(), r);
            for _ in 0..200 {
                let q = Vec3::new(rng.next_f32(), rng.next_f32() * 0.5, rng.next_f32() * 2.0);
                let mut found = Vec::new();
                grid.within(q, |i, _| found.push(i));
                found.sort_unstable();
                let want: Vec<usize> = (0..points.len())
                    .filter(|&i| points[i].distance_squared(q) <= r * r)
                    .collect();
                assert_eq!(found, want, "r = {r}");
            }
        }
    }
}

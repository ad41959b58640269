//! A share of a render's work (`foton render --part I/N`), which the host hands a render
//! ([`crate::integrator::RenderContext::part`]) and the film records: below both `film` and
//! `integrator`, which share it. Part of the plugin interface (docs/plugins.md, "Versions").

/// One of `count` disjoint shares of a render's work, `index` counted from 0. The shares of
/// the `count` parts cover the work exactly once, and a render of a part fills a film whose
/// sums add up, over the parts, to the whole render's: the film records the part it holds
/// ([`Film::part`], set through [`crate::integrator::RenderContext::part`]), so that a host can tell an integrator that ignored it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Part {
    pub index: u32,
    pub count: u32,
}

impl Part {
    pub const WHOLE: Part = Part { index: 0, count: 1 };

    /// Part `index` of `count`; None unless index < count.
    pub fn new(index: u32, count: u32) -> Option<Part> {
        (index < count).then_some(Part { index, count })
    }

    pub fn is_whole(&self) -> bool {
        self.count == 1
    }

    /// This part's share of `total` units of work (samples, iterations): the contiguous range
    /// [total i / n, total (i + 1) / n), so that shares differ in size by one at most.
    pub fn share(&self, total: u64) -> std::ops::Range<u64> {
        let split = |i: u64| (total as u128 * i as u128 / self.count as u128) as u64;
        split(self.index as u64)..split(self.index as u64 + 1)
    }
}

impl std::fmt::Display for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

//! Union–find over `0..n` with the smaller index as each set's root, so the roots (and any
//! numbering taken from them) do not depend on the order of the unions.

/// Disjoint sets of `0..n`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Dsu(Vec<u32>);

impl Dsu {
    /// `n` singletons.
    pub(crate) fn new(n: usize) -> Dsu {
        Dsu((0..n as u32).collect())
    }

    /// Make it `n` singletons again, keeping the allocation.
    pub(crate) fn reset(&mut self, n: usize) {
        self.0.clear();
        self.0.extend(0..n as u32);
    }

    /// The root of `x`'s set (its smallest member), halving the path on the way.
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let p = self.0[x as usize];
            self.0[x as usize] = self.0[p as usize];
            x = p;
        }
        x
    }

    /// Join the sets of `a` and `b`.
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.0[hi as usize] = lo;
        }
    }
}

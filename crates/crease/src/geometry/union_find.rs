//! Union–find over element ids (path halving; the smaller root wins, so a set's root is its
//! smallest id, whatever the order of the unions).

/// Disjoint sets over `0..n`.
pub(crate) struct UnionFind(Vec<u32>);

impl UnionFind {
    /// `n` singleton sets.
    pub(crate) fn new(n: usize) -> Self {
        UnionFind((0..n as u32).collect())
    }

    /// The root of x's set: its smallest id (a union always puts the larger root under the
    /// smaller).
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let y = self.0[x as usize];
            self.0[x as usize] = self.0[y as usize];
            x = y;
        }
        x
    }

    /// Joins the sets of a and b; false if they were already one.
    pub(crate) fn union(&mut self, a: u32, b: u32) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        self.0[ra.max(rb) as usize] = ra.min(rb);
        true
    }
}

//! Independent sets of nodes for parallel sweeps: a greedy graph colouring in which two nodes
//! sharing a tet never get the same colour.
//!
//! Moving a node reads the positions of the corners of the tets around it and changes only its
//! own position and the measures of those tets. Two nodes of one colour share no tet, so neither
//! reads what the other writes: a colour class can be smoothed in any order, or all at once, with
//! the same result. The colouring itself is sequential and depends only on the order it is given,
//! so a sweep does the same arithmetic for any number of threads.
//!
//! The nodes are coloured in the sweep's order (worst cluster first), each with the smallest
//! colour that no earlier node around it has: the worst node is in the first class, and each
//! class lists its nodes worst first.

/// No colour yet.
const NONE: u32 = u32::MAX;

/// Reusable buffers of [`Colouring::classes`].
#[derive(Debug, Default)]
pub(crate) struct Colouring {
    /// Colour per mesh node (`NONE` outside the nodes being coloured).
    colour: Vec<u32>,
    /// Per colour: the position in the order of the last node that found it taken.
    taken: Vec<u32>,
}

impl Colouring {
    /// The colour classes of `order` (mesh nodes; each at most once), colouring greedily in that
    /// order; nodes sharing a tet get different colours. The tets around node `v` are
    /// `star[start[v]..start[v + 1]]`. Classes come in colour order, each in `order`'s order.
    pub fn classes<const K: usize>(
        &mut self,
        order: &[u32],
        start: &[u32],
        star: &[u32],
        tets: &[[u32; K]],
    ) -> Vec<Vec<u32>> {
        let np = start.len().saturating_sub(1);
        if self.colour.len() != np {
            self.colour = vec![NONE; np];
        }
        self.taken.clear();
        let mut classes: Vec<Vec<u32>> = Vec::new();
        for (p, &v) in order.iter().enumerate() {
            let p = p as u32;
            for &t in &star[start[v as usize] as usize..start[v as usize + 1] as usize] {
                for &u in &tets[t as usize] {
                    let c = self.colour[u as usize];
                    if c != NONE {
                        self.taken[c as usize] = p;
                    }
                }
            }
            let c = self
                .taken
                .iter()
                .position(|&q| q != p)
                .unwrap_or(self.taken.len());
            if c == self.taken.len() {
                self.taken.push(NONE);
                classes.push(Vec::new());
            }
            self.colour[v as usize] = c as u32;
            classes[c].push(v);
        }
        for &v in order {
            self.colour[v as usize] = NONE;
        }
        classes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::smooth::incidence;

    /// A strip of tets over a row of points: tet i is (i, i+1, i+2, i+3).
    fn strip(n: u32) -> Vec<[u32; 4]> {
        (0..n).map(|i| [i, i + 1, i + 2, i + 3]).collect()
    }

    #[test]
    fn classes_are_independent_and_cover_the_order() {
        let tets = strip(20);
        let (start, star) = incidence(23, &tets);
        let order: Vec<u32> = [5, 0, 22, 7, 6, 8, 1, 2, 3, 4, 9, 10, 11, 12, 13, 14]
            .into_iter()
            .collect();
        let mut col = Colouring::default();
        let classes = col.classes(&order, &start, &star, &tets);
        // Every node once, classes in order's order.
        let mut all: Vec<u32> = classes.concat();
        all.sort_unstable();
        let mut want = order.clone();
        want.sort_unstable();
        assert_eq!(all, want);
        let pos = |v: u32| order.iter().position(|&u| u == v).unwrap();
        for class in &classes {
            assert!(class.windows(2).all(|w| pos(w[0]) < pos(w[1])));
            for t in &tets {
                let n = t.iter().filter(|v| class.contains(v)).count();
                assert!(n <= 1, "tet {t:?} has {n} nodes of one class");
            }
        }
        // The first node of the order is in the first class; four consecutive points of the
        // strip share a tet, so at least four colours.
        assert_eq!(classes[0][0], 5);
        assert!(classes.len() >= 4);
        // The buffers are left clean: the same call gives the same classes.
        assert_eq!(col.classes(&order, &start, &star, &tets), classes);
    }
}

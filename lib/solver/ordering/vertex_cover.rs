//! The smallest vertex separator along a cut: a minimum vertex cover of the edges
//! across it.
//!
//! A cut of a graph into `L` and `R` leaves the edges across it, a bipartite graph
//! between the `L` nodes that have a neighbour in `R` and the `R` nodes that have
//! one in `L`. Any set of nodes that touches every such edge separates `L` from
//! `R`; either side's layer is one, and the smallest is a minimum vertex cover of
//! the bipartite graph. By König's theorem its size is that of a maximum matching,
//! and it is read off one: with `Z` the nodes reachable from the unmatched `L`
//! nodes by alternating paths (any edge from `L`, the matching edge from `R`), the
//! cover is (`L` \ `Z`) ∪ (`R` ∩ `Z`). The matching is Hopcroft–Karp's,
//! O(E √V). This is how METIS turns its edge separators into vertex separators;
//! on a mesh whose cut is jagged (unstructured elements, a curved body) it mixes
//! nodes of both layers and is markedly smaller than either.

const NONE: u32 = u32::MAX;

/// The edges across a cut: `a` nodes `0..n_a`, `b` nodes `0..n_b`; the `b`
/// neighbours of `a` node `i` are `adjacent[start[i]..start[i + 1]]`.
pub struct Crossing {
    pub n_b: usize,
    pub start: Vec<usize>,
    pub adjacent: Vec<u32>,
}

impl Crossing {
    fn n_a(&self) -> usize {
        self.start.len() - 1
    }

    fn of(&self, a: usize) -> &[u32] {
        &self.adjacent[self.start[a]..self.start[a + 1]]
    }

    /// A minimum vertex cover: (`a` nodes in it, `b` nodes in it).
    pub fn minimum_cover(&self) -> (Vec<bool>, Vec<bool>) {
        let (match_a, match_b) = self.maximum_matching();
        // alternating search from the unmatched a nodes
        let (mut seen_a, mut seen_b) = (vec![false; self.n_a()], vec![false; self.n_b]);
        let mut queue: Vec<u32> = (0..self.n_a() as u32).filter(|&a| match_a[a as usize] == NONE).collect();
        for &a in &queue {
            seen_a[a as usize] = true;
        }
        let mut head = 0;
        while head < queue.len() {
            let a = queue[head] as usize;
            head += 1;
            for &b in self.of(a) {
                if !seen_b[b as usize] {
                    seen_b[b as usize] = true;
                    let next = match_b[b as usize];
                    if next != NONE && !seen_a[next as usize] {
                        seen_a[next as usize] = true;
                        queue.push(next);
                    }
                }
            }
        }
        (seen_a.iter().map(|&s| !s).collect(), seen_b)
    }

    /// Hopcroft–Karp: (the `b` match of each `a` node, the `a` match of each `b`
    /// node), `NONE` for unmatched. Shortest augmenting paths by breadth-first
    /// layers, then disjoint ones along the layers by an explicit-stack search (no
    /// recursion depth bound on long paths).
    fn maximum_matching(&self) -> (Vec<u32>, Vec<u32>) {
        let n_a = self.n_a();
        let (mut match_a, mut match_b) = (vec![NONE; n_a], vec![NONE; self.n_b]);
        let mut dist = vec![NONE; n_a];
        let mut next_edge = vec![0usize; n_a];
        let mut queue = Vec::with_capacity(n_a);
        let (mut stack, mut via): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
        loop {
            // layers from the free a nodes
            queue.clear();
            for a in 0..n_a {
                dist[a] = if match_a[a] == NONE { 0 } else { NONE };
                if match_a[a] == NONE {
                    queue.push(a as u32);
                }
            }
            let mut found = false;
            let mut head = 0;
            while head < queue.len() {
                let a = queue[head] as usize;
                head += 1;
                for &b in self.of(a) {
                    let next = match_b[b as usize];
                    if next == NONE {
                        found = true;
                    } else if dist[next as usize] == NONE {
                        dist[next as usize] = dist[a] + 1;
                        queue.push(next);
                    }
                }
            }
            if !found {
                return (match_a, match_b);
            }
            next_edge.copy_from_slice(&self.start[..n_a]);
            for root in 0..n_a {
                if match_a[root] != NONE {
                    continue;
                }
                stack.clear();
                via.clear();
                stack.push(root as u32);
                while let Some(&top) = stack.last() {
                    let a = top as usize;
                    if next_edge[a] == self.start[a + 1] {
                        // a dead end: off the layers for this phase
                        dist[a] = NONE;
                        stack.pop();
                        via.pop();
                        continue;
                    }
                    let b = self.adjacent[next_edge[a]];
                    next_edge[a] += 1;
                    let next = match_b[b as usize];
                    if next == NONE {
                        // augment along the stack: each a takes the b that led on
                        via.push(b);
                        for (&a, &b) in stack.iter().zip(&via) {
                            match_a[a as usize] = b;
                            match_b[b as usize] = a;
                        }
                        break;
                    }
                    if dist[next as usize] == dist[a].wrapping_add(1) {
                        via.push(b);
                        stack.push(next);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn crossing(n_b: usize, lists: &[&[u32]]) -> Crossing {
        let mut start = vec![0];
        let mut adjacent = Vec::new();
        for l in lists {
            adjacent.extend_from_slice(l);
            start.push(adjacent.len());
        }
        Crossing { n_b, start, adjacent }
    }

    fn covers(c: &Crossing, (ca, cb): &(Vec<bool>, Vec<bool>)) -> bool {
        (0..c.n_a()).all(|a| c.of(a).iter().all(|&b| ca[a] || cb[b as usize]))
    }

    fn size((ca, cb): &(Vec<bool>, Vec<bool>)) -> usize {
        ca.iter().chain(cb).filter(|&&x| x).count()
    }

    /// The smallest cover by trying every subset (small graphs only).
    fn brute_force(c: &Crossing) -> usize {
        let n = c.n_a() + c.n_b;
        (0u32..1 << n)
            .filter(|m| {
                let ca: Vec<bool> = (0..c.n_a()).map(|i| m >> i & 1 == 1).collect();
                let cb: Vec<bool> = (0..c.n_b).map(|j| m >> (c.n_a() + j) & 1 == 1).collect();
                covers(c, &(ca, cb))
            })
            .map(|m| m.count_ones() as usize)
            .min()
            .unwrap_or(0)
    }

    #[test]
    fn the_cover_touches_every_edge_and_is_the_smallest() {
        // a star on either side: one node covers it
        let star = crossing(4, &[&[0, 1, 2, 3]]);
        assert_eq!(size(&star.minimum_cover()), 1);
        // a perfect matching of 3: 3 nodes
        let three = crossing(3, &[&[0], &[1], &[2]]);
        assert_eq!(size(&three.minimum_cover()), 3);
        // a jagged cut: neither side's layer (4 and 4 nodes) but a mix of 3 (a0, b0 and b1, or a0, b0 and a3)
        let jagged = crossing(4, &[&[0, 1, 2, 3], &[0], &[0], &[1]]);
        let cover = jagged.minimum_cover();
        assert!(covers(&jagged, &cover));
        assert_eq!(size(&cover), brute_force(&jagged));
        assert_eq!(size(&cover), 3);
        // random bipartite graphs against the brute force (every size within 7 + 7)
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 33) as u32
        };
        for _ in 0..300 {
            let (n_a, n_b) = (1 + next() as usize % 7, 1 + next() as usize % 7);
            let lists: Vec<Vec<u32>> = (0..n_a).map(|_| (0..n_b as u32).filter(|_| next() % 3 == 0).collect()).collect();
            let refs: Vec<&[u32]> = lists.iter().map(|l| &l[..]).collect();
            let c = crossing(n_b, &refs);
            let cover = c.minimum_cover();
            assert!(covers(&c, &cover), "{lists:?}");
            assert_eq!(size(&cover), brute_force(&c), "{lists:?}");
        }
    }
}

//! Element colouring: the hexahedra split into colours such that no two elements
//! of one colour share a node.
//!
//! Two elements without a common node have no common row (nor column) in the
//! stiffness matrix, so the elements of one colour can add their matrices into
//! the assembled values at the same time, each into entries no other one touches.
//! Summing colour after colour, in a fixed order, gives every entry the same
//! sequence of additions at any thread count.
//!
//! **Greedy, first fit.** Elements are taken in increasing index; each gets the
//! lowest colour that none of the elements sharing one of its nodes has. A node
//! keeps the set of colours of its elements as a bit set. A structured hexahedral
//! grid gets 8 colours (the parities of the three cell indices); an element's
//! colour never exceeds the number of elements it touches, so the bit sets are
//! sized from the largest node valence.

/// The colours of a set of elements: `elements[offsets[c]..offsets[c + 1]]` are
/// those of colour `c`, in increasing index.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Colouring {
    offsets: Vec<usize>,
    elements: Vec<u32>,
}

impl Colouring {
    /// Greedy first-fit colouring of `elements` (node lists) over `n_nodes` nodes.
    pub fn greedy<'a>(n_nodes: usize, elements: impl Iterator<Item = &'a [u32]> + Clone) -> Self {
        let mut valence = vec![0u32; n_nodes];
        let mut n_elements = 0;
        for nodes in elements.clone() {
            n_elements += 1;
            for &a in nodes {
                valence[a as usize] += 1;
            }
        }
        // an element meets at most Σ_a (valence_a − 1) others: that many colours + 1
        let max_nodes = elements.clone().map(<[u32]>::len).max().unwrap_or(0);
        let max_valence = valence.iter().copied().max().unwrap_or(0) as usize;
        let words = (max_nodes * max_valence.saturating_sub(1)).div_ceil(64) + 1;
        let mut used = vec![0u64; n_nodes * words];
        let mut colour = Vec::with_capacity(n_elements);
        let mut n_colours = 0;
        let mut forbidden = vec![0u64; words];
        for nodes in elements {
            forbidden.fill(0);
            for &a in nodes {
                let a = a as usize;
                for (f, u) in forbidden.iter_mut().zip(&used[a * words..(a + 1) * words]) {
                    *f |= u;
                }
            }
            let (w, bits) = forbidden.iter().enumerate().find(|(_, f)| **f != u64::MAX).map(|(w, f)| (w, *f)).expect("sized above for every element's neighbours");
            let c = 64 * w + (!bits).trailing_zeros() as usize;
            for &a in nodes {
                used[a as usize * words + w] |= 1 << (c % 64);
            }
            colour.push(c as u32);
            n_colours = n_colours.max(c + 1);
        }
        // counting sort by colour: increasing index within each colour
        let mut offsets = vec![0usize; n_colours + 1];
        for &c in &colour {
            offsets[c as usize + 1] += 1;
        }
        for c in 0..n_colours {
            offsets[c + 1] += offsets[c];
        }
        let mut fill = offsets.clone();
        let mut sorted = vec![0u32; colour.len()];
        for (e, &c) in colour.iter().enumerate() {
            sorted[fill[c as usize]] = e as u32;
            fill[c as usize] += 1;
        }
        Self { offsets, elements: sorted }
    }

    pub fn n_colours(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// The elements of colour `c`, in increasing index.
    pub fn colour(&self, c: usize) -> &[u32] {
        &self.elements[self.offsets[c]..self.offsets[c + 1]]
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        self.offsets.len() * std::mem::size_of::<usize>() + self.elements.len() * 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::pattern::structured_hex_grid;

    fn check(n_nodes: usize, elements: &[Vec<u32>], c: &Colouring) {
        let mut seen = vec![false; elements.len()];
        for k in 0..c.n_colours() {
            let mut owner = vec![u32::MAX; n_nodes];
            let col = c.colour(k);
            assert!(col.windows(2).all(|w| w[0] < w[1]), "increasing within colour {k}");
            for &e in col {
                assert!(!seen[e as usize], "element {e} coloured twice");
                seen[e as usize] = true;
                for &a in &elements[e as usize] {
                    assert_eq!(owner[a as usize], u32::MAX, "elements {} and {e} of colour {k} share node {a}", owner[a as usize]);
                    owner[a as usize] = e;
                }
            }
        }
        assert!(seen.iter().all(|&s| s), "every element has a colour");
    }

    #[test]
    fn a_structured_grid_takes_eight_colours_and_no_colour_shares_a_node() {
        let (nodes, hexes) = structured_hex_grid(5, 4, 3);
        let elements: Vec<Vec<u32>> = hexes.iter().map(|h| h.to_vec()).collect();
        let c = Colouring::greedy(nodes.len(), elements.iter().map(|e| &e[..]));
        check(nodes.len(), &elements, &c);
        assert_eq!(c.n_colours(), 8);
    }

    #[test]
    fn a_star_of_elements_around_one_node_needs_one_colour_each() {
        // 70 two-node "elements" all through node 0: 70 colours, past one 64-bit word
        let elements: Vec<Vec<u32>> = (1..=70u32).map(|a| vec![0, a]).collect();
        let c = Colouring::greedy(71, elements.iter().map(|e| &e[..]));
        check(71, &elements, &c);
        assert_eq!(c.n_colours(), 70);
    }

    #[test]
    fn no_elements_no_colours() {
        let c = Colouring::greedy(3, std::iter::empty::<&[u32]>());
        assert_eq!(c.n_colours(), 0);
    }
}

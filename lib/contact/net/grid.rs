//! One structured a × b grid: the paper's single patch (sec. 5).
//!
//! 1. Edges in exactly one face are the boundary. Each boundary node must have
//!    exactly two boundary neighbours; following them gives the boundary loops.
//!    More than one loop is a **hole** (a rectangle has one outline).
//! 2. A topological rectangle has exactly 4 **corners** (boundary nodes in exactly
//!    one face), every other boundary node in exactly 2 faces (a node in 3 faces is a
//!    re-entrant corner, e.g. of an L), and every interior node in exactly 4 faces.
//! 3. From the corner c₀ with the smallest node id, walk both boundary directions
//!    to the next corners: side 1 (direction ξ¹) gives a nodes, side 2 (ξ²) b nodes.
//!    Cell (i, j) is then the face that holds edge (i,j)–(i+1,j) and node (i,j+1);
//!    its fourth node is (i+1,j+1). Rows are filled j = 0, 1, …; every face must be
//!    used exactly once.
//! 4. Orientation: the patch normal n̄ = ā_1 × ā_2 / ‖ā_1 × ā_2‖ (eq. 4.3) must point
//!    out of the master body. Cell (i,j) is outward when its face's node cycle is
//!    (i,j) → (i+1,j) → (i+1,j+1) → (i,j+1). If all cells run the other way, j is
//!    flipped (ā_2 → −ā_2); a mix of both is an inconsistently oriented face set.

use std::collections::HashSet;

use super::surface::{edge, Surface};
use super::types::{ControlNet, NetError};

/// Order the faces of `s` into one structured grid (see the module docs).
pub(super) fn grid(s: &Surface) -> Result<ControlNet, NetError> {
    let set_name = s.name();
    let nf = s.quads.len();
    let (quads, edges, node_faces) = (&s.quads, &s.edges, &s.node_faces);
    let tag = |n: u32| s.tag(n);

    // 1. Boundary loops.
    let bnd = s.boundary_adjacency();
    if let Some((&n, nb)) = bnd.iter().find(|(_, nb)| nb.len() != 2) {
        return Err(NetError::NonRectangular {
            set: set_name,
            what: format!("boundary node {} is where {} boundary edges meet (faces touching only at a corner: {})", tag(n), nb.len(), s.describe_all(&node_faces[&n])),
        });
    }
    let mut seen: HashSet<u32> = HashSet::new();
    let mut loops = 0;
    for &start in bnd.keys() {
        if seen.contains(&start) {
            continue;
        }
        loops += 1;
        let (mut prev, mut cur) = (start, start);
        loop {
            seen.insert(cur);
            let nb = &bnd[&cur];
            let next = if nb[0] != prev { nb[0] } else { nb[1] };
            prev = cur;
            cur = next;
            if cur == start {
                break;
            }
        }
    }
    if loops != 1 {
        return Err(NetError::Hole { set: set_name, loops });
    }

    // 2. Corners, re-entrant corners, interior valence.
    let corners: Vec<u32> = bnd.keys().copied().filter(|n| node_faces[n].len() == 1).collect();
    if let Some(n) = bnd.keys().copied().find(|n| node_faces[n].len() > 2) {
        return Err(NetError::NonRectangular {
            set: set_name,
            what: format!("boundary node {} is a re-entrant corner in {} faces ({})", tag(n), node_faces[&n].len(), s.describe_all(&node_faces[&n])),
        });
    }
    if corners.len() != 4 {
        let list: Vec<String> = corners.iter().map(|&n| tag(n).to_string()).collect();
        return Err(NetError::NonRectangular {
            set: set_name,
            what: format!("{} corner nodes (nodes in exactly one face: {}), a rectangle has 4", corners.len(), list.join(", ")),
        });
    }
    if let Some((&n, fs)) = node_faces.iter().find(|(n, fs)| !bnd.contains_key(*n) && fs.len() != 4) {
        return Err(NetError::IrregularInterior { set: set_name, node: tag(n), count: fs.len(), faces: s.describe_all(fs) });
    }

    // 3. Walk the two sides from the first corner, then fill the rows.
    let c0 = corners[0];
    let side = |first: u32| -> Vec<u32> {
        let mut out = vec![c0, first];
        let (mut prev, mut cur) = (c0, first);
        while node_faces[&cur].len() != 1 {
            let nb = &bnd[&cur];
            let next = if nb[0] != prev { nb[0] } else { nb[1] };
            prev = cur;
            cur = next;
            out.push(cur);
        }
        out
    };
    let (nb0, nb1) = (bnd[&c0][0].min(bnd[&c0][1]), bnd[&c0][0].max(bnd[&c0][1]));
    let row0 = side(nb0);
    let col0 = side(nb1);
    let (a, b) = (row0.len(), col0.len());
    let not_grid = |what: String| NetError::NotAGrid { set: set_name.clone(), what };
    if (a - 1) * (b - 1) != nf {
        return Err(not_grid(format!("its sides have {a} and {b} nodes, so a grid would have {} faces, but the set has {nf}", (a - 1) * (b - 1))));
    }
    let mut nodes = vec![u32::MAX; a * b];
    nodes[..a].copy_from_slice(&row0);
    for (j, &n) in col0.iter().enumerate() {
        nodes[a * j] = n;
    }
    let mut used = vec![false; nf];
    // cell_face[i + (a-1) j]
    let mut cell_face = vec![0usize; nf];
    for j in 0..b - 1 {
        for i in 0..a - 1 {
            let (p00, p10, p01) = (nodes[i + a * j], nodes[i + 1 + a * j], nodes[i + a * (j + 1)]);
            let candidates = edges.get(&edge(p00, p10)).map(Vec::as_slice).unwrap_or(&[]);
            let Some(&k) = candidates.iter().find(|&&k| !used[k] && quads[k].contains(&p01) && quads[k].contains(&p00)) else {
                return Err(not_grid(format!("no face continues the grid at nodes {}, {}, {}", tag(p00), tag(p10), tag(p01))));
            };
            let Some(&p11) = quads[k].iter().find(|n| ![p00, p10, p01].contains(*n)) else {
                return Err(not_grid(format!("{} is degenerate", s.describe(k))));
            };
            let slot = &mut nodes[i + 1 + a * (j + 1)];
            if *slot != u32::MAX && *slot != p11 {
                return Err(not_grid(format!("{} does not close the grid cell ({i}, {j})", s.describe(k))));
            }
            *slot = p11;
            used[k] = true;
            cell_face[i + (a - 1) * j] = k;
        }
    }

    // 4. Orientation: +1 if the face cycle runs (i,j)→(i+1,j)→…, −1 otherwise.
    let sense = |c: usize| -> i32 {
        let (i, j) = (c % (a - 1), c / (a - 1));
        let q = quads[cell_face[c]];
        let p00 = nodes[i + a * j];
        let p10 = nodes[i + 1 + a * j];
        let pos = q.iter().position(|&n| n == p00).unwrap_or(0);
        if q[(pos + 1) % 4] == p10 {
            1
        } else {
            -1
        }
    };
    let s0 = sense(0);
    if let Some(c) = (1..nf).find(|&c| sense(c) != s0) {
        return Err(NetError::Orientation { set: set_name, face: s.describe(cell_face[c]), other: s.describe(cell_face[0]) });
    }
    if s0 < 0 {
        // Flip j: row j becomes row b-1-j, so ā_2 changes sign and n̄ points outward.
        let flipped: Vec<u32> = (0..a * b).map(|p| nodes[p % a + a * (b - 1 - p / a)]).collect();
        nodes = flipped;
    }
    Ok(ControlNet { a, b, nodes })
}

//! Several rectangular grids: a box corner, an L, a gmsh surface made of several
//! transfinite patches. One B-spline patch per grid, C⁰ where two patches meet.
//!
//! The patch layout is read off the mesh by its **separatrices**. A node is
//! *irregular* when it is interior and not in 4 faces, or on the boundary and in 3
//! or more faces (a re-entrant corner). From every irregular node, each interior edge
//! is followed straight on (through a regular interior node, the edge that shares no
//! face with the incoming one) until it reaches the boundary or another irregular
//! node. These lines cut the surface; every piece must then be one structured grid
//! ([`super::grid`]). A block-structured mesh — several transfinite surfaces glued
//! conformally — always splits this way: its patch edges run between irregular
//! nodes and the boundary.

use std::collections::BTreeSet;

use super::grid::grid;
use super::surface::{edge, Surface};
use super::types::{ControlNet, NetError};

/// The grids of `s`, in the order of their smallest face position.
pub(super) fn patches(s: &Surface) -> Result<Vec<ControlNet>, NetError> {
    let fail = |what: String| NetError::NotPatches { set: s.name(), what };
    s.check_orientation()?;
    s.check_vertex_fans()?;
    let irregular = |n: u32| -> bool {
        let v = s.valence(n);
        if s.is_boundary(n) {
            v >= 3
        } else {
            v != 4
        }
    };
    // Cut along the separatrices.
    let mut cut: BTreeSet<(u32, u32)> = BTreeSet::new();
    for &v in s.node_faces.keys().filter(|&&n| irregular(n)) {
        for w0 in s.neighbours(v) {
            let mut e = (v, w0);
            while s.edges[&edge(e.0, e.1)].len() == 2 && cut.insert(edge(e.0, e.1)) {
                let (u, w) = e;
                if s.is_boundary(w) || irregular(w) {
                    break;
                }
                // The edge at w that shares no face with (u, w).
                let beside: BTreeSet<u32> = s.edges[&edge(u, w)].iter().flat_map(|&k| s.quads[k]).collect();
                let Some(next) = s.neighbours(w).into_iter().find(|m| !beside.contains(m)) else {
                    break;
                };
                e = (w, next);
            }
        }
    }
    // Pieces: faces joined across edges that are not cut.
    let nf = s.quads.len();
    let mut piece = vec![usize::MAX; nf];
    let mut pieces: Vec<Vec<usize>> = Vec::new();
    for start in 0..nf {
        if piece[start] != usize::MAX {
            continue;
        }
        let id = pieces.len();
        let mut members = vec![start];
        piece[start] = id;
        let mut i = 0;
        while i < members.len() {
            let q = s.quads[members[i]];
            for c in 0..4 {
                let e = edge(q[c], q[(c + 1) % 4]);
                if cut.contains(&e) {
                    continue;
                }
                for &f in &s.edges[&e] {
                    if piece[f] == usize::MAX {
                        piece[f] = id;
                        members.push(f);
                    }
                }
            }
            i += 1;
        }
        members.sort_unstable();
        pieces.push(members);
    }
    let mut nets = Vec::with_capacity(pieces.len());
    for (p, members) in pieces.iter().enumerate() {
        let sub = s.subset(members);
        let net = grid(&sub).map_err(|e| fail(format!("piece {} of {} ({} faces, first {}) is not one grid: {e}", p + 1, pieces.len(), members.len(), s.describe(members[0]))))?;
        nets.push(net);
    }
    Ok(nets)
}

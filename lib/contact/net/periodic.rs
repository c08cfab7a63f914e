//! A grid closed in one direction: a tube, a shaft, a roller (the periodic patch).
//!
//! The surface is an annulus of quads: two boundary loops, every boundary node in 2
//! faces and every interior node in 4. Row j = 0 is the boundary loop through the
//! smallest boundary node id, walked the way its faces run it, so that each cell's
//! node cycle is (i,j) → (i+1,j) → (i+1,j+1) → (i,j+1) and n̄ = ā_1 × ā_2/‖·‖ points
//! out of the body (eq. 4.3). Row j+1 is read off the faces on row j; the walk ends
//! on the other boundary loop. The index i runs around the tube and wraps: column a
//! is column 0, so ξ¹ is the closed (periodic) direction.

use std::collections::BTreeSet;

use super::surface::{edge, Surface};
use super::types::{ControlNet, NetError};

/// Order the faces of `s` into an a × b grid closed along ξ¹.
pub(super) fn periodic(s: &Surface) -> Result<ControlNet, NetError> {
    let fail = |what: String| NetError::NotPeriodic { set: s.name(), what };
    s.check_orientation()?;
    s.check_vertex_fans()?;
    let loops = s.boundary_loops();
    if loops.len() != 2 {
        return Err(fail(format!("its boundary is {} closed loops; a tube (a band closed on itself) has 2", loops.len())));
    }
    for (&n, fs) in &s.node_faces {
        let want = if s.is_boundary(n) { 2 } else { 4 };
        if fs.len() != want {
            return Err(fail(format!("node {} is in {} faces, a closed grid has {want} there ({})", s.tag(n), fs.len(), s.describe_all(fs))));
        }
    }
    let first = loops.iter().map(|l| l.iter().copied().min().unwrap_or(u32::MAX)).min().unwrap_or(u32::MAX);
    let Some(lp) = loops.iter().find(|l| l.contains(&first)) else {
        return Err(fail("no boundary loop".into()));
    };
    // Row 0: start at `first`, walk so that the face on each edge runs it forward.
    let pos = lp.iter().position(|&n| n == first).unwrap_or(0);
    let mut row: Vec<u32> = lp[pos..].iter().chain(&lp[..pos]).copied().collect();
    let runs_forward = |u: u32, v: u32| -> Option<([u32; 4], usize)> {
        s.edges.get(&edge(u, v))?.iter().find_map(|&k| {
            let q = s.quads[k];
            let c = q.iter().position(|&m| m == u)?;
            (q[(c + 1) % 4] == v).then_some((q, c))
        })
    };
    if runs_forward(row[0], row[1]).is_none() {
        row[1..].reverse();
    }
    let a = row.len();
    let mut nodes = row.clone();
    let mut used: BTreeSet<u32> = row.iter().copied().collect();
    let mut faces_used = 0;
    loop {
        let j = nodes.len() / a - 1;
        let mut next = vec![u32::MAX; a];
        for i in 0..a {
            let (p00, p10) = (row[i], row[(i + 1) % a]);
            let Some((q, c)) = runs_forward(p00, p10) else {
                return Err(fail(format!("no face runs the edge from node {} to node {} of row {j}", s.tag(p00), s.tag(p10))));
            };
            faces_used += 1;
            let (p11, p01) = (q[(c + 2) % 4], q[(c + 3) % 4]);
            for (slot, p) in [(i, p01), ((i + 1) % a, p11)] {
                if next[slot] != u32::MAX && next[slot] != p {
                    return Err(fail(format!("the faces above row {j} do not agree on node {} of row {}", s.tag(next[slot]), j + 1)));
                }
                next[slot] = p;
            }
        }
        if next.iter().any(|n| used.contains(n)) || next.iter().collect::<BTreeSet<_>>().len() != a {
            return Err(fail(format!("row {} meets a row already placed (the band is twisted or not a grid)", j + 1)));
        }
        used.extend(next.iter().copied());
        nodes.extend_from_slice(&next);
        let done = next.iter().all(|&n| s.is_boundary(n));
        row = next;
        if done {
            break;
        }
        if nodes.len() > s.node_faces.len() {
            return Err(fail("the rows never reach the other boundary loop".into()));
        }
    }
    let b = nodes.len() / a;
    if faces_used != s.quads.len() || nodes.len() != s.node_faces.len() {
        return Err(fail(format!("the closed grid holds {} of the {} faces", faces_used, s.quads.len())));
    }
    Ok(ControlNet { a, b, nodes })
}

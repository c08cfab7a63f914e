//! Reading a master face set into a net of the shape asked for, or the first that
//! fits (`NetChoice::Auto`).

use super::surface::Surface;
use super::types::{ControlNet, MasterNet, NetChoice, NetError, NetShape, PatchNet};
use super::{grid, patches, periodic};
use crate::mesh::Mesh;

/// Order the face set `name` of `mesh` into one structured grid ([`grid`]).
pub fn control_net(mesh: &Mesh, name: &str) -> Result<ControlNet, NetError> {
    grid::grid(&Surface::of_set(mesh, name)?)
}

/// Order the face set `name` as `choice` asks; `Auto` takes the first of one grid,
/// a closed grid, several grids and any quad surface that fits, and says which.
pub fn master_net(mesh: &Mesh, name: &str, choice: NetChoice) -> Result<MasterNet, NetError> {
    let s = Surface::of_set(mesh, name)?;
    match choice {
        NetChoice::Grid => Ok(grid::grid(&s)?.into()),
        NetChoice::Periodic => {
            let net = periodic::periodic(&s)?;
            Ok(MasterNet { shape: NetShape::Periodic { a: net.a, b: net.b }, nodes: net.nodes })
        }
        NetChoice::Patches => Ok(from_patches(patches::patches(&s)?)),
        NetChoice::Quads => quads(&s),
        NetChoice::Auto => {
            if let Ok(net) = grid::grid(&s) {
                return Ok(net.into());
            }
            if let Ok(net) = periodic::periodic(&s) {
                return Ok(MasterNet { shape: NetShape::Periodic { a: net.a, b: net.b }, nodes: net.nodes });
            }
            if let Ok(ps) = patches::patches(&s) {
                if ps.len() > 1 {
                    return Ok(from_patches(ps));
                }
            }
            quads(&s)
        }
    }
}

/// Several grids over one node list (first appearance order).
fn from_patches(ps: Vec<ControlNet>) -> MasterNet {
    let mut nodes: Vec<u32> = Vec::new();
    let mut pos: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    let patches = ps
        .into_iter()
        .map(|net| {
            let local = net
                .nodes
                .iter()
                .map(|&n| {
                    *pos.entry(n).or_insert_with(|| {
                        nodes.push(n);
                        nodes.len() as u32 - 1
                    })
                })
                .collect();
            PatchNet { a: net.a, b: net.b, nodes: local }
        })
        .collect();
    MasterNet { nodes, shape: NetShape::Patches(patches) }
}

/// Any manifold, consistently oriented quad surface; nodes in first-appearance order.
fn quads(s: &Surface) -> Result<MasterNet, NetError> {
    s.check_orientation()?;
    s.check_vertex_fans()?;
    let mut nodes: Vec<u32> = Vec::new();
    let mut pos: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    let faces = s
        .quads
        .iter()
        .map(|q| {
            q.map(|n| {
                *pos.entry(n).or_insert_with(|| {
                    nodes.push(n);
                    nodes.len() as u32 - 1
                })
            })
        })
        .collect();
    Ok(MasterNet { nodes, shape: NetShape::Quads(faces) })
}

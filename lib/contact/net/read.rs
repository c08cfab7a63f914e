//! Reading a master face set into a net of the shape asked for, or into the smooth
//! master that fits it best for the B-spline orders given ([`smooth_net`]).

use super::surface::Surface;
use super::types::{ControlNet, MasterNet, NetChoice, NetError, NetShape, PatchNet, SmoothNet, SmoothNetError};
use super::{grid, patches, periodic};
use crate::mesh::Mesh;

/// Order the face set `name` of `mesh` into one structured grid ([`grid`]).
pub fn control_net(mesh: &Mesh, name: &str) -> Result<ControlNet, NetError> {
    grid::grid(&Surface::of_set(mesh, name)?)
}

/// Order the face set `name` as `choice` asks.
pub fn master_net(mesh: &Mesh, name: &str, choice: NetChoice) -> Result<MasterNet, NetError> {
    let s = Surface::of_set(mesh, name)?;
    match choice {
        NetChoice::Grid => Ok(grid::grid(&s)?.into()),
        NetChoice::Periodic => Ok(closed(periodic::periodic(&s)?)),
        NetChoice::Patches => Ok(from_patches(patches::patches(&s)?)),
        NetChoice::Quads => quads(&s),
        NetChoice::GridOrQuads => match grid::grid(&s) {
            Ok(net) => Ok(net.into()),
            Err(_) => quads(&s),
        },
    }
}

/// The smooth master of the face set `name` for B-spline orders `orders`: the first
/// that fits of one grid (the paper's patch, open knots), a grid closed on itself
/// (periodic knots along ξ¹), several grids (one patch each, every grid large enough
/// for the orders) and, for any other manifold quad surface, the Catmull–Clark limit
/// surface ([`check_subdivision`]). The face set is read and checked once; each shape
/// is tried on it. One grid or a closed grid too small for the orders is an error,
/// not a reason to try the next shape.
pub fn smooth_net(mesh: &Mesh, name: &str, orders: [usize; 2]) -> Result<SmoothNet, SmoothNetError> {
    let s = Surface::of_set(mesh, name)?;
    let fits = |net: MasterNet| match net.check_orders(orders) {
        Ok(()) => Ok(SmoothNet::Bspline(net)),
        Err(source) => Err(SmoothNetError::Orders { net, source }),
    };
    let grid = match grid::grid(&s) {
        Ok(net) => return fits(net.into()),
        Err(e) => e.to_string(),
    };
    if let Ok(net) = periodic::periodic(&s) {
        return fits(closed(net));
    }
    let patches = match patches::patches(&s) {
        Ok(ps) => {
            let net = from_patches(ps);
            match net.check_orders(orders) {
                Ok(()) => return Ok(SmoothNet::Bspline(net)),
                Err(e) => format!("it splits into {}, too small for orders {orders:?}: {e}", net.describe()),
            }
        }
        Err(e) => e.to_string(),
    };
    let net = quads(&s)?;
    match check_subdivision(mesh, name, &net) {
        Ok(()) => Ok(SmoothNet::Subdivision(net)),
        Err(subdivision) => Err(SmoothNetError::NoShape { grid, patches, subdivision }),
    }
}

/// Whether the Catmull–Clark surface can be built on `net`, the quads of the face set
/// `master` (interior valences 3–14, a support of at most 36 nodes per face), the culprit named
/// by gmsh tags.
pub fn check_subdivision(mesh: &Mesh, master: &str, net: &MasterNet) -> Result<(), String> {
    use crate::spline::subdivision::SubdivisionError as E;
    let Err(e) = crate::spline::Atlas::subdivision(net.nodes.len(), net.cells()) else { return Ok(()) };
    let node = |k: u32| net.nodes.get(k as usize).and_then(|&n| mesh.node_tags.get(n as usize)).copied().unwrap_or(k as u64);
    let face = |f: usize| {
        let set = mesh.face_set(master);
        let quad = set.and_then(|s| s.quad_tags.get(f)).copied().unwrap_or(f as u64);
        format!("quad {quad}")
    };
    Err(match e {
        E::ValenceTooLow { node: k, valence } => format!("interior node {} (gmsh tag) has valence {valence}; Catmull–Clark needs at least 3", node(k)),
        E::ValenceTooHigh { node: k, valence, max } => format!("interior node {} (gmsh tag) has valence {valence}, above the supported {max}", node(k)),
        E::NonManifoldVertex { node: k, .. } => format!("the faces around node {} (gmsh tag) do not form one fan", node(k)),
        E::SupportTooLarge { face: f, nodes, max } => format!("{} depends on {nodes} nodes, more than {max}", face(f)),
        E::StencilIncomplete { face: f } => format!("the faces around the corners of {} do not form a Catmull–Clark stencil (a mesh too small or folded there)", face(f)),
        other => other.to_string(),
    })
}

/// One grid closed along ξ¹.
fn closed(net: ControlNet) -> MasterNet {
    MasterNet { shape: NetShape::Periodic { a: net.a, b: net.b }, nodes: net.nodes }
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

//! Benchmark: write and read back a `.scmesh` of a 100×100×100 hex grid
//! (1,030,301 nodes, 1,000,000 hexahedra, two node sets, one face set).
//! Target (issue 2): under 3 s for write + read on the 2-core machine.
//!
//! cargo bench --bench stage_io

use std::time::Instant;

use splinecontact::format::scmesh;
use splinecontact::mesh::{Body, FaceSet, HexFace, Mesh, NodeSet};

fn grid(n: u32) -> Mesh {
    let np = n + 1;
    let id = |i: u32, j: u32, k: u32| i + np * (j + np * k);
    let mut nodes = Vec::with_capacity((np * np * np) as usize);
    for k in 0..np {
        for j in 0..np {
            for i in 0..np {
                nodes.push([i as f64 / n as f64, j as f64 / n as f64 * 1.1, k as f64 / n as f64 * 0.7]);
            }
        }
    }
    let mut hexes = Vec::with_capacity((n * n * n) as usize);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                hexes.push([id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)]);
            }
        }
    }
    let m = hexes.len();
    let base: Vec<u32> = (0..np * np).collect();
    let top_faces: Vec<HexFace> = (0..n * n).map(|e| HexFace { element: (n * n * (n - 1) + e), local: 1 }).collect();
    Mesh {
        node_tags: (1..=nodes.len() as u64).collect(),
        nodes,
        hexes,
        hex_body: vec![0; m],
        bodies: vec![Body { name: "block".into(), physical_tag: 1 }],
        node_sets: vec![NodeSet { name: "base".into(), physical_tag: 2, dim: 2, nodes: base }],
        face_sets: vec![FaceSet { name: "top".into(), physical_tag: 3, quad_tags: (1..=top_faces.len() as u64).collect(), faces: top_faces }],
        element_tags: (1..=m as u64).collect(),
    }
}

fn main() {
    let mesh = grid(100);
    let dir = std::env::temp_dir().join(format!("sc-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("grid.scmesh");
    let t = Instant::now();
    scmesh::write(&path, &mesh, "bench").unwrap();
    let write = t.elapsed().as_secs_f64();
    let size = std::fs::metadata(&path).unwrap().len();
    let t = Instant::now();
    let back = scmesh::read(&path).unwrap();
    let read = t.elapsed().as_secs_f64();
    assert!(back == mesh, "round trip differs");
    println!("scmesh {} nodes, {} hexes, {:.1} MB: write {write:.3} s, read {read:.3} s, total {:.3} s (target < 3 s)", mesh.nodes.len(), mesh.hexes.len(), size as f64 / 1e6, write + read);
    std::fs::remove_dir_all(&dir).ok();
}

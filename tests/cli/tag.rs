//! sc-tag: master control nets on real and hand-built meshes, every refusal with its
//! message, the .sccontact round trip, and sc-export of a contact model read by meshio.

use std::path::{Path, PathBuf};

use splinecontact::format::scmesh;
use splinecontact::format::sccontact::{ContactModel, MasterKind, SlaveKind};
use splinecontact::mesh::{FaceSet, Mesh};
use splinecontact::spline::{BSplinePatch, Vec3};

use crate::common::grid::block;
use crate::common::*;

/// The committed Parisch mesh imported into `dir/m.scmesh`.
fn parisch_scmesh(dir: &Path) -> PathBuf {
    let out = dir.join("m.scmesh");
    let o = run("sc-import", &[repo().join("meshes/parisch.msh").to_str().unwrap(), "-o", out.to_str().unwrap(), "--quiet"], dir);
    assert!(o.status.success(), "{}", stderr(&o));
    out
}

fn write_mesh(dir: &Path, mesh: &Mesh) -> PathBuf {
    let p = dir.join("m.scmesh");
    scmesh::write(&p, mesh, "test").unwrap();
    p
}

fn tag(dir: &Path, mesh: &Path, pairs: &[&str]) -> (std::process::Output, PathBuf) {
    let out = dir.join("c.sccontact");
    let mut args = vec![mesh.to_str().unwrap().to_string(), "-o".into(), out.to_str().unwrap().into()];
    for p in pairs {
        args.push("--pair".into());
        args.push(p.to_string());
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    (run("sc-tag", &args, dir), out)
}

/// n̄ of the B-spline patch at ξ̄ over the pair's net.
fn normal_at(model: &ContactModel, pair: usize, xi: [f64; 2]) -> Vec3 {
    let p = &model.pairs[pair];
    let patch = BSplinePatch::new(p.net.grid().unwrap().a, p.net.grid().unwrap().b, p.orders[0], p.orders[1]).unwrap();
    let x: Vec<Vec3> = p.net.nodes.iter().map(|&n| Vec3::from(model.mesh.nodes[n as usize])).collect();
    patch.evaluate(&x, xi).n_bar
}

#[test]
fn parisch_master_is_a_4x4_net_facing_up() {
    let dir = tempdir();
    let mesh = parisch_scmesh(dir.path());
    let (o, out) = tag(dir.path(), &mesh, &["contact:upper_bottom:lower_top:bspline:3:3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let m = ContactModel::read(&out).unwrap();
    let p = &m.pairs[0];
    assert_eq!((p.net.grid().unwrap().a, p.net.grid().unwrap().b, p.orders, p.master_kind, p.slave_kind), (4, 4, [3, 3], MasterKind::Bspline, SlaveKind::FaceSet));
    assert_eq!(p.slave_nodes.len(), 9);
    let lower = m.mesh.body("lower").unwrap() as u32;
    for (k, &n) in p.net.nodes.iter().enumerate() {
        let x = m.mesh.nodes[n as usize];
        assert_eq!(x[2], 10.0, "net node {k} is not on the lower block's top");
        // Grid order: neighbours in i and j are 10 mm apart along one axis.
        let (i, j) = (k % 4, k / 4);
        if i > 0 {
            let y = m.mesh.nodes[p.net.grid().unwrap().at(i - 1, j) as usize];
            assert!(((x[0] - y[0]).abs() + (x[1] - y[1]).abs() - 10.0).abs() < 1e-9);
        }
    }
    assert!(m.mesh.hexes.iter().zip(&m.mesh.hex_body).any(|(h, &b)| b == lower && h.contains(&p.net.grid().unwrap().at(0, 0))));
    for xi in [[0.0, 0.0], [0.5, 0.5], [0.9, 0.2]] {
        let n = normal_at(&m, 0, xi);
        assert!((n.z - 1.0).abs() < 1e-12, "n̄ at {xi:?} = {n:?}: must point +z, out of the lower block");
    }
}

#[test]
fn block_faces_give_outward_nets_flipping_j_when_needed() {
    let dir = tempdir();
    let mesh = write_mesh(dir.path(), &block([3, 2, 4], [3.0, 2.0, 4.0], 0.0));
    let pairs = ["top:origin:z1", "bottom:origin:z0", "left:x1:x0:bspline:3:4", "front:origin:y0:facet"];
    let (o, out) = tag(dir.path(), &mesh, &pairs);
    assert!(o.status.success(), "{}", stderr(&o));
    let m = ContactModel::read(&out).unwrap();
    let expect = [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]];
    for (k, e) in expect.iter().enumerate() {
        let p = &m.pairs[k];
        let sizes = [(4, 3), (4, 3), (3, 5), (4, 5)];
        assert_eq!((p.net.nodes.len()), sizes[k].0 * sizes[k].1, "pair {}", p.name);
        let n = if p.master_kind == MasterKind::Facet {
            let mut q = p.clone();
            q.orders = [2, 2];
            let mm = ContactModel { pairs: vec![q], ..m.clone() };
            normal_at(&mm, 0, [0.3, 0.6])
        } else {
            normal_at(&m, k, [0.3, 0.6])
        };
        assert!((n - Vec3::from(*e)).norm() < 1e-12, "pair {}: n̄ = {n:?}, outward is {e:?}", p.name);
    }
    assert_eq!(m.pairs[0].slave_kind, SlaveKind::NodeSet);
}

/// A face set spanning two perpendicular faces of a block (z1 ∪ x1) is still a
/// topological rectangle (folded along the shared edge): it is accepted.
#[test]
fn folded_face_set_is_a_grid() {
    let dir = tempdir();
    let mut b = block([2, 2, 2], [1.0; 3], 0.0);
    let (z1, x1) = (b.face_set("z1").unwrap().clone(), b.face_set("x1").unwrap().clone());
    b.face_sets.push(FaceSet { name: "fold".into(), physical_tag: 0, faces: [z1.faces, x1.faces].concat(), quad_tags: [z1.quad_tags, x1.quad_tags].concat() });
    let mesh = write_mesh(dir.path(), &b);
    let (o, out) = tag(dir.path(), &mesh, &["p:origin:fold:bspline:3:3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let m = ContactModel::read(&out).unwrap();
    assert_eq!(m.pairs[0].net.nodes.len(), 15);
}

/// A mesh of `block` with face set "m" = the z1 faces that pass `keep` (by hex index).
fn block_with_top(n: [usize; 3], keep: impl Fn(u32) -> bool) -> Mesh {
    let mut b = block(n, [n[0] as f64, n[1] as f64, n[2] as f64], 0.0);
    let z1 = b.face_set("z1").unwrap().clone();
    let (faces, tags): (Vec<_>, Vec<_>) = z1.faces.iter().zip(1..).filter(|(f, _)| keep(f.element)).map(|(f, t)| (*f, 500 + t as u64)).unzip();
    b.face_sets.push(FaceSet { name: "m".into(), physical_tag: 0, faces, quad_tags: tags });
    b
}

fn refused(mesh: &Mesh, pair: &str, needles: &[&str]) {
    let dir = tempdir();
    let p = write_mesh(dir.path(), mesh);
    let (o, out) = tag(dir.path(), &p, &[pair]);
    assert_fails(&o, 2, needles, &out);
}

#[test]
fn hole_gets_a_subdivision_master() {
    // 3×3 top faces minus the centre one (hex 4): no grid, pieces of one face each, so
    // one patch is refused with its reason; the hole's four corners are boundary nodes
    // in 3 faces, which the Catmull–Clark master takes (corner rule), so `bspline`
    // chooses it and says so.
    let m = block_with_top([3, 3, 1], |e| e != 4);
    refused(&m, "p:origin:m:patch", &["pair 'p': master face set 'm' has a hole", "2 closed loops"]);
    let dir = tempdir();
    let p = write_mesh(dir.path(), &m);
    let (o, out) = tag(dir.path(), &p, &["s:origin:m", "f:origin:m:facet", "b:origin:m:bspline:2:2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("against master 'm', 8 quads on 16 nodes, subdivision orders [4, 4]"), "{e}");
    // facets take any quad set; bilinear B-spline patches fit the one-face pieces
    assert!(e.contains("against master 'm', 8 quads on 16 nodes, facet orders [2, 2]") && e.contains("8 grids (2 × 2, 2 × 2, 2 × 2, 2 × 2, 2 × 2, 2 × 2, 2 × 2, 2 × 2), multipatch bspline orders [2, 2]"), "{e}");
    assert_eq!(ContactModel::read(&out).unwrap().pairs.len(), 3);
}

#[test]
fn l_shape_is_refused_as_one_patch_and_taken_by_subdivision() {
    // 2×2 top faces minus hex 3's: one patch names the re-entrant corner with its
    // faces; `bspline` takes the Catmull–Clark surface, the corner interpolated.
    let m = block_with_top([2, 2, 1], |e| e != 3);
    refused(&m, "p:origin:m:patch", &["non-rectangular outline", "re-entrant corner in 3 faces", "quad 501 (face 1 of hex 1)"]);
    let dir = tempdir();
    let p = write_mesh(dir.path(), &m);
    let (o, out) = tag(dir.path(), &p, &["p:origin:m"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("3 quads on 8 nodes, subdivision orders [4, 4]"), "{}", stderr(&o));
    assert_eq!(ContactModel::read(&out).unwrap().pairs.len(), 1);
}

/// The box of issue 26, meshed by gmsh with all hexahedra but unstructured
/// (`tests/data/gmsh/allhex_box.geo`): its top has boundary nodes in 1 and 3 faces.
/// One patch is refused, naming such a node; `bspline` takes the Catmull–Clark
/// surface, which is the flat top: every face evaluated on a 5 × 5 grid of
/// parameters lies on z = 0.3 inside the unit square.
#[test]
fn an_unstructured_gmsh_box_top_gets_a_subdivision_master() {
    let dir = tempdir();
    let mesh = dir.path().join("m.scmesh");
    let msh = repo().join("tests/data/gmsh/allhex_box.msh");
    let o = run("sc-import", &[msh.to_str().unwrap(), "-o", mesh.to_str().unwrap(), "--quiet"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let (o, _) = tag(dir.path(), &mesh, &["p:bottom:top:patch"]);
    assert!(!o.status.success() && stderr(&o).contains("is a re-entrant corner in 3 faces"), "{}", stderr(&o));
    let (o, out) = tag(dir.path(), &mesh, &["c:bottom:top"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("against master 'top', 42 quads on 51 nodes, subdivision orders [4, 4]"), "{}", stderr(&o));
    let m = ContactModel::read(&out).unwrap();
    let p = &m.pairs[0];
    assert_eq!(p.master_kind, MasterKind::Subdivision);
    let cells = p.net.cells();
    let atlas = splinecontact::spline::Atlas::subdivision(p.net.nodes.len(), cells.clone()).unwrap();
    let x: Vec<Vec3> = p.net.nodes.iter().map(|&n| Vec3::from(m.mesh.nodes[n as usize])).collect();
    let mut atlas = atlas;
    atlas.update(&x).unwrap();
    let mut worst = 0.0f64;
    for chart in 0..cells.len() {
        for i in 0..5 {
            for j in 0..5 {
                let sp = atlas.evaluate(chart, [i as f64 / 4.0, j as f64 / 4.0]);
                worst = worst.max((sp.x_bar.z - 0.3).abs());
                assert!((-1e-12..=1.0 + 1e-12).contains(&sp.x_bar.x) && (-1e-12..=1.0 + 1e-12).contains(&sp.x_bar.y), "chart {chart}: {:?}", sp.x_bar);
                assert!(sp.n_bar.z > 1.0 - 1e-12, "chart {chart}: n̄ = {:?}", sp.n_bar);
            }
        }
    }
    assert!(worst < 1e-14, "the flat top is not flat: {worst:e}");
}

/// A fan of 15 hexahedra around a vertical edge: the top's centre node has valence
/// 15, above the 14 a Catmull–Clark stencil of 36 nodes holds. No smooth master fits
/// (one grid, 15 one-cell grids too small for orders [3, 3], subdivision), and each
/// reason is given; facets take it.
#[test]
fn a_node_of_valence_15_has_no_smooth_master() {
    let n = 15;
    let mut nodes = Vec::new();
    for z in [0.0, 1.0] {
        nodes.push(Vec3::new(0.0, 0.0, z));
        for i in 0..n {
            let th = std::f64::consts::TAU * i as f64 / n as f64;
            let th2 = std::f64::consts::TAU * (i as f64 + 0.5) / n as f64;
            nodes.push(Vec3::new(th.cos(), th.sin(), z)); // e_i
            nodes.push(Vec3::new(1.3 * th2.cos(), 1.3 * th2.sin(), z)); // f_i
        }
    }
    let layer = (1 + 2 * n) as u32;
    let (e, f) = (|i: usize| 1 + 2 * (i % n) as u32, |i: usize| 2 + 2 * (i % n) as u32);
    let hexes: Vec<[u32; 8]> = (0..n).map(|i| [0, e(i), f(i), e(i + 1), layer, layer + e(i), layer + f(i), layer + e(i + 1)]).collect();
    let top: Vec<splinecontact::mesh::HexFace> = (0..n as u32).map(|h| splinecontact::mesh::HexFace { element: h, local: 1 }).collect();
    let m = Mesh {
        node_tags: (1..=nodes.len() as u64).collect(),
        nodes: nodes.iter().map(|p| [p.x, p.y, p.z]).collect(),
        hex_body: vec![0; n],
        hexes,
        bodies: vec![splinecontact::mesh::Body { name: "b".into(), physical_tag: 1 }],
        node_sets: vec![splinecontact::mesh::NodeSet { name: "origin".into(), physical_tag: 2, dim: 0, nodes: vec![0] }],
        face_sets: vec![FaceSet { name: "m".into(), physical_tag: 3, quad_tags: (1..=n as u64).collect(), faces: top }],
        element_tags: (1..=n as u64).collect(),
    };
    refused(&m, "p:origin:m", &["pair 'p': master face set 'm' has no smooth master", "one grid:", "several grids: it splits into 15 grids", "too small for orders [3, 3]", "subdivision:", "valence 15"]);
    let dir = tempdir();
    let p = write_mesh(dir.path(), &m);
    let (o, _) = tag(dir.path(), &p, &["f:origin:m:facet"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn faces_meeting_at_a_point_are_refused() {
    let m = block_with_top([2, 2, 1], |e| e == 0 || e == 3);
    refused(&m, "p:origin:m:patch", &["non-rectangular outline", "4 boundary edges meet"]);
    for kind in ["bspline", "facet", "subdivision"] {
        refused(&m, &format!("p:origin:m:{kind}"), &["is not a manifold surface at node 14 (gmsh tag)", "quad 501 (face 1 of hex 1)", "quad 504 (face 1 of hex 4)"]);
    }
}

#[test]
fn branch_is_refused() {
    // The top of a 2×1 block plus the interior face between its two hexes: three
    // faces on one edge.
    let mut b = block_with_top([2, 1, 1], |_| true);
    let s = b.face_sets.last_mut().unwrap();
    s.faces.push(splinecontact::mesh::HexFace { element: 0, local: 3 });
    s.quad_tags.push(999);
    refused(&b, "p:origin:m", &["face set 'm' branches", "shared by 3 faces", "quad 999 (face 3 of hex 1)"]);
}

#[test]
fn face_set_spanning_two_bodies_is_refused() {
    let dir = tempdir();
    let mut mesh = scmesh::read(&parisch_scmesh(dir.path())).unwrap();
    let (a, b) = (mesh.face_set("lower_top").unwrap().clone(), mesh.face_set("upper_bottom").unwrap().clone());
    mesh.face_sets.push(FaceSet { name: "both".into(), physical_tag: 0, faces: [a.faces, b.faces].concat(), quad_tags: [a.quad_tags, b.quad_tags].concat() });
    refused(&mesh, "p:upper_top:both", &["face set 'both' spans two bodies", "'lower'", "'upper'", "quad "]);
}

#[test]
fn orders_too_high_for_the_net_are_refused() {
    let dir = tempdir();
    let mesh = parisch_scmesh(dir.path());
    let (o, out) = tag(dir.path(), &mesh, &["c:upper_bottom:lower_top:bspline:3:5"]);
    assert_fails(&o, 2, &["pair 'c': master 'lower_top' is a 4 × 4 grid: a 4-node row cannot carry order 5"], &out);
    let (o, out) = tag(dir.path(), &mesh, &["c:upper_bottom:lower_top:bspline:3:7"]);
    assert_fails(&o, 2, &["order 7 exceeds the supported maximum 6"], &out);
    let (o, out) = tag(dir.path(), &mesh, &["c:upper_bottom:lower_top:bspline:1:3"]);
    assert_fails(&o, 2, &["order 1 is below 2"], &out);
}

#[test]
fn bad_pairs_are_refused() {
    let dir = tempdir();
    let mesh = parisch_scmesh(dir.path());
    for (pair, needle) in [
        ("c:nothing:lower_top", "slave 'nothing' is neither a node set nor a face set"),
        ("c:upper_bottom:nothing", "face set 'nothing' does not exist (face sets: "),
        ("c:upper_bottom", "a name, a slave set and a master face set are needed"),
        ("c:upper_bottom:lower_top:nurbs", "unknown master kind \"nurbs\""),
    ] {
        let (o, out) = tag(dir.path(), &mesh, &[pair]);
        assert_fails(&o, 2, &[needle], &out);
    }
    let (o, out) = tag(dir.path(), &mesh, &["c:upper_bottom:lower_top", "c:upper_bottom:lower_top:facet"]);
    assert_fails(&o, 2, &["pair 'c' is defined twice"], &out);
    let (o, out) = tag(dir.path(), &mesh, &[]);
    assert_fails(&o, 2, &["no contact pairs given"], &out);
}

#[test]
fn pairs_file_round_trip_and_yaml_dump() {
    let dir = tempdir();
    let mesh = parisch_scmesh(dir.path());
    let yaml = dir.path().join("pairs.yaml");
    std::fs::write(&yaml, "pairs:\n  - {name: smooth, slave: upper_bottom, master: lower_top, master_kind: bspline, orders: [4, 2]}\n  - {name: flat, slave: load_node, master: lower_top, master_kind: facet}\n").unwrap();
    let out = dir.path().join("c.sccontact");
    let o = run("sc-tag", &[mesh.to_str().unwrap(), "-o", out.to_str().unwrap(), "--pairs", yaml.to_str().unwrap()], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let m = ContactModel::read(&out).unwrap();
    assert_eq!(m.pairs.len(), 2);
    assert_eq!((m.pairs[1].orders, m.pairs[1].slave_nodes.len()), ([2, 2], 1));
    // Round trip through the encoder is bit-identical.
    let again = dir.path().join("again.sccontact");
    m.write(&again).unwrap();
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
    assert_eq!(ContactModel::read(&again).unwrap(), m);
    let o = run("sc-export", &[out.to_str().unwrap(), "--format", "yaml", "-o", "-"], dir.path());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success() && text.contains("format: sccontact") && text.contains("pair/0/knots_1") && text.contains("orders:"), "{text}");
    // A bad pairs file names the key and line.
    std::fs::write(&yaml, "pairs:\n  - {name: a, slave: upper_bottom, mastr: lower_top}\n").unwrap();
    let o = run("sc-tag", &[mesh.to_str().unwrap(), "-o", out.to_str().unwrap(), "--pairs", yaml.to_str().unwrap()], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("mastr") && stderr(&o).contains("line 2"), "{}", stderr(&o));
}

#[test]
fn export_writes_mesh_surface_and_net_read_by_meshio() {
    let dir = tempdir();
    let mesh = parisch_scmesh(dir.path());
    let (o, out) = tag(dir.path(), &mesh, &["contact:upper_bottom:lower_top:bspline:3:3", "flat:upper_bottom:lower_top:facet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let vtu = dir.path().join("model.vtu");
    let o = run("sc-export", &[out.to_str().unwrap(), "-o", vtu.to_str().unwrap()], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    for (pair, spans) in [("contact", 2), ("flat", 3)] {
        let surface = dir.path().join(format!("model_{pair}_surface.vtu"));
        let net = dir.path().join(format!("model_{pair}_net.vtu"));
        let o = python_script("check_contact_vtu.py", &[&vtu, &surface, &net]);
        let js = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "meshio check failed: {js}{}", String::from_utf8_lossy(&o.stderr));
        let quads = spans * spans * 64;
        assert!(js.contains("\"hexes\": 13") && js.contains(&format!("\"quads\": {quads}")) && js.contains("\"lines\": 24") && js.contains("\"net_points\": 16"), "{pair}: {js}");
    }
}

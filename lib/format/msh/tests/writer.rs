//! A small MSH writer for the tests: a model of nodes, elements and physical
//! groups written in all four encodings (2.2/4.1 × ASCII/binary), and the
//! two-hexahedra model most tests start from.

use super::*;

/// One element of a test model: MSH 2.2 takes `physical` as its first tag, MSH
/// 4.1 takes it from the entity `(dim of type, entity)`.
#[derive(Clone)]
pub(super) struct El {
    pub(super) tag: u64,
    pub(super) ty: i32,
    pub(super) physical: i32,
    pub(super) entity: i32,
    pub(super) nodes: Vec<u64>,
}

#[derive(Clone)]
pub(super) struct Model {
    pub(super) names: Vec<(u8, i32, &'static str)>,
    pub(super) nodes: Vec<(u64, [f64; 3])>,
    pub(super) elements: Vec<El>,
    /// Extra physical tags of MSH 4.1 entities: (dim, entity, physical).
    pub(super) extra_physicals: Vec<(u8, i32, i32)>,
}

pub(super) fn el(tag: u64, ty: i32, physical: i32, entity: i32, nodes: &[u64]) -> El {
    El { tag, ty, physical, entity, nodes: nodes.to_vec() }
}

pub(super) fn dim_of(ty: i32) -> u8 {
    types::element_type(ty).map(|t| t.dim).unwrap_or(3)
}

pub(super) fn push_names(out: &mut Vec<u8>, m: &Model) {
    if m.names.is_empty() {
        return;
    }
    out.extend_from_slice(format!("$PhysicalNames\n{}\n", m.names.len()).as_bytes());
    for (d, t, n) in &m.names {
        out.extend_from_slice(format!("{d} {t} \"{n}\"\n").as_bytes());
    }
    out.extend_from_slice(b"$EndPhysicalNames\n");
}

impl Model {
    pub(super) fn v2_ascii(&self) -> Vec<u8> {
        let mut o = b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n".to_vec();
        push_names(&mut o, self);
        o.extend_from_slice(format!("$Nodes\n{}\n", self.nodes.len()).as_bytes());
        for (t, x) in &self.nodes {
            o.extend_from_slice(format!("{t} {:?} {:?} {:?}\n", x[0], x[1], x[2]).as_bytes());
        }
        o.extend_from_slice(format!("$EndNodes\n$Elements\n{}\n", self.elements.len()).as_bytes());
        for e in &self.elements {
            let nodes: Vec<String> = e.nodes.iter().map(|n| n.to_string()).collect();
            o.extend_from_slice(format!("{} {} 2 {} {} {}\n", e.tag, e.ty, e.physical, e.entity, nodes.join(" ")).as_bytes());
        }
        o.extend_from_slice(b"$EndElements\n");
        o
    }

    pub(super) fn v2_binary(&self) -> Vec<u8> {
        let mut o = b"$MeshFormat\n2.2 1 8\n".to_vec();
        o.extend_from_slice(&1i32.to_le_bytes());
        o.extend_from_slice(b"\n$EndMeshFormat\n");
        push_names(&mut o, self);
        o.extend_from_slice(format!("$Nodes\n{}\n", self.nodes.len()).as_bytes());
        for (t, x) in &self.nodes {
            o.extend_from_slice(&(*t as i32).to_le_bytes());
            x.iter().for_each(|v| o.extend_from_slice(&v.to_le_bytes()));
        }
        o.extend_from_slice(format!("\n$EndNodes\n$Elements\n{}\n", self.elements.len()).as_bytes());
        // One block per element: legal, and exercises the block loop.
        for e in &self.elements {
            for v in [e.ty, 1, 2, e.tag as i32, e.physical, e.entity] {
                o.extend_from_slice(&v.to_le_bytes());
            }
            e.nodes.iter().for_each(|&n| o.extend_from_slice(&(n as i32).to_le_bytes()));
        }
        o.extend_from_slice(b"\n$EndElements\n");
        o
    }

    /// Entities (dim, tag) → physical tags, in first-use order.
    pub(super) fn entities(&self) -> Vec<(u8, i32, Vec<i32>)> {
        let mut out: Vec<(u8, i32, Vec<i32>)> = Vec::new();
        for e in &self.elements {
            let d = dim_of(e.ty);
            match out.iter_mut().find(|x| x.0 == d && x.1 == e.entity) {
                Some(x) => {
                    if e.physical != 0 && !x.2.contains(&e.physical) {
                        x.2.push(e.physical)
                    }
                }
                None => out.push((d, e.entity, if e.physical != 0 { vec![e.physical] } else { vec![] })),
            }
        }
        for &(d, entity, p) in &self.extra_physicals {
            if let Some(x) = out.iter_mut().find(|x| x.0 == d && x.1 == entity) {
                x.2.push(p);
            }
        }
        out
    }

    /// Element blocks (dim, entity, type, elements) in first-use order.
    pub(super) fn blocks(&self) -> Vec<(u8, i32, i32, Vec<&El>)> {
        let mut out: Vec<(u8, i32, i32, Vec<&El>)> = Vec::new();
        for e in &self.elements {
            let d = dim_of(e.ty);
            match out.iter_mut().find(|b| b.0 == d && b.1 == e.entity && b.2 == e.ty) {
                Some(b) => b.3.push(e),
                None => out.push((d, e.entity, e.ty, vec![e])),
            }
        }
        out
    }

    pub(super) fn v4_ascii(&self) -> Vec<u8> {
        let mut o = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n".to_vec();
        push_names(&mut o, self);
        let ents = self.entities();
        let count = |d: u8| ents.iter().filter(|e| e.0 == d).count();
        o.extend_from_slice(format!("$Entities\n{} {} {} {}\n", count(0), count(1), count(2), count(3)).as_bytes());
        for d in 0..4u8 {
            for (_, tag, phys) in ents.iter().filter(|e| e.0 == d) {
                let bbox = if d == 0 { "0 0 0" } else { "0 0 0 1 1 1" };
                let p: Vec<String> = phys.iter().map(|p| p.to_string()).collect();
                let bound = if d == 0 { "" } else { " 0" };
                o.extend_from_slice(format!("{tag} {bbox} {} {}{bound}\n", phys.len(), p.join(" ")).as_bytes());
            }
        }
        o.extend_from_slice(b"$EndEntities\n");
        let n = self.nodes.len();
        o.extend_from_slice(format!("$Nodes\n1 {n} 1 {n}\n3 1 0 {n}\n").as_bytes());
        for (t, _) in &self.nodes {
            o.extend_from_slice(format!("{t}\n").as_bytes());
        }
        for (_, x) in &self.nodes {
            o.extend_from_slice(format!("{:?} {:?} {:?}\n", x[0], x[1], x[2]).as_bytes());
        }
        let blocks = self.blocks();
        o.extend_from_slice(format!("$EndNodes\n$Elements\n{} {} 1 {}\n", blocks.len(), self.elements.len(), self.elements.len()).as_bytes());
        for (d, ent, ty, els) in &blocks {
            o.extend_from_slice(format!("{d} {ent} {ty} {}\n", els.len()).as_bytes());
            for e in els {
                let nodes: Vec<String> = e.nodes.iter().map(|n| n.to_string()).collect();
                o.extend_from_slice(format!("{} {}\n", e.tag, nodes.join(" ")).as_bytes());
            }
        }
        o.extend_from_slice(b"$EndElements\n");
        o
    }

    pub(super) fn v4_binary(&self) -> Vec<u8> {
        let mut o = b"$MeshFormat\n4.1 1 8\n".to_vec();
        o.extend_from_slice(&1i32.to_le_bytes());
        o.extend_from_slice(b"\n$EndMeshFormat\n");
        push_names(&mut o, self);
        let i = |o: &mut Vec<u8>, v: i32| o.extend_from_slice(&v.to_le_bytes());
        let z = |o: &mut Vec<u8>, v: u64| o.extend_from_slice(&v.to_le_bytes());
        let f = |o: &mut Vec<u8>, v: f64| o.extend_from_slice(&v.to_le_bytes());
        let ents = self.entities();
        o.extend_from_slice(b"$Entities\n");
        for d in 0..4u8 {
            z(&mut o, ents.iter().filter(|e| e.0 == d).count() as u64);
        }
        for d in 0..4u8 {
            for (_, tag, phys) in ents.iter().filter(|e| e.0 == d) {
                i(&mut o, *tag);
                for _ in 0..if d == 0 { 3 } else { 6 } {
                    f(&mut o, 0.5);
                }
                z(&mut o, phys.len() as u64);
                phys.iter().for_each(|&p| i(&mut o, p));
                if d > 0 {
                    z(&mut o, 1);
                    i(&mut o, -1);
                }
            }
        }
        o.extend_from_slice(b"\n$EndEntities\n$Nodes\n");
        let n = self.nodes.len() as u64;
        [1, n, 1, n].iter().for_each(|&v| z(&mut o, v));
        i(&mut o, 3);
        i(&mut o, 1);
        i(&mut o, 0);
        z(&mut o, n);
        self.nodes.iter().for_each(|(t, _)| z(&mut o, *t));
        self.nodes.iter().for_each(|(_, x)| x.iter().for_each(|&v| f(&mut o, v)));
        o.extend_from_slice(b"\n$EndNodes\n$Elements\n");
        let blocks = self.blocks();
        let ne = self.elements.len() as u64;
        [blocks.len() as u64, ne, 1, ne].iter().for_each(|&v| z(&mut o, v));
        for (d, ent, ty, els) in &blocks {
            i(&mut o, i32::from(*d));
            i(&mut o, *ent);
            i(&mut o, *ty);
            z(&mut o, els.len() as u64);
            for e in els {
                z(&mut o, e.tag);
                e.nodes.iter().for_each(|&v| z(&mut o, v));
            }
        }
        o.extend_from_slice(b"\n$EndElements\n");
        o
    }

    pub(super) fn all(&self) -> [(&'static str, Vec<u8>); 4] {
        [
            ("2.2 ASCII", self.v2_ascii()),
            ("2.2 binary", self.v2_binary()),
            ("4.1 ASCII", self.v4_ascii()),
            ("4.1 binary", self.v4_binary()),
        ]
    }
}

/// Two unit hexahedra side by side along x, with named volumes `left` and
/// `right`, the physical surface `top` (two quads at z = 1) and the physical
/// point `corner` (node 1).
pub(super) fn two_hexes() -> Model {
    Model {
        names: vec![(3, 1, "left"), (3, 2, "right"), (2, 3, "top"), (0, 4, "corner")],
        nodes: vec![
            (1, [0., 0., 0.]),
            (2, [1., 0., 0.]),
            (3, [1., 1., 0.]),
            (4, [0., 1., 0.]),
            (5, [0., 0., 1.]),
            (6, [1., 0., 1.]),
            (7, [1., 1., 1.]),
            (8, [0., 1., 1.]),
            (9, [2., 0., 0.]),
            (10, [2., 1., 0.]),
            (11, [2., 0., 1.]),
            (12, [2., 1., 1.]),
        ],
        elements: vec![
            el(30, 15, 4, 1, &[1]),
            el(20, 3, 3, 5, &[5, 6, 7, 8]),
            el(21, 3, 3, 5, &[6, 11, 12, 7]),
            el(1, 5, 1, 1, &[1, 2, 3, 4, 5, 6, 7, 8]),
            el(2, 5, 2, 2, &[2, 9, 10, 3, 6, 11, 12, 7]),
        ],
        extra_physicals: Vec::new(),
    }
}

//! gmsh element types: number → (name, dimension, number of nodes).
//!
//! The numbers are gmsh's `MSH_*` constants (the same in MSH 2.2 and 4.1); names,
//! dimensions and node counts are what `gmsh.model.mesh.getElementProperties`
//! reports. A reader must know every node count to walk binary element data, so
//! a type missing here is an error, never a guess. Polygons and polyhedra
//! (34, 35) have no fixed node count and are not listed.

/// One gmsh element type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct ElementType {
    /// gmsh type number (`elementType` / `elm-type` in the spec).
    pub number: i32,
    /// gmsh's name, e.g. `"Tetrahedron 4"`.
    pub name: &'static str,
    pub dim: u8,
    pub nodes: usize,
}

/// gmsh type of the 8-node hexahedron, the only volume element we read.
pub(super) const HEX8: i32 = 5;
/// gmsh type of the 4-node quadrangle, the only face-set element.
pub(super) const QUAD4: i32 = 3;

impl ElementType {
    /// `"4-node tetrahedron"`, `"point"`.
    pub fn describe(&self) -> String {
        let shape = self.name.split(' ').next().unwrap_or(self.name).to_lowercase();
        if self.number == 15 {
            shape
        } else {
            format!("{}-node {}", self.nodes, shape)
        }
    }
}

/// The element type with gmsh number `number`, if gmsh defines it.
pub(super) fn element_type(number: i32) -> Option<ElementType> {
    let (name, dim, nodes) = match number {
        1 => ("Line 2", 1, 2),
        2 => ("Triangle 3", 2, 3),
        3 => ("Quadrilateral 4", 2, 4),
        4 => ("Tetrahedron 4", 3, 4),
        5 => ("Hexahedron 8", 3, 8),
        6 => ("Prism 6", 3, 6),
        7 => ("Pyramid 5", 3, 5),
        8 => ("Line 3", 1, 3),
        9 => ("Triangle 6", 2, 6),
        10 => ("Quadrilateral 9", 2, 9),
        11 => ("Tetrahedron 10", 3, 10),
        12 => ("Hexahedron 27", 3, 27),
        13 => ("Prism 18", 3, 18),
        14 => ("Pyramid 14", 3, 14),
        15 => ("Point", 0, 1),
        16 => ("Quadrilateral 8", 2, 8),
        17 => ("Hexahedron 20", 3, 20),
        18 => ("Prism 15", 3, 15),
        19 => ("Pyramid 13", 3, 13),
        20 => ("Triangle 9", 2, 9),
        21 => ("Triangle 10", 2, 10),
        22 => ("Triangle 12", 2, 12),
        23 => ("Triangle 15", 2, 15),
        24 => ("Triangle 15I", 2, 15),
        25 => ("Triangle 21", 2, 21),
        26 => ("Line 4", 1, 4),
        27 => ("Line 5", 1, 5),
        28 => ("Line 6", 1, 6),
        29 => ("Tetrahedron 20", 3, 20),
        30 => ("Tetrahedron 35", 3, 35),
        31 => ("Tetrahedron 56", 3, 56),
        32 => ("Tetrahedron 22", 3, 22),
        33 => ("Tetrahedron 28", 3, 28),
        36 => ("Quadrilateral 16", 2, 16),
        37 => ("Quadrilateral 25", 2, 25),
        38 => ("Quadrilateral 36", 2, 36),
        39 => ("Quadrilateral 12", 2, 12),
        40 => ("Quadrilateral 16I", 2, 16),
        41 => ("Quadrilateral 20", 2, 20),
        42 => ("Triangle 28", 2, 28),
        43 => ("Triangle 36", 2, 36),
        44 => ("Triangle 45", 2, 45),
        45 => ("Triangle 55", 2, 55),
        46 => ("Triangle 66", 2, 66),
        47 => ("Quadrilateral 49", 2, 49),
        48 => ("Quadrilateral 64", 2, 64),
        49 => ("Quadrilateral 81", 2, 81),
        50 => ("Quadrilateral 100", 2, 100),
        51 => ("Quadrilateral 121", 2, 121),
        52 => ("Triangle 18", 2, 18),
        53 => ("Triangle 21I", 2, 21),
        54 => ("Triangle 24", 2, 24),
        55 => ("Triangle 27", 2, 27),
        56 => ("Triangle 30", 2, 30),
        57 => ("Quadrilateral 24", 2, 24),
        58 => ("Quadrilateral 28", 2, 28),
        59 => ("Quadrilateral 32", 2, 32),
        60 => ("Quadrilateral 36I", 2, 36),
        61 => ("Quadrilateral 40", 2, 40),
        62 => ("Line 7", 1, 7),
        63 => ("Line 8", 1, 8),
        64 => ("Line 9", 1, 9),
        65 => ("Line 10", 1, 10),
        66 => ("Line 11", 1, 11),
        71 => ("Tetrahedron 84", 3, 84),
        72 => ("Tetrahedron 120", 3, 120),
        73 => ("Tetrahedron 165", 3, 165),
        74 => ("Tetrahedron 220", 3, 220),
        75 => ("Tetrahedron 286", 3, 286),
        79 => ("Tetrahedron 34", 3, 34),
        80 => ("Tetrahedron 40", 3, 40),
        81 => ("Tetrahedron 46", 3, 46),
        82 => ("Tetrahedron 52", 3, 52),
        83 => ("Tetrahedron 58", 3, 58),
        84 => ("Line 1", 1, 1),
        85 => ("Triangle 1", 2, 1),
        86 => ("Quadrilateral 1", 2, 1),
        87 => ("Tetrahedron 1", 3, 1),
        88 => ("Hexahedron 1", 3, 1),
        89 => ("Prism 1", 3, 1),
        90 => ("Prism 40", 3, 40),
        91 => ("Prism 75", 3, 75),
        92 => ("Hexahedron 64", 3, 64),
        93 => ("Hexahedron 125", 3, 125),
        94 => ("Hexahedron 216", 3, 216),
        95 => ("Hexahedron 343", 3, 343),
        96 => ("Hexahedron 512", 3, 512),
        97 => ("Hexahedron 729", 3, 729),
        98 => ("Hexahedron 1000", 3, 1000),
        99 => ("Hexahedron 32", 3, 32),
        100 => ("Hexahedron 44", 3, 44),
        101 => ("Hexahedron 56", 3, 56),
        102 => ("Hexahedron 68", 3, 68),
        103 => ("Hexahedron 80", 3, 80),
        104 => ("Hexahedron 92", 3, 92),
        105 => ("Hexahedron 104", 3, 104),
        118 => ("Pyramid 30", 3, 30),
        119 => ("Pyramid 55", 3, 55),
        120 => ("Pyramid 91", 3, 91),
        121 => ("Pyramid 140", 3, 140),
        122 => ("Pyramid 204", 3, 204),
        123 => ("Pyramid 285", 3, 285),
        124 => ("Pyramid 385", 3, 385),
        _ => return None,
    };
    Some(ElementType { number, name, dim, nodes })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn descriptions() {
        assert_eq!(element_type(4).map(|t| t.describe()).as_deref(), Some("4-node tetrahedron"));
        assert_eq!(element_type(17).map(|t| t.describe()).as_deref(), Some("20-node hexahedron"));
        assert_eq!(element_type(15).map(|t| t.describe()).as_deref(), Some("point"));
        assert!(element_type(34).is_none());
    }
}

//! VTK XML output for ParaView: `.vtu` unstructured grids written with vtkio in
//! binary (base64, little-endian, UInt64 headers) encoding, and `.pvd` collections
//! for time series. Files are written atomically.
//!
//! Field names are stable (documented in `docs/formats.md`): ParaView state files
//! and scripts may rely on them.

use std::io::Write;
use std::path::Path;

use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

use super::stage::{write_atomic, write_atomic_with, StageError};
use crate::mesh::Mesh;

/// Values of one data array.
#[derive(Debug, Clone, PartialEq)]
pub enum FieldValues {
    F64(Vec<f64>),
    I32(Vec<i32>),
    I64(Vec<i64>),
    U8(Vec<u8>),
}

impl FieldValues {
    fn len(&self) -> usize {
        match self {
            Self::F64(v) => v.len(),
            Self::I32(v) => v.len(),
            Self::I64(v) => v.len(),
            Self::U8(v) => v.len(),
        }
    }
    fn into_buffer(self) -> IOBuffer {
        match self {
            Self::F64(v) => v.into(),
            Self::I32(v) => v.into(),
            Self::I64(v) => v.into(),
            Self::U8(v) => v.into(),
        }
    }
}

/// A named point or cell array with `components` values per entity
/// (1 scalar, 3 vector, 9 tensor in row-major order).
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub name: String,
    pub components: u32,
    pub values: FieldValues,
}

impl Field {
    pub fn scalar_f64(name: &str, v: Vec<f64>) -> Self {
        Self { name: name.into(), components: 1, values: FieldValues::F64(v) }
    }
    pub fn vector_f64(name: &str, v: Vec<f64>) -> Self {
        Self { name: name.into(), components: 3, values: FieldValues::F64(v) }
    }
    pub fn tensor_f64(name: &str, v: Vec<f64>) -> Self {
        Self { name: name.into(), components: 9, values: FieldValues::F64(v) }
    }
}

/// VTK cell kinds we write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellKind {
    Vertex,
    Line,
    Quad,
    Hexahedron,
}

impl CellKind {
    fn vtk(self) -> CellType {
        match self {
            Self::Vertex => CellType::Vertex,
            Self::Line => CellType::Line,
            Self::Quad => CellType::Quad,
            Self::Hexahedron => CellType::Hexahedron,
        }
    }
}

/// An unstructured grid ready to be written: points, cells of one or more kinds,
/// point and cell data.
#[derive(Debug, Clone, Default)]
pub struct Grid {
    pub points: Vec<[f64; 3]>,
    /// Cell connectivity, concatenated, with `offsets[c]` the end of cell `c`.
    pub connectivity: Vec<u64>,
    pub offsets: Vec<u64>,
    pub kinds: Vec<CellKind>,
    pub point_data: Vec<Field>,
    pub cell_data: Vec<Field>,
}

/// Writing VTK failed.
#[derive(Debug, thiserror::Error)]
pub enum VtkError {
    #[error("{path}: field '{field}' has {found} values, expected {expected} ({entities} {kind} × {components} components)")]
    FieldSize { path: String, field: String, found: usize, expected: usize, entities: usize, kind: &'static str, components: u32 },
    #[error("{path}: VTK encoding failed: {what}")]
    Encode { path: String, what: String },
    #[error(transparent)]
    Stage(#[from] StageError),
}

impl Grid {
    pub fn push_cell(&mut self, kind: CellKind, nodes: &[u32]) {
        self.connectivity.extend(nodes.iter().map(|&n| n as u64));
        self.offsets.push(self.connectivity.len() as u64);
        self.kinds.push(kind);
    }

    pub fn n_cells(&self) -> usize {
        self.kinds.len()
    }

    fn check(&self, path: &str) -> Result<(), VtkError> {
        let sets = [(&self.point_data, self.points.len(), "points"), (&self.cell_data, self.n_cells(), "cells")];
        for (fields, n, kind) in sets {
            for f in fields {
                let expected = n * f.components as usize;
                if f.values.len() != expected {
                    return Err(VtkError::FieldSize {
                        path: path.into(),
                        field: f.name.clone(),
                        found: f.values.len(),
                        expected,
                        entities: n,
                        kind,
                        components: f.components,
                    });
                }
            }
        }
        Ok(())
    }

    /// Encode as a `.vtu` document.
    pub fn to_vtu_bytes(self, path: &str) -> Result<Vec<u8>, VtkError> {
        self.check(path)?;
        let attr = |fields: Vec<Field>| -> Vec<Attribute> {
            fields
                .into_iter()
                .map(|f| {
                    let elem = match f.components {
                        1 => ElementType::Scalars { num_comp: 1, lookup_table: None },
                        3 => ElementType::Vectors,
                        9 => ElementType::Tensors,
                        n => ElementType::Generic(n),
                    };
                    Attribute::DataArray(DataArray { name: f.name, elem, data: f.values.into_buffer() })
                })
                .collect()
        };
        let points: Vec<f64> = self.points.iter().flatten().copied().collect();
        let piece = UnstructuredGridPiece {
            points: IOBuffer::F64(points),
            cells: Cells {
                cell_verts: VertexNumbers::XML { connectivity: self.connectivity, offsets: self.offsets },
                types: self.kinds.iter().map(|k| k.vtk()).collect(),
            },
            data: Attributes { point: attr(self.point_data), cell: attr(self.cell_data) },
        };
        let vtk = Vtk {
            version: Version::new_xml(1, 0),
            title: String::new(),
            byte_order: ByteOrder::LittleEndian,
            data: DataSet::inline(piece),
            file_path: None,
        };
        let mut out = Vec::new();
        vtk.write_xml(&mut out).map_err(|e| VtkError::Encode { path: path.into(), what: format!("{e:?}") })?;
        Ok(out)
    }

    /// Write a `.vtu` file atomically.
    pub fn write_vtu(self, path: &Path) -> Result<(), VtkError> {
        let bytes = self.to_vtu_bytes(&path.display().to_string())?;
        write_atomic(path, &bytes)?;
        Ok(())
    }
}

/// The mesh as a grid: hexahedra with cell data `body` (body index) and
/// `gmsh_element_tag`, point data `gmsh_node_tag` and one 0/1 `set:<name>` array per
/// node set.
pub fn mesh_grid(mesh: &Mesh) -> Grid {
    let mut g = Grid { points: mesh.nodes.clone(), ..Default::default() };
    g.connectivity.reserve(mesh.hexes.len() * 8);
    for h in &mesh.hexes {
        g.push_cell(CellKind::Hexahedron, h);
    }
    g.cell_data.push(Field { name: "body".into(), components: 1, values: FieldValues::I32(mesh.hex_body.iter().map(|&b| b as i32).collect()) });
    g.cell_data.push(Field {
        name: "gmsh_element_tag".into(),
        components: 1,
        values: FieldValues::I64(mesh.element_tags.iter().map(|&t| t as i64).collect()),
    });
    g.point_data.push(Field {
        name: "gmsh_node_tag".into(),
        components: 1,
        values: FieldValues::I64(mesh.node_tags.iter().map(|&t| t as i64).collect()),
    });
    for s in &mesh.node_sets {
        let mut v = vec![0u8; mesh.nodes.len()];
        for &n in &s.nodes {
            v[n as usize] = 1;
        }
        g.point_data.push(Field { name: format!("set:{}", s.name), components: 1, values: FieldValues::U8(v) });
    }
    g
}

/// Write a ParaView collection (`.pvd`) listing `(time, file)` pairs; file names
/// are written as given (relative to the `.pvd`'s folder).
pub fn write_pvd(path: &Path, entries: &[(f64, String)]) -> Result<(), StageError> {
    write_atomic_with(path, |w: &mut dyn Write| {
        writeln!(w, "<?xml version=\"1.0\"?>")?;
        writeln!(w, "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">")?;
        writeln!(w, "  <Collection>")?;
        for (t, f) in entries {
            writeln!(w, "    <DataSet timestep=\"{t:?}\" group=\"\" part=\"0\" file=\"{}\"/>", xml_escape(f))?;
        }
        writeln!(w, "  </Collection>")?;
        writeln!(w, "</VTKFile>")
    })
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('"', "&quot;").replace('<', "&lt;").replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_size_mismatch_names_the_field() {
        let mut g = Grid { points: vec![[0.0; 3]; 2], ..Default::default() };
        g.point_data.push(Field::vector_f64("displacement", vec![0.0; 5]));
        let e = g.to_vtu_bytes("a.vtu").unwrap_err().to_string();
        assert!(e.contains("displacement") && e.contains("expected 6"), "{e}");
    }

    #[test]
    fn vtu_is_little_endian_base64_binary() {
        let mut g = Grid { points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], ..Default::default() };
        g.push_cell(CellKind::Line, &[0, 1]);
        let s = String::from_utf8(g.to_vtu_bytes("a.vtu").unwrap()).unwrap();
        assert!(s.contains("LittleEndian") && s.contains("format=\"binary\"") && s.contains("Float64"), "{s}");
    }
}

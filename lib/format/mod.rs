//! Every on-disk format, and nothing numerical: the versioned stage container,
//! the mesh stage file, gmsh's MSH, VTK output and the pipeline YAML.

pub mod msh;
pub mod scmesh;
pub mod stage;

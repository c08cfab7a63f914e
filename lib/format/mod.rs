//! Every on-disk format, and nothing numerical: the versioned stage container,
//! the mesh stage file, gmsh's MSH, VTK output, the pipeline YAML and the CSV
//! tables `sc-solve` writes.

pub mod csv;
pub mod msh;
pub mod pipeline;
pub mod sccontact;
pub mod scmesh;
pub mod scres;
pub mod setup;
pub mod stage;
pub mod vtk;

//! # splinecontact
//!
//! 3D large-deformation frictional contact of hex8 bodies with the master surface
//! smoothed by one B-spline patch, after Santos & Bandeira (2018), *Numerical
//! modeling of contact problems with the finite element method utilizing a B-Spline
//! surface for contact surface smoothing*, Lat. Am. J. Solids Struct. 15(5).
//!
//! ## Crate map
//! From the bottom layer up: a module imports only its own layer and those below
//! (`tests/structure.rs` checks it, and that no files import each other in a circle).
//!
//! | module   | what it holds |
//! |----------|---------------|
//! | `mesh`   | the mesh: nodes, hex8, bodies, node and face sets, hex8 topology |
//! | `spline` | the B-spline master patch and its bilinear-facet counterpart |
//! | `folder_lock` | one pipeline at a time per output folder (a lock file naming its owner) |
//! | `os`     | what is asked of the operating system directly: the binaries' allocator (large blocks on huge pages) |
//! | `material`, `fem` | constitutive models; the hex8 element: shape functions, quadrature, kinematics, internal force and tangent |
//! | `assembly` | dof numbering, the sparsity pattern built once, element scatter |
//! | `contact` | contact pairs: settings, the control net, the node-to-surface and mortar elements, the pair during the solve |
//! | `post`   | stresses and contact fields for output |
//! | `format` | on-disk formats: stage container, `.scmesh`, `.sccontact`, results, gmsh MSH, VTK, setup and pipeline YAML, CSV tables |
//! | `solver` | linear solvers, Newton, Uzawa, load stepping, restart |
//! | `check`  | the pre-solve check: contact pairs at the start (projections, gaps, flipped masters, adjust), rigid-body modes |
//! | `stages` | each pipeline stage as a library call (the binaries are thin wrappers) |
//! | `pipeline` | the YAML pipeline runner |
//!
//! ## Notation (paper symbol ↔ Rust name ↔ equation)
//! | paper | Rust | eq. |
//! |-------|------|-----|
//! | F, J = det F, b = F Fᵀ | `F`, `J`, `b` | 3.3 |
//! | σ (Cauchy) | `sigma` | 3.3 |
//! | g_N, t_N, λ_N, ε_N | `g_n`, `t_n`, `lambda_n`, `eps_n` | 4.2–4.3 |
//! | ξ̄^α, ā_α, ā_αβ, b̄_αβ | `xi`, `a_alpha`, `a_ab`, `b_ab` | 4.10–4.13 |

// Errors carry their culprit (file and line, element, set name, the failing Newton
// state) and travel only on cold paths: their size is deliberate, not boxed.
#![allow(clippy::result_large_err)]

pub mod assembly;
pub mod check;
pub mod contact;
pub mod fem;
pub mod folder_lock;
pub mod format;
pub mod material;
pub mod mesh;
pub mod os;
pub mod pipeline;
pub mod post;
pub mod solver;
pub mod spline;
pub mod stages;

//! `sc-export`: any stage file → VTK for ParaView, or a human-readable YAML dump.

use std::path::Path;

use super::StageRunError;
use crate::format::stage::{write_atomic_with, StageFile};
use crate::format::scres::Results;
use crate::format::sccontact::{ContactModel, ContactPair, MasterKind};
use crate::format::{sccontact, scmesh, scres, vtk};
use crate::spline::{BSplinePatch, FacetSurface, SurfacePoint, Vec3};
use crate::contact::master::Projector;
use crate::post::stresses;

/// Output formats of `sc-export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ExportFormat {
    /// One `.vtu` unstructured grid (a mesh).
    Vtu,
    /// A `.pvd` time series with one `.vtu` per converged increment (results files).
    Pvd,
    /// Every record of the stage file, human-readable.
    Yaml,
}

impl ExportFormat {
    /// The format implied by an output file's extension.
    pub fn from_extension(path: &Path) -> Option<Self> {
        match path.extension()?.to_str()? {
            "vtu" => Some(Self::Vtu),
            "pvd" => Some(Self::Pvd),
            "yaml" | "yml" => Some(Self::Yaml),
            _ => None,
        }
    }
}

/// What an export wrote, and what the user must hear about it even when quiet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Exported {
    /// One line describing what was written.
    pub written: String,
    /// What was read but could not be exported: an incomplete results file names the
    /// bytes it left out (`Results::tail`), each warning naming the input file.
    pub warnings: Vec<String>,
}

impl From<String> for Exported {
    fn from(written: String) -> Self {
        Self { written, warnings: Vec::new() }
    }
}

/// Export `input` to `output` in `format` (or the one implied by the extension).
pub fn export(input: &Path, output: &Path, format: Option<ExportFormat>) -> Result<Exported, StageRunError> {
    let format = match format.or_else(|| ExportFormat::from_extension(output)) {
        Some(f) => f,
        None => {
            return Err(StageRunError::Usage(format!(
                "{}: cannot tell the output format from the extension; use .vtu, .pvd or .yaml, or give --format",
                output.display()
            )))
        }
    };
    let file = StageFile::read_known(input, &[(scmesh::FORMAT, scmesh::MAJOR), (scres::FORMAT, scres::MAJOR), (sccontact::FORMAT, sccontact::MAJOR)])?;
    match format {
        ExportFormat::Yaml => {
            write_atomic_with(output, |w| file.dump_yaml(w))?;
            Ok(format!("wrote {} ({} {}.{} as YAML)", output.display(), file.format, file.major, file.minor).into())
        }
        ExportFormat::Vtu => match file.format.as_str() {
            scmesh::FORMAT => {
                let mesh = scmesh::from_stage(&file)?;
                let (n, m) = (mesh.nodes.len(), mesh.hexes.len());
                vtk::mesh_grid(&mesh).write_vtu(output)?;
                Ok(format!("wrote {} ({n} points, {m} hexahedra)", output.display()).into())
            }
            sccontact::FORMAT => {
                let model = ContactModel::from_stage(&file)?;
                write_contact_vtu(&model, output).map(Exported::from)
            }
            other => Err(StageRunError::Usage(format!("{}: a '{other}' file cannot be exported as .vtu (supported: scmesh, sccontact)", input.display()))),
        },
        ExportFormat::Pvd => match file.format.as_str() {
            scres::FORMAT => {
                let results = Results::from_stage(&file)?;
                let written = write_results_pvd(&results, output)?;
                let warnings = results.tail.iter().map(|t| format!("{}: {t}", input.display())).collect();
                Ok(Exported { written, warnings })
            }
            other => Err(StageRunError::Usage(format!(
                "{}: a '{other}' file holds no time series; .pvd is written for results files (use .vtu for a mesh)",
                input.display()
            ))),
        },
    }
}

/// One `.vtu` per converged increment beside the `.pvd` (`<stem>_<k>.vtu`, k = 0 is
/// the undeformed state), and the `.pvd` indexing them by load factor.
pub fn write_results_pvd(results: &Results, output: &Path) -> Result<String, StageRunError> {
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "results".into());
    let dir = output.parent().filter(|p| !p.as_os_str().is_empty()).map(Path::to_path_buf).unwrap_or_default();
    let mesh = &results.mesh;
    let mut entries = Vec::new();
    let zero = scres::Increment {
        info: scres::IncrementInfo { load_factor: 0.0, cutbacks: 0, iterations: vec![], reactions: vec![], seconds_output: 0.0, contact: vec![] },
        u: vec![[0.0; 3]; mesh.nodes.len()],
        stress: vec![[[0.0; 9]; 8]; mesh.hexes.len()],
        contact: vec![],
        friction: vec![],
        face_pressure: vec![],
        charts: vec![],
    };
    // friction fields in every step when any increment carries them
    let frictional = results.increments.iter().any(|i| i.friction.iter().any(|f| !f.is_empty()));
    for (k, inc) in std::iter::once(&zero).chain(results.increments.iter()).enumerate() {
        let name = format!("{stem}_{k}.vtu");
        let mut g = vtk::mesh_grid(mesh);
        g.point_data.push(vtk::Field::vector_f64("displacement", inc.u.iter().flatten().copied().collect()));
        let elem = stresses::element_average(&inc.stress);
        let nodal = stresses::nodal_average(mesh, &elem);
        push_stress_fields(&mut g.point_data, &nodal);
        push_stress_fields(&mut g.cell_data, &elem);
        if !results.pairs.is_empty() {
            push_contact_fields(&mut g.point_data, mesh.nodes.len(), results, &inc.contact);
            if frictional {
                push_friction_fields(&mut g.point_data, mesh.nodes.len(), results, &inc.friction);
            }
        }
        g.write_vtu(&dir.join(&name))?;
        entries.push((inc.info.load_factor, name));
    }
    vtk::write_pvd(output, &entries)?;
    // the master surfaces moving with their bodies: one series per pair
    let mut surfaces = Vec::new();
    for p in &results.pairs {
        let mut series = Vec::new();
        for (k, inc) in std::iter::once(&zero).chain(results.increments.iter()).enumerate() {
            let x: Vec<Vec3> = p
                .net
                .nodes
                .iter()
                .map(|&n| {
                    let (x0, u) = (mesh.nodes[n as usize], inc.u[n as usize]);
                    Vec3::new(x0[0] + u[0], x0[1] + u[1], x0[2] + u[2])
                })
                .collect();
            let name = format!("{stem}_{}_surface_{k}.vtu", p.name);
            master_surface_grid(p, &x)?.write_vtu(&dir.join(&name))?;
            series.push((inc.info.load_factor, name));
        }
        let pvd = dir.join(format!("{stem}_{}_surface.pvd", p.name));
        vtk::write_pvd(&pvd, &series)?;
        surfaces.push(pvd.display().to_string());
    }
    // the slave surfaces with the pressure per node and per face: one series per pair
    let mut slaves = Vec::new();
    for (p, pair) in results.pairs.iter().enumerate() {
        let Some(faces) = pair.slave_faces(mesh) else { continue };
        let mut series = Vec::new();
        for (k, inc) in std::iter::once(&zero).chain(results.increments.iter()).enumerate() {
            let name = format!("{stem}_{}_slave_{k}.vtu", pair.name);
            let pressure = |s: usize| inc.contact.get(p).and_then(|st| st.get(s)).map_or(0.0, |row| -row[1]);
            // the face pressures the results file carries (files written before it: computed)
            let stored = inc.face_pressure.get(p).filter(|v| v.len() == faces.len()).map(Vec::as_slice);
            slave_surface_grid(mesh, pair, &faces, &inc.u, pressure, stored).write_vtu(&dir.join(&name))?;
            series.push((inc.info.load_factor, name));
        }
        let pvd = dir.join(format!("{stem}_{}_slave.pvd", pair.name));
        vtk::write_pvd(&pvd, &series)?;
        slaves.push(pvd.display().to_string());
    }
    let also = if surfaces.is_empty() { String::new() } else { format!("; master surfaces (deformed, per increment): {}", surfaces.join(", ")) };
    let also = if slaves.is_empty() { also } else { format!("{also}; slave surfaces with the pressure per node and per face: {}", slaves.join(", ")) };
    Ok(format!("wrote {} ({} increments + the undeformed state){also}", output.display(), results.increments.len()))
}

/// A pair's slave surface, deformed by `u`: its faces as quads over the slave nodes,
/// point data `contact_pressure` (−t_N of each slave node, `pressure(s)` by slave
/// index) and `gmsh_node_tag`, cell data `contact_pressure_face` (the mean of the
/// interpolated pressure over the face, `post::contact_pressure`; `face_pressure`
/// when given, one per face of `faces`).
pub fn slave_surface_grid(mesh: &crate::mesh::Mesh, pair: &ContactPair, faces: &[[u32; 4]], u: &[[f64; 3]], pressure: impl Fn(usize) -> f64, face_pressure: Option<&[f64]>) -> vtk::Grid {
    let nodes = &pair.slave_nodes;
    let points = nodes
        .iter()
        .map(|&n| {
            let (x, d) = (mesh.nodes[n as usize], u[n as usize]);
            [x[0] + d[0], x[1] + d[1], x[2] + d[2]]
        })
        .collect();
    let mut g = vtk::Grid { points, ..Default::default() };
    let local = |n: u32| nodes.binary_search(&n).ok();
    let mut kept = Vec::with_capacity(faces.len());
    for f in faces {
        if let [Some(a), Some(b), Some(c), Some(d)] = f.map(local) {
            g.push_cell(vtk::CellKind::Quad, &[a as u32, b as u32, c as u32, d as u32]);
            kept.push(*f);
        }
    }
    let nodal: Vec<f64> = (0..nodes.len()).map(&pressure).collect();
    let face = match face_pressure {
        Some(v) if kept.len() == faces.len() => v.to_vec(),
        _ => crate::post::contact_pressure::face_pressures(mesh, &kept, |n| local(n).map_or(0.0, |s| nodal[s])),
    };
    g.point_data.push(vtk::Field::scalar_f64("contact_pressure", nodal));
    g.point_data.push(vtk::Field { name: "gmsh_node_tag".into(), components: 1, values: vtk::FieldValues::I64(nodes.iter().map(|&n| mesh.node_tags[n as usize] as i64).collect()) });
    g.cell_data.push(vtk::Field::scalar_f64("contact_pressure_face", face));
    g
}

/// Contact point data on the slave nodes of every pair (state columns of
/// [`scres::CONTACT_STATE_COLUMNS`]): `contact_pressure` = −t_N (≥ 0, summed over
/// pairs), `contact_gap` g_N, `contact_lambda_n` λ_N, `contact_status` (1 active,
/// 0 open, −1 outside the master patch, −2 not a slave node). Gap and λ_N are NaN
/// off the slave nodes. An increment without states (the undeformed state) gets
/// open slave nodes with NaN gaps, so every step of a series has the same arrays.
fn push_contact_fields(out: &mut Vec<vtk::Field>, n: usize, results: &Results, states: &[Vec<[f64; 6]>]) {
    let mut pressure = vec![0.0; n];
    let mut gap = vec![f64::NAN; n];
    let mut lambda = vec![f64::NAN; n];
    let mut status = vec![-2.0; n];
    for (p, pair) in results.pairs.iter().enumerate() {
        for (s, &node) in pair.slave_nodes.iter().enumerate() {
            let i = node as usize;
            match states.get(p).and_then(|st| st.get(s)) {
                Some(&[g, t, l, code, _, _]) => {
                    pressure[i] -= t;
                    gap[i] = g;
                    lambda[i] = l;
                    status[i] = code;
                }
                None => status[i] = 0.0,
            }
        }
    }
    out.push(vtk::Field::scalar_f64("contact_pressure", pressure));
    out.push(vtk::Field::scalar_f64("contact_gap", gap));
    out.push(vtk::Field::scalar_f64("contact_lambda_n", lambda));
    out.push(vtk::Field::scalar_f64("contact_status", status));
}

/// Friction point data on the slave nodes ([`scres::FRICTION_COLUMNS`]):
/// `contact_tangential_traction` t_T (the traction the slave exerts on the master;
/// the master holds the slave back with −t_T), `contact_slip` (ξ̄ − ξ̄_n)^α ā_α of the
/// increment, `contact_stick_slip` (0 not active, 1 stick, 2 slip, −2 not a slave
/// node of a frictional pair).
fn push_friction_fields(out: &mut Vec<vtk::Field>, n: usize, results: &Results, friction: &[Vec<[f64; 9]>]) {
    let mut traction = vec![0.0; 3 * n];
    let mut slip = vec![0.0; 3 * n];
    let mut state = vec![-2.0; n];
    for (p, pair) in results.pairs.iter().enumerate() {
        let rows = friction.get(p).filter(|f| !f.is_empty());
        for (s, &node) in pair.slave_nodes.iter().enumerate() {
            let i = node as usize;
            match rows.and_then(|r| r.get(s)) {
                Some(row) => {
                    for c in 0..3 {
                        traction[3 * i + c] += row[c];
                        slip[3 * i + c] = row[3 + c];
                    }
                    state[i] = row[8];
                }
                None => state[i] = state[i].max(0.0),
            }
        }
    }
    out.push(vtk::Field::vector_f64("contact_tangential_traction", traction));
    out.push(vtk::Field::vector_f64("contact_slip", slip));
    out.push(vtk::Field::scalar_f64("contact_stick_slip", state));
}

/// Sub-quads per knot span (B-spline) or facet, per direction, in the tessellated
/// master surface.
pub const SUBDIVISIONS: usize = 8;

/// A contact model: the mesh as `output`, and per pair `<stem>_<pair>_surface.vtu`
/// (the master surface tessellated, point data `normal` = n̄ and `xi` = (ξ¹, ξ², 0))
/// and `<stem>_<pair>_net.vtu` (the control net as lines through the nodes).
pub fn write_contact_vtu(model: &ContactModel, output: &Path) -> Result<String, StageRunError> {
    if output.as_os_str() == "-" {
        return Err(StageRunError::Usage("a contact model exports to several .vtu files; give a file name, not -".into()));
    }
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "contact".into());
    let dir = output.parent().filter(|p| !p.as_os_str().is_empty()).map(Path::to_path_buf).unwrap_or_default();
    let mut written = vec![output.display().to_string()];
    vtk::mesh_grid(&model.mesh).write_vtu(output)?;
    for p in &model.pairs {
        let x: Vec<Vec3> = p.net.nodes.iter().map(|&n| Vec3::from(model.mesh.nodes[n as usize])).collect();
        let surface = dir.join(format!("{stem}_{}_surface.vtu", p.name));
        master_surface_grid(p, &x)?.write_vtu(&surface)?;
        let net = dir.join(format!("{stem}_{}_net.vtu", p.name));
        control_net_grid(p, &x, &model.mesh).write_vtu(&net)?;
        written.push(surface.display().to_string());
        written.push(net.display().to_string());
    }
    Ok(format!("wrote {}", written.join(", ")))
}

/// The master surface of a pair, [`SUBDIVISIONS`]² quads per knot span (B-spline)
/// or facet. Each span gets its own points, so the facets' normals stay per facet.
pub fn master_surface_grid(p: &ContactPair, x: &[Vec3]) -> Result<vtk::Grid, StageRunError> {
    let bad = |e: crate::spline::SplineError| StageRunError::Usage(format!("pair '{}': {e}", p.name));
    let Some(grid) = p.net.grid() else { return atlas_surface_grid(p, x) };
    let (a, b) = (grid.a, grid.b);
    enum Master {
        Bspline(BSplinePatch),
        Facet(FacetSurface),
    }
    let master = match p.master_kind {
        MasterKind::Bspline => {
            let patch = BSplinePatch::new(a, b, p.orders[0], p.orders[1]).map_err(bad)?;
            patch.check_control_net(x).map_err(bad)?;
            Master::Bspline(patch)
        }
        MasterKind::Facet => {
            let f = FacetSurface::new(a, b).map_err(bad)?;
            f.check_control_net(x).map_err(bad)?;
            Master::Facet(f)
        }
        other => return Err(StageRunError::Usage(format!("pair '{}': a {} master on one grid", p.name, other.name()))),
    };
    let spans = match &master {
        Master::Bspline(patch) => patch.n_spans(),
        Master::Facet(f) => f.n_cells(),
    };
    let eval = |cell: [usize; 2], xi: [f64; 2]| match &master {
        Master::Bspline(patch) => patch.evaluate(x, xi),
        Master::Facet(f) => {
            let mut out = SurfacePoint::default();
            f.evaluate_in_cell_into(x, cell, xi, &mut out);
            out
        }
    };
    let s = SUBDIVISIONS;
    let mut g = vtk::Grid::default();
    let (mut normal, mut xis) = (Vec::new(), Vec::new());
    for sj in 0..spans[1] {
        for si in 0..spans[0] {
            push_piece(&mut g, &mut normal, &mut xis, |u, v| {
                let xi = [(si as f64 + u as f64 / s as f64) / spans[0] as f64, (sj as f64 + v as f64 / s as f64) / spans[1] as f64];
                (xi, eval([si, sj], xi))
            });
        }
    }
    g.point_data.push(vtk::Field::vector_f64("normal", normal));
    g.point_data.push(vtk::Field::vector_f64("xi", xis));
    Ok(g)
}

/// One piece of a master surface (a knot span, a facet, a chart) as
/// ([`SUBDIVISIONS`] + 1)² points and [`SUBDIVISIONS`]² quads; `at(u, v)` gives the
/// parameter and the surface point of sample (u, v).
fn push_piece(g: &mut vtk::Grid, normal: &mut Vec<f64>, xis: &mut Vec<f64>, at: impl Fn(usize, usize) -> ([f64; 2], SurfacePoint)) {
    let s = SUBDIVISIONS;
    let base = g.points.len() as u32;
    for v in 0..=s {
        for u in 0..=s {
            let (xi, sp) = at(u, v);
            g.points.push([sp.x_bar.x, sp.x_bar.y, sp.x_bar.z]);
            normal.extend([sp.n_bar.x, sp.n_bar.y, sp.n_bar.z]);
            xis.extend([xi[0], xi[1], 0.0]);
        }
    }
    let id = |u: usize, v: usize| base + (u + (s + 1) * v) as u32;
    for v in 0..s {
        for u in 0..s {
            g.push_cell(vtk::CellKind::Quad, &[id(u, v), id(u + 1, v), id(u + 1, v + 1), id(u, v + 1)]);
        }
    }
}

/// A master of many charts (closed, multi-patch, free quads): [`SUBDIVISIONS`]² quads
/// per chart, each chart with its own points; point data `normal` and the chart
/// parameter `xi`, cell data `chart`.
fn atlas_surface_grid(p: &ContactPair, x: &[Vec3]) -> Result<vtk::Grid, StageRunError> {
    let projector = Projector::for_net(p.master_kind, p.orders, &p.net, x).map_err(|e| StageRunError::Usage(format!("pair '{}': {e}", p.name)))?;
    let Projector::Atlas(atlas) = &projector else {
        return Err(StageRunError::Usage(format!("pair '{}': a one-grid master reached the atlas export", p.name)));
    };
    let s = SUBDIVISIONS;
    let mut g = vtk::Grid::default();
    let (mut normal, mut xis, mut charts) = (Vec::new(), Vec::new(), Vec::new());
    for c in 0..atlas.atlas().n_charts() {
        push_piece(&mut g, &mut normal, &mut xis, |u, v| {
            let uv = [u as f64 / s as f64, v as f64 / s as f64];
            (uv, atlas.evaluate(c, uv))
        });
        charts.extend(std::iter::repeat_n(c as i32, s * s));
    }
    g.point_data.push(vtk::Field::vector_f64("normal", normal));
    g.point_data.push(vtk::Field::vector_f64("xi", xis));
    g.cell_data.push(vtk::Field { name: "chart".into(), components: 1, values: vtk::FieldValues::I32(charts) });
    Ok(g)
}

/// The control net as VTK lines: rows (along ξ¹) and columns (along ξ²) through the
/// net's nodes (the current coordinates `x`, in net order); point data
/// `gmsh_node_tag` and the grid position `i`, `j`. Other nets: the edges of their
/// cells, point data `gmsh_node_tag` and the node's position `k` in the net.
pub fn control_net_grid(p: &ContactPair, x: &[Vec3], mesh: &crate::mesh::Mesh) -> vtk::Grid {
    let tags = vtk::Field {
        name: "gmsh_node_tag".into(),
        components: 1,
        values: vtk::FieldValues::I64(p.net.nodes.iter().map(|&n| mesh.node_tags[n as usize] as i64).collect()),
    };
    let Some(grid) = p.net.grid() else {
        let mut g = vtk::Grid { points: x.iter().map(|v| [v.x, v.y, v.z]).collect(), ..Default::default() };
        let edges = p.net.edges();
        for (u, v) in edges {
            g.push_cell(vtk::CellKind::Line, &[u, v]);
        }
        g.point_data.push(tags);
        g.point_data.push(vtk::Field { name: "k".into(), components: 1, values: vtk::FieldValues::I32((0..x.len() as i32).collect()) });
        return g;
    };
    let (a, b) = (grid.a, grid.b);
    let mut g = vtk::Grid { points: x.iter().map(|v| [v.x, v.y, v.z]).collect(), ..Default::default() };
    let id = |i: usize, j: usize| (i + a * j) as u32;
    for j in 0..b {
        for i in 0..a - 1 {
            g.push_cell(vtk::CellKind::Line, &[id(i, j), id(i + 1, j)]);
        }
    }
    for i in 0..a {
        for j in 0..b - 1 {
            g.push_cell(vtk::CellKind::Line, &[id(i, j), id(i, j + 1)]);
        }
    }
    g.point_data.push(tags);
    g.point_data.push(vtk::Field { name: "i".into(), components: 1, values: vtk::FieldValues::I32((0..a * b).map(|k| (k % a) as i32).collect()) });
    g.point_data.push(vtk::Field { name: "j".into(), components: 1, values: vtk::FieldValues::I32((0..a * b).map(|k| (k / a) as i32).collect()) });
    g
}

fn push_stress_fields(fields: &mut Vec<vtk::Field>, s: &[stresses::Tensor9]) {
    fields.push(vtk::Field::tensor_f64("stress", s.iter().flatten().copied().collect()));
    fields.push(vtk::Field::scalar_f64("von_mises", s.iter().map(stresses::von_mises).collect()));
    let p: Vec<[f64; 3]> = s.iter().map(stresses::principal).collect();
    fields.push(vtk::Field::scalar_f64("principal_max", p.iter().map(|p| p[2]).collect()));
    fields.push(vtk::Field::scalar_f64("principal_min", p.iter().map(|p| p[0]).collect()));
}
